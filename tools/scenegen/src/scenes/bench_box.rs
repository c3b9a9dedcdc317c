//! `bench-box/`: the box-guide scene of `blutrace bench`'s speed-of-light table. An edge-lit
//! PMMA box guide with a Lambertian strip on one edge, graded dots on the back, a white
//! sheet under it and the target above: the shapes a hand-written kernel can trace with
//! analytic planes (`src/bench/reference.rs` refuses any scene not of this shape), and
//! still a backlight whose light has to be extracted by the dots.

use super::GENERATED;
use crate::shapes::{guide_box, sheet_up};
use crate::templates::{
    Detector, Dots, Led, MtlNote, dotted_guide_faces, geometry, lambert, medium, obj_and_mtl,
    preamble, scene_file, trace_table,
};
use crate::{GenFile, P3, Part, dim, triangle_count};

/// Default photons: the map's noise floor (`cv_noise_floor`, the cv of noise alone) about
/// 0.1, so the first picture shows the backlight, not its noise (a few seconds on 2 cores;
/// `tests/bundled_scenes.rs` checks it).
const PHOTONS: u64 = 2_000_000;

/// Guide size (x along the light, y along the lit edge, z thickness) (mm); the guide spans
/// 0..SIZE.
pub const SIZE: P3 = [120.0, 80.0, 3.0];
/// PMMA refractive index.
pub const N_PMMA: f64 = 1.49;
/// PMMA absorption (1/mm), notebook14's.
pub const ABSORPTION: f64 = 0.0003;
/// Air gap between the emitting strip and the guide's x = 0 edge face (mm).
pub const STRIP_GAP: f64 = 0.1;
/// Radiant power of the strip (W).
pub const STRIP_POWER_W: f64 = 1.0;
/// Air gap between the back face and the reflector sheet (mm).
pub const SHEET_GAP: f64 = 0.1;
/// Reflector sheet albedo (Lambertian).
pub const SHEET_ALBEDO: f64 = 0.96;
/// Detector height above the front face (mm).
pub const DETECTOR_GAP: f64 = 0.5;
/// Square dot lattice pitch (mm).
pub const DOT_PITCH: f64 = 0.5;
/// Dot density in u = x / L (area fraction), lowest degree first: graded by hand from
/// sparse at the lit edge to dense at the far one, not optimized.
pub const DOT_DENSITY: [f64; 3] = [0.05, 0.2, 0.4];
/// Ink albedo.
pub const INK_ALBEDO: f64 = 0.9;

/// The guide and the reflector sheet under it (from under the strip to the far edge).
pub fn parts() -> Vec<Part> {
    let [sx, sy, _] = SIZE;
    vec![
        guide_box("guide", SIZE),
        sheet_up(
            "sheet",
            "reflector_sheet",
            [-STRIP_GAP, 0.0],
            [sx, sy],
            -SHEET_GAP,
        ),
    ]
}

fn scene_toml(triangles: usize) -> String {
    let [sx, sy, sz] = SIZE;
    let [c0, c1, c2] = DOT_DENSITY;
    let header = format!(
        "bench-box: an edge-lit box guide for `blutrace bench`: blutrace traces it beside a
hand-written reference kernel of the same physics (src/bench/reference.rs, analytic
planes), and a test checks that both give the same fates and flux within their errors.
Edit the numbers freely, but keep the shapes (a box guide, one flat Lambertian strip on an
edge, dots on the back, one flat Lambertian sheet, the target above): the reference
kernel refuses any other scene.
{GENERATED}

Axes (mm): x runs from the lit edge to the far edge, y along the lit edge, z through
the thickness; the front face is at +z, towards the viewer.

- Light guide: {sx} x {sy} x {sz} at x 0..{sx}, y 0..{sy}, z 0..{sz}. PMMA n = {N_PMMA},
  absorption {ABSORPTION} /mm (an attenuation length of 3.3 m): notebook14's value, an
  assumption for a commercial light-guide grade; the purest PMMA glass absorbs 15 times
  less (about 2e-4 /cm near 500 nm by laser calorimetry: B. Christ and M. Marhic, Proc.
  SPIE 297, 1982). Tags lgp_front (z = {sz}), lgp_back (z = 0, ink dots), lgp_edge (the
  four sides, bare: light reaching them may leave the guide).
- Ink dots on the back face: square lattice, pitch {DOT_PITCH}, at the cell centres,
  density d = {c0} + {c1} u + {c2} u^2 (area fraction, u = x/{sx}), graded by hand, not
  optimized; ink albedo {INK_ALBEDO}, as the other bundled scenes: an assumption for a
  white (TiO2) screen-printed ink, no measured value found.
- Emitter: one flat Lambertian strip (an LED-type source, cos^1) covering the x = 0 edge
  face, {sy} (y) x {sz} (z), {STRIP_GAP} in front of it (x = {xs}), in air, facing +x,
  {STRIP_POWER_W} W: the edge light of an LED bar whose LEDs are dense enough to merge.
  Its body is the strip itself (front Lambertian, back absorbing), as the bundled LEDs'.
  Left out: a housing round the strip (light leaving through the {STRIP_GAP} gap above the
  front face or below the back face is not caught; what goes down meets the sheet).
- Reflector sheet (tag reflector_sheet): z = {zs} ({SHEET_GAP} air gap below the back face),
  x {xs}..{sx}, y 0..{sy}; Lambertian, albedo {SHEET_ALBEDO}: white polyester LCD
  reflector films are required to reflect over 96 % (lcdpartscn.com, \"Reflector film,
  reflective film\"). A stand-in: fully diffuse, where real white PET has a weak gloss.
- Detector: {DETECTOR_GAP} above the front face (z = {zd}), exactly covering it, 1 mm bins.

Geometry: bench-box.obj (tags are its usemtl names), {triangles} triangles.
",
        xs = dim(-STRIP_GAP),
        zs = dim(-SHEET_GAP),
        zd = dim(sz + DETECTOR_GAP),
    );
    let dots = Dots {
        inside: "pmma",
        ink_albedo: INK_ALBEDO,
        lattice: "square",
        pitch: DOT_PITCH,
        axis: [1.0, 0.0, 0.0],
        length: sx,
        density: &DOT_DENSITY,
        normalized: true,
        mirror: None,
    };
    let [front, edge, back] = dotted_guide_faces(&dots);
    let strip = Led {
        cos_exponent: Some(1.0),
        power_w: STRIP_POWER_W,
        // Whole millimetres without `.0` (`80`, not `80.0`), as the scene has always read.
        size_format: dim,
        ..Led::facing_x("edge_strip", [-STRIP_GAP, 0.5 * sy, 0.5 * sz], [sy, sz])
    };
    let description = format!(
        "Edge-lit {} x {} x {} mm PMMA box guide, Lambertian edge strip, graded square dots, white sheet: blutrace bench's reference scene",
        dim(sx),
        dim(sy),
        dim(sz)
    );
    let detector = Detector::new(
        [0.0, 0.0, sz + DETECTOR_GAP],
        [sx, sy],
        [sx as usize, sy as usize],
    );
    scene_file(
        &header,
        &[
            preamble("bench-box", &description),
            geometry("bench-box.obj"),
            medium("pmma", N_PMMA, ABSORPTION, None),
            front,
            edge,
            back,
            lambert("reflector_sheet", SHEET_ALBEDO),
            strip.toml(),
            detector.toml(),
            trace_table(PHOTONS, 100_000)
                + "# The averaged Fresnel, as the reference kernel (crates/bench) traces: its\n\
                   # speed and agreement tables compare like with like.\n\
                   polarization = false\n",
        ],
    )
}

/// `bench-box/scene.toml`, `.obj` and `.mtl`.
pub fn files() -> Vec<GenFile> {
    let parts = parts();
    let header = format!("bench-box: box guide and sheet (see scene.toml). Units mm.\n{GENERATED}");
    let [obj, mtl] = obj_and_mtl(
        "bench-box",
        "bench-box.obj",
        &header,
        &parts,
        MtlNote::Plain,
    );
    vec![
        GenFile::text("bench-box/scene.toml", scene_toml(triangle_count(&parts))),
        obj,
        mtl,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dots_stay_below_square_packing_and_grow_along_the_guide() {
        let d = |u: f64| DOT_DENSITY[0] + DOT_DENSITY[1] * u + DOT_DENSITY[2] * u * u;
        assert!(d(0.0) > 0.0 && d(1.0) < std::f64::consts::FRAC_PI_4);
        assert!(d(1.0) > d(0.5) && d(0.5) > d(0.0));
    }
}
