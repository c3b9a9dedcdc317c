//! `phone-led`: a 6.1-inch phone backlight edge-lit by a row of side-view LEDs along one
//! short edge, each with a measured (tabulated) intensity profile read from `led.ies`
//! (`led.csv` holds the same profile as a CSV table).
//!
//! The LEDs are few and far apart on purpose, so the edge-lit LED backlight's classic
//! defects show in the flux map: a bright fan ("hot spot") in front of each LED, dark
//! wedges between them and dark corners at both ends of the row.

use super::GENERATED;
use crate::shapes::{guide_box, sheet_up};
use crate::templates::{
    Detector, Dots, Led, MtlNote, absorber, dotted_guide_faces, geometry, medium, obj_and_mtl,
    phong, preamble, reflector_sheet, scene_file, trace_table,
};
use crate::{GenFile, P3, Part, comment, dim, num, triangle_count};

/// Default photons: the map's noise floor (`cv_noise_floor`, the cv of noise alone) about
/// 0.1, so the first picture shows the backlight, not its noise (a few seconds on 2 cores;
/// `tests/bundled_scenes.rs` checks it).
const PHOTONS: u64 = 2_000_000;

/// Light guide length along x, LED edge to far edge (mm).
pub const L: f64 = 140.0;
/// Light guide width along y, the LED row's direction (mm).
pub const W: f64 = 68.0;
/// Light guide thickness (mm).
pub const T: f64 = 0.55;
/// PMMA refractive index.
pub const N_PMMA: f64 = 1.49;
/// PMMA absorption (1/mm).
pub const ABSORPTION: f64 = 0.0005;
/// Number of LEDs, in a row centred on the x = 0 edge.
pub const LEDS: usize = 6;
/// LED spacing, centre to centre (mm). The row is shorter than the edge, as on phones
/// whose LED strip stops short of the corners: the end LEDs are 9 mm from the sides.
pub const LED_PITCH: f64 = 10.0;
/// LED emitting window along y (mm).
pub const LED_W: f64 = 3.0;
/// LED emitting window along z (mm).
pub const LED_H: f64 = 0.4;
/// Air gap between the LED windows and the guide's edge face (mm).
pub const LED_GAP: f64 = 0.1;
/// Radiant power per LED (W).
pub const LED_POWER_W: f64 = 0.03;
/// Peak intensity written to `led.ies` (cd).
pub const PEAK_CD: f64 = 2.0;
/// Depth of the LED housing behind the guide's edge face (mm): it spans x = -depth..0.
pub const HOUSING_DEPTH: f64 = 1.0;
/// Air gap between the back face and the reflector sheet (mm).
pub const SHEET_GAP: f64 = 0.1;
/// Detector height above the front face (mm).
pub const DETECTOR_GAP: f64 = 0.3;
/// Width of the black light-shielding tape over the LED edge, from the edge face (mm):
/// the display's active area, and the detector, start here.
pub const SHIELD_WIDTH: f64 = 2.0;
/// Height of the shielding tape above the front face (mm).
pub const SHIELD_GAP: f64 = 0.05;
/// Ink dot cell pitch (mm).
pub const DOT_PITCH: f64 = 0.3;
/// Ink dot density polynomial in u = x / L, lowest degree first (area fraction): sparse
/// near the LEDs, rising steeply near the far end, tuned by hand so the flux beyond the
/// first 10 mm stays within about 10% of its mean along x.
pub const DOT_DENSITY: [f64; 7] = [0.025, 0.02, 0.0, 0.04, 0.04, 0.0, 0.1];
/// Ink albedo.
pub const INK_ALBEDO: f64 = 0.9;
/// Angle step of the intensity table (degrees).
pub const PROFILE_STEP_DEG: usize = 5;

/// The illustrative side-view LED profile (relative intensity at `theta` degrees from the
/// window's normal): a shallow batwing, wider than Lambertian, peaking near 35 degrees,
/// `(0.75 + 0.6 sin^2 theta) cos^0.8 theta`. Not a measurement of any product.
pub fn profile_shape(theta_deg: f64) -> f64 {
    let t = theta_deg.to_radians();
    (0.75 + 0.6 * t.sin().powi(2)) * t.cos().max(0.0).powf(0.8)
}

/// The table written to both profile files: angles 0..=90 in [`PROFILE_STEP_DEG`] steps
/// and relative intensities (largest 1) rounded to 4 decimals.
pub fn profile_table() -> Vec<(f64, f64)> {
    let angles: Vec<f64> = (0..=90)
        .step_by(PROFILE_STEP_DEG)
        .map(|d| d as f64)
        .collect();
    let max = angles.iter().map(|&a| profile_shape(a)).fold(0.0, f64::max);
    angles
        .iter()
        .map(|&a| (a, (profile_shape(a) / max * 1e4).round() / 1e4))
        .collect()
}

/// Luminous flux (lm) of the IES table: 2 pi times the integral of I sin(theta) with I
/// linear between table angles (fine midpoint rule).
pub fn ies_lumens() -> f64 {
    let t = profile_table();
    let steps = 9000;
    let mut sum = 0.0;
    for k in 0..steps {
        let d = 90.0 * (k as f64 + 0.5) / steps as f64;
        let i = (d / PROFILE_STEP_DEG as f64) as usize;
        let f = (d - t[i].0) / PROFILE_STEP_DEG as f64;
        let rel = t[i].1 + f * (t[i + 1].1 - t[i].1);
        sum += rel * PEAK_CD * d.to_radians().sin() * (90f64 / steps as f64).to_radians();
    }
    2.0 * std::f64::consts::PI * sum
}

/// LED window centres.
pub fn leds() -> Vec<P3> {
    (0..LEDS)
        .map(|i| {
            let k = i as f64 - 0.5 * (LEDS as f64 - 1.0);
            [-LED_GAP, 0.5 * W + k * LED_PITCH, 0.5 * T]
        })
        .collect()
}

/// The scene's parts: light guide, LED housing, reflector sheet, shielding tape.
pub fn parts() -> Vec<Part> {
    // LED housing: back wall at x = -d, top over the LEDs and the air gap (level with the
    // front face), end caps at y = 0 and W; the reflector sheet closes it from below.
    // Normals face into the housing.
    let mut housing = Part::new("led_housing");
    let (d, z0, t) = (-HOUSING_DEPTH, -SHEET_GAP, "led_housing");
    housing.quad(t, [d, 0.0, z0], [d, W, z0], [d, W, T], [d, 0.0, T]);
    housing.quad(t, [d, 0.0, T], [d, W, T], [0.0, W, T], [0.0, 0.0, T]);
    housing.quad(t, [d, 0.0, z0], [d, 0.0, T], [0.0, 0.0, T], [0.0, 0.0, z0]);
    housing.quad(t, [d, W, z0], [0.0, W, z0], [0.0, W, T], [d, W, T]);
    let sheet = sheet_up("reflector_sheet", "reflector_sheet", [d, 0.0], [L, W], z0);
    // Black light-shielding tape over the housing and the first mm of the guide, facing
    // down.
    let mut tape = Part::new("shield_tape");
    let z = T + SHIELD_GAP;
    tape.quad(
        "shield_tape",
        [d, 0.0, z],
        [d, W, z],
        [SHIELD_WIDTH, W, z],
        [SHIELD_WIDTH, 0.0, z],
    );
    vec![guide_box("lgp", [L, W, T]), housing, sheet, tape]
}

/// `c0 + c1 u + c2 u^2 ...` without the zero terms, for comments.
fn polynomial(c: &[f64]) -> String {
    let terms: Vec<String> = c
        .iter()
        .enumerate()
        .filter(|(_, c)| **c != 0.0)
        .map(|(k, c)| match k {
            0 => num(*c),
            1 => format!("{} u", num(*c)),
            _ => format!("{} u^{k}", num(*c)),
        })
        .collect();
    terms.join(" + ")
}

fn csv() -> String {
    let mut s = comment(&format!(
        "Side-view LED relative intensity by angle from the emitting window's normal.
ILLUSTRATIVE ONLY: a smooth batwing-ish shape, (0.75 + 0.6 sin^2 t) cos^0.8 t, wider
than Lambertian; not a measurement of any product. Same table as led.ies.
{GENERATED}"
    ));
    s += "theta_deg,relative_intensity\n";
    for (a, i) in profile_table() {
        s += &format!("{},{:.4}\n", dim(a), i);
    }
    s
}

fn ies() -> String {
    let table = profile_table();
    let mut s = String::from("IESNA:LM-63-2002\r\n");
    for line in [
        "[TEST] none: ILLUSTRATIVE profile, not a measurement",
        "[TESTLAB] blutrace scenegen",
        "[ISSUEDATE] 2024-01-01",
        "[MANUFAC] none (illustrative)",
        "[LUMCAT] SV-3004-ILLUSTRATIVE",
        "[LUMINAIRE] side-view white LED, 3.0 x 0.4 mm emitting window",
        "[LAMP] white LED",
        "[OTHER] Generated by tools/scenegen (scenes/phone-led). Same table as led.csv.",
        "[MORE] Rotationally symmetric (one horizontal angle); type C, 0 = window normal.",
    ] {
        s += line;
        s += "\r\n";
    }
    s += "TILT=NONE\r\n";
    // Lamps, lumens per lamp, multiplier, vertical angles, horizontal angles, photometric
    // type C, units metres, width, length, height of the luminous opening.
    s += &format!(
        "1 {:.2} 1.0 {} 1 1 2 {} {} 0.0\r\n",
        ies_lumens(),
        table.len(),
        num(LED_W * 1e-3),
        num(LED_H * 1e-3)
    );
    s += "1.0 1.0 0.1\r\n";
    let angles: Vec<String> = table.iter().map(|(a, _)| dim(*a)).collect();
    s += &angles.join(" ");
    s += "\r\n0\r\n";
    let cd: Vec<String> = table
        .iter()
        .map(|(_, i)| format!("{:.4}", i * PEAK_CD))
        .collect();
    for row in cd.chunks(10) {
        s += &row.join(" ");
        s += "\r\n";
    }
    s
}

fn scene_toml(triangles: usize) -> String {
    // Each LED's luminous flux, to 0.01 lm.
    let lumens = (ies_lumens() * 100.0).round() / 100.0;
    let header = format!(
        "phone-led: a 6.1-inch phone backlight edge-lit by {LEDS} side-view LEDs on one short edge.
{GENERATED}

Axes (mm): x runs from the LED edge to the far edge (light propagates along x), y along
the LED row, z through the thickness; the front face is at +z, towards the viewer.

Chosen as typical of a phone (lengths in mm):
- Light guide: {L} x {W} x {T} (x, y, z; a 6.1\" 2:1 panel is about 141 x 65) at
  x 0..{L}, y 0..{W}, z 0..{T}. PMMA n = {N_PMMA}, absorption {ABSORPTION} /mm. Tags lgp_front
  (z = {T}), lgp_back (z = 0, ink dots), lgp_edge (the four sides, bare: light reaching
  them leaves the guide).
- Ink dots on the back face: hex lattice, pitch {DOT_PITCH}, density graded along x,
  d = {poly} (area fraction, u = x/L), ink albedo {INK_ALBEDO}.
- LEDs: {LEDS} side-view LEDs, emitting windows {LED_W} (y) x {LED_H} (z), centred at z = {zc},
  at y = {y0}, {y1}, ... ({pitch_s} apart), facing +x from x = {xl} ({LED_GAP} air gap before
  the edge face). {LED_POWER_W} W (and {lm} lm) each. Intensity profile: led.ies (LM-63-2002,
  type C, one horizontal angle, i.e. rotationally symmetric about the window's normal);
  led.csv holds the same table. ILLUSTRATIVE: a shallow batwing, wider than Lambertian,
  peaking near 35 degrees; not a measured product. Each LED has a body (its `body` entry
  below): photons returning to an LED meet its emitting window (diffuse, albedo 0.8) or,
  from behind, its absorbing package.
- LED housing (tag led_housing): a white box round the LED row, x {xh}..0, y 0..{W},
  z {zs}..{T}: back wall, top (level with the front face, covering the LEDs and the air
  gap), end caps; the reflector sheet closes it from below. Phong: reflectance 0.9,
  diffuse (specular 0.1, exponent 10).
- Reflector sheet (tag reflector_sheet): z = {zs} ({SHEET_GAP} air gap below the back face),
  x {xh}..{L}, y 0..{W}. Phong: reflectance 0.95, specular 0.1, exponent 10.
- Light-shielding tape (tag shield_tape, black absorber): {SHIELD_GAP} above the front face
  (z = {zt}), x {xh}..{SHIELD_WIDTH}, y 0..{W}, over the LED housing and the first {SHIELD_WIDTH} of the guide,
  where the LEDs' light is most concentrated (as the black tape and bezel of a phone).
- Detector: {DETECTOR_GAP} above the front face (z = {zd}), over the active area beyond the
  tape, x {SHIELD_WIDTH}..{L}, y 0..{W}, 1 mm bins.

What to look for in the flux map: light enters the guide within the critical cone
(+-42 degrees of x), so in front of each LED a bright fan opens (hot spots), between the
LEDs dark wedges a few mm deep remain, and at both ends of the row, whose end LEDs sit
{end} from the sides, deeper dark corners (the bare side faces mirror the light by total
internal reflection, so a corner looks like half of a {corner} gap between LEDs). Real
phones hide this strip under the bezel.

Geometry: phone-led.obj (tags are its usemtl names), {triangles} triangles.
",
        poly = polynomial(&DOT_DENSITY),
        zc = dim(0.5 * T),
        y0 = dim(leds()[0][1]),
        y1 = dim(leds()[1][1]),
        pitch_s = dim(LED_PITCH),
        xl = dim(-LED_GAP),
        lm = lumens,
        xh = dim(-HOUSING_DEPTH),
        end = dim(leds()[0][1]),
        corner = dim(2.0 * leds()[0][1]),
        zs = dim(-SHEET_GAP),
        zd = dim(T + DETECTOR_GAP),
        zt = dim(T + SHIELD_GAP),
    );
    let dots = Dots {
        inside: "pmma",
        ink_albedo: INK_ALBEDO,
        lattice: "hex",
        pitch: DOT_PITCH,
        axis: [1.0, 0.0, 0.0],
        length: L,
        density: &DOT_DENSITY,
        normalized: true,
        mirror: None,
    };
    let description = format!(
        "6.1-inch phone BLU: {L} x {W} x {T} mm PMMA light guide edge-lit by {LEDS} side-view LEDs with a tabulated (IES) profile"
    );
    let mut tables = vec![
        preamble("phone-led", &description),
        geometry("phone-led.obj"),
        medium("pmma", N_PMMA, ABSORPTION, None),
    ];
    tables.extend(dotted_guide_faces(&dots));
    tables.push(phong("led_housing", 0.9, 0.1, 10.0));
    tables.push(reflector_sheet());
    tables.push(absorber("shield_tape"));
    for (i, c) in leds().iter().enumerate() {
        let name = format!("led{}", i + 1);
        let led = Led {
            power_w: LED_POWER_W,
            lumens: Some(lumens),
            intensity_file: Some("led.ies"),
            ..Led::facing_x(&name, *c, [LED_W, LED_H])
        };
        tables.push(led.toml());
    }
    let detector = Detector::new(
        [SHIELD_WIDTH, 0.0, T + DETECTOR_GAP],
        [L - SHIELD_WIDTH, W],
        [(L - SHIELD_WIDTH) as usize, W as usize],
    );
    tables.push(detector.toml());
    tables.push(trace_table(PHOTONS, 100_000));
    scene_file(&header, &tables)
}

/// `phone-led/scene.toml`, `.obj`, `.mtl`, `led.ies` and `led.csv`.
pub fn files() -> Vec<GenFile> {
    let parts = parts();
    let header =
        format!("phone-led: LED edge-lit phone backlight (see scene.toml). Units mm.\n{GENERATED}");
    let [obj, mtl] = obj_and_mtl(
        "phone-led",
        "phone-led.obj",
        &header,
        &parts,
        MtlNote::DisplayOnly,
    );
    vec![
        GenFile::text("phone-led/scene.toml", scene_toml(triangle_count(&parts))),
        obj,
        mtl,
        GenFile::text("phone-led/led.ies", ies()),
        GenFile::text("phone-led/led.csv", csv()),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profile_is_a_wide_batwing() {
        let t = profile_table();
        assert_eq!(t.len(), 19);
        assert_eq!(t[18], (90.0, 0.0));
        let peak = t.iter().position(|&(_, i)| i == 1.0).unwrap();
        assert!((30.0..=45.0).contains(&t[peak].0), "peak at {}", t[peak].0);
        // Wider than Lambertian: relative to its on-axis value, more intensity at 60.
        assert!(t[12].1 / t[0].1 > 60f64.to_radians().cos());
    }

    #[test]
    fn leds_fit_the_edge_and_the_housing() {
        for c in leds() {
            assert!(c[1] - 0.5 * LED_W > 0.0 && c[1] + 0.5 * LED_W < W);
            assert!(c[2] - 0.5 * LED_H > 0.0 && c[2] + 0.5 * LED_H < T);
            assert!(c[0] > -HOUSING_DEPTH && c[0] < 0.0);
        }
        let d: Vec<u32> = DOT_DENSITY.iter().map(|c| (c * 100.0) as u32).collect();
        assert!(
            d.iter().sum::<u32>() < 90,
            "density stays below hex packing"
        );
    }
}
