//! Shared helpers for integration tests: tiny scenes written to temporary folders.
#![allow(dead_code)]

pub mod bsdf;

use blutrace::accel::BackendChoice;
use blutrace::optics::dots::{Density, DotPattern, Gradation, Lattice, Placement, XUnit};
use blutrace::run::{self, RunOptions, RunResult};
use blutrace::scene::Scene;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// OBJ text for an axis-aligned box with one tag per face, in the order
/// -x, +x, -y, +y, -z, +z. Faces are wound outward.
pub fn box_obj(min: [f64; 3], max: [f64; 3], tags: [&str; 6]) -> String {
    let mut s = String::new();
    for i in 0..8 {
        let p = [
            if i & 1 == 0 { min[0] } else { max[0] },
            if i & 2 == 0 { min[1] } else { max[1] },
            if i & 4 == 0 { min[2] } else { max[2] },
        ];
        writeln!(s, "v {} {} {}", p[0], p[1], p[2]).unwrap();
    }
    // Corner index = x + 2y + 4z (1-based in OBJ), quads wound outward.
    let faces = [
        [0, 4, 6, 2], // -x
        [1, 3, 7, 5], // +x
        [0, 1, 5, 4], // -y
        [2, 6, 7, 3], // +y
        [0, 2, 3, 1], // -z
        [4, 5, 7, 6], // +z
    ];
    for (f, tag) in faces.iter().zip(tags) {
        writeln!(s, "usemtl {tag}").unwrap();
        writeln!(s, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1).unwrap();
        writeln!(s, "f {} {} {}", f[0] + 1, f[2] + 1, f[3] + 1).unwrap();
    }
    s
}

/// A scene written to a temporary folder: derefs to the scene file's path; the folder is
/// removed when this is dropped.
pub struct SceneDir {
    path: PathBuf,
    _dir: tempfile::TempDir,
}

impl std::ops::Deref for SceneDir {
    type Target = Path;

    fn deref(&self) -> &Path {
        &self.path
    }
}

impl AsRef<Path> for SceneDir {
    fn as_ref(&self) -> &Path {
        &self.path
    }
}

/// A fresh temporary folder named after `label`, removed on drop. The label is made a
/// plain file name first (letters, digits, `-`, `_`; anything else becomes `-`): a case
/// label such as "above pi/4" must never name a path under a folder that may not exist.
pub fn temp_folder(label: &str) -> tempfile::TempDir {
    let safe: String = label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '-'
            }
        })
        .collect();
    tempfile::Builder::new()
        .prefix(&format!("blutrace-{safe}-"))
        .tempdir()
        .unwrap_or_else(|e| panic!("cannot create a temporary folder for {label:?}: {e}"))
}

/// Write a scene (scene.toml plus named files) into a fresh temporary folder.
pub fn write_scene(name: &str, toml: &str, files: &[(&str, &str)]) -> SceneDir {
    let dir = temp_folder(&format!("test-{name}"));
    for (f, text) in files {
        std::fs::write(dir.path().join(f), text).unwrap();
    }
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, toml).unwrap();
    SceneDir { path, _dir: dir }
}

/// Load a scene written by [`write_scene`], panicking with the loader's message.
pub fn load(path: &Path) -> Scene {
    Scene::load(path).unwrap_or_else(|e| panic!("{e:#}"))
}

/// Trace `photons` photons with the BVH backend.
pub fn trace(scene: &Scene, photons: u64, seed: u64, threads: usize) -> RunResult {
    trace_with(scene, photons, seed, threads, BackendChoice::Bvh)
}

/// Trace with a chosen backend.
pub fn trace_with(
    scene: &Scene,
    photons: u64,
    seed: u64,
    threads: usize,
    backend: BackendChoice,
) -> RunResult {
    let opts = RunOptions {
        photons,
        seed,
        threads: Some(threads),
        backend,
        ..RunOptions::default()
    };
    run::trace(scene, &opts, &|_| {}).unwrap_or_else(|e| panic!("{e:#}"))
}

/// Trace with options given in full.
pub fn trace_opts(scene: &Scene, opts: &RunOptions) -> RunResult {
    run::trace(scene, opts, &|_| {}).unwrap_or_else(|e| panic!("{e:#}"))
}

/// Trace on two threads with the BVH backend and `estimator`, and check that the ledger
/// balances.
pub fn trace_balanced(
    scene: &Scene,
    photons: u64,
    seed: u64,
    estimator: blutrace::optics::surface::Estimator,
) -> RunResult {
    let r = trace_opts(
        scene,
        &RunOptions {
            photons,
            seed,
            threads: Some(2),
            backend: BackendChoice::Bvh,
            estimator,
            ..RunOptions::default()
        },
    );
    assert_balanced(&r);
    r
}

/// The fraction of the emitted power `f` picks out of a run's ledger, and its standard
/// error from the spread of the run's photon groups (those holding photons).
pub fn ledger_fraction(r: &RunResult, f: &dyn Fn(&blutrace::tally::Ledger) -> f64) -> (f64, f64) {
    let l = &r.tally.ledger;
    let parts: Vec<f64> = r
        .groups
        .iter()
        .filter(|g| g.ledger.photons > 0)
        .map(|g| f(&g.ledger) / g.ledger.photons as f64)
        .collect();
    let k = parts.len() as f64;
    let mean = parts.iter().sum::<f64>() / k;
    let var = parts.iter().map(|p| (p - mean).powi(2)).sum::<f64>() / (k - 1.0);
    (f(l) / l.photons as f64, (var / k).sqrt())
}

/// What `blutrace check SCENE` (with `--json` when `json`) prints; panics, showing its
/// stderr, when it fails.
pub fn check_output(scene: &Path, json: bool) -> String {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_blutrace"));
    cmd.arg("check").arg(scene);
    if json {
        cmd.arg("--json");
    }
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Assert that the ledger balances exactly (every photon has one fate).
pub fn assert_balanced(r: &RunResult) {
    let l = &r.tally.ledger;
    assert_eq!(l.accounted(), l.emitted, "ledger does not balance");
    assert_eq!(l.emitted.value(), l.photons as f64);
    let groups: u64 = r.groups.iter().map(|g| g.ledger.photons).sum();
    assert_eq!(groups, l.photons, "group tallies do not add up to the run");
}

/// Assert that one of `scene`'s warnings contains `needle` (listing them if none does).
#[track_caller]
pub fn assert_warns(scene: &Scene, needle: &str) {
    assert!(
        scene.warnings.iter().any(|w| w.contains(needle)),
        "no warning contains {needle:?}: {:?}",
        scene.warnings
    );
}

/// Fraction `k / n` and whether it is within `z` standard errors of `p`.
pub fn within_sigma(k: f64, n: f64, p: f64, z: f64) -> (f64, f64, bool) {
    let frac = k / n;
    let sigma = (p * (1.0 - p) / n).sqrt();
    (frac, sigma, (frac - p).abs() <= z * sigma)
}

/// A small edge-lit plate with graded dots, an absorbing PMMA and a Lambert back sheet.
pub fn plate_scene(name: &str) -> Scene {
    let led = "[[sources]]\ntype = \"led\"\ncenter = [-10.001, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\n\
               u = [0.0, 1.0, 0.0]\nwidth_mm = 10.0\nheight_mm = 0.5\npower_w = 2.0\n";
    let plate = box_obj(
        [-10.0, -10.0, -0.5],
        [10.0, 10.0, 0.5],
        ["edge", "edge", "edge", "edge", "dots", "face"],
    );
    let sheet = "v -12 -12 -0.7\nv 12 -12 -0.7\nv 12 12 -0.7\nv -12 12 -0.7\nusemtl sheet\nf 1 2 3\nf 1 3 4\n";
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"plate.obj\"\n[[geometry]]\nfile = \"sheet.obj\"\n\
         [media.pmma]\nn = 1.49\nabsorption_per_mm = 0.02\n\
         [surfaces.face]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.edge]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.sheet]\nmodel = \"lambert\"\nalbedo = 0.8\n\
         [surfaces.dots]\nmodel = \"dots\"\ninside = \"pmma\"\nink_albedo = 0.7\nlattice = \"square\"\npitch_mm = 0.5\n\
         origin = [-10.0, 0.0, -0.5]\naxis = [1.0, 0.0, 0.0]\nlength_mm = 20.0\ndensity = [0.1, 0.4]\n{led}\
         [detector]\norigin = [-10.0, -10.0, 0.6]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [20.0, 20.0]\n\
         bins = [10, 10]\nangular_bins = [6, 8]\n"
    );
    load(&write_scene(
        name,
        &toml,
        &[("plate.obj", &plate), ("sheet.obj", sheet)],
    ))
}

/// An edge-lit box guide: 120 x 80 x 3 mm lossless PMMA lit through its x = 0 edge by a
/// Lambertian strip covering that edge, graded hex dots on the back, a Lambert sheet under
/// it and a target plane above. Long TIR paths make its photons draw many numbers each.
pub fn guide_scene(name: &str) -> Scene {
    guide_scene_with(name, "")
}

/// [`guide_scene`] with more `[surfaces.dots]` fields (TOML lines, e.g. a placement).
pub fn guide_scene_with(name: &str, dots: &str) -> Scene {
    let guide = box_obj(
        [0.0, 0.0, 0.0],
        [120.0, 80.0, 3.0],
        ["edge", "edge", "edge", "edge", "dots", "face"],
    );
    let sheet = "v -2 -2 -0.2\nv 122 -2 -0.2\nv 122 82 -0.2\nv -2 82 -0.2\nusemtl sheet\nf 1 2 3\nf 1 3 4\n";
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"guide.obj\"\n[[geometry]]\nfile = \"sheet.obj\"\n\
         [media.pmma]\nn = 1.49\n\
         [surfaces.face]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.edge]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.sheet]\nmodel = \"lambert\"\nalbedo = 0.95\n\
         [surfaces.dots]\nmodel = \"dots\"\ninside = \"pmma\"\nink_albedo = 0.9\nlattice = \"hex\"\npitch_mm = 0.5\n\
         origin = [0.0, 0.0, 0.0]\naxis = [1.0, 0.0, 0.0]\nlength_mm = 120.0\ndensity = [0.1, 0.3]\n{dots}\n\
         [[sources]]\ntype = \"led\"\ncenter = [-0.01, 40.0, 1.5]\nnormal = [1.0, 0.0, 0.0]\n\
         u = [0.0, 1.0, 0.0]\nwidth_mm = 80.0\nheight_mm = 3.0\npower_w = 1.0\n\
         [detector]\norigin = [0.0, 0.0, 3.5]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [120.0, 80.0]\nbins = [24, 16]\n"
    );
    load(&write_scene(
        name,
        &toml,
        &[("guide.obj", &guide), ("sheet.obj", sheet)],
    ))
}

/// The guide of [`guide_scene`] reduced to the question of where the light goes: 120 x 80
/// x 3 mm lossless PMMA lit through its x = 0 edge by the same Lambertian strip, every
/// face a smooth dielectric except the back (tag `dots`, the `[surfaces.dots]` fields
/// given in `dots`, `inside` already set), no sheet, and the target just beyond the far
/// edge (x = 120): its `detected_w` is the power that leaves through the far edge.
pub fn edge_lit_slab(name: &str, dots: &str) -> Scene {
    edge_lit_slab_lit_by(
        name,
        dots,
        "[[sources]]\ntype = \"led\"\ncenter = [-0.01, 40.0, 1.5]\nnormal = [1.0, 0.0, 0.0]\n\
         u = [0.0, 1.0, 0.0]\nwidth_mm = 80.0\nheight_mm = 3.0\npower_w = 1.0\n",
    )
}

/// [`edge_lit_slab`] lit by the `[[sources]]` given (TOML) instead of its strip.
pub fn edge_lit_slab_lit_by(name: &str, dots: &str, sources: &str) -> Scene {
    let guide = box_obj(
        [0.0, 0.0, 0.0],
        [120.0, 80.0, 3.0],
        ["edge", "edge", "edge", "edge", "dots", "face"],
    );
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"guide.obj\"\n[media.pmma]\nn = 1.49\n\
         [surfaces.face]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.edge]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.dots]\nmodel = \"dots\"\ninside = \"pmma\"\norigin = [0.0, 0.0, 0.0]\n\
         axis = [1.0, 0.0, 0.0]\nlength_mm = 120.0\n{dots}\n{sources}\
         [detector]\norigin = [120.01, 0.0, 0.0]\nu = [0.0, 1.0, 0.0]\nv = [0.0, 0.0, 1.0]\n\
         size_mm = [80.0, 3.0]\nbins = [8, 1]\n"
    );
    load(&write_scene(name, &toml, &[("guide.obj", &guide)]))
}

/// Wilson-Hilferty: the chi-square quantile for `k` degrees of freedom at normal score `z`.
pub fn chi2_quantile(k: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3)
}

/// Every `scene.toml` below the crate's `scenes/` folder, sorted: a new bundled scene is
/// covered without being listed anywhere.
pub fn bundled_scene_files() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.file_name().is_some_and(|n| n == "scene.toml") {
                out.push(p);
            }
        }
    }
    let mut out = Vec::new();
    walk(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes"),
        &mut out,
    );
    out.sort();
    out
}

/// A dot pattern on the plane z = 0 (face coordinates = x, y): pitch 0.5 mm, `length` mm
/// along x from the origin, dots at the lattice points.
pub fn dot_pattern(lattice: Lattice, density: Density, length: f64) -> DotPattern {
    DotPattern {
        lattice,
        pitch: 0.5,
        origin: glam::DVec3::ZERO,
        axis: glam::DVec3::X,
        across: glam::DVec3::Y,
        grade: Gradation {
            density,
            length,
            x_unit: XUnit::Normalized,
            mirror: false,
        },
        placement: Placement::Lattice,
        placement_seed: 0,
    }
}

/// The `scene.toml` of the bundled scene `name`.
pub fn repo_scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
        .join("scene.toml")
}
