//! `cad-reflector`: an edge-lit light guide whose lamp reflector is a CAD export: a
//! parabolic trough made in Blender by `tools/cad/make_reflector.py` (run headless by
//! `tools/cad/export-reflector.sh`) and exported as glTF 2.0 and OBJ. This module writes
//! the rest: the light guide and reflector sheet (`lgp.obj`) and two scene files, one
//! per export:
//!
//! ```toml
//! # scene.toml: the glTF export with Blender's defaults (metres, +y up), which are
//! # also blutrace's glTF defaults: no scale, no rotation
//! [[geometry]]
//! file = "reflector.gltf"
//!
//! # scene-obj.toml: the OBJ export, written in millimetres
//! [[geometry]]
//! file = "reflector.obj"
//! ```
//!
//! The exported files are not generated here ([`EXPORTED`]); the constants below must
//! match the Python script's.

use super::GENERATED;
use crate::shapes::{guide_box, sheet_up};
use crate::templates::{
    Ccfl, Detector, Dots, MtlNote, dotted_guide_faces, geometry, lamp_reflector, medium,
    obj_and_mtl, preamble, reflector_sheet, scene_file, trace_table,
};
use crate::{GenFile, P3, Part, dim, num, triangle_count};

/// Default photons: the map's noise floor (`cv_noise_floor`, the cv of noise alone) about
/// 0.1, so the first picture shows the backlight, not its noise (a few seconds on 2 cores;
/// `tests/bundled_scenes.rs` checks it).
const PHOTONS: u64 = 1_500_000;

/// Files below `scenes/` written by `tools/cad/export-reflector.sh`, not by scenegen.
pub const EXPORTED: &[&str] = &[
    "cad-reflector/reflector.bin",
    "cad-reflector/reflector.gltf",
    "cad-reflector/reflector.mtl",
    "cad-reflector/reflector.obj",
];

/// Light guide length along x (mm).
pub const L: f64 = 160.0;
/// Light guide width along y, the lamp's direction; also the reflector's length (mm).
pub const W: f64 = 120.0;
/// Light guide thickness (mm) (`T` in make_reflector.py).
pub const T: f64 = 6.5;
/// PMMA refractive index.
pub const N_PMMA: f64 = 1.49;
/// PMMA absorption (1/mm).
pub const ABSORPTION: f64 = 0.0003;
/// Air gap between the reflector's lips and the guide's edge face (mm).
pub const LIP_GAP: f64 = 0.3;
/// Air gap between the back face and the reflector sheet (mm).
pub const SHEET_GAP: f64 = 0.2;
/// The parabola's focal length (mm) (`FOCAL` in make_reflector.py).
pub const FOCAL: f64 = 1.2;
/// CCFL radius (mm).
pub const LAMP_R: f64 = 1.0;
/// Detector height above the front face (mm).
pub const DETECTOR_GAP: f64 = 0.75;
/// Ink dot cell pitch (mm).
pub const DOT_PITCH: f64 = 0.6;
/// Ink dot density polynomial in x / L (area fraction), lowest degree first.
pub const DOT_DENSITY: [f64; 2] = [0.2, 0.6];
/// Ink albedo.
pub const INK_ALBEDO: f64 = 0.9;

/// The parabola's axis height: midway between the lips (on the sheet and at the front
/// face's height).
pub fn zc() -> f64 {
    0.5 * (T - SHEET_GAP)
}

/// The parabola's vertex x: its lips, `(T + SHEET_GAP) / 2` off the axis, are at
/// `x = -LIP_GAP`.
pub fn x_vertex() -> f64 {
    let half = 0.5 * (T + SHEET_GAP);
    -LIP_GAP - half * half / (4.0 * FOCAL)
}

/// The lamp's centre: the parabola's focus, at mid-length.
pub fn lamp() -> P3 {
    [x_vertex() + FOCAL, 0.5 * W, zc()]
}

/// Light guide and reflector sheet (the lamp reflector comes from the CAD files).
pub fn parts() -> Vec<Part> {
    vec![
        guide_box("lgp", [L, W, T]),
        sheet_up(
            "reflector_sheet",
            "reflector_sheet",
            [-LIP_GAP, 0.0],
            [L, W],
            -SHEET_GAP,
        ),
    ]
}

fn scene_toml(obj: bool, triangles: usize) -> String {
    let (which, file) = if obj {
        (
            "the OBJ export (reflector.obj + .mtl, written in mm)",
            "reflector.obj",
        )
    } else {
        (
            "the glTF export (reflector.gltf + .bin, Blender's defaults: metres and +y up, as \
             glTF specifies and blutrace reads glTF by default)",
            "reflector.gltf",
        )
    };
    let other = if obj { "scene.toml" } else { "scene-obj.toml" };
    let c = lamp();
    let header = format!(
        "cad-reflector: an edge-lit light guide with a CAD-made parabolic lamp reflector, loaded
from {which}. {other} is the same scene with the other export.
{GENERATED}
The reflector files are made by tools/cad/export-reflector.sh (Blender 3.4.1, headless,
running tools/cad/make_reflector.py): regenerate them there, not here.

Axes (mm): x from the lamp edge to the far edge, y along the lamp, z towards the viewer.

- Light guide: {L} x {W} x {T} at x 0..{L}, y 0..{W}, z 0..{T}; PMMA n = {N_PMMA}, absorption
  {ABSORPTION} /mm. Tags lgp_front, lgp_back (ink dots), lgp_edge. From lgp.obj.
- Ink dots: hex lattice, pitch {DOT_PITCH}, density {d0} + {d1} (x/L), ink albedo {INK_ALBEDO}.
- Lamp reflector (tag lamp_reflector, the CAD file's material name): a parabolic trough,
  focal length {FOCAL}, vertex at x = {xv}, axis at z = {zc}, opening towards the guide; lips
  {LIP_GAP} short of the edge face, on the reflector sheet (z = {zs}) and at the front face's
  height (z = {T}), where a flat strip continues to the guide's edge; flat end caps at
  y = 0 and {W}. Phong: reflectance 0.95, specular 0.8, exponent 100.
- CCFL: radius {LAMP_R}, length {W}, 1 W, on the focus: centre ({cx}, {cy}, {cz}) mm.
- Reflector sheet (tag reflector_sheet): z = {zs} ({SHEET_GAP} below the back face), x {x0}..{L}.
  Phong: reflectance 0.95, specular 0.1, exponent 10. From lgp.obj.
- Detector: {DETECTOR_GAP} above the front face (z = {zd}), exactly covering it.

Geometry: lgp.obj ({triangles} triangles) and {file}.
",
        d0 = num(DOT_DENSITY[0]),
        d1 = num(DOT_DENSITY[1]),
        xv = dim(x_vertex()),
        zc = dim(zc()),
        zs = dim(-SHEET_GAP),
        cx = dim(c[0]),
        cy = dim(c[1]),
        cz = dim(c[2]),
        x0 = dim(-LIP_GAP),
        zd = dim(T + DETECTOR_GAP),
    );
    let dots = Dots {
        inside: "pmma",
        ink_albedo: INK_ALBEDO,
        lattice: "hex",
        pitch: DOT_PITCH,
        axis: [1.0, 0.0, 0.0],
        length: L,
        density: &DOT_DENSITY,
        normalized: true,
        mirror: None,
    };
    let [front, edge, back] = dotted_guide_faces(&dots);
    let (suffix, fmt) = if obj { ("-obj", "OBJ") } else { ("", "glTF") };
    let description = format!(
        "Edge-lit {L} x {W} x {T} mm PMMA guide, one CCFL in a parabolic reflector exported from Blender ({fmt})"
    );
    scene_file(
        &header,
        &[
            preamble(&format!("cad-reflector{suffix}"), &description),
            geometry("lgp.obj"),
            geometry(file),
            medium("pmma", N_PMMA, ABSORPTION, None),
            front,
            edge,
            back,
            lamp_reflector(),
            reflector_sheet(),
            Ccfl::new("lamp", c, LAMP_R, W).toml(),
            Detector::new([0.0, 0.0, T + DETECTOR_GAP], [L, W], [80, 60]).toml(),
            trace_table(PHOTONS, 100_000),
        ],
    )
}

/// `cad-reflector/scene.toml`, `scene-obj.toml`, `lgp.obj` and `lgp.mtl`.
pub fn files() -> Vec<GenFile> {
    let parts = parts();
    let triangles = triangle_count(&parts);
    let header = format!(
        "cad-reflector: light guide and reflector sheet (see scene.toml). Units mm.\n{GENERATED}"
    );
    let [obj, mtl] = obj_and_mtl(
        "cad-reflector",
        "lgp.obj",
        &header,
        &parts,
        MtlNote::DisplayOnly,
    );
    vec![
        GenFile::text("cad-reflector/scene.toml", scene_toml(false, triangles)),
        GenFile::text("cad-reflector/scene-obj.toml", scene_toml(true, triangles)),
        obj,
        mtl,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lamp_fits_behind_the_lips_inside_the_parabola() {
        let c = lamp();
        // Nearest parabola point to the focus is the vertex, FOCAL away.
        const { assert!(FOCAL - LAMP_R >= 0.15) };
        assert!(c[0] + LAMP_R < -LIP_GAP - 0.1, "lamp pokes out of the lips");
        assert!((c[0] + 1.438021).abs() < 1e-6, "matches make_reflector.py");
    }
}
