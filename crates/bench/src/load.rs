//! Loading a CAD-sized scene as a user's file is loaded: the bench scene with its lamp
//! reflectors split into about 540k triangles, written to a temporary folder as one OBJ
//! and read back with every load check (closed solids, media, lamp placement, contacts,
//! the detector). Checks that visit every triangle for every lamp point are what make a
//! large mesh slow to open (such checks once took 17 s on this mesh), so the bench keeps
//! the load time in view, beside the tracing rate of the same mesh.
//!
//! ```text
//! blutrace bench        # the "loading" row: seconds, and photons traced in that time
//! ```

use anyhow::{Context, Result};
use blutrace::run::metrics::median;
use blutrace::scene::Scene;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// The large scene's load time.
#[derive(Clone, Debug, serde::Serialize)]
pub struct LoadRow {
    /// Triangles in the loaded scene.
    pub triangles: usize,
    /// Size of the OBJ file read (bytes).
    pub obj_bytes: usize,
    /// Median seconds of `Scene::load` (reading, checks, recentring).
    pub seconds: f64,
}

/// The OBJ and the scene file that loads it, in the temporary folder.
const OBJ: &str = "large.obj";

/// Load the scene of `scene_dir` with its lamp reflectors split into 4^5 triangles each,
/// `repeat` times (median), from files written to a temporary folder.
pub fn large_load_row(scene_dir: &Path, repeat: usize) -> Result<LoadRow> {
    let toml_path = scene_dir.join("scene.toml");
    let mut scene = Scene::load(&toml_path)?;
    crate::subdivide_tag(&mut scene, "lamp_reflector", 5)?;
    let dir = tempfile::tempdir().context("cannot create a temporary folder")?;
    let obj = obj_text(&scene);
    std::fs::write(dir.path().join(OBJ), &obj)?;
    let text = std::fs::read_to_string(&toml_path)
        .with_context(|| format!("cannot read {}", toml_path.display()))?;
    let toml = one_geometry_file(&text)
        .with_context(|| format!("{}: cannot rewrite its geometry", toml_path.display()))?;
    let large_toml = dir.path().join("scene.toml");
    std::fs::write(&large_toml, toml)?;
    let mut times = Vec::new();
    let mut triangles = 0;
    for _ in 0..repeat.max(1) {
        let t = Instant::now();
        let loaded = Scene::load(&large_toml)?;
        times.push(t.elapsed().as_secs_f64());
        triangles = loaded.mesh.len();
    }
    Ok(LoadRow {
        triangles,
        obj_bytes: obj.len(),
        seconds: median(times),
    })
}

/// The scene's mesh as OBJ text in the scene file's frame (the loaded mesh is recentred),
/// one `usemtl` per run of a tag; coordinates in Rust's shortest exact form, so the
/// file holds the mesh bit for bit.
fn obj_text(scene: &Scene) -> String {
    let mesh = &scene.mesh;
    let mut s = String::with_capacity(64 * mesh.positions.len() + 32 * mesh.len());
    for p in &mesh.positions {
        let q = *p + scene.offset;
        let _ = writeln!(s, "v {:?} {:?} {:?}", q.x, q.y, q.z);
    }
    let mut tag = None;
    for (t, tri) in mesh.tri_tag.iter().zip(&mesh.triangles) {
        if tag != Some(*t) {
            let _ = writeln!(s, "usemtl {}", scene.tags[*t as usize]);
            tag = Some(*t);
        }
        let _ = writeln!(s, "f {} {} {}", tri[0] + 1, tri[1] + 1, tri[2] + 1);
    }
    s
}

/// `text` (a scene file) with its geometry replaced by the one OBJ [`OBJ`] in scene
/// millimetres: the geometry files and the procedural parts, all in the written mesh.
fn one_geometry_file(text: &str) -> Result<String> {
    let mut doc: toml::Table = toml::from_str(text)?;
    let mut entry = toml::Table::new();
    entry.insert("file".into(), OBJ.into());
    doc.insert("geometry".into(), toml::Value::Array(vec![entry.into()]));
    doc.remove("procedural");
    Ok(toml::to_string(&doc)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The written scene loads to the same mesh, tags and sources as the original (the
    /// bench times the load of the scene it means to).
    #[test]
    fn the_written_scene_is_the_scene() {
        let dir =
            Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes/edge-holder");
        let scene = Scene::load(&dir.join("scene.toml")).unwrap();
        let tmp = tempfile::tempdir().unwrap();
        std::fs::write(tmp.path().join(OBJ), obj_text(&scene)).unwrap();
        let text = std::fs::read_to_string(dir.join("scene.toml")).unwrap();
        let path = tmp.path().join("scene.toml");
        std::fs::write(&path, one_geometry_file(&text).unwrap()).unwrap();
        let copy = Scene::load(&path).unwrap();
        assert_eq!(copy.mesh.positions, scene.mesh.positions);
        assert_eq!(copy.mesh.triangles, scene.mesh.triangles);
        assert_eq!(copy.tags, scene.tags);
        assert_eq!(copy.offset, scene.offset);
        assert_eq!(copy.sources.list.len(), scene.sources.list.len());
    }
}
