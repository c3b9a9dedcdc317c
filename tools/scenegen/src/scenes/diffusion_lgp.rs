//! `diffusion-lgp`: an edge-lit "diffusion" light guide: PMMA filled with micro-beads
//! instead of printed dots, so the light is extracted by volume scattering along the
//! whole guide. One CCFL in a white cavity on the x = 0 edge, a white reflector sheet
//! under the guide. Three bead loads share the geometry: `scene.toml` (the middle one),
//! `scene-light.toml` and `scene-heavy.toml`.

use super::{GENERATED, trace_table};
use crate::{
    CCFL_BODY, GenFile, ObjTags, P3, Part, arr, box_corners, comment, dim, dims, hexahedron, num,
    tags_of, write_mtl, write_obj,
};

/// Guide size (x along the light, y across, z thickness) (mm); it spans 0..SIZE.
pub const SIZE: P3 = [200.0, 120.0, 4.0];
/// PMMA refractive index.
pub const N_PMMA: f64 = 1.49;
/// PMMA bulk absorption (1/mm): cast PMMA, as in notebook14.
pub const ABSORPTION: f64 = 0.0003;
/// Bead radius (um): Momentive TSR9000 polymethylsilsesquioxane spheres, mean diameter
/// 2.0 um (ChemPoint product page "Momentive TSR9000 for Light Diffusion").
pub const BEAD_RADIUS_UM: f64 = 1.0;
/// Bead refractive index (TSR9000: 1.42).
pub const BEAD_N: f64 = 1.42;
/// The three bead loads (volume fractions): design choices spanning too little (most
/// light reaches the far edge) to too much (most is extracted near the lamp).
pub const LOADS: [(&str, &str, f64); 3] = [
    ("scene-light.toml", "light", 1e-4),
    ("scene.toml", "medium", 3e-4),
    ("scene-heavy.toml", "heavy", 1e-3),
];
/// Depth of the lamp cavity behind the x = 0 edge (mm): it spans x = -CAVITY..0.
pub const CAVITY: f64 = 4.0;
/// CCFL radius (mm).
pub const LAMP_R: f64 = 1.0;
/// Albedo of the white lamp cavity and reflector sheet (Lambertian, white PET; as the
/// other bundled scenes' sheets).
pub const WHITE_ALBEDO: f64 = 0.95;
/// Gap between the guide's back face and the reflector sheet (mm).
pub const SHEET_GAP: f64 = 0.2;
/// Detector height above the front face (mm).
pub const DETECTOR_GAP: f64 = 0.5;
/// Flux bins along x and across.
pub const BINS: [usize; 2] = [40, 24];

/// The lamp's centre: mid-cavity.
pub fn lamp() -> P3 {
    [-0.5 * CAVITY, 0.5 * SIZE[1], 0.5 * SIZE[2]]
}

/// The guide, the lamp cavity (five white walls open onto the guide's x = 0 edge), the
/// reflector sheet and white tape along the other three edges.
pub fn parts() -> Vec<Part> {
    let [sx, sy, sz] = SIZE;
    let mut guide = Part::new("guide");
    hexahedron(
        &mut guide,
        &box_corners([0.0; 3], SIZE),
        "lgp_front",
        "lgp_back",
        "lgp_edge",
    );
    let mut cavity = Part::new("cavity");
    let (d, t) = (-CAVITY, "lamp_cavity");
    cavity.quad(t, [d, 0.0, 0.0], [d, 0.0, sz], [d, sy, sz], [d, sy, 0.0]);
    cavity.quad(
        t,
        [d, 0.0, 0.0],
        [d, sy, 0.0],
        [0.0, sy, 0.0],
        [0.0, 0.0, 0.0],
    );
    cavity.quad(t, [d, 0.0, sz], [0.0, 0.0, sz], [0.0, sy, sz], [d, sy, sz]);
    cavity.quad(
        t,
        [d, 0.0, 0.0],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, sz],
        [d, 0.0, sz],
    );
    cavity.quad(t, [d, sy, 0.0], [d, sy, sz], [0.0, sy, sz], [0.0, sy, 0.0]);
    let mut sheet = Part::new("sheet");
    let z = -SHEET_GAP;
    sheet.quad(
        "reflector_sheet",
        [0.0, 0.0, z],
        [sx, 0.0, z],
        [sx, sy, z],
        [0.0, sy, z],
    );
    // White tape on the three edges away from the lamp, a sheet gap off each.
    let mut tape = Part::new("tape");
    let (g, t) = (SHEET_GAP, "edge_tape");
    tape.quad(
        t,
        [sx + g, 0.0, 0.0],
        [sx + g, sy, 0.0],
        [sx + g, sy, sz],
        [sx + g, 0.0, sz],
    );
    tape.quad(
        t,
        [0.0, -g, 0.0],
        [0.0, -g, sz],
        [sx, -g, sz],
        [sx, -g, 0.0],
    );
    tape.quad(
        t,
        [0.0, sy + g, 0.0],
        [sx, sy + g, 0.0],
        [sx, sy + g, sz],
        [0.0, sy + g, sz],
    );
    vec![guide, cavity, sheet, tape]
}

fn scene_toml(load: &str, fv: f64, triangles: usize) -> String {
    let [sx, sy, sz] = SIZE;
    let others: Vec<String> = LOADS
        .iter()
        .map(|(f, l, v)| format!("{f} ({l}, {})", num(*v)))
        .collect();
    let header = format!(
        "diffusion-lgp ({load} load): an edge-lit diffusion light guide: no printed dots, the
light is extracted by micro-beads dispersed in the PMMA (volume scattering).
{GENERATED}

Axes (mm): x along the light (lamp at x < 0), y across, z towards the viewer.

- Guide: {sx} x {sy} x {sz} at x 0..{sx}, y 0..{sy}, z 0..{sz}; PMMA n = {N_PMMA},
  absorption {ABSORPTION} /mm (cast PMMA, as notebook14). Smooth dielectric faces: tags
  lgp_front (z = {sz}), lgp_back (z = 0), lgp_edge.
- Beads: spheres of radius {r} um, index {nb} (Momentive TSR9000 polymethylsilsesquioxane
  beads: mean diameter 2.0 um, refractive index 1.42; ChemPoint product page \"Momentive
  TSR9000 for Light Diffusion\"), volume fraction {fv} (a design choice; the three bundled
  loads are {others}). blutrace computes mu_s and g from Mie theory at 550 nm (blutrace
  check shows them). Stand-in limits: one bead size, the Henyey-Greenstein phase function
  with the Mie g, independent scattering, one wavelength.
- Lamp cavity (tag lamp_cavity, Lambertian, albedo {WHITE_ALBEDO}): x {d}..0, five walls open onto
  the guide's x = 0 edge. CCFL radius {LAMP_R}, length {sy}, 1 W, centre {c}, in air.
- Reflector sheet (tag reflector_sheet, Lambertian, albedo {WHITE_ALBEDO}, white PET) {SHEET_GAP} below the
  back face, covering it. White tape (tag edge_tape, the same Lambertian white) {SHEET_GAP} off
  the far (x = {sx}) and side edges, facing them.
- Detector: {DETECTOR_GAP} above the front face (z = {zd}), covering it, {bx} x {by} bins.

Geometry: diffusion-lgp.obj (usemtl names are tags), {triangles} triangles.
",
        r = num(BEAD_RADIUS_UM),
        nb = num(BEAD_N),
        fv = num(fv),
        others = others.join(", "),
        d = dim(-CAVITY),
        c = dims(&lamp()),
        zd = dim(sz + DETECTOR_GAP),
        bx = BINS[0],
        by = BINS[1],
    );
    let mut s = comment(&header);
    s += &format!(
        "
version = 1
name = \"diffusion-lgp-{load}\"
description = \"Edge-lit diffusion light guide {sx} x {sy} x {sz} mm, beads at {fvs} by volume, no dots\"

[[geometry]]
file = \"diffusion-lgp.obj\"

[media.pmma]
n = {n}
absorption_per_mm = {ABSORPTION}
particles = {{ radius_um = {r}, n = {nb}, volume_fraction = {fvs}, wavelength_nm = 550.0 }}

[surfaces.lgp_front]
model = \"dielectric\"
inside = \"pmma\"

[surfaces.lgp_back]
model = \"dielectric\"
inside = \"pmma\"

[surfaces.lgp_edge]
model = \"dielectric\"
inside = \"pmma\"

[surfaces.lamp_cavity]
model = \"lambert\"
albedo = {w}

[surfaces.reflector_sheet]
model = \"lambert\"
albedo = {w}

[surfaces.edge_tape]
model = \"lambert\"
albedo = {w}

[[sources]]
type = \"ccfl\"
name = \"lamp\"
center = {c}
axis = [0.0, 1.0, 0.0]
radius_mm = {lr}
length_mm = {l}
power_w = 1.0
{CCFL_BODY}
[detector]
origin = {o}
u = [1.0, 0.0, 0.0]
v = [0.0, 1.0, 0.0]
size_mm = {ds}
bins = [{bx}, {by}]
angular_bins = [18, 36]

{trace}",
        n = num(N_PMMA),
        r = num(BEAD_RADIUS_UM),
        nb = num(BEAD_N),
        fvs = num(fv),
        w = num(WHITE_ALBEDO),
        c = arr(&lamp()),
        lr = num(LAMP_R),
        l = num(sy - 1.0),
        o = arr(&[0.0, 0.0, sz + DETECTOR_GAP]),
        ds = arr(&[sx, sy]),
        bx = BINS[0],
        by = BINS[1],
        trace = trace_table(400_000, 100_000),
    );
    s
}

/// The three scene files, the `.obj` and the `.mtl`.
pub fn files() -> Vec<GenFile> {
    let parts = parts();
    let triangles = parts.iter().map(Part::triangle_count).sum();
    let header = format!(
        "diffusion-lgp: edge-lit diffusion light guide (see scene.toml). Units mm.\n{GENERATED}"
    );
    let mut files: Vec<GenFile> = LOADS
        .iter()
        .map(|(file, load, fv)| {
            GenFile::text(
                &format!("diffusion-lgp/{file}"),
                scene_toml(load, *fv, triangles),
            )
        })
        .collect();
    files.push(GenFile::text(
        "diffusion-lgp/diffusion-lgp.obj",
        write_obj(&header, &parts, ObjTags::Usemtl("diffusion-lgp.mtl")),
    ));
    files.push(GenFile::text(
        "diffusion-lgp/diffusion-lgp.mtl",
        write_mtl(&header, &tags_of(&parts)),
    ));
    files
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lamp_fits_in_its_cavity() {
        let c = lamp();
        assert!(c[0] - LAMP_R > -CAVITY + 0.2 && c[0] + LAMP_R < -0.2);
        assert!(c[2] - LAMP_R > 0.2 && c[2] + LAMP_R < SIZE[2] - 0.2);
    }
}
