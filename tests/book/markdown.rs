//! Just enough Markdown for the book's tests: fenced code blocks, headings and their
//! anchors as mdBook makes them, and the targets of inline links and images.

// Each test crate that includes this module uses part of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The book's source folder and the README, relative to the repository.
pub const BOOK_SRC: &str = "docs/book/src";

/// The repository's root.
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every Markdown file of the book (sorted) and the README.
pub fn pages() -> Vec<PathBuf> {
    let mut out = Vec::new();
    collect(&repo().join(BOOK_SRC), &mut out);
    out.sort();
    out.push(repo().join("README.md"));
    out
}

fn collect(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            collect(&path, out);
        } else if path.extension().is_some_and(|e| e == "md") {
            out.push(path);
        }
    }
}

/// A fenced code block: its info string, its text and the line its fence opens on (1-based).
pub struct Block {
    pub info: String,
    pub text: String,
    pub line: usize,
}

/// A page split into its fenced code blocks and its prose (the lines outside them; the
/// fences' lines are blanked so line numbers stay).
pub fn split(text: &str) -> (Vec<Block>, String) {
    let mut blocks = Vec::new();
    let mut prose = String::new();
    let mut open: Option<(String, Block)> = None;
    for (i, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        match &mut open {
            None if trimmed.starts_with("```") => {
                let indent = line.len() - trimmed.len();
                let fence = trimmed
                    .chars()
                    .take_while(|&c| c == '`')
                    .collect::<String>();
                let info = trimmed[fence.len()..].trim().to_owned();
                let block = Block {
                    info,
                    text: String::new(),
                    line: i + 1,
                };
                open = Some((format!("{}{fence}", " ".repeat(indent)), block));
                prose.push('\n');
            }
            None => {
                prose.push_str(line);
                prose.push('\n');
            }
            Some((fence, block)) => {
                if trimmed.starts_with(fence.trim_start())
                    && trimmed.trim_end().chars().all(|c| c == '`')
                {
                    blocks.push(open.take().unwrap().1);
                } else {
                    let indent = fence.len() - fence.trim_start().len();
                    let body = if line.len() >= indent && line[..indent].trim().is_empty() {
                        &line[indent..]
                    } else {
                        line
                    };
                    block.text.push_str(body);
                    block.text.push('\n');
                }
                prose.push('\n');
            }
        }
    }
    assert!(open.is_none(), "a code fence is not closed");
    (blocks, prose)
}

/// Prose with inline code spans blanked (a link inside backticks is not a link).
fn without_code_spans(prose: &str) -> String {
    let mut out = String::with_capacity(prose.len());
    let mut in_code = false;
    for c in prose.chars() {
        if c == '`' {
            in_code = !in_code;
            out.push(' ');
        } else if in_code && c != '\n' {
            out.push(' ');
        } else {
            out.push(c);
        }
    }
    out
}

/// The anchors mdBook gives the page's headings: the heading's text lower-cased, letters,
/// digits, `_` and `-` kept, spaces made `-`, anything else dropped; a repeated anchor
/// gets `-1`, `-2`, ...
pub fn anchors(prose: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for line in prose.lines() {
        let hashes = line.chars().take_while(|&c| c == '#').count();
        if !(1..=6).contains(&hashes) || !line[hashes..].starts_with(' ') {
            continue;
        }
        let id: String = line[hashes..]
            .trim()
            .chars()
            .filter_map(|c| match c {
                c if c.is_alphanumeric() || c == '_' || c == '-' => {
                    Some(c.to_lowercase().next().unwrap())
                }
                c if c.is_whitespace() => Some('-'),
                _ => None,
            })
            .collect();
        let repeats = out
            .iter()
            .filter(|a| *a == &id || a.starts_with(&format!("{id}-")))
            .count();
        out.push(if repeats == 0 {
            id
        } else {
            format!("{id}-{repeats}")
        });
    }
    out
}

/// The targets of the prose's inline links and images, `[text](target)`, with their lines.
pub fn links(prose: &str) -> Vec<(usize, String)> {
    let text = without_code_spans(prose);
    let mut out = Vec::new();
    let mut rest = text.as_str();
    let mut offset = 0;
    while let Some(at) = rest.find("](") {
        let start = at + 2;
        let Some(len) = rest[start..].find(')') else {
            break;
        };
        let target = rest[start..start + len].trim().to_owned();
        let line = text[..offset + at].matches('\n').count() + 1;
        out.push((line, target));
        offset += start + len;
        rest = &text[offset..];
    }
    out
}
