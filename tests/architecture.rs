//! The library's shape, checked: no two modules of `crates/blutrace/src` import each
//! other (a two-module circle means one concept split over two files, or a layer reaching
//! up), no source file is longer than about 800 lines, and no library file mentions the
//! command-line parser or the benchmarks.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Longest source file accepted (lines): the guide's "about 800", with room for a doc
/// comment or two.
const MAX_LINES: usize = 850;

fn library_src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("crates/blutrace/src")
}

/// Every `.rs` file under `dir`.
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(sources(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
    out.sort();
    out
}

/// The module path of a file (`optics/dots.rs` -> `optics::dots`).
fn module_of(root: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(root).unwrap().with_extension("");
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
        parts.pop();
    }
    parts
}

/// The code of a file without its test module and comment lines.
fn code(text: &str) -> String {
    let text = text.split("#[cfg(test)]\nmod tests").next().unwrap_or(text);
    text.lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The paths `crate::a::b`, `super::c`, `self::d` a file's code names.
fn named_paths(code: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let bytes = code.as_bytes();
    for start in ["crate::", "super::", "self::"] {
        let mut from = 0;
        while let Some(i) = code[from..].find(start) {
            let at = from + i;
            from = at + start.len();
            if at > 0 && (bytes[at - 1].is_ascii_alphanumeric() || bytes[at - 1] == b'_') {
                continue;
            }
            let rest = &code[at..];
            let end = rest
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(rest.len());
            let segments = rest[..end].split("::").filter(|s| !s.is_empty());
            out.push(segments.map(str::to_string).collect());
        }
    }
    out
}

/// The module a path names, resolved from module `current` against the known modules.
fn resolve(
    current: &[String],
    path: &[String],
    modules: &BTreeSet<Vec<String>>,
) -> Option<Vec<String>> {
    let (mut base, mut rest): (Vec<String>, &[String]) = match path.first()?.as_str() {
        "crate" => (Vec::new(), &path[1..]),
        "self" => (current.to_vec(), &path[1..]),
        "super" => (current.to_vec(), path),
        _ => return None,
    };
    while rest.first().is_some_and(|s| s == "super") {
        base.pop();
        rest = &rest[1..];
    }
    (0..=rest.len())
        .rev()
        .map(|k| [base.clone(), rest[..k].to_vec()].concat())
        .find(|m| modules.contains(m))
}

/// `a` is `b` or one holds the other (a parent uses its children freely).
fn nested(a: &[String], b: &[String]) -> bool {
    a.starts_with(b) || b.starts_with(a)
}

#[test]
fn no_two_library_modules_import_each_other() {
    let root = library_src();
    let files = sources(&root);
    let modules: BTreeSet<Vec<String>> = files.iter().map(|f| module_of(&root, f)).collect();
    let mut edges: BTreeMap<(Vec<String>, Vec<String>), String> = BTreeMap::new();
    for file in &files {
        let from = module_of(&root, file);
        let text = std::fs::read_to_string(file).unwrap();
        for path in named_paths(&code(&text)) {
            if let Some(to) = resolve(&from, &path, &modules)
                && !nested(&from, &to)
            {
                edges.entry((from.clone(), to)).or_insert(path.join("::"));
            }
        }
    }
    assert!(
        edges.len() > 100,
        "the scan found only {} imports",
        edges.len()
    );
    let circles: Vec<String> = edges
        .iter()
        .filter(|((a, b), _)| a < b && edges.contains_key(&(b.clone(), a.clone())))
        .map(|((a, b), via)| {
            let back = &edges[&(b.clone(), a.clone())];
            format!(
                "{} -> {} ({via}) and back ({back})",
                a.join("::"),
                b.join("::")
            )
        })
        .collect();
    assert!(
        circles.is_empty(),
        "import circles:\n{}",
        circles.join("\n")
    );
}

#[test]
fn source_files_stay_short_and_the_library_stays_a_library() {
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for dir in [
        "src",
        "crates/blutrace/src",
        "crates/bench/src",
        "python/src",
    ] {
        files.extend(sources(&workspace.join(dir)));
    }
    assert!(files.len() > 50, "found only {} files", files.len());
    let long: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let n = std::fs::read_to_string(f).unwrap().lines().count();
            (n > MAX_LINES).then(|| format!("{}: {n} lines", f.display()))
        })
        .collect();
    assert!(
        long.is_empty(),
        "files over {MAX_LINES} lines:\n{}",
        long.join("\n")
    );
    for file in sources(&library_src()) {
        let text = code(&std::fs::read_to_string(&file).unwrap());
        for word in ["clap::", "blutrace_bench", "crate::cli", "crate::bench"] {
            assert!(!text.contains(word), "{} uses {word}", file.display());
        }
    }
}
