//! What the targets share: a per-process scratch folder holding fixture files, the fuzz
//! input written as a file in it (the loaders read regular files by path), and the fixed
//! scene files that name that input.
//!
//! The folder is `/dev/shm/blutrace-fuzz-<target>-<pid>` (else under the system temp
//! folder); libFuzzer ends the process without running destructors, so `tools/fuzz.sh`
//! removes these folders after each run.

#![allow(dead_code)]

use blutrace::scene::Scene;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// `fuzz/fixtures`, found at run time (the fixtures are copied, never written).
pub const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures");

/// The scene every mesh target loads (`@FILE@`, `@TAG@` filled in).
pub const MESH_SCENE: &str = include_str!("../../fixtures/mesh-scene.toml");

/// The scene the intensity targets load (`@FILE@` filled in).
pub const INTENSITY_SCENE: &str = include_str!("../../fixtures/intensity-scene.toml");

static DIR: OnceLock<PathBuf> = OnceLock::new();

/// This process's scratch folder, created on first use with the files of the fixture
/// folders `fixtures` (names relative to `fuzz/fixtures`) copied into it, and each of
/// `files` (name, contents) written.
pub fn workdir(target: &str, fixtures: &[&str], files: &[(&str, &str)]) -> &'static Path {
    DIR.get_or_init(|| {
        let shm = Path::new("/dev/shm");
        let base = if shm.is_dir() {
            shm.to_path_buf()
        } else {
            std::env::temp_dir()
        };
        let dir = base.join(format!("blutrace-fuzz-{target}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create the scratch folder");
        for f in fixtures {
            let from = Path::new(FIXTURES).join(f);
            for entry in std::fs::read_dir(&from).expect("read a fixture folder") {
                let entry = entry.unwrap();
                if entry.file_type().unwrap().is_file() {
                    std::fs::copy(entry.path(), dir.join(entry.file_name()))
                        .expect("copy a fixture");
                }
            }
        }
        for (name, text) in files {
            std::fs::write(dir.join(name), text).expect("write a fixture");
        }
        dir
    })
}

/// With `BLUTRACE_FUZZ_VERBOSE=1` set, print what a load returned (to see how far the
/// seeds get: `cargo fuzz run TARGET seeds/TARGET -- -runs=0`).
pub fn report<T>(what: &str, r: &anyhow::Result<T>) {
    static ON: OnceLock<bool> = OnceLock::new();
    if *ON.get_or_init(|| std::env::var_os("BLUTRACE_FUZZ_VERBOSE").is_some()) {
        match r {
            Ok(_) => eprintln!("{what}: Ok"),
            Err(e) => eprintln!("{what}: {e:#}"),
        }
    }
}

/// Write the fuzz input as `dir/name` and return its path.
pub fn put(dir: &Path, name: &str, data: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, data).expect("write the fuzz input");
    path
}

/// The mesh scene for geometry file `file`, with `tag = "lgp"` when `tagged`.
pub fn mesh_scene(file: &str, tagged: bool) -> String {
    MESH_SCENE
        .replace("@FILE@", file)
        .replace("@TAG@", if tagged { "tag = \"lgp\"" } else { "" })
}

/// A mesh target: the input is geometry file `name` of the fixed mesh scene, which is
/// loaded whole (reader, tags, closed-solid orientation, media and lamp checks). An `Err`
/// is the intended outcome for a bad file; only panics, aborts, hangs and memory blow-ups
/// are findings.
pub fn mesh_case(target: &str, name: &str, tagged: bool, data: &[u8]) {
    let scene = mesh_scene(name, tagged);
    let dir = workdir(target, &["gltf"], &[("scene.toml", &scene)]);
    put(dir, name, data);
    let loaded = Scene::load(&dir.join("scene.toml"));
    report("scene", &loaded);
    if let Ok(scene) = loaded {
        // Cheap derived quantities a trace starts from.
        let _ = scene.content_hash();
        let _ = scene.triangles_per_tag();
    }
}

/// An intensity target: the input is the table `name` (`led.ies` or `led.csv`), read by
/// `IntensityProfile::read`; a table it accepts is sampled (every result must be a
/// finite angle within [0, 90] degrees and a probability within [0, 1]), then the fixed
/// slab scene whose LED names it is loaded.
pub fn intensity_case(target: &str, name: &str, data: &[u8]) {
    use blutrace::sources::intensity::IntensityProfile;
    let scene = INTENSITY_SCENE.replace("@FILE@", name);
    let dir = workdir(
        target,
        &[],
        &[("scene.toml", &scene), ("slab.obj", SLAB_OBJ)],
    );
    let path = put(dir, name, data);
    let read = IntensityProfile::read(&path);
    report("table", &read);
    let Ok(p) = read else {
        return;
    };
    let half_pi = std::f64::consts::FRAC_PI_2;
    for k in 0..=64 {
        let u = k as f64 / 64.0;
        let t = p.sample_theta(u);
        assert!(
            t.is_finite() && (0.0..=half_pi).contains(&t),
            "sample_theta({u}) = {t}"
        );
        let i = p.intensity(t);
        assert!(i.is_finite() && i >= 0.0, "intensity({t}) = {i}");
        let q = p.probability(0.0, t);
        assert!(
            q.is_finite() && (-1e-9..=1.0 + 1e-9).contains(&q),
            "probability(0, {t}) = {q}"
        );
    }
    report("scene", &Scene::load(&dir.join("scene.toml")));
}

/// test/slab's box (tags lgp_front, lgp_back, lgp_edge).
pub const SLAB_OBJ: &str = include_str!("../../fixtures/scene/slab.obj");
