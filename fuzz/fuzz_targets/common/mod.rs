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

/// The scene the ray file targets load (`@FILE@` filled in).
pub const RAYFILE_SCENE: &str = include_str!("../../fixtures/rayfile-scene.toml");

/// The scene the bsdf target loads (`@FILE@`, `@TRISTIMULUS@` filled in).
pub const BSDF_SCENE: &str = include_str!("../../fixtures/bsdf-scene.toml");

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

/// Photons emitted, or BSDF samples drawn per angle, from a scene that loaded.
const DRAWS: u64 = 16;

/// Whether `d` is a finite unit vector.
fn unit(d: glam::DVec3) -> bool {
    d.is_finite() && (d.length() - 1.0).abs() < 1e-6
}

/// A ray file target: the input is the ray file `name` (`led.TM25RAY` or `led.txt`) of
/// the fixed slab scene (fuzz/fixtures/rayfile-scene.toml), loaded whole by `Scene::load`
/// (reader, placement and lamp checks, alias table, spectrum); a scene that loads emits
/// a few photons, each of which must start at a finite point with a unit direction and,
/// in a spectral scene, a wavelength within 360-830 nm.
pub fn rayfile_case(target: &str, name: &str, data: &[u8]) {
    let scene = RAYFILE_SCENE.replace("@FILE@", name);
    let dir = workdir(
        target,
        &[],
        &[("scene.toml", &scene), ("slab.obj", SLAB_OBJ)],
    );
    put(dir, name, data);
    let loaded = Scene::load(&dir.join("scene.toml"));
    report("scene", &loaded);
    let Ok(scene) = loaded else {
        return;
    };
    let (lo, hi) = blutrace::sources::spectrum::VISIBLE_NM;
    for i in 0..DRAWS {
        let mut rng = blutrace::rng::PhotonRng::new(1, i);
        let e = scene.sources.sample(&mut rng);
        let (o, d) = (e.ray.origin, e.ray.dir);
        assert!(o.is_finite() && unit(d), "photon {i}: from {o} along {d}");
        let nm = e.light.nm();
        let ok = (lo..=hi).contains(&nm) || !scene.sources.spectral();
        assert!(ok, "photon {i}: wavelength {nm} nm");
    }
}

/// The bsdf target: the input is the IS BSDF file `t.bsdf` scattering on the back face of
/// the fixed slab scene (fuzz/fixtures/bsdf-scene.toml; `tristimulus = "Y"` when the input
/// names XYZ), loaded whole by `Scene::load` (parser, tables, TIS checks); a table that
/// loads is sampled at a few angles of incidence from both sides, and every scattered
/// direction must be a finite unit vector with a finite weight within [0, 1].
pub fn bsdf_case(target: &str, data: &[u8]) {
    let xyz = data.windows(3).any(|w| w.eq_ignore_ascii_case(b"xyz"));
    let channel = if xyz { "tristimulus = \"Y\"" } else { "" };
    let scene = BSDF_SCENE
        .replace("@FILE@", "t.bsdf")
        .replace("@TRISTIMULUS@", channel);
    let dir = workdir(target, &[], &[("slab.obj", SLAB_OBJ)]);
    std::fs::write(dir.join("scene.toml"), scene).expect("write the scene");
    put(dir, "t.bsdf", data);
    let loaded = Scene::load(&dir.join("scene.toml"));
    report("scene", &loaded);
    if let Ok(scene) = loaded {
        scatter_back_face(&scene);
    }
}

/// Photons arriving at the slab's back face (tag `lgp_back`) at 0-89 degrees, from air
/// below and from the PMMA above, scattered by its model.
fn scatter_back_face(scene: &Scene) {
    let tag = scene.tags.iter().position(|t| t == "lgp_back");
    let pmma = scene.media.iter().position(|m| m.name == "pmma");
    let (Some(tag), Some(pmma)) = (tag, pmma) else {
        panic!("the fixture scene has lgp_back and pmma");
    };
    for deg in [0.0f64, 30.0, 60.0, 89.0] {
        let (s, c) = deg.to_radians().sin_cos();
        scatter_from(scene, tag, glam::DVec3::new(s, 0.0, c), 0);
        scatter_from(scene, tag, glam::DVec3::new(s, 0.0, -c), pmma as u16);
    }
}

/// [`DRAWS`] photons along `dir` in medium `medium` meeting the back face (normal -z) of
/// tag `tag`, analog and weighted: every one that leaves goes along a unit direction with
/// a weight within [0, 1].
fn scatter_from(scene: &Scene, tag: usize, dir: glam::DVec3, medium: u16) {
    use blutrace::estimator::Estimator;
    use blutrace::optics::surface::Outcome;
    let hit = blutrace::geometry::SurfaceHit {
        t: 1.0,
        prim: 0,
        point: glam::DVec3::new(10.0, 10.0, 0.0),
        normal: -glam::DVec3::Z,
    };
    for est in [Estimator::Analog, Estimator::Weighted] {
        for i in 0..DRAWS {
            let mut rng = blutrace::rng::PhotonRng::new(2, i);
            let out = scene.surfaces[tag].interact(&scene.media, &hit, dir, medium, est, &mut rng);
            if let Outcome::Scattered { dir: d, weight, .. } = out {
                let w_ok = weight.is_finite() && (0.0..=1.0 + 1e-9).contains(&weight);
                assert!(unit(d) && w_ok, "from {dir}: to {d}, weight {weight}");
            }
        }
    }
}
