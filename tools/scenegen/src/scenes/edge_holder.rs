//! `edge-holder/`: an edge-lit guide whose lamp holder is procedural (`[[procedural]]`
//! `lamp_holder`), so its shape is a number of the scene file for `optimize --vary`.

use super::GENERATED;
use crate::shapes::guide_box;
use crate::templates::{
    Ccfl, Detector, Dots, MtlNote, dotted_guide_faces, geometry, lamp_reflector, medium,
    obj_and_mtl, preamble, reflector_sheet, scene_file, trace_table,
};
use crate::{GenFile, P3, Part, arr, num};

/// Default photons: the map's noise floor (`cv_noise_floor`, the cv of noise alone) about
/// 0.1, so the first picture shows the backlight, not its noise (a few seconds on 2 cores;
/// `tests/bundled_scenes.rs` checks it).
const PHOTONS: u64 = 1_500_000;

/// Guide size (x along the light, y along the lamp, z thickness) (mm).
pub const SIZE: P3 = [100.0, 60.0, 3.0];
/// CCFL radius (mm).
pub const LAMP_R: f64 = 1.0;
/// The lamp axis sits this far before the guide's edge (mm).
pub const LAMP_X: f64 = -2.0;
/// Holder radius (mm): its rim (aperture = the guide's thickness) lies sqrt(R^2 - (t/2)^2)
/// ahead of the axis: 1.61 mm, 0.39 mm short of the edge (a gap that leaks); at R = 2.5
/// it reaches the edge. Beyond that it would wrap over the guide's faces, which needs a
/// bezel this scene does not model.
pub const HOLDER_R: f64 = 2.2;
/// Dot density (constant), square lattice pitch (mm).
pub const DOT_DENSITY: f64 = 0.2;

/// The guide and the reflector sheet under it.
pub fn parts() -> Vec<Part> {
    let [sx, sy, _] = SIZE;
    let mut sheet = Part::new("sheet");
    // From x = 2: clear of any holder up to 4 mm radius.
    let z = -0.2;
    sheet.quad(
        "reflector_sheet",
        [2.0, -1.0, z],
        [2.0, sy + 1.0, z],
        [sx + 1.0, sy + 1.0, z],
        [sx + 1.0, -1.0, z],
    );
    vec![guide_box("guide", SIZE), sheet]
}

fn scene_toml() -> String {
    let [sx, sy, sz] = SIZE;
    let header = format!(
        "edge-holder: a 100 x 60 x 3 mm PMMA guide lit through its x = 0 edge by one CCFL
(r = 1 mm, axis 2 mm before the edge) in a procedural circular lamp holder (Phong,
as notebook14's), constant dots (0.2, square, 0.5 mm) on the back, a white sheet under
it from x = 2 (the target too, clear of the holder's rim). The holder's radius, aperture and the lamp's place are scene numbers: see the README
(\"Optimizing the layout\") for `optimize --vary` on the holder.
{GENERATED}"
    );
    let lamp = [LAMP_X, 0.5 * sy, 0.5 * sz];
    let holder = format!(
        "[[procedural]]
type = \"lamp_holder\"
tag = \"lamp_reflector\"
center = {c}
axis = [0.0, 1.0, 0.0]
opening = [1.0, 0.0, 0.0]
length_mm = {sy}
aperture_mm = {sz}
section = {{ shape = \"circle\", radius_mm = {r} }}
segments = 32
end_caps = true
",
        c = arr(&lamp),
        sy = num(sy),
        sz = num(sz),
        r = num(HOLDER_R),
    );
    let dots = Dots {
        inside: "pmma",
        ink_albedo: 0.9,
        lattice: "square",
        pitch: 0.5,
        axis: [1.0, 0.0, 0.0],
        length: sx,
        density: &[DOT_DENSITY],
        normalized: false,
        mirror: None,
    };
    let [front, edge, back] = dotted_guide_faces(&dots);
    scene_file(
        &header,
        &[
            preamble(
                "edge-holder",
                "Edge-lit guide with a procedural lamp holder",
            ),
            geometry("edge-holder.obj"),
            holder,
            medium("pmma", 1.49, 0.0003, None),
            front,
            edge,
            back,
            lamp_reflector(),
            reflector_sheet(),
            Ccfl::new("lamp", lamp, LAMP_R, sy - 1.0).toml(),
            Detector::new([2.0, 0.0, sz + 0.5], [sx - 2.0, sy], [49, 30]).toml(),
            trace_table(PHOTONS, 100_000),
        ],
    )
}

/// `edge-holder/scene.toml`, `.obj` and `.mtl`.
pub fn files() -> Vec<GenFile> {
    let parts = parts();
    let header = format!("edge-holder: guide and sheet (see scene.toml). Units mm.\n{GENERATED}");
    let [obj, mtl] = obj_and_mtl(
        "edge-holder",
        "edge-holder.obj",
        &header,
        &parts,
        MtlNote::Plain,
    );
    vec![
        GenFile::text("edge-holder/scene.toml", scene_toml()),
        obj,
        mtl,
    ]
}
