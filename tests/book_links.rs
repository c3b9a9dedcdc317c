//! Every relative link and image of the book (`docs/book/src`) and the README resolves: the
//! file exists and, with `#anchor`, the anchor is a heading of that page. Every page is in
//! the book's table of contents, so mdBook builds it.

#[path = "book/markdown.rs"]
mod markdown;

use markdown::{BOOK_SRC, anchors, links, pages, repo, split};
use std::collections::BTreeMap;
use std::path::{Component, Path, PathBuf};

/// Drops `.` and resolves `..` without touching the file system.
fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            c => out.push(c),
        }
    }
    out
}

/// Every broken link of `pages`, as `file:line: target: why`.
fn broken_links(pages: &[PathBuf]) -> Vec<String> {
    let mut anchors_of: BTreeMap<PathBuf, Vec<String>> = BTreeMap::new();
    for page in pages {
        let (_, prose) = split(&std::fs::read_to_string(page).unwrap());
        anchors_of.insert(normalize(page), anchors(&prose));
    }
    let mut broken = Vec::new();
    for page in pages {
        let (_, prose) = split(&std::fs::read_to_string(page).unwrap());
        let name = page
            .strip_prefix(repo())
            .unwrap_or(page)
            .display()
            .to_string();
        for (line, target) in links(&prose) {
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            let (file, anchor) = match target.split_once('#') {
                Some((f, a)) => (f, Some(a)),
                None => (target.as_str(), None),
            };
            let resolved = if file.is_empty() {
                normalize(page)
            } else {
                normalize(&page.parent().unwrap().join(file))
            };
            if !resolved.exists() {
                broken.push(format!("{name}:{line}: {target}: no such file"));
                continue;
            }
            if let Some(anchor) = anchor {
                match anchors_of.get(&resolved) {
                    Some(known) if known.iter().any(|a| a == anchor) => {}
                    Some(_) => {
                        broken.push(format!("{name}:{line}: {target}: no heading #{anchor}"))
                    }
                    None => broken.push(format!(
                        "{name}:{line}: {target}: an anchor into a non-page"
                    )),
                }
            }
        }
    }
    broken
}

#[test]
fn every_link_of_the_book_and_the_readme_resolves() {
    let pages = pages();
    assert!(
        pages.len() > 20,
        "the book's pages were not found: {pages:?}"
    );
    let broken = broken_links(&pages);
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn a_broken_link_or_anchor_is_found() {
    let dir = tempfile::tempdir().unwrap();
    let page = dir.path().join("a.md");
    std::fs::write(dir.path().join("b.md"), "# Title\n\n## Some `code` here\n").unwrap();
    std::fs::write(
        &page,
        "# A\n\n[ok](b.md#some-code-here) [ok](#a) `[not a link](nowhere.md)`\n\
         [gone](c.md)\n[bad anchor](b.md#title-2)\n```\n[in code](nowhere.md)\n```\n",
    )
    .unwrap();
    let pages = [page, dir.path().join("b.md")];
    let broken = broken_links(&pages);
    assert_eq!(broken.len(), 2, "{broken:?}");
    assert!(broken[0].ends_with(":4: c.md: no such file"), "{broken:?}");
    assert!(
        broken[1].ends_with(":5: b.md#title-2: no heading #title-2"),
        "{broken:?}"
    );
}

#[test]
fn every_page_is_in_the_table_of_contents() {
    let src = repo().join(BOOK_SRC);
    let summary = std::fs::read_to_string(src.join("SUMMARY.md")).unwrap();
    let (_, prose) = split(&summary);
    let listed: Vec<PathBuf> = links(&prose)
        .into_iter()
        .map(|(_, t)| src.join(t))
        .collect();
    let missing: Vec<_> = pages()
        .into_iter()
        .filter(|p| p.starts_with(&src) && !p.ends_with("SUMMARY.md") && !listed.contains(p))
        .collect();
    assert!(missing.is_empty(), "pages not in SUMMARY.md: {missing:?}");
}

#[test]
fn the_readme_stays_short_and_points_into_the_book() {
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(
        lines <= 250,
        "README.md has {lines} lines; the book is for the rest"
    );
    let (_, prose) = split(&readme);
    let into_book = links(&prose)
        .iter()
        .filter(|(_, t)| t.starts_with("docs/book/src/"))
        .count();
    assert!(
        into_book >= 10,
        "the README links {into_book} times into the book"
    );
    for needed in [
        "cargo run --release -- trace scenes/notebook14",
        "bash tools/test.sh",
        "-- --ignored",
    ] {
        assert!(readme.contains(needed), "the README lost `{needed}`");
    }
}
