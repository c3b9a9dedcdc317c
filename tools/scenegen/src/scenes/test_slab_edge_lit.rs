//! `test/slab-edge-lit`: a long lossless, dot-free PMMA plate lit through one end face by a
//! CCFL in a black box. Light that enters through the end face is totally reflected at the
//! front, back and side faces, so none should reach the detector above the front face.

use super::{GENERATED, trace_table};
use crate::{
    GenFile, ObjTags, P3, Part, arr, box_corners, comment, dim, dims, hexahedron, num, tags_of,
    write_mtl, write_obj,
};

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
    let mut plate = Part::new("plate");
    hexahedron(
        &mut plate,
        &box_corners([0.0; 3], SIZE),
        "lgp_front",
        "lgp_back",
        "lgp_edge",
    );
    // Five absorbing walls of the box x = -d..0, y 0..sy, z 0..sz; the sixth side is the
    // plate's end face. The walls meet the plate only along its end face's edges.
    let mut walls = Part::new("absorber");
    let d = -BOX_DEPTH;
    let t = "absorber";
    walls.quad(t, [d, 0.0, 0.0], [d, 0.0, sz], [d, sy, sz], [d, sy, 0.0]);
    walls.quad(
        t,
        [d, 0.0, 0.0],
        [d, sy, 0.0],
        [0.0, sy, 0.0],
        [0.0, 0.0, 0.0],
    );
    walls.quad(t, [d, 0.0, sz], [0.0, 0.0, sz], [0.0, sy, sz], [d, sy, sz]);
    walls.quad(
        t,
        [d, 0.0, 0.0],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, sz],
        [d, 0.0, sz],
    );
    walls.quad(t, [d, sy, 0.0], [d, sy, sz], [0.0, sy, sz], [0.0, sy, 0.0]);
    vec![plate, walls]
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
    let mut s = comment(&header);
    s += &format!(
        "
version = 1
name = \"test-slab-edge-lit\"
description = \"Lossless dot-free PMMA plate {sx} x {sy} x {sz} mm lit through one end face by a boxed-in CCFL\"

[[geometry]]
file = \"slab-edge-lit.obj\"

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

[surfaces.absorber]
model = \"absorber\"

[[sources]]
type = \"ccfl\"
name = \"lamp\"
center = {c}
axis = [0.0, 1.0, 0.0]
radius_mm = {r}
length_mm = {l}
power_w = 1.0

[detector]
origin = {o}
u = [1.0, 0.0, 0.0]
v = [0.0, 1.0, 0.0]
size_mm = {ds}
bins = [100, 20]
angular_bins = [18, 36]

{trace}",
        n = num(N_PMMA),
        c = arr(&lamp()),
        r = num(LAMP_R),
        l = num(sy),
        o = arr(&[0.0, 0.0, sz + DETECTOR_GAP]),
        ds = arr(&[sx, sy]),
        trace = trace_table(100_000, 100_000),
    );
    s
}

/// `test/slab-edge-lit/scene.toml`, `.obj` and `.mtl`.
pub fn files() -> Vec<GenFile> {
    let parts = parts();
    let triangles = parts.iter().map(Part::triangle_count).sum();
    let header = format!(
        "test/slab-edge-lit: edge-lit lossless PMMA plate (see scene.toml). Units mm.\n{GENERATED}"
    );
    vec![
        GenFile::text("test/slab-edge-lit/scene.toml", scene_toml(triangles)),
        GenFile::text(
            "test/slab-edge-lit/slab-edge-lit.obj",
            write_obj(&header, &parts, ObjTags::Usemtl("slab-edge-lit.mtl")),
        ),
        GenFile::text(
            "test/slab-edge-lit/slab-edge-lit.mtl",
            write_mtl(&header, &tags_of(&parts)),
        ),
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
