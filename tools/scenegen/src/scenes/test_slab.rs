//! `test/slab`: a lossless, dot-free PMMA slab with a small LED at its centre, emitting
//! inside the PMMA. For physics tests (Fresnel escape, total internal reflection).

use super::{GENERATED, trace_table};
use crate::{
    GenFile, ObjTags, P3, Part, arr, box_corners, comment, dim, dims, hexahedron, num, tags_of,
    write_mtl, write_obj,
};

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
    let mut slab = Part::new("slab");
    hexahedron(
        &mut slab,
        &box_corners([0.0; 3], SIZE),
        "lgp_front",
        "lgp_back",
        "lgp_edge",
    );
    vec![slab]
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
    let mut s = comment(&header);
    s += &format!(
        "
version = 1
name = \"test-slab\"
description = \"Lossless dot-free PMMA slab {sx} x {sy} x {sz} mm with an LED emitting inside it at its centre\"

[[geometry]]
file = \"slab.obj\"

[media.pmma]
n = {n}
absorption_per_mm = 0.0

[surfaces.lgp_front]
model = \"dielectric\"
inside = \"pmma\"

[surfaces.lgp_back]
model = \"dielectric\"
inside = \"pmma\"

[surfaces.lgp_edge]
model = \"dielectric\"
inside = \"pmma\"

[[sources]]
type = \"led\"
name = \"led\"
center = {c}
normal = [0.0, 0.0, 1.0]
u = [1.0, 0.0, 0.0]
width_mm = {w}
height_mm = {w}
power_w = 1.0
cos_exponent = 1.0
medium = \"pmma\"

[detector]
origin = {d}
u = [1.0, 0.0, 0.0]
v = [0.0, 1.0, 0.0]
size_mm = {ds}
bins = [20, 20]
angular_bins = [18, 36]

{trace}",
        n = num(N_PMMA),
        c = arr(&led()),
        w = num(LED_SIZE),
        d = arr(&[0.0, 0.0, sz + DETECTOR_GAP]),
        ds = arr(&[sx, sy]),
        trace = trace_table(100_000, 1000),
    );
    s
}

/// `test/slab/scene.toml`, `.obj` and `.mtl`.
pub fn files() -> Vec<GenFile> {
    let parts = parts();
    let triangles = parts.iter().map(Part::triangle_count).sum();
    let header = format!("test/slab: lossless PMMA slab (see scene.toml). Units mm.\n{GENERATED}");
    vec![
        GenFile::text("test/slab/scene.toml", scene_toml(triangles)),
        GenFile::text(
            "test/slab/slab.obj",
            write_obj(&header, &parts, ObjTags::Usemtl("slab.mtl")),
        ),
        GenFile::text("test/slab/slab.mtl", write_mtl(&header, &tags_of(&parts))),
    ]
}
