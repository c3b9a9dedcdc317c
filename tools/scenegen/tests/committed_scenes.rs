//! The committed `scenes/` folder must be exactly what the generator writes: regenerate
//! into a temporary folder and compare byte for byte, both ways.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn committed_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// Every file below `root`, as `/`-separated relative paths.
fn list(root: &Path) -> BTreeSet<String> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeSet<String>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                let rel = p.strip_prefix(root).unwrap();
                let parts: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                out.insert(parts.join("/"));
            }
        }
    }
    let mut out = BTreeSet::new();
    walk(root, root, &mut out);
    out
}

#[test]
fn committed_scenes_match_the_generator() {
    let tmp = std::env::temp_dir().join(format!("scenegen-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    let files = scenegen::write_all(&tmp).expect("write scenes");
    let committed = committed_dir();
    let generated = list(&tmp);
    let present = list(&committed);
    let hint = "run `cargo run -p scenegen --release` in the workspace root and commit scenes/";
    let missing: Vec<_> = generated.difference(&present).collect();
    // Files made by other tools (the CAD exports of tools/cad/) are committed, not generated.
    let external = scenegen::scenes::cad_reflector::EXPORTED;
    let extra: Vec<_> = present
        .difference(&generated)
        .filter(|f| !external.contains(&f.as_str()))
        .collect();
    let mut differing = Vec::new();
    for f in &files {
        let a = std::fs::read(tmp.join(&f.path)).unwrap();
        assert_eq!(
            a, f.bytes,
            "{}: written bytes differ from generated",
            f.path
        );
        if std::fs::read(committed.join(&f.path)).is_ok_and(|b| a != b) {
            differing.push(f.path.clone());
        }
    }
    std::fs::remove_dir_all(&tmp).unwrap();
    assert!(
        missing.is_empty() && extra.is_empty() && differing.is_empty(),
        "scenes/ is stale ({hint}):\n  not committed: {missing:?}\n  not generated: {extra:?}\n  differ: {differing:?}"
    );
}

#[test]
fn generation_is_deterministic() {
    assert_eq!(scenegen::all_files(), scenegen::all_files());
}

#[test]
fn test_scenes_are_small() {
    use scenegen::scenes::*;
    for (name, parts) in [
        ("test/slab", test_slab::parts()),
        ("test/slab-edge-lit", test_slab_edge_lit::parts()),
        ("test/two-tags", test_two_tags::parts()),
    ] {
        let n: usize = parts.iter().map(|p| p.triangle_count()).sum();
        assert!(n < 1000, "{name}: {n} triangles");
    }
}
