//! `edge-holder/`: an edge-lit guide whose lamp holder is procedural (`[[procedural]]`
//! `lamp_holder`), so its shape is a number of the scene file for `optimize --vary`.

use super::{GENERATED, trace_table};
use crate::{
    CCFL_BODY, GenFile, ObjTags, P3, Part, arr, box_corners, hexahedron, num, tags_of, write_mtl,
    write_obj,
};

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
    let mut guide = Part::new("guide");
    hexahedron(
        &mut guide,
        &box_corners([0.0; 3], SIZE),
        "lgp_front",
        "lgp_back",
        "lgp_edge",
    );
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
    vec![guide, sheet]
}

fn scene_toml() -> String {
    let [sx, sy, sz] = SIZE;
    format!(
        "# edge-holder: a 100 x 60 x 3 mm PMMA guide lit through its x = 0 edge by one CCFL
# (r = 1 mm, axis 2 mm before the edge) in a procedural circular lamp holder (Phong,
# as notebook14's), constant dots (0.2, square, 0.5 mm) on the back, a white sheet under
# it from x = 2 (the target too, clear of the holder's rim). The holder's radius, aperture and the lamp's place are scene numbers: see the README
# (\"Optimizing the layout\") for `optimize --vary` on the holder.
# {GENERATED}

version = 1
name = \"edge-holder\"
description = \"Edge-lit guide with a procedural lamp holder\"

[[geometry]]
file = \"edge-holder.obj\"

[[procedural]]
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

[media.pmma]
n = 1.49
absorption_per_mm = 0.0003

[surfaces.lgp_front]
model = \"dielectric\"
inside = \"pmma\"

[surfaces.lgp_edge]
model = \"dielectric\"
inside = \"pmma\"

[surfaces.lgp_back]
model = \"dots\"
inside = \"pmma\"
ink_albedo = 0.9
lattice = \"square\"
pitch_mm = 0.5
origin = [0.0, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
length_mm = {sx}
density = [{d}]

[surfaces.lamp_reflector]
model = \"phong\"
reflectance = 0.95
specular = 0.8
exponent = 100.0

[surfaces.reflector_sheet]
model = \"phong\"
reflectance = 0.95
specular = 0.1
exponent = 10.0

[[sources]]
type = \"ccfl\"
name = \"lamp\"
center = {c}
axis = [0.0, 1.0, 0.0]
radius_mm = {lr}
length_mm = {ll}
power_w = 1.0
{CCFL_BODY}
[detector]
origin = [2.0, 0.0, {dz}]
u = [1.0, 0.0, 0.0]
v = [0.0, 1.0, 0.0]
size_mm = [{dx}, {sy}]
bins = [49, 30]
angular_bins = [18, 36]

{trace}",
        c = arr(&[LAMP_X, 0.5 * sy, 0.5 * sz]),
        sx = num(sx),
        sy = num(sy),
        sz = num(sz),
        r = num(HOLDER_R),
        d = num(DOT_DENSITY),
        lr = num(LAMP_R),
        ll = num(sy - 1.0),
        dz = num(sz + 0.5),
        dx = num(sx - 2.0),
        trace = trace_table(400_000, 100_000),
    )
}

/// `edge-holder/scene.toml`, `.obj` and `.mtl`.
pub fn files() -> Vec<GenFile> {
    let parts = parts();
    let header = format!("edge-holder: guide and sheet (see scene.toml). Units mm.\n{GENERATED}");
    vec![
        GenFile::text("edge-holder/scene.toml", scene_toml()),
        GenFile::text(
            "edge-holder/edge-holder.obj",
            write_obj(&header, &parts, ObjTags::Usemtl("edge-holder.mtl")),
        ),
        GenFile::text(
            "edge-holder/edge-holder.mtl",
            write_mtl(&header, &tags_of(&parts)),
        ),
    ]
}
