//! Lamp bodies: light returning to a lamp meets its exact analytic body (issue 13).
//!
//! Closed forms (derived here, analog estimator, so each photon's fate is a Bernoulli
//! draw and tolerances are binomial standard errors):
//! - A CCFL (radius r) on the axis of a long concentric mirror tube of reflectance R with
//!   lossless mirror end caps: in the cross-section a ray keeps its distance b from the
//!   axis under reflection by a concentric circle, and an emitted ray has b <= r (its line
//!   passes through a point of the lamp); end caps only flip the axial component. So every
//!   reflected photon comes straight back to the body. With an absorbing body, the body
//!   takes R of the power and the mirror 1 - R. With a Lambertian body of albedo a (whose
//!   reflections leave outward, as emission does), the body takes R (1 - a) / (1 - a R) and
//!   the mirror (1 - R) / (1 - a R).
//! - An LED (a one-sided Lambertian rectangle w x h with an absorbing body) facing a
//!   perfect plane mirror at distance d: a reflected photon travels as if from the LED's
//!   mirror image at distance 2 d, so the fraction that comes back onto the LED's front is
//!   the view factor between two directly opposed w x h rectangles 2 d apart (Hottel's
//!   closed form, Howell's catalogue C-11); the rest passes beside the LED and escapes.
//! - A meshed absorbing tube around a transparent-bodied CCFL converges with the facet
//!   count to the analytic absorbing body (the emission's spawn offset keeps photons off a
//!   finely faceted mesh inscribed in the emitting surface).

mod support;

use blutrace::accel::BackendChoice;
use blutrace::estimator::Estimator;
use blutrace::run::RunOptions;
use blutrace::scene::Scene;
use std::f64::consts::TAU;
use std::fmt::Write;
use support::{assert_balanced, assert_warns, load, trace_opts, write_scene};

/// OBJ of a closed tube (side and end caps) about the y axis, wound outward.
fn tube_obj(radius: f64, half_length: f64, facets: usize, tag: &str, caps: &str) -> String {
    let mut s = String::new();
    writeln!(s, "v 0 {} 0\nv 0 {} 0", -half_length, half_length).unwrap();
    for k in 0..facets {
        let phi = TAU * k as f64 / facets as f64;
        let (x, z) = (radius * phi.cos(), radius * phi.sin());
        writeln!(s, "v {x} {} {z}\nv {x} {} {z}", -half_length, half_length).unwrap();
    }
    // Vertex 1, 2: cap centres; ring k: 3 + 2k (y = -h), 4 + 2k (y = +h).
    let ring = |k: usize, top: bool| 3 + 2 * (k % facets) + top as usize;
    writeln!(s, "usemtl {tag}").unwrap();
    for k in 0..facets {
        let (a0, a1, b0, b1) = (
            ring(k, false),
            ring(k, true),
            ring(k + 1, false),
            ring(k + 1, true),
        );
        // Outward for a ring ordered counter-clockwise seen from +y... x = cos, z = sin
        // turns from +x to +z, which is clockwise seen from +y: wind accordingly.
        writeln!(s, "f {a0} {a1} {b1}\nf {a0} {b1} {b0}").unwrap();
    }
    writeln!(s, "usemtl {caps}").unwrap();
    for k in 0..facets {
        writeln!(s, "f 1 {} {}", ring(k, false), ring(k + 1, false)).unwrap();
        writeln!(s, "f 2 {} {}", ring(k + 1, true), ring(k, true)).unwrap();
    }
    s
}

/// A CCFL (r = 1 mm, 200 mm) in a Lambertian box open at the top (an absorbing lid), so
/// that much of its light comes back to it; `extra` adds surfaces and geometry.
fn lamp_in_box(name: &str, body: &str, tube: Option<usize>) -> Scene {
    let box_obj = support::box_obj(
        [-6.0, -105.0, -6.0],
        [6.0, 105.0, 6.0],
        ["wall", "wall", "wall", "wall", "wall", "lid"],
    );
    let mut geometry = "[[geometry]]\nfile = \"box.obj\"\n".to_string();
    let mut files = vec![("box.obj", box_obj)];
    let mut surfaces = String::new();
    if let Some(n) = tube {
        geometry += "[[geometry]]\nfile = \"tube.obj\"\n";
        files.push(("tube.obj", tube_obj(1.0, 100.0, n, "tube", "tube")));
        surfaces += "[surfaces.tube]\nmodel = \"absorber\"\n";
    }
    let toml = format!(
        "version = 1\n{geometry}\
         [surfaces.wall]\nmodel = \"lambert\"\nalbedo = 0.9\n\
         [surfaces.lid]\nmodel = \"absorber\"\n{surfaces}\
         [[sources]]\ntype = \"ccfl\"\nname = \"lamp\"\ncenter = [0.0, 0.0, 0.0]\naxis = [0.0, 1.0, 0.0]\n\
         radius_mm = 1.0\nlength_mm = 200.0\npower_w = 1.0\nbody = {body}\n\
         [detector]\norigin = [-6.0, -105.0, 20.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [12.0, 210.0]\nbins = [2, 2]\n"
    );
    let files: Vec<(&str, &str)> = files.iter().map(|(n, t)| (*n, t.as_str())).collect();
    load(&write_scene(name, &toml, &files))
}

fn analog(photons: u64, backend: BackendChoice) -> RunOptions {
    RunOptions {
        photons,
        seed: 7,
        threads: Some(2),
        backend,
        estimator: Estimator::Analog,
        ..RunOptions::default()
    }
}

/// The fraction of photons and its binomial standard error.
fn fraction(k: f64, n: u64) -> (f64, f64) {
    let p = k / n as f64;
    (p, (p * (1.0 - p) / n as f64).sqrt())
}

#[test]
fn a_meshed_absorbing_tube_converges_to_the_analytic_body() {
    const N: u64 = 100_000;
    let exact = lamp_in_box("body-exact", "\"absorber\"", None);
    let r = trace_opts(&exact, &analog(N, BackendChoice::Bvh));
    assert_balanced(&r);
    let (want, se_want) = fraction(r.tally.ledger.absorbed_by_source[0].value(), N);
    assert!(want > 0.1, "the box sends light back: {want}");
    for facets in [64, 512, 4096] {
        let scene = lamp_in_box(
            &format!("body-mesh-{facets}"),
            "\"transparent\"",
            Some(facets),
        );
        assert_warns(&scene, "tag 'tube' lies within");
        let tube = scene.tags.iter().position(|t| t == "tube").unwrap();
        for backend in [BackendChoice::Bvh, BackendChoice::Auto] {
            let r = trace_opts(&scene, &analog(N, backend));
            assert_balanced(&r);
            assert_eq!(r.tally.ledger.absorbed_by_source[0].value(), 0.0);
            let (got, se) = fraction(r.tally.ledger.absorbed_by_surface[tube].value(), N);
            // Inscribed facets are smaller than the circle by the sag r (1 - cos(pi/n)).
            let sag = 1.0 - (std::f64::consts::PI / facets as f64).cos();
            let tol = 4.0 * se.hypot(se_want) + sag;
            assert!(
                (got - want).abs() <= tol,
                "{facets} facets ({backend:?}): tube takes {got:.4}, analytic body {want:.4} (tolerance {tol:.4})"
            );
        }
    }
}

/// A CCFL in a concentric mirror tube (radius 2 mm, finely faceted) with mirror end caps.
fn lamp_in_mirror(name: &str, body: &str, reflectance: f64) -> Scene {
    // 65536 facets: a facet's normal is off the circle's by at most pi / 65536, which moves
    // a returning ray's distance from the axis by < 3e-4 mm: negligible here.
    let mirror = tube_obj(2.0, 50.001, 65536, "mirror", "caps");
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"mirror.obj\"\n\
         [surfaces.mirror]\nmodel = \"mirror\"\nreflectance = {reflectance}\n\
         [surfaces.caps]\nmodel = \"mirror\"\nreflectance = 1.0\n\
         [[sources]]\ntype = \"ccfl\"\nname = \"lamp\"\ncenter = [0.0, 0.0, 0.0]\naxis = [0.0, 1.0, 0.0]\n\
         radius_mm = 1.0\nlength_mm = 100.0\npower_w = 1.0\nbody = {body}\n\
         [detector]\norigin = [-2.0, -50.0, 30.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [4.0, 100.0]\nbins = [2, 2]\n"
    );
    load(&write_scene(name, &toml, &[("mirror.obj", &mirror)]))
}

#[test]
fn a_concentric_mirror_returns_every_reflected_photon_to_the_body() {
    const N: u64 = 40_000;
    let (refl, albedo) = (0.7, 0.45);
    let cases = [
        ("\"absorber\"", 0.0),
        (
            &*format!("{{ model = \"lambert\", albedo = {albedo} }}"),
            albedo,
        ),
    ];
    for (body, a) in cases {
        let scene = lamp_in_mirror("mirror-tube", body, refl);
        let r = trace_opts(&scene, &analog(N, BackendChoice::Bvh));
        assert_balanced(&r);
        let l = &r.tally.ledger;
        let mirror = scene.tags.iter().position(|t| t == "mirror").unwrap();
        let want = refl * (1.0 - a) / (1.0 - a * refl);
        let (got, se) = fraction(l.absorbed_by_source[0].value(), N);
        assert!(
            (got - want).abs() <= 4.0 * se,
            "body {body}: takes {got:.4} +- {se:.4}, closed form {want:.4}"
        );
        let got_mirror = l.absorbed_by_surface[mirror].value() / N as f64;
        assert!(
            (got + got_mirror - 1.0).abs() < 1e-12,
            "nothing else: {got_mirror}"
        );
    }
}

#[test]
fn weighted_and_analog_agree_on_a_reflecting_body() {
    let scene = lamp_in_box(
        "body-weighted",
        "{ model = \"phong\", reflectance = 0.6, specular = 0.5, exponent = 20.0 }",
        None,
    );
    let a = trace_opts(&scene, &analog(60_000, BackendChoice::Bvh));
    let w = trace_opts(
        &scene,
        &RunOptions {
            estimator: Estimator::Weighted,
            ..analog(60_000, BackendChoice::Bvh)
        },
    );
    assert_balanced(&a);
    assert_balanced(&w);
    let (pa, sa) = fraction(a.tally.ledger.absorbed_by_source[0].value(), 60_000);
    let pw = w.tally.ledger.absorbed_by_source[0].value() / 60_000.0;
    // The weighted estimate's error is at most the analog one's here (same paths, weights
    // instead of deaths); 4 combined standard errors.
    assert!(
        (pa - pw).abs() <= 4.0 * sa * 2f64.sqrt(),
        "analog {pa:.4} vs weighted {pw:.4}"
    );
}

/// View factor between two directly opposed, parallel `a x b` rectangles `c` apart
/// (Hottel; Howell, "A Catalog of Radiation Heat Transfer Configuration Factors", C-11).
fn opposed_rectangles(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    2.0 / (std::f64::consts::PI * x * y)
        * ((((1.0 + x * x) * (1.0 + y * y)) / (1.0 + x * x + y * y))
            .sqrt()
            .ln()
            + x * sy * (x / sy).atan()
            + y * sx * (y / sx).atan()
            - x * x.atan()
            - y * y.atan())
}

#[test]
fn an_led_facing_a_mirror_gets_back_the_view_factor_of_its_image() {
    // Two unit squares 1 apart: 0.19982 (the catalogue's value), a check of the formula.
    assert!((opposed_rectangles(1.0, 1.0, 1.0) - 0.19982).abs() < 1e-5);
    // A 2 x 1 mm LED at z = 0 facing +z, a 2 m square mirror of reflectance 1 at
    // z = 0.5 mm; photons past the mirror's edge (grazing within 0.06 degrees: a
    // fraction below 1e-6 of a Lambertian emission) are negligible.
    let (w, h, d) = (2.0, 1.0, 0.5);
    let mirror = "v -1000 -1000 0.5\nv 1000 -1000 0.5\nv 1000 1000 0.5\nv -1000 1000 0.5\n\
                  usemtl mirror\nf 1 2 3\nf 1 3 4\n";
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"mirror.obj\"\n\
         [surfaces.mirror]\nmodel = \"mirror\"\nreflectance = 1.0\n\
         [[sources]]\ntype = \"led\"\nname = \"led\"\ncenter = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n\
         u = [1.0, 0.0, 0.0]\nwidth_mm = {w}\nheight_mm = {h}\npower_w = 1.0\nbody = \"absorber\"\n\
         [detector]\norigin = [3000.0, 3000.0, 3000.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [1.0, 1.0]\nbins = [1, 1]\n"
    );
    let scene = load(&write_scene("led-mirror", &toml, &[("mirror.obj", mirror)]));
    let n = 200_000;
    for backend in [BackendChoice::Bvh, BackendChoice::Auto] {
        let r = trace_opts(&scene, &analog(n, backend));
        assert_balanced(&r);
        let (back, se) = fraction(r.tally.ledger.absorbed_by_source[0].value(), n);
        let expected = opposed_rectangles(w, h, 2.0 * d);
        assert!(
            (back - expected).abs() < 4.0 * se,
            "{backend:?}: {back} +- {se} returned to the LED, view factor {expected}"
        );
        let (escaped, _) = fraction(r.tally.ledger.escaped.value(), n);
        assert!(
            (back + escaped - 1.0).abs() < 1e-12,
            "nothing else: {escaped}"
        );
    }
}

#[test]
fn an_led_body_absorbs_at_its_back_and_reflects_at_its_front() {
    // An LED facing +x in front of a Lambertian wall at x = 1: light comes back to its
    // front (model: mirror of reflectance 1 sends it back to the wall: nothing is lost
    // there). Behind it, a wall at x = -1 that the LED cannot see sends light to its back
    // only through the side walls: the back absorbs whatever reaches it.
    let obj = support::box_obj(
        [-1.0, -3.0, -3.0],
        [1.0, 3.0, 3.0],
        ["wall", "wall", "wall", "wall", "wall", "wall"],
    );
    let toml = "version = 1\n[[geometry]]\nfile = \"box.obj\"\n\
         [surfaces.wall]\nmodel = \"lambert\"\nalbedo = 0.5\n\
         [[sources]]\ntype = \"led\"\nname = \"led\"\ncenter = [0.0, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\n\
         u = [0.0, 1.0, 0.0]\nwidth_mm = 2.0\nheight_mm = 2.0\npower_w = 1.0\n\
         body = { model = \"mirror\", reflectance = 1.0 }\n\
         [detector]\norigin = [-1.0, -3.0, 10.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [2.0, 6.0]\nbins = [1, 1]\n";
    let scene = load(&write_scene("led-body", toml, &[("box.obj", &obj)]));
    let r = trace_opts(&scene, &analog(20_000, BackendChoice::Bvh));
    assert_balanced(&r);
    let body = r.tally.ledger.absorbed_by_source[0].value();
    // Only the back can absorb; the back is reached (the box is closed), so some is.
    assert!(body > 0.0, "the back absorbs");
    // Transparent: nothing is booked to the source.
    let t = toml.replace(
        "body = { model = \"mirror\", reflectance = 1.0 }",
        "body = \"transparent\"",
    );
    let scene = load(&write_scene("led-transparent", &t, &[("box.obj", &obj)]));
    let r = trace_opts(&scene, &analog(20_000, BackendChoice::Bvh));
    assert_eq!(r.tally.ledger.absorbed_by_source[0].value(), 0.0);
    assert_balanced(&r);
}

#[test]
fn a_package_depth_makes_a_box_that_absorbs_only_through_its_model() {
    // A package with a perfect mirror model: nothing is ever booked to the source.
    let obj = support::box_obj(
        [-3.0, -3.0, -3.0],
        [3.0, 3.0, 3.0],
        ["wall", "wall", "wall", "wall", "wall", "wall"],
    );
    let toml = "version = 1\n[[geometry]]\nfile = \"box.obj\"\n\
         [surfaces.wall]\nmodel = \"lambert\"\nalbedo = 0.5\n\
         [[sources]]\ntype = \"led\"\nname = \"led\"\ncenter = [0.0, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\n\
         u = [0.0, 1.0, 0.0]\nwidth_mm = 2.0\nheight_mm = 1.0\npower_w = 1.0\n\
         body = { model = \"mirror\", reflectance = 1.0 }\npackage_depth_mm = 1.0\n\
         [detector]\norigin = [-3.0, -3.0, 10.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [6.0, 6.0]\nbins = [1, 1]\n";
    let scene = load(&write_scene("led-package", toml, &[("box.obj", &obj)]));
    let r = trace_opts(&scene, &analog(20_000, BackendChoice::Bvh));
    assert_balanced(&r);
    assert_eq!(r.tally.ledger.absorbed_by_source[0].value(), 0.0);
    assert!(
        r.tally.ledger.interactions > 20_000,
        "light meets the walls and the package"
    );
}

#[test]
fn a_sheet_through_a_lamp_is_reported() {
    // A Lambertian sheet (not a solid) through the middle of the tube.
    let sheet =
        "v -5 -120 0.2\nv 5 -120 0.2\nv 5 120 0.2\nv -5 120 0.2\nusemtl sheet\nf 1 2 3\nf 1 3 4\n";
    let toml = "version = 1\n[[geometry]]\nfile = \"sheet.obj\"\n\
         [surfaces.sheet]\nmodel = \"lambert\"\nalbedo = 0.9\n\
         [[sources]]\ntype = \"ccfl\"\nname = \"lamp\"\ncenter = [0.0, 0.0, 0.0]\naxis = [0.0, 1.0, 0.0]\n\
         radius_mm = 1.0\nlength_mm = 200.0\npower_w = 1.0\n\
         [detector]\norigin = [-6.0, -105.0, 20.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [12.0, 210.0]\nbins = [2, 2]\n";
    let scene = load(&write_scene(
        "sheet-through-lamp",
        toml,
        &[("sheet.obj", sheet)],
    ));
    assert_warns(&scene, "emitting surface cuts tag 'sheet'");
}
