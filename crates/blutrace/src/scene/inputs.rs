//! The files a scene reads: the scene file itself, its geometry files (and a glTF file's
//! buffer files), and every table, spectrum, placement and ray file its surfaces and
//! sources name.
//!
//! ```toml
//! [[geometry]]
//! file = "guide.gltf"          # read, and its buffers[].uri files beside it
//! [surfaces.film]
//! model = "bsdf_table"
//! file = "film.bsdf"           # read
//! [[sources]]
//! type = "rayfile"
//! file = "led.TM25RAY"         # read
//! ```
//!
//! Output writers refuse a destination that is, or holds, one of these
//! ([`crate::output::atomic::check_apart`]): a run never deletes or replaces what it reads.

use super::config::SceneFile;
use std::path::{Path, PathBuf};

/// Every file loading the scene file `path` (parsed as `file`) reads, as the scene names
/// them joined to its folder (so relative to the working directory when `path` is).
pub fn input_files(file: &SceneFile, path: &Path) -> Vec<PathBuf> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut files = vec![path.to_path_buf()];
    for g in &file.geometry {
        let geometry = dir.join(&g.file);
        files.extend(gltf_buffer_files(&geometry));
        files.push(geometry);
    }
    files.extend(table_files(file).map(|f| dir.join(f)));
    files
}

/// The measured tables, spectra and ray files the surfaces and sources of `file` name,
/// relative to the scene file (the content hash covers their bytes too).
pub(super) fn table_files(file: &SceneFile) -> impl Iterator<Item = PathBuf> + '_ {
    let surfaces = file.surfaces.values().flat_map(|s| s.files());
    surfaces.chain(file.sources.iter().flat_map(|s| s.files()))
}

/// The files a `.gltf` file's `buffers[].uri` name beside it (none for `.glb`, embedded
/// `data:` buffers, or a file that does not parse: loading reports those).
fn gltf_buffer_files(gltf: &Path) -> Vec<PathBuf> {
    let is_gltf = gltf
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf"));
    let text = match is_gltf {
        true => crate::input_file::read_text(gltf, "geometry file").ok(),
        false => None,
    };
    let Some(json) = text.and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok()) else {
        return Vec::new();
    };
    let base = gltf.parent().unwrap_or(Path::new("."));
    let uris = json["buffers"].as_array().cloned().unwrap_or_default();
    uris.iter()
        .filter_map(|b| b["uri"].as_str())
        .filter(|u| !u.starts_with("data:"))
        .map(|u| base.join(super::meshio::percent_decoded(u)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gltf_file_brings_its_buffer_files() {
        let dir = tempfile::tempdir().unwrap();
        let gltf = dir.path().join("part.gltf");
        let json = r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"my%20part.bin","byteLength":4},{"uri":"data:application/octet-stream;base64,AAAA","byteLength":3}]}"#;
        std::fs::write(&gltf, json).unwrap();
        assert_eq!(
            gltf_buffer_files(&gltf),
            vec![dir.path().join("my part.bin")]
        );
        assert!(gltf_buffer_files(&dir.path().join("part.glb")).is_empty());
    }
}
