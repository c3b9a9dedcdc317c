//! `test/prism-plate` and `test/prism-plate-meshed`: a small edge-lit PMMA plate whose
//! back face carries graded, asymmetric micro-prism extraction grooves: procedural
//! (`model = "grooves"`) in the first scene, meshed groove by groove in the second, with
//! everything else identical. `tests/prisms_films.rs` checks the two agree within
//! statistical error.

use super::GENERATED;
use crate::shapes::{Facing, lamp_box, sheet_up};
use crate::templates::{
    Detector, Led, MtlNote, absorber, dielectric, geometry, medium, obj_and_mtl, preamble,
    scene_file, trace_table,
};
use crate::{GenFile, P3, Part, arr, dim, dims, num, triangle_count};

/// Plate size (x, y, z) (mm); the plate spans 0..SIZE, lit through its x = 0 end face.
pub const SIZE: P3 = [20.0, 8.0, 1.0];
/// PMMA refractive index.
pub const N_PMMA: f64 = 1.49;
/// Groove pitch along x (mm): `SIZE[0] / PITCH` grooves, one per cell.
pub const PITCH: f64 = 0.25;
/// Angle between the two facets of a groove (deg).
pub const APEX_DEG: f64 = 110.0;
/// Tilt of the V (deg): facet base angles 90 - apex/2 + tilt (lamp side) and - tilt.
pub const TILT_DEG: f64 = 10.0;
/// Fill fraction of each pitch, `FILL[0] + FILL[1] x` with x = (cell centre) / length.
pub const FILL: [f64; 2] = [0.05, 0.2];
/// Depth (x) of the black LED box behind the x = 0 end face (mm): x -BOX_DEPTH..0.
pub const BOX_DEPTH: f64 = 1.0;
/// LED emitting rectangle: width along y, height along z (mm).
pub const LED: [f64; 2] = [6.0, 0.8];
/// The absorbing floor below the back face: its height z (mm) and its margin around the
/// plate's footprint.
pub const FLOOR: [f64; 2] = [-0.5, 2.0];
/// Detector height above the front face (mm).
pub const DETECTOR_GAP: f64 = 0.2;

/// Number of grooves (cells).
pub fn grooves() -> usize {
    (SIZE[0] / PITCH).round() as usize
}

/// Facet base angles (lamp side, far side) (radians).
pub fn base_angles() -> (f64, f64) {
    let half = 90.0 - 0.5 * APEX_DEG;
    (
        (half + TILT_DEG).to_radians(),
        (half - TILT_DEG).to_radians(),
    )
}

/// Profile of the back face along x: `(x, z)` from `(0, 0)` to `(SIZE[0], 0)`; notches
/// rise into the plate (z > 0). Cell `k` spans `k p..(k+1) p` and holds one notch of
/// width `f p` centred in it, `f` the fill polynomial at the cell centre, exactly as the
/// procedural model lays it out.
pub fn profile() -> Vec<[f64; 2]> {
    let (lo, hi) = base_angles();
    let cot_sum = 1.0 / lo.tan() + 1.0 / hi.tan();
    let mut pts = vec![[0.0, 0.0]];
    for k in 0..grooves() {
        let centre = (k as f64 + 0.5) * PITCH;
        let f = FILL[0] + FILL[1] * centre / SIZE[0];
        let w = f * PITCH;
        let depth = w / cot_sum;
        let s_l = centre - 0.5 * w;
        pts.push([s_l, 0.0]);
        pts.push([s_l + depth / lo.tan(), depth]);
        pts.push([centre + 0.5 * w, 0.0]);
    }
    pts.push([SIZE[0], 0.0]);
    pts
}

/// Deepest notch (mm).
pub fn max_depth() -> f64 {
    profile().iter().map(|p| p[1]).fold(0.0, f64::max)
}

/// The LED's centre: mid-box.
pub fn led() -> P3 {
    [-0.5 * BOX_DEPTH, 0.5 * SIZE[1], 0.5 * SIZE[2]]
}

/// A triangle of the plate's y = `y` side face from profile-plane points `(x, z)`, wound
/// so its normal points along `outward_y`.
fn side_tri(part: &mut Part, y: f64, outward_y: f64, t: [[f64; 2]; 3]) {
    let [a, b, c] = t.map(|q| [q[0], y, q[1]]);
    // y-component of (b - a) x (c - a).
    let ny = (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2]);
    assert!(ny != 0.0, "degenerate side triangle {t:?}");
    if (ny > 0.0) == (outward_y > 0.0) {
        part.tri("lgp_side", a, b, c);
    } else {
        part.tri("lgp_side", a, c, b);
    }
}

/// The plate: a box, or (`meshed`) the box with every notch cut into its back face.
pub fn plate(meshed: bool) -> Part {
    let [sx, sy, sz] = SIZE;
    let mut p = Part::new("plate");
    p.quad(
        "lgp_front",
        [0.0, 0.0, sz],
        [sx, 0.0, sz],
        [sx, sy, sz],
        [0.0, sy, sz],
    );
    p.quad(
        "lgp_edge",
        [0.0, 0.0, 0.0],
        [0.0, 0.0, sz],
        [0.0, sy, sz],
        [0.0, sy, 0.0],
    );
    p.quad(
        "lgp_side",
        [sx, 0.0, 0.0],
        [sx, sy, 0.0],
        [sx, sy, sz],
        [sx, 0.0, sz],
    );
    if !meshed {
        p.quad(
            "lgp_back",
            [0.0, 0.0, 0.0],
            [0.0, sy, 0.0],
            [sx, sy, 0.0],
            [sx, 0.0, 0.0],
        );
        p.quad(
            "lgp_side",
            [0.0, 0.0, 0.0],
            [sx, 0.0, 0.0],
            [sx, 0.0, sz],
            [0.0, 0.0, sz],
        );
        p.quad(
            "lgp_side",
            [0.0, sy, 0.0],
            [0.0, sy, sz],
            [sx, sy, sz],
            [sx, sy, 0.0],
        );
        return p;
    }
    let prof = profile();
    // Back face: each profile segment extruded along y, normal out of the plate.
    for w in prof.windows(2) {
        let ([x0, z0], [x1, z1]) = (w[0], w[1]);
        p.quad(
            "lgp_back",
            [x0, 0.0, z0],
            [x0, sy, z0],
            [x1, sy, z1],
            [x1, 0.0, z1],
        );
    }
    // Side faces: the cross-section polygon. Between consecutive apexes a convex "tooth"
    // (apex, notch end, next notch start, next apex); above the apex chain a fan from the
    // top corners.
    let top_l = [0.0, sz];
    let top_r = [sx, sz];
    let n = grooves();
    let apex = |k: usize| prof[2 + 3 * k];
    let end = |k: usize| prof[3 + 3 * k];
    let start = |k: usize| prof[1 + 3 * k];
    for (y, out) in [(0.0, -1.0), (sy, 1.0)] {
        side_tri(&mut p, y, out, [top_l, prof[0], start(0)]);
        side_tri(&mut p, y, out, [top_l, start(0), apex(0)]);
        for k in 0..n - 1 {
            side_tri(&mut p, y, out, [apex(k), end(k), start(k + 1)]);
            side_tri(&mut p, y, out, [apex(k), start(k + 1), apex(k + 1)]);
            side_tri(&mut p, y, out, [top_l, apex(k), apex(k + 1)]);
        }
        side_tri(&mut p, y, out, [top_l, apex(n - 1), top_r]);
        side_tri(&mut p, y, out, [top_r, apex(n - 1), end(n - 1)]);
        side_tri(&mut p, y, out, [top_r, end(n - 1), prof[prof.len() - 1]]);
    }
    p
}

/// Signed area of the fan triangle `(top-left corner, a, b)` in the profile plane: all
/// must share one sign for the fan to be a triangulation.
pub fn fan_areas() -> Vec<f64> {
    let prof = profile();
    let t = [0.0, SIZE[2]];
    (0..grooves() - 1)
        .map(|k| {
            let (a, b) = (prof[2 + 3 * k], prof[5 + 3 * k]);
            (a[0] - t[0]) * (b[1] - t[1]) - (b[0] - t[0]) * (a[1] - t[1])
        })
        .collect()
}

/// The LED box (five black walls, open towards the plate's end face) and the floor.
fn surroundings() -> Vec<Part> {
    let [sx, sy, sz] = SIZE;
    let [z, m] = FLOOR;
    vec![
        lamp_box("absorber", "absorber", BOX_DEPTH, [sy, sz], Facing::Out),
        sheet_up("floor", "floor", [-m, -m], [sx + m, sy + m], z),
    ]
}

/// Every part of a scene.
pub fn parts(meshed: bool) -> Vec<Part> {
    let mut v = vec![plate(meshed)];
    v.extend(surroundings());
    v
}

fn scene_toml(meshed: bool, triangles: usize) -> String {
    let [sx, sy, sz] = SIZE;
    let (lo, hi) = base_angles();
    let (folder, file) = if meshed {
        ("test/prism-plate-meshed", "prism-plate-meshed.obj")
    } else {
        ("test/prism-plate", "prism-plate.obj")
    };
    let how = if meshed {
        "meshed groove by groove (every facet a smooth\ndielectric quad; the side faces are the notched cross-section)"
    } else {
        "procedural (model = \"grooves\": the back face is one\nflat quad; the notches are traced exactly in their layer)"
    };
    let header = format!(
        "{folder}: a small edge-lit PMMA plate with graded, asymmetric micro-prism extraction
grooves on its back face, {how}.
The pair test/prism-plate and test/prism-plate-meshed differ only in that;
tests/prisms_films.rs checks they agree. A test scene, not a backlight.
{GENERATED}

- Plate: {sx} x {sy} x {sz} mm at x 0..{sx}, y 0..{sy}, z 0..{sz}; PMMA n = {N_PMMA}, no absorption.
  Tags: lgp_front (z = {sz}), lgp_back (z = 0, the grooves), lgp_edge (the lit x = 0 end, to
  air), lgp_side (x = {sx} and both y sides: onto an index-matched black medium, so light
  reaching them is absorbed there without reflection).
- Grooves: {ng} V notches cut into the back face, running along y, pitch {PITCH} mm (one per
  cell x k p..(k+1) p, centred in it); apex {APEX_DEG} deg, tilt {TILT_DEG} deg: the facet facing the
  lamp (-x side of the apex) has a base angle of {a_lo} deg, the far facet {a_hi} deg. Each notch
  takes the fraction f = {f0} + {f1} x of its cell (x = cell centre / {sx} mm), so it is
  {dmin}..{dmax} mm deep.
- LED: {lw} x {lh} mm (y x z), Lambertian, 1 W, centre {c}, facing +x, in a black box
  (tag absorber) x {d}..0, y 0..{sy}, z 0..{sz} whose open side is the plate's end face.
- Floor (tag floor, black): z = {fz}, {fm} mm beyond the plate's footprint on every side.
- Detector: {DETECTOR_GAP} mm above the front face (z = {zd}), exactly covering it; 1 mm bins along x.

Geometry: {file} (usemtl names are tags), {triangles} triangles.
",
        ng = grooves(),
        a_lo = dim(lo.to_degrees()),
        a_hi = dim(hi.to_degrees()),
        f0 = num(FILL[0]),
        f1 = num(FILL[1]),
        dmin = num(profile()[2][1]),
        dmax = num(max_depth()),
        lw = dim(LED[0]),
        lh = dim(LED[1]),
        c = dims(&led()),
        d = dim(-BOX_DEPTH),
        fz = dim(FLOOR[0]),
        fm = dim(FLOOR[1]),
        zd = dim(sz + DETECTOR_GAP),
    );
    let back = if meshed {
        dielectric("lgp_back", "pmma")
    } else {
        format!(
            "[surfaces.lgp_back]
model = \"grooves\"
inside = \"pmma\"
relief = \"cut\"
apex_deg = {apex}
tilt_deg = {tilt}
pitch_mm = {p}
origin = [0.0, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
length_mm = {sx}
density = {fill}
x_unit = \"normalized\"
",
            apex = num(APEX_DEG),
            tilt = num(TILT_DEG),
            p = num(PITCH),
            sx = num(sx),
            fill = arr(&FILL),
        )
    };
    let led = Led {
        body: false,
        ..Led::facing_x("led", led(), LED)
    };
    let kind = if meshed { "meshed" } else { "procedural" };
    let description = format!(
        "Edge-lit PMMA plate {sx} x {sy} x {sz} mm with graded asymmetric V-groove extraction ({kind})"
    );
    let detector = Detector::new(
        [0.0, 0.0, sz + DETECTOR_GAP],
        [sx, sy],
        [sx.round() as usize, 1],
    );
    scene_file(
        &header,
        &[
            preamble(&folder.replace('/', "-"), &description),
            geometry(file),
            medium("pmma", N_PMMA, 0.0, None),
            medium("black", N_PMMA, 1e9, None),
            dielectric("lgp_front", "pmma"),
            back,
            dielectric("lgp_edge", "pmma"),
            dielectric("lgp_side", "pmma") + "outside = \"black\"\n",
            absorber("absorber"),
            absorber("floor"),
            led.toml(),
            detector.toml(),
            trace_table(200_000, 100_000),
        ],
    )
}

fn scene_files(meshed: bool) -> Vec<GenFile> {
    let parts = parts(meshed);
    let (folder, obj) = if meshed {
        ("test/prism-plate-meshed", "prism-plate-meshed.obj")
    } else {
        ("test/prism-plate", "prism-plate.obj")
    };
    let header = format!(
        "{folder}: edge-lit PMMA plate with V-groove extraction (see scene.toml). Units mm.\n{GENERATED}"
    );
    let [obj, mtl] = obj_and_mtl(folder, obj, &header, &parts, MtlNote::Plain);
    vec![
        GenFile::text(
            &format!("{folder}/scene.toml"),
            scene_toml(meshed, triangle_count(&parts)),
        ),
        obj,
        mtl,
    ]
}

/// `test/prism-plate/` (procedural grooves): scene.toml, .obj, .mtl.
pub fn files() -> Vec<GenFile> {
    scene_files(false)
}

/// `test/prism-plate-meshed/` (meshed grooves): scene.toml, .obj, .mtl.
pub fn files_meshed() -> Vec<GenFile> {
    scene_files(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_fan_is_a_triangulation() {
        let a = fan_areas();
        assert!(a.iter().all(|&x| x < 0.0) || a.iter().all(|&x| x > 0.0));
    }

    #[test]
    fn notches_fit_their_cells_and_the_plate() {
        let prof = profile();
        assert!(prof.windows(2).all(|w| w[1][0] > w[0][0]), "x increases");
        assert!(max_depth() < 0.1 * SIZE[2]);
        for k in 0..grooves() {
            let lo = k as f64 * PITCH;
            assert!(prof[1 + 3 * k][0] > lo && prof[3 + 3 * k][0] < lo + PITCH);
        }
    }

    #[test]
    fn meshed_plate_is_closed_and_outward() {
        let p = plate(true);
        let mut edges = std::collections::BTreeMap::new();
        let mut volume = 0.0;
        for (_, tris) in &p.groups {
            for t in tris {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    *edges.entry((a, b)).or_insert(0) += 1;
                }
                let [a, b, c] = t.map(|i| p.verts[i as usize]);
                let cross = [
                    b[1] * c[2] - b[2] * c[1],
                    b[2] * c[0] - b[0] * c[2],
                    b[0] * c[1] - b[1] * c[0],
                ];
                volume += (a[0] * cross[0] + a[1] * cross[1] + a[2] * cross[2]) / 6.0;
            }
        }
        // Every directed edge is matched by its reverse exactly once: closed, consistent.
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1, "edge {a}-{b} used {n} times");
            assert_eq!(edges.get(&(b, a)), Some(&1), "edge {a}-{b} has no twin");
        }
        let [sx, sy, sz] = SIZE;
        assert!(volume > 0.0 && volume < sx * sy * sz, "volume {volume}");
        assert!(p.triangle_count() < 1000 - 12, "{}", p.triangle_count());
    }
}
