//! `bef-stack`: a small edge-lit backlight with its optical films: a dotted light guide on a
//! white reflector sheet, a surface diffuser sheet, and two crossed prism films
//! (brightness enhancement films, BEF) with procedural 90 deg prisms of 50 um pitch.
//! The films are in their own geometry file, so a test can drop them to measure the
//! on-axis gain they give.

use super::GENERATED;
use crate::shapes::{Facing, guide_box, lamp_box, sheet_up, solid_box};
use crate::templates::{
    Detector, Dots, Led, dielectric, dotted_guide_faces, geometry, medium, preamble,
    rough_dielectric, scene_file, silver_mirror, trace_table, white_pet_lambert,
};
use crate::{
    GenFile, ObjTags, P3, Part, arr, dim, dims, num, tags_of, triangle_count, write_mtl, write_obj,
};

/// Light guide size (x, y, z) (mm); it spans 0..GUIDE, lit through its x = 0 edge.
pub const GUIDE: P3 = [40.0, 30.0, 0.8];
/// PMMA refractive index (guide).
pub const N_PMMA: f64 = 1.49;
/// PET refractive index (diffuser and prism films).
pub const N_PET: f64 = 1.58;
/// Dot pattern: hex pitch (mm) and density d(x) = c0 + c1 x + c2 x^2, x normalized.
pub const DOT_PITCH: f64 = 0.4;
/// Dot density polynomial.
pub const DOT_DENSITY: [f64; 3] = [0.08, 0.0, 0.55];
/// Gap between the reflector sheet and the guide's back face (mm).
pub const SHEET_GAP: f64 = 0.1;
/// Lamp housing depth behind the x = 0 edge (mm): x -HOUSING..0.
pub const HOUSING: f64 = 1.5;
/// LED bar emitting rectangle (y x z, mm).
pub const LED: [f64; 2] = [28.0, 0.6];
/// Diffuser sheet: bottom z and thickness (mm).
pub const DIFFUSER: [f64; 2] = [0.85, 0.1];
/// Diffuser top face GGX roughness.
pub const ROUGHNESS: f64 = 0.6;
/// Prism films: bottom z of each and thickness (mm).
pub const BEF_Z: [f64; 2] = [1.0, 1.2];
/// Prism film base thickness (mm).
pub const BEF_T: f64 = 0.1;
/// Prism pitch (mm) and apex angle (deg).
pub const PRISM: [f64; 2] = [0.05, 90.0];
/// Detector height (z, mm).
pub const DETECTOR_Z: f64 = 1.4;

/// The LED's centre: mid-housing.
pub fn led() -> P3 {
    [-0.5 * HOUSING, 0.5 * GUIDE[1], 0.5 * GUIDE[2]]
}

/// Guide, reflector sheet, lamp housing and diffuser.
pub fn stack_parts() -> Vec<Part> {
    let [gx, gy, gz] = GUIDE;
    let [z0, th] = DIFFUSER;
    vec![
        guide_box("guide", GUIDE),
        sheet_up(
            "reflector_sheet",
            "reflector_sheet",
            [0.0, 0.0],
            [gx, gy],
            -SHEET_GAP,
        ),
        // Five mirror walls round the LED, open towards the guide's x = 0 edge.
        lamp_box(
            "lamp_reflector",
            "lamp_reflector",
            HOUSING,
            [gy, gz],
            Facing::In,
        ),
        solid_box(
            "diffuser",
            [0.0, 0.0, z0],
            [gx, gy, z0 + th],
            ["diffuser_top", "diffuser_back", "diffuser_edge"],
        ),
    ]
}

/// The two prism films.
pub fn film_parts() -> Vec<Part> {
    let [gx, gy, _] = GUIDE;
    (1..=2)
        .map(|i| {
            let z0 = BEF_Z[i - 1];
            let tags = ["top", "back", "edge"].map(|face| format!("bef{i}_{face}"));
            let [top, back, edge] = tags.each_ref().map(String::as_str);
            solid_box(
                &format!("bef{i}"),
                [0.0, 0.0, z0],
                [gx, gy, z0 + BEF_T],
                [top, back, edge],
            )
        })
        .collect()
}

/// The prism films' surfaces: bef1's prisms run along y, bef2's along x.
fn film_surfaces() -> Vec<String> {
    let mut tables = Vec::new();
    for (i, axis) in [(1, [1.0, 0.0, 0.0]), (2, [0.0, 1.0, 0.0])] {
        let z0 = BEF_Z[i - 1];
        let pet = format!("pet_bef{i}");
        tables.push(format!(
            "[surfaces.bef{i}_top]
model = \"grooves\"
inside = \"{pet}\"
relief = \"raised\"
apex_deg = {apex}
pitch_mm = {p}
origin = {o}
axis = {a}
",
            apex = num(PRISM[1]),
            p = num(PRISM[0]),
            o = arr(&[0.0, 0.0, z0 + BEF_T]),
            a = arr(&axis),
        ));
        tables.push(dielectric(&format!("bef{i}_back"), &pet));
        tables.push(dielectric(&format!("bef{i}_edge"), &pet));
    }
    tables
}

/// The LED bar's luminous flux (lm): see the scene's header.
const LUMENS: f64 = 300.0;

fn scene_toml(triangles: usize) -> String {
    let [gx, gy, gz] = GUIDE;
    let [dz, dt] = DIFFUSER;
    let height = 0.5 * PRISM[0] / (0.5 * PRISM[1]).to_radians().tan();
    let header = format!(
        "bef-stack: a small edge-lit backlight with its optical films (bottom to top): white
reflector sheet, dotted light guide, surface diffuser sheet, two crossed prism films (BEF).
{GENERATED}

- Light guide: {gx} x {gy} x {gz} mm at x 0..{gx}, y 0..{gy}, z 0..{gz}; PMMA n = {N_PMMA}. Tags lgp_front,
  lgp_edge (smooth), lgp_back: ink dots (albedo 0.92) on a hex lattice of pitch {DOT_PITCH} mm,
  density {d0} + {d2} x^2 (x = distance from the lit edge / {gx} mm).
- Reflector sheet (tag reflector_sheet, Lambertian, albedo 0.95): z = {sz}, under the guide.
- LED bar: {lw} x {lh} mm (y x z), Lambertian, 1 W, centre {c}, facing +x, in a mirror housing
  (tag lamp_reflector, reflectance 0.95) x {hd}..0 round the guide's x = 0 edge. 300 lm (an
  assumption for the luminance maps: a white LED's spectrum gives about 300 lm per radiant
  watt, as phone-led's table gives 306 and notebook14-color's FL11 spectrum 337).
- Diffuser sheet: PET n = {N_PET}, z {dz}..{dtop}, same footprint. Top face (diffuser_top) rough:
  model \"diffuser\", GGX roughness {ROUGHNESS}; back and edges smooth.
- Prism films bef1 (z {b1}..{b1t}) and bef2 (z {b2}..{b2t}): PET n = {N_PET}, base {BEF_T} mm thick, top face
  carrying procedural raised prisms (model \"grooves\"): apex {apex} deg, pitch {pp} mm ({pum} um),
  {ph} mm high. bef1's prisms run along y (axis x), bef2's along x (axis y): crossed.
  They are in bef-films.obj alone, so dropping that file gives the same stack without BEF.
- Detector: z = {DETECTOR_Z} ({gap} mm above bef2's prism tips), covering the guide's footprint;
  angular bins of 5 deg in theta.

Geometry: bef-stack.obj and bef-films.obj (usemtl names are tags), {triangles} triangles.
",
        d0 = num(DOT_DENSITY[0]),
        d2 = num(DOT_DENSITY[2]),
        sz = dim(-SHEET_GAP),
        lw = dim(LED[0]),
        lh = dim(LED[1]),
        c = dims(&led()),
        hd = dim(-HOUSING),
        dtop = dim(dz + dt),
        b1 = dim(BEF_Z[0]),
        b1t = dim(BEF_Z[0] + BEF_T),
        b2 = dim(BEF_Z[1]),
        b2t = dim(BEF_Z[1] + BEF_T),
        apex = dim(PRISM[1]),
        pp = num(PRISM[0]),
        pum = dim(PRISM[0] * 1000.0),
        ph = num(height),
        gap = num(DETECTOR_Z - BEF_Z[1] - BEF_T - height),
    );
    let dots = Dots {
        inside: "pmma",
        ink_albedo: 0.92,
        lattice: "hex",
        pitch: DOT_PITCH,
        axis: [1.0, 0.0, 0.0],
        length: gx,
        density: &DOT_DENSITY,
        normalized: true,
        mirror: None,
    };
    let description = format!(
        "Edge-lit guide {gx} x {gy} x {gz} mm with reflector, diffuser sheet and two crossed 90 deg prism films"
    );
    let mut tables = vec![
        preamble("bef-stack", &description),
        geometry("bef-stack.obj"),
        geometry("bef-films.obj"),
    ];
    tables.push(medium("pmma", N_PMMA, 0.0, None));
    for pet in ["pet_diffuser", "pet_bef1", "pet_bef2"] {
        tables.push(medium(pet, N_PET, 0.0, None));
    }
    tables.extend(dotted_guide_faces(&dots));
    tables.push(white_pet_lambert("reflector_sheet"));
    tables.push(silver_mirror("lamp_reflector"));
    tables.push(rough_dielectric("diffuser_top", "pet_diffuser", ROUGHNESS));
    tables.push(dielectric("diffuser_back", "pet_diffuser"));
    tables.push(dielectric("diffuser_edge", "pet_diffuser"));
    tables.extend(film_surfaces());
    let bar = Led {
        lumens: Some(LUMENS),
        ..Led::facing_x("led_bar", led(), LED)
    };
    tables.push(bar.toml());
    tables.push(Detector::new([0.0, 0.0, DETECTOR_Z], [gx, gy], [20, 15]).toml());
    tables.push(trace_table(200_000, 100_000));
    scene_file(&header, &tables)
}

/// `bef-stack/scene.toml`, `bef-stack.obj`, `bef-films.obj` and `bef-stack.mtl`.
pub fn files() -> Vec<GenFile> {
    let stack = stack_parts();
    let films = film_parts();
    let triangles = triangle_count(&stack) + triangle_count(&films);
    let header = format!(
        "bef-stack: edge-lit backlight with diffuser and crossed prism films (see scene.toml). Units mm.\n{GENERATED}"
    );
    let all: Vec<Part> = stack.iter().chain(&films).cloned().collect();
    vec![
        GenFile::text("bef-stack/scene.toml", scene_toml(triangles)),
        GenFile::text(
            "bef-stack/bef-stack.obj",
            write_obj(&header, &stack, ObjTags::Usemtl("bef-stack.mtl")),
        ),
        GenFile::text(
            "bef-stack/bef-films.obj",
            write_obj(&header, &films, ObjTags::Usemtl("bef-stack.mtl")),
        ),
        GenFile::text(
            "bef-stack/bef-stack.mtl",
            write_mtl(&header, &tags_of(&all)),
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layers_do_not_touch_and_prisms_clear_the_next_layer() {
        let prism_h = 0.5 * PRISM[0]; // 90 deg apex
        // Bottom to top: (low, high) z of each layer, prisms included.
        let layers = [
            (0.0, GUIDE[2]),
            (DIFFUSER[0], DIFFUSER[0] + DIFFUSER[1]),
            (BEF_Z[0], BEF_Z[0] + BEF_T + prism_h),
            (BEF_Z[1], BEF_Z[1] + BEF_T + prism_h),
            (DETECTOR_Z, DETECTOR_Z),
        ];
        assert!(layers.windows(2).all(|w| w[0].1 < w[1].0), "{layers:?}");
        let c = led();
        assert!(c[0] > -HOUSING && c[0] < 0.0 && c[2] + 0.5 * LED[1] < GUIDE[2]);
        let max_density: f64 = DOT_DENSITY.iter().sum();
        assert!(max_density < 0.9);
    }
}
