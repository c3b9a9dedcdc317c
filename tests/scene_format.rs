//! The scene file format round-trips: every bundled scene, parsed into a `SceneFile` and
//! written back as TOML, parses to the same `SceneFile`, with each surface's `model` tag
//! and each source's `type` tag in place.

use blutrace::scene::config::SceneFile;
use std::path::Path;

fn scene_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            scene_files(&p, out);
        } else if p.file_name().is_some_and(|n| n == "scene.toml") {
            out.push(p);
        }
    }
}

#[test]
fn every_bundled_scene_file_round_trips_through_toml() {
    let mut files = Vec::new();
    scene_files(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes"),
        &mut files,
    );
    assert!(files.len() >= 5, "found {} scene files", files.len());
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let file: SceneFile = toml::from_str(&text).unwrap();
        let written = toml::to_string(&file).unwrap();
        let again: SceneFile = toml::from_str(&written)
            .unwrap_or_else(|e| panic!("{}: the written file does not parse: {e}", f.display()));
        assert_eq!(format!("{file:?}"), format!("{again:?}"), "{}", f.display());
        let table: toml::Table = toml::from_str(&written).unwrap();
        for (tag, s) in table["surfaces"].as_table().unwrap() {
            assert!(
                s.get("model").is_some(),
                "{}: surfaces.{tag} lost its model",
                f.display()
            );
        }
        for s in table["sources"].as_array().unwrap() {
            assert!(
                s.get("type").is_some(),
                "{}: a source lost its type",
                f.display()
            );
        }
    }
}
