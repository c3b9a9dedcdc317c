//! `test/slab`: a lossless, dot-free PMMA slab with a small LED at its centre, emitting
//! inside the PMMA. For physics tests (Fresnel escape, total internal reflection).

use super::GENERATED;
use crate::shapes::guide_box;
use crate::templates::{
    Detector, Led, MtlNote, bare_guide_faces, geometry, medium, obj_and_mtl, preamble, scene_file,
    trace_table,
};
use crate::{GenFile, P3, Part, dim, dims, triangle_count};

/// Slab size (x, y, z) (mm); the slab spans 0..SIZE.
pub const SIZE: P3 = [20.0, 20.0, 2.0];
/// PMMA refractive index.
pub const N_PMMA: f64 = 1.49;
/// Detector height above the front face (mm): tiny, so it counts what leaves the front face.
pub const DETECTOR_GAP: f64 = 0.01;
/// LED side (mm).
pub const LED_SIZE: f64 = 0.1;

/// The LED's centre: the slab's centre.
pub fn led() -> P3 {
    SIZE.map(|s| 0.5 * s)
}

/// The slab.
pub fn parts() -> Vec<Part> {
    vec![guide_box("slab", SIZE)]
}

fn scene_toml(triangles: usize) -> String {
    let [sx, sy, sz] = SIZE;
    let header = format!(
        "test/slab: a lossless, dot-free PMMA slab with a tiny LED at its centre that emits
inside the PMMA. A physics test scene, not a backlight.
{GENERATED}

- Slab: {sx} x {sy} x {sz} mm at x 0..{sx}, y 0..{sy}, z 0..{sz}; PMMA n = {N_PMMA}, no absorption.
  Every face is a smooth dielectric: tags lgp_front (z = {sz}), lgp_back (z = 0), lgp_edge.
- LED: {LED_SIZE} x {LED_SIZE} mm at the slab's centre {c}, facing +z, Lambertian
  (cos_exponent 1), emitting into the PMMA.
- Detector: {DETECTOR_GAP} mm above the front face (z = {zd}), exactly covering it, so it counts the
  light leaving the front face (all but grazing photons within {DETECTOR_GAP} mm of its edges).
- Directions whose three direction cosines are all below sqrt(1 - 1/n^2) are totally
  reflected at every face of a box and never leave: such photons end at the bounce cap
  (max_bounces = 1000 here) and are counted as killed.

Geometry: slab.obj (usemtl names are tags), {triangles} triangles.
",
        c = dims(&led()),
        zd = dim(sz + DETECTOR_GAP),
    );
    let [front, back, edge] = bare_guide_faces("pmma");
    let led = Led {
        cos_exponent: Some(1.0),
        medium: Some("pmma"),
        body: false,
        ..Led::new(
            "led",
            led(),
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            [LED_SIZE, LED_SIZE],
        )
    };
    let description = format!(
        "Lossless dot-free PMMA slab {sx} x {sy} x {sz} mm with an LED emitting inside it at its centre"
    );
    scene_file(
        &header,
        &[
            preamble("test-slab", &description),
            geometry("slab.obj"),
            medium("pmma", N_PMMA, 0.0, None),
            front,
            back,
            edge,
            led.toml(),
            Detector::new([0.0, 0.0, sz + DETECTOR_GAP], [sx, sy], [20, 20]).toml(),
            trace_table(100_000, 1000),
        ],
    )
}

/// `test/slab/scene.toml`, `.obj` and `.mtl`.
pub fn files() -> Vec<GenFile> {
    let parts = parts();
    let header = format!("test/slab: lossless PMMA slab (see scene.toml). Units mm.\n{GENERATED}");
    let [obj, mtl] = obj_and_mtl("test/slab", "slab.obj", &header, &parts, MtlNote::Plain);
    vec![
        GenFile::text("test/slab/scene.toml", scene_toml(triangle_count(&parts))),
        obj,
        mtl,
    ]
}
