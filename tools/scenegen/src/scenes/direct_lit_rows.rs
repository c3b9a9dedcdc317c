//! `direct-lit-rows`: the bundled `direct-lit` scene written with blutrace's parametric
//! constructs instead of a meshed box and one entry per lamp: the six lamps are one
//! `[[sources]]` row (`array`) and the box is a `[[procedural]]` `direct_lit_box`, so the
//! lamp count, pitch and height and the ridge height are single numbers of the scene file
//! for `blutrace optimize --vary`. Only the diffuser plate is meshed. Same physics as
//! `direct-lit` (a test traces both).

use super::direct_lit::{BOX_X, BOX_Y, DEPTH, DirectLit, LAMP_POWER_W, LAMP_R, PLATE_T, Reflector};
use super::{GENERATED, trace_table};
use crate::{
    CCFL_BODY, GenFile, ObjTags, Part, arr, box_corners, comment, dim, hexahedron, num, tags_of,
};
use crate::{write_mtl, write_obj};

/// The plate's geometry file.
pub const OBJ: &str = "plate.obj";
/// Its display-material library.
pub const MTL: &str = "plate.mtl";

/// The scene's files below `direct-lit-rows/`.
pub fn files() -> Vec<GenFile> {
    let d = DirectLit::bundled();
    let Reflector::Ridges { height } = d.reflector else {
        unreachable!("the bundled box is ridged")
    };
    let mut plate = Part::new("diffuser");
    hexahedron(
        &mut plate,
        &box_corners([0.0, 0.0, DEPTH], [BOX_X, BOX_Y, DEPTH + PLATE_T]),
        "diffuser_top",
        "diffuser_back",
        "diffuser_edge",
    );
    let header =
        format!("direct-lit-rows: the diffuser plate (see scene.toml). Units mm.\n{GENERATED}");
    let mtl_header =
        format!("{header}\nDisplay colours only: blutrace reads the usemtl names as tags.");
    let parts = [plate];
    let plate_note = d.plate_note();
    let text = format!(
        "direct-lit-rows: the bundled direct-lit scene (see its scene.toml for the parts and
their sources) with its six lamps as one source row and its box generated at load.
{GENERATED}

The diffuser plate (tags diffuser_top, diffuser_back, diffuser_edge): {plate_note}

Parameters for `blutrace optimize --vary` (README, Optimizing the layout):
- sources.0.center.2: lamp height above the valleys (mm);
- sources.0.array.pitch_mm and sources.0.array.count: the row (power_w is per lamp);
- procedural.0.ridge_height_mm: the back reflector's ridges (0: flat), and
  procedural.0.profile = \"triangle\" | \"parabola\".
The box's valleys follow the lamps wherever they are.
"
    );
    let mut s = comment(&text);
    s += &format!(
        "
version = 1
name = \"direct-lit-rows\"
description = \"direct-lit as parameters: a row of {n} CCFLs at {pitch} mm pitch over a generated {BOX_X} x {BOX_Y} x {DEPTH} mm ridged box\"

[[geometry]]
file = \"{OBJ}\"

[[procedural]]
type = \"direct_lit_box\"
tag = \"box_reflector\"
origin = [0.0, 0.0, 0.0]
size_mm = {size}
ridge_height_mm = {height}
profile = \"triangle\"

{plate}
[[sources]]
type = \"ccfl\"
name = \"lamp\"
center = {center}
axis = [0.0, 1.0, 0.0]
radius_mm = {r}
length_mm = {len}
power_w = {p}
array = {{ count = {n}, pitch_mm = {pitch_num}, direction = [1.0, 0.0, 0.0] }}
{CCFL_BODY}
[detector]
origin = {origin}
u = [1.0, 0.0, 0.0]
v = [0.0, 1.0, 0.0]
size_mm = {dsize}
bins = [{bx}, {by}]
angular_bins = [18, 36]

{trace}",
        n = d.lamps,
        pitch = dim(d.pitch),
        size = arr(&[BOX_X, BOX_Y, DEPTH]),
        height = num(height),
        plate = plate_and_walls(&d),
        center = arr(&[0.5 * BOX_X, 0.5 * BOX_Y, d.lamp_height]),
        r = num(LAMP_R),
        len = num(d.lamp_length()),
        p = num(LAMP_POWER_W),
        pitch_num = num(d.pitch),
        origin = arr(&[0.0, 0.0, DEPTH + PLATE_T + super::direct_lit::DETECTOR_GAP]),
        dsize = arr(&[BOX_X, BOX_Y]),
        bx = d.bins[0],
        by = d.bins[1],
        trace = trace_table(d.photons, 100_000),
    );
    vec![
        GenFile::text("direct-lit-rows/scene.toml", s),
        GenFile::text(
            &format!("direct-lit-rows/{OBJ}"),
            write_obj(&header, &parts, ObjTags::Usemtl(MTL)),
        ),
        GenFile::text(
            &format!("direct-lit-rows/{MTL}"),
            write_mtl(&mtl_header, &tags_of(&parts)),
        ),
    ]
}

/// `direct-lit`'s media and surfaces, as its own scene file writes them (from `[media.pc]`
/// to its first `[[sources]]`), so both scenes keep one plate and one box model.
fn plate_and_walls(d: &DirectLit) -> String {
    let full = d.scene_toml(0);
    let start = full.find("[media.pc]").expect("direct-lit has [media.pc]");
    let end = full.find("[[sources]]").expect("direct-lit has sources");
    full[start..end].trim_end().to_string() + "\n"
}
