//! `test/slab-edge-lit`: a long lossless, dot-free PMMA plate lit through one end face by a
//! CCFL in a black box. Light that enters through the end face is totally reflected at the
//! front, back and side faces, so none should reach the detector above the front face.

use super::GENERATED;
use crate::shapes::{Facing, guide_box, lamp_box};
use crate::templates::{
    Ccfl, Detector, MtlNote, absorber, bare_guide_faces, geometry, medium, obj_and_mtl, preamble,
    scene_file, trace_table,
};
use crate::{GenFile, P3, Part, dim, dims, triangle_count};

/// Plate size (x, y, z) (mm); the plate spans 0..SIZE, lit through its x = 0 end face.
pub const SIZE: P3 = [100.0, 20.0, 2.0];
/// PMMA refractive index.
pub const N_PMMA: f64 = 1.49;
/// Depth of the lamp box behind the end face (mm): it spans x = -BOX_DEPTH..0.
pub const BOX_DEPTH: f64 = 3.0;
/// CCFL radius (mm).
pub const LAMP_R: f64 = 0.75;
/// Detector height above the front face (mm).
pub const DETECTOR_GAP: f64 = 0.5;

/// The lamp's centre: mid-box.
pub fn lamp() -> P3 {
    [-0.5 * BOX_DEPTH, 0.5 * SIZE[1], 0.5 * SIZE[2]]
}

/// The plate and the absorber box.
pub fn parts() -> Vec<Part> {
    let [_, sy, sz] = SIZE;
    // Five absorbing walls of the box x = -d..0, y 0..sy, z 0..sz; the sixth side is the
    // plate's end face. The walls meet the plate only along its end face's edges.
    let walls = lamp_box("absorber", "absorber", BOX_DEPTH, [sy, sz], Facing::Out);
    vec![guide_box("plate", SIZE), walls]
}

fn scene_toml(triangles: usize) -> String {
    let [sx, sy, sz] = SIZE;
    let header = format!(
        "test/slab-edge-lit: a long lossless, dot-free PMMA plate lit through one end face by a
CCFL boxed in by black walls. A physics test scene, not a backlight.
{GENERATED}

- Plate: {sx} x {sy} x {sz} mm at x 0..{sx}, y 0..{sy}, z 0..{sz}; PMMA n = {N_PMMA}, no absorption.
  Smooth dielectric faces: tags lgp_front (z = {sz}), lgp_back (z = 0), lgp_edge.
- Lamp box (tag absorber, black): x {d}..0, y 0..{sy}, z 0..{sz}, five walls whose open side is
  the plate's x = 0 end face; the walls meet the plate along that face's edges, so lamp
  light leaves the box only into the plate.
- CCFL: radius {LAMP_R}, length {sy} (the box's y extent), 1 W, centre {c}, in air.
- Light refracted into the plate through the end face travels within the critical angle
  of x, so it is totally reflected at the front, back and side faces and leaves only
  through the end faces: nothing should reach the detector.
- Detector: {DETECTOR_GAP} mm above the front face (z = {zd}), exactly covering it.

Geometry: slab-edge-lit.obj (usemtl names are tags), {triangles} triangles.
",
        d = dim(-BOX_DEPTH),
        c = dims(&lamp()),
        zd = dim(sz + DETECTOR_GAP),
    );
    let [front, back, edge] = bare_guide_faces("pmma");
    let lamp = Ccfl {
        body: false,
        ..Ccfl::new("lamp", lamp(), LAMP_R, sy)
    };
    let description = format!(
        "Lossless dot-free PMMA plate {sx} x {sy} x {sz} mm lit through one end face by a boxed-in CCFL"
    );
    scene_file(
        &header,
        &[
            preamble("test-slab-edge-lit", &description),
            geometry("slab-edge-lit.obj"),
            medium("pmma", N_PMMA, 0.0, None),
            front,
            back,
            edge,
            absorber("absorber"),
            lamp.toml(),
            Detector::new([0.0, 0.0, sz + DETECTOR_GAP], [sx, sy], [100, 20]).toml(),
            trace_table(100_000, 100_000),
        ],
    )
}

/// `test/slab-edge-lit/scene.toml`, `.obj` and `.mtl`.
pub fn files() -> Vec<GenFile> {
    let parts = parts();
    let header = format!(
        "test/slab-edge-lit: edge-lit lossless PMMA plate (see scene.toml). Units mm.\n{GENERATED}"
    );
    let [obj, mtl] = obj_and_mtl(
        "test/slab-edge-lit",
        "slab-edge-lit.obj",
        &header,
        &parts,
        MtlNote::Plain,
    );
    vec![
        GenFile::text(
            "test/slab-edge-lit/scene.toml",
            scene_toml(triangle_count(&parts)),
        ),
        obj,
        mtl,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lamp_fits_in_its_box() {
        let c = lamp();
        assert!(c[0] - LAMP_R > -BOX_DEPTH + 0.2);
        assert!(c[0] + LAMP_R < -0.2);
        assert!(c[2] - LAMP_R > 0.2 && c[2] + LAMP_R < SIZE[2] - 0.2);
    }
}
