//! `diffusion-lgp`: an edge-lit "diffusion" light guide: PMMA filled with micro-beads
//! instead of printed dots, so the light is extracted by volume scattering along the
//! whole guide. One CCFL in a white cavity on the x = 0 edge, a white reflector sheet
//! under the guide. Three bead loads share the geometry: `scene.toml` (the middle one),
//! `scene-light.toml` and `scene-heavy.toml`.

use super::GENERATED;
use crate::shapes::{Facing, guide_box, lamp_box, sheet_up};
use crate::templates::{
    Beads, Ccfl, Detector, MtlNote, WHITE_PET_ALBEDO, bare_guide_faces, geometry, medium,
    obj_and_mtl, preamble, scene_file, trace_table, white_pet_lambert,
};
use crate::{GenFile, P3, Part, dim, dims, num, triangle_count};

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
pub const WHITE_ALBEDO: f64 = WHITE_PET_ALBEDO;
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
    let cavity = lamp_box("cavity", "lamp_cavity", CAVITY, [sy, sz], Facing::Out);
    let sheet = sheet_up("sheet", "reflector_sheet", [0.0, 0.0], [sx, sy], -SHEET_GAP);
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
    vec![guide_box("guide", SIZE), cavity, sheet, tape]
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
    let beads = Beads {
        radius_um: BEAD_RADIUS_UM,
        n: BEAD_N,
        volume_fraction: fv,
    };
    let [front, back, edge] = bare_guide_faces("pmma");
    let description = format!(
        "Edge-lit diffusion light guide {sx} x {sy} x {sz} mm, beads at {} by volume, no dots",
        num(fv)
    );
    let detector = Detector::new([0.0, 0.0, sz + DETECTOR_GAP], [sx, sy], BINS);
    scene_file(
        &header,
        &[
            preamble(&format!("diffusion-lgp-{load}"), &description),
            geometry("diffusion-lgp.obj"),
            medium("pmma", N_PMMA, ABSORPTION, Some(&beads)),
            front,
            back,
            edge,
            white_pet_lambert("lamp_cavity"),
            white_pet_lambert("reflector_sheet"),
            white_pet_lambert("edge_tape"),
            Ccfl::new("lamp", lamp(), LAMP_R, sy - 1.0).toml(),
            detector.toml(),
            trace_table(400_000, 100_000),
        ],
    )
}

/// The three scene files, the `.obj` and the `.mtl`.
pub fn files() -> Vec<GenFile> {
    let parts = parts();
    let triangles = triangle_count(&parts);
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
    files.extend(obj_and_mtl(
        "diffusion-lgp",
        "diffusion-lgp.obj",
        &header,
        &parts,
        MtlNote::Plain,
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
