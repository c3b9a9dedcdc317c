//! `notebook14`: the founding paper's 14-inch notebook backlight, with two lamp holders
//! of two CCFLs each on the left and right edges of a rectangular PMMA light guide.

use super::GENERATED;
use crate::shapes::{guide_box, sheet_up};
use crate::templates::{
    Ccfl, Detector, Dots, MtlNote, dotted_guide_faces, geometry, lamp_reflector, medium,
    obj_and_mtl, preamble, reflector_sheet, scene_file, trace_table,
};
use crate::{GenFile, LampHolder, P3, Part, dim, triangle_count};

/// Default photons: the map's noise floor (`cv_noise_floor`, the cv of noise alone) about
/// 0.1, so the first picture shows the backlight, not its noise (a few seconds on 2 cores;
/// `tests/bundled_scenes.rs` checks it).
const PHOTONS: u64 = 6_000_000;

/// Light guide length along x, lamp edge to lamp edge (mm).
pub const L: f64 = 290.0;
/// Light guide width along y, the lamps' direction (mm).
pub const W: f64 = 215.0;
/// Light guide thickness (mm).
pub const T: f64 = 3.0;
/// PMMA refractive index (the paper's value).
pub const N_PMMA: f64 = 1.49;
/// PMMA absorption (1/mm).
pub const ABSORPTION: f64 = 0.0003;
/// Air gap between the back face and the reflector sheet (mm).
pub const SHEET_GAP: f64 = 0.15;
/// Air gap between the lamp reflector's lips and the guide's edge face (mm).
pub const LIP_GAP: f64 = 0.3;
/// CCFL radius (mm).
pub const LAMP_R: f64 = 1.0;
/// Lamp axis distance from the guide's edge face (mm): lamps at x = -2.35 and L + 2.35.
pub const LAMP_INSET: f64 = 2.35;
/// Half the centre-to-centre distance of the two lamps of a holder (mm).
pub const LAMP_DZ: f64 = 1.1;
/// Segments along each lamp reflector's arc.
pub const ARC_SEGMENTS: usize = 64;
/// Detector height above the front face (mm).
pub const DETECTOR_GAP: f64 = 0.75;
/// Ink dot cell pitch (mm).
pub const DOT_PITCH: f64 = 0.6;
/// Constant ink dot density (area fraction).
pub const DOT_DENSITY: f64 = 0.2;
/// Ink albedo.
pub const INK_ALBEDO: f64 = 0.9;

/// The left lamp holder (the right one is its mirror image about x = L/2).
pub fn holder() -> LampHolder {
    LampHolder {
        gap: LIP_GAP,
        z_lo: -SHEET_GAP,
        z_lo_edge: -SHEET_GAP,
        z_seal: Some(0.0),
        z_hi: T,
        xc: -LAMP_INSET,
        y0: 0.0,
        y1: W,
        segments: ARC_SEGMENTS,
    }
}

/// Lamp names and centres.
pub fn lamps() -> Vec<(&'static str, P3)> {
    let zc = holder().zc();
    let (xl, xr, y) = (-LAMP_INSET, L + LAMP_INSET, 0.5 * W);
    vec![
        ("left_lower", [xl, y, zc - LAMP_DZ]),
        ("left_upper", [xl, y, zc + LAMP_DZ]),
        ("right_lower", [xr, y, zc - LAMP_DZ]),
        ("right_upper", [xr, y, zc + LAMP_DZ]),
    ]
}

/// The scene's parts: light guide, two lamp holders, reflector sheet.
pub fn parts() -> Vec<Part> {
    let left = holder().part("lamp_holder_left", "lamp_reflector");
    let mut right = Part::new("lamp_holder_right");
    right.append_mapped(&left, |p| [L - p[0], p[1], p[2]], true);
    let sheet = sheet_up(
        "reflector_sheet",
        "reflector_sheet",
        [-LIP_GAP, 0.0],
        [L + LIP_GAP, W],
        -SHEET_GAP,
    );
    vec![guide_box("lgp", [L, W, T]), left, right, sheet]
}

fn scene_toml(triangles: usize) -> String {
    let h = holder();
    let zc = h.zc();
    let header = format!(
        "notebook14: the 14-inch notebook backlight of the founding paper (Design, Analysis, and
Optimization of LCD Backlight Unit using Ray Tracing Simulation, section 3).
{GENERATED}

Axes (mm): x runs lamp edge to lamp edge (light propagates along x), y along the lamps,
z through the thickness; the front face is at +z, towards the viewer.

From the paper: a notebook BLU for a 14\" LCD; a rectangular PMMA light guide (n = 1.49);
two lamp holders at the left and right edges, each enclosing two CCFLs that emit
Lambertian light from their surface; lamp reflectors and the reflection sheet are Phong
surfaces, the ink dots on the back face Lambertian; dots in square or hexagonal cells of
pitch under 1 mm; all dots the same size for the first result (figure 4); a 100 x 100
grid on a target surface at the front face; 400,000 photons.

Not given by the paper, chosen as typical (lengths in mm):
- Light guide: {L} x {W} x {T} (x, y, z) at x 0..{L}, y 0..{W}, z 0..{T}
  (a 14.1\" 4:3 panel's active area is 286 x 214). PMMA absorption {ABSORPTION} /mm.
  Tags lgp_front (z = {T}), lgp_back (z = 0, ink dots), lgp_edge (the four sides).
- Ink dots: hex lattice, pitch {DOT_PITCH}, constant density {DOT_DENSITY} (area fraction), ink albedo
  {INK_ALBEDO}; mirrored about x = {half} since lamps light both x edges.
- CCFLs: radius {LAMP_R}, length {W} (the guide's y extent), 1 W and 300 lm each
  (300 lm/W: a typical tri-phosphor white spectrum), centres at
  x = {xl} (left) and {xr} (right), y = {yc}, z = {zlo} and {zhi} (stacked in z, {tube_gap}
  apart): {air} of air between a tube and the guide's edge face.
- Lamp reflectors (tag lamp_reflector): a circular arc of radius {r} about
  (x, z) = ({xl}, {zc}), {ARC_SEGMENTS} segments, wrapped round both tubes ({clear} clearance) and
  open towards the guide; its lips end {LIP_GAP} short of the edge face, the lower lip on the
  reflector sheet (z = {zs}), the upper lip at the front face's height (z = {T}) where a flat
  {LIP_GAP}-wide strip continues it to the edge of the front face; flat end caps at y = 0 and
  y = {W} close the arc and the air gap in front of the edge; a wall at x = 0 from the
  sheet up to the back face seals the air gap under the guide (as a reflector taped to the
  guide's back does), so lamp light enters the guide only through its edge face. Phong:
  reflectance 0.95, specular 0.8, exponent 100.
- Reflector sheet (tag reflector_sheet): z = {zs} ({SHEET_GAP} air gap below the back face),
  x {x0}..{x1}, y 0..{W}: the light guide's footprint plus the air gaps up to both lamp
  reflectors' lower lips, which it meets, so lamp light reaches the viewer only through
  the guide. Phong: reflectance 0.95, mostly diffuse (specular 0.1, exponent 10).
- Detector: {DETECTOR_GAP} above the front face (z = {zd}), exactly covering it.

Geometry: notebook14.obj (tags are its usemtl names), {triangles} triangles.
",
        half = dim(0.5 * L),
        xl = dim(-LAMP_INSET),
        xr = dim(L + LAMP_INSET),
        yc = dim(0.5 * W),
        zlo = dim(zc - LAMP_DZ),
        zhi = dim(zc + LAMP_DZ),
        tube_gap = dim(2.0 * (LAMP_DZ - LAMP_R)),
        air = dim(LAMP_INSET - LAMP_R),
        r = dim(h.radius()),
        zc = dim(zc),
        clear = dim(h.radius() - LAMP_DZ - LAMP_R),
        zs = dim(-SHEET_GAP),
        x0 = dim(-LIP_GAP),
        x1 = dim(L + LIP_GAP),
        zd = dim(T + DETECTOR_GAP),
    );
    let dots = Dots {
        inside: "pmma",
        ink_albedo: INK_ALBEDO,
        lattice: "hex",
        pitch: DOT_PITCH,
        axis: [1.0, 0.0, 0.0],
        length: L,
        density: &[DOT_DENSITY],
        normalized: true,
        mirror: Some(true),
    };
    let description = format!(
        "14-inch notebook BLU: {L} x {W} x {T} mm PMMA light guide, two CCFLs in each of two lamp holders, constant-density ink dots"
    );
    let mut tables = vec![
        preamble("notebook14", &description),
        geometry("notebook14.obj"),
        medium("pmma", N_PMMA, ABSORPTION, None),
    ];
    tables.extend(dotted_guide_faces(&dots));
    tables.push(lamp_reflector());
    tables.push(reflector_sheet());
    for (name, c) in lamps() {
        let lamp = Ccfl {
            lumens: Some(300.0),
            ..Ccfl::new(name, c, LAMP_R, W)
        };
        tables.push(lamp.toml());
    }
    tables.push(Detector::new([0.0, 0.0, T + DETECTOR_GAP], [L, W], [100, 100]).toml());
    tables.push(trace_table(PHOTONS, 100_000));
    scene_file(&header, &tables)
}

/// `notebook14/scene.toml`, `.obj` and `.mtl`.
pub fn files() -> Vec<GenFile> {
    let parts = parts();
    let header =
        format!("notebook14: 14-inch notebook backlight (see scene.toml). Units mm.\n{GENERATED}");
    let [obj, mtl] = obj_and_mtl(
        "notebook14",
        "notebook14.obj",
        &header,
        &parts,
        MtlNote::DisplayOnly,
    );
    vec![
        GenFile::text("notebook14/scene.toml", scene_toml(triangle_count(&parts))),
        obj,
        mtl,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lamps_sit_in_air_inside_their_reflector() {
        let h = holder();
        let r = h.radius();
        for (name, c) in lamps() {
            let x = if c[0] < 0.0 { c[0] } else { L - c[0] };
            // Inside the arc's circle with clearance, in front of nothing else.
            let d = (x - h.xc).hypot(c[2] - h.zc());
            assert!(d + LAMP_R < r - 0.4, "{name}: too close to the reflector");
            assert!(x + LAMP_R < -LIP_GAP - 1.0, "{name}: not behind the lips");
        }
        // The two tubes of a holder do not touch.
        let l = lamps();
        for pair in [&l[0..2], &l[2..4]] {
            let d = (pair[0].1[0] - pair[1].1[0]).hypot(pair[0].1[2] - pair[1].1[2]);
            assert!(d > 2.0 * LAMP_R + 0.1, "tubes {d} apart");
        }
    }

    #[test]
    fn reflector_sheet_lies_below_the_light_guide() {
        let parts = parts();
        let sheet = parts[3].triangles_of("reflector_sheet");
        for t in &sheet {
            for p in t {
                assert!((p[2] + SHEET_GAP).abs() < 1e-12);
                assert!(p[0] >= -LIP_GAP && p[0] <= L + LIP_GAP);
            }
        }
        let lgp_back = parts[0].triangles_of("lgp_back");
        assert!(lgp_back.iter().flatten().all(|p| p[2] == 0.0));
        // Every lamp reflector point is outside the guide's x range.
        for holder in &parts[1..3] {
            for p in &holder.verts {
                assert!(p[0] <= 0.0 || p[0] >= L, "{p:?}");
            }
        }
    }
}
