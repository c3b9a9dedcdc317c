//! `direct-lit-rows`: the bundled `direct-lit` scene written with blutrace's parametric
//! constructs instead of a meshed box and one entry per lamp: the six lamps are one
//! `[[sources]]` row (`array`) and the box is a `[[procedural]]` `direct_lit_box`, so the
//! lamp count, pitch and height and the ridge height are single numbers of the scene file
//! for `blutrace optimize --vary`. Only the diffuser plate is meshed. Same physics as
//! `direct-lit` (a test traces both).

use super::GENERATED;
use super::direct_lit::{
    BOX_X, BOX_Y, DEPTH, DirectLit, LAMP_POWER_W, LAMP_R, Reflector, diffuser_plate,
};
use crate::templates::{
    Ccfl, MtlNote, Row, geometry, obj_and_mtl, preamble, scene_file, trace_table,
};
use crate::{GenFile, arr, dim, num};

/// The plate's geometry file (its display-material library is `plate.mtl`).
pub const OBJ: &str = "plate.obj";

/// The scene's files below `direct-lit-rows/`.
pub fn files() -> Vec<GenFile> {
    let d = DirectLit::bundled();
    let header =
        format!("direct-lit-rows: the diffuser plate (see scene.toml). Units mm.\n{GENERATED}");
    let [obj, mtl] = obj_and_mtl(
        "direct-lit-rows",
        OBJ,
        &header,
        &[diffuser_plate()],
        MtlNote::DisplayOnly,
    );
    vec![
        GenFile::text("direct-lit-rows/scene.toml", scene_toml(&d)),
        obj,
        mtl,
    ]
}

/// The header: what differs from `direct-lit` and the parameters to vary.
fn header(d: &DirectLit) -> String {
    format!(
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
",
        plate_note = d.plate_note()
    )
}

/// `direct-lit`'s box as a `[[procedural]]` `direct_lit_box`, its plate and walls as
/// `direct-lit` writes them, its lamps as one row.
fn scene_toml(d: &DirectLit) -> String {
    let Reflector::Ridges { height } = d.reflector else {
        unreachable!("the bundled box is ridged")
    };
    let description = format!(
        "direct-lit as parameters: a row of {} CCFLs at {} mm pitch over a generated {BOX_X} x {BOX_Y} x {DEPTH} mm ridged box",
        d.lamps,
        dim(d.pitch)
    );
    let procedural = format!(
        "[[procedural]]
type = \"direct_lit_box\"
tag = \"box_reflector\"
origin = [0.0, 0.0, 0.0]
size_mm = {}
ridge_height_mm = {}
profile = \"triangle\"
",
        arr(&[BOX_X, BOX_Y, DEPTH]),
        num(height)
    );
    let row = Ccfl {
        power_w: LAMP_POWER_W,
        row: Some(Row {
            count: d.lamps,
            pitch: d.pitch,
            direction: [1.0, 0.0, 0.0],
        }),
        ..Ccfl::new(
            "lamp",
            [0.5 * BOX_X, 0.5 * BOX_Y, d.lamp_height],
            LAMP_R,
            d.lamp_length(),
        )
    };
    let mut tables = vec![
        preamble("direct-lit-rows", &description),
        geometry(OBJ),
        procedural,
    ];
    tables.extend(d.plate_and_walls());
    tables.push(row.toml());
    tables.push(d.detector().toml());
    tables.push(trace_table(d.photons, 100_000));
    scene_file(&header(d), &tables)
}
