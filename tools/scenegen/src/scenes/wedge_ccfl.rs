//! `wedge-ccfl`: a wedge light guide lit by one CCFL on its thick edge, stored as glTF 2.0
//! (`.gltf` JSON plus a `.bin` buffer) under a translated root node.

use super::GENERATED;
use crate::templates::{
    Ccfl, Detector, Dots, dotted_guide_faces, geometry, lamp_reflector, medium, preamble,
    reflector_sheet, scene_file, trace_table,
};
use crate::{GenFile, LampHolder, P3, Part, dim, dims, hexahedron, triangle_count, write_gltf};

/// Default photons: the map's noise floor (`cv_noise_floor`, the cv of noise alone) about
/// 0.1, so the first picture shows the backlight, not its noise (a few seconds on 2 cores;
/// `tests/bundled_scenes.rs` checks it).
const PHOTONS: u64 = 4_000_000;

/// Light guide length along x, lamp edge to far edge (mm).
pub const L: f64 = 200.0;
/// Light guide width along y (mm).
pub const W: f64 = 150.0;
/// Thickness at the lamp edge, x = 0 (mm).
pub const T0: f64 = 3.0;
/// Thickness at the far edge, x = L (mm).
pub const T1: f64 = 1.0;
/// PMMA refractive index.
pub const N_PMMA: f64 = 1.49;
/// PMMA absorption (1/mm).
pub const ABSORPTION: f64 = 0.0003;
/// Air gap between the back face and the reflector sheet, along z (mm).
pub const SHEET_GAP: f64 = 0.15;
/// Air gap between the lamp reflector's lips and the guide's edge face (mm).
pub const LIP_GAP: f64 = 0.3;
/// CCFL radius (mm).
pub const LAMP_R: f64 = 1.0;
/// Lamp axis distance from the thick edge face (mm).
pub const LAMP_INSET: f64 = 1.8;
/// Segments along the lamp reflector's arc.
pub const ARC_SEGMENTS: usize = 64;
/// Detector height above the front face (mm).
pub const DETECTOR_GAP: f64 = 0.75;
/// Ink dot cell pitch (mm).
pub const DOT_PITCH: f64 = 0.6;
/// Constant ink dot density (area fraction).
pub const DOT_DENSITY: f64 = 0.15;
/// Ink albedo.
pub const INK_ALBEDO: f64 = 0.9;
/// Translation of the glTF root node: the file stores the guide centred on its origin in
/// x and y.
pub const ROOT_TRANSLATION: P3 = [0.5 * L, 0.5 * W, 0.0];

/// Rise of the sloping back face per mm of x.
pub fn slope() -> f64 {
    (T0 - T1) / L
}

/// Height of the back face at `x`.
pub fn back_z(x: f64) -> f64 {
    slope() * x
}

/// Height of the reflector sheet (parallel to the back face) at `x`.
pub fn sheet_z(x: f64) -> f64 {
    back_z(x) - SHEET_GAP
}

/// The unit vector along the back face's slope, away from the lamp.
pub fn dot_axis() -> P3 {
    let len = L.hypot(T0 - T1);
    [L / len, 0.0, (T0 - T1) / len]
}

/// The lamp holder on the thick edge.
pub fn holder() -> LampHolder {
    LampHolder {
        gap: LIP_GAP,
        z_lo: sheet_z(-LIP_GAP),
        z_lo_edge: sheet_z(0.0),
        z_seal: Some(0.0),
        z_hi: T0,
        xc: -LAMP_INSET,
        y0: 0.0,
        y1: W,
        segments: ARC_SEGMENTS,
    }
}

/// The lamp's centre.
pub fn lamp() -> P3 {
    [-LAMP_INSET, 0.5 * W, holder().zc()]
}

/// The scene's parts (world coordinates): light guide, lamp holder, reflector sheet.
pub fn parts() -> Vec<Part> {
    let mut lgp = Part::new("lgp");
    let c = |x: f64, y: f64, front: bool| [x, y, if front { T0 } else { back_z(x) }];
    let corners = [
        [
            [c(0.0, 0.0, false), c(0.0, 0.0, true)],
            [c(0.0, W, false), c(0.0, W, true)],
        ],
        [
            [c(L, 0.0, false), c(L, 0.0, true)],
            [c(L, W, false), c(L, W, true)],
        ],
    ];
    hexahedron(&mut lgp, &corners, "lgp_front", "lgp_back", "lgp_edge");
    let holder = holder().part("lamp_holder", "lamp_reflector");
    let mut sheet = Part::new("reflector_sheet");
    let (x0, x1) = (-LIP_GAP, L);
    sheet.quad(
        "reflector_sheet",
        [x0, 0.0, sheet_z(x0)],
        [x1, 0.0, sheet_z(x1)],
        [x1, W, sheet_z(x1)],
        [x0, W, sheet_z(x0)],
    );
    vec![lgp, holder, sheet]
}

fn scene_toml(triangles: usize) -> String {
    let h = holder();
    let axis = dot_axis();
    let lamp = lamp();
    let header = format!(
        "wedge-ccfl: a wedge light guide lit by one CCFL on its thick edge.
{GENERATED}

Axes (mm): x runs from the lamp edge to the far edge (light propagates along x), y along
the lamp, z through the thickness; the front face is at +z, towards the viewer.

The founding paper names wedge light guides (\"rectangular or wedge in shape\") but gives
no wedge design; every dimension here is chosen as typical (lengths in mm):
- Light guide: {L} x {W} (x, y), {T0} thick at the lamp edge (x = 0) tapering linearly to
  {T1} at the far edge (x = {L}); flat front face at z = {T0}, back face sloping from z = 0 at
  x = 0 to z = {zb} at x = {L}. PMMA, n = {N_PMMA}, absorption {ABSORPTION} /mm.
  Tags lgp_front, lgp_back (ink dots), lgp_edge (the four sides).
- Ink dots on the sloping back face: square lattice, pitch {DOT_PITCH}, constant density
  {DOT_DENSITY}, ink albedo {INK_ALBEDO}, not mirrored; the pattern's axis is the unit vector along
  the slope, ({L}, 0, {rise}) / |({L}, 0, {rise})|, so it lies in the face, and its length is the
  slope's length.
- CCFL: radius {LAMP_R}, length {W}, 1 W, centre (x, z) = ({lx}, {lz}): {air} of air to the edge face.
- Lamp reflector (tag lamp_reflector): a circular arc of radius {r} about the lamp axis,
  {ARC_SEGMENTS} segments, open towards the guide; its lips end {LIP_GAP} short of the edge face,
  the lower lip on the reflector sheet, the upper lip at the front face's height (z = {T0})
  where a flat strip continues it to the front face's edge; flat end caps at y = 0 and
  y = {W} close the arc and the air gap. Phong: reflectance 0.95, specular 0.8, exponent 100.
- Reflector sheet (tag reflector_sheet): parallel to the sloping back face, {SHEET_GAP} below it
  (along z), from the lamp reflector's lower lip (x = {x0}) to the far edge (x = {L}).
  Phong: reflectance 0.95, specular 0.1, exponent 10.
- Detector: {DETECTOR_GAP} above the front face (z = {zd}), exactly covering it.

Geometry: wedge-ccfl.gltf + wedge-ccfl.bin (tags are material names), {triangles} triangles,
written as the glTF specification says (metres, +y up), so it loads with the glTF defaults
units = \"m\", up = \"y\". The glTF root node \"blu\" is translated by {tr} mm (in the
file's own frame): the file's vertices are relative to it, and this file's coordinates
are world coordinates in millimetres, z up.
",
        zb = dim(back_z(L)),
        rise = dim(T0 - T1),
        lx = dim(lamp[0]),
        lz = dim(lamp[2]),
        air = dim(LAMP_INSET - LAMP_R),
        r = dim(h.radius()),
        x0 = dim(-LIP_GAP),
        zd = dim(T0 + DETECTOR_GAP),
        tr = dims(&ROOT_TRANSLATION),
    );
    let dots = Dots {
        inside: "pmma",
        ink_albedo: INK_ALBEDO,
        lattice: "square",
        pitch: DOT_PITCH,
        axis,
        length: L.hypot(T0 - T1),
        density: &[DOT_DENSITY],
        normalized: true,
        mirror: Some(false),
    };
    let [front, edge, back] = dotted_guide_faces(&dots);
    let description = format!(
        "Wedge PMMA light guide {L} x {W} mm, {T0} to {T1} mm thick, one CCFL on the thick edge, constant-density ink dots on the sloping back face"
    );
    scene_file(
        &header,
        &[
            preamble("wedge-ccfl", &description),
            geometry("wedge-ccfl.gltf"),
            medium("pmma", N_PMMA, ABSORPTION, None),
            front,
            edge,
            back,
            lamp_reflector(),
            reflector_sheet(),
            Ccfl::new("lamp", lamp, LAMP_R, W).toml(),
            Detector::new([0.0, 0.0, T0 + DETECTOR_GAP], [L, W], [100, 100]).toml(),
            trace_table(PHOTONS, 100_000),
        ],
    )
}

/// `wedge-ccfl/scene.toml`, `.gltf` and `.bin`.
pub fn files() -> Vec<GenFile> {
    let parts = parts();
    let triangles = triangle_count(&parts);
    let (json, bin) = write_gltf(
        "wedge-ccfl",
        "blu",
        ROOT_TRANSLATION,
        &parts,
        "wedge-ccfl.bin",
    );
    vec![
        GenFile::text("wedge-ccfl/scene.toml", scene_toml(triangles)),
        GenFile::text("wedge-ccfl/wedge-ccfl.gltf", json),
        GenFile {
            path: "wedge-ccfl/wedge-ccfl.bin".into(),
            bytes: bin,
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dot_axis_lies_in_the_back_face() {
        let parts = parts();
        let a = dot_axis();
        for [p, q, r] in parts[0].triangles_of("lgp_back") {
            let e1 = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
            let e2 = [r[0] - p[0], r[1] - p[1], r[2] - p[2]];
            let n = [
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ];
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            let dot = (a[0] * n[0] + a[1] * n[1] + a[2] * n[2]) / len;
            assert!(dot.abs() < 1e-12, "{dot}");
            // Outward: down and towards the far (thin) end's underside.
            assert!(n[2] < 0.0);
        }
        assert!((a[0] * a[0] + a[2] * a[2] - 1.0).abs() < 1e-15);
    }

    #[test]
    fn lamp_sits_in_air_inside_its_reflector() {
        let h = holder();
        let c = lamp();
        let d = (c[0] - h.xc).hypot(c[2] - h.zc());
        assert!(d + LAMP_R < h.radius() - 1.0);
        assert!(c[0] + LAMP_R < -LIP_GAP - 0.4);
        // The sheet stays below the back face everywhere.
        for x in [0.0, 0.5 * L, L] {
            assert!(sheet_z(x) < back_z(x) - 0.1);
        }
    }
}
