//! Closed-form physics checks, with tolerances in standard errors.
//!
//! Every Monte Carlo test here is seeded, so it is repeatable; its tolerance is stated in
//! standard errors of the estimate (4 sigma: a correct tracer fails about once in 16,000
//! seeds, a wrong one by far more).

mod support;

use blutrace::accel::BackendChoice;
use blutrace::geometry::SurfaceHit;
use blutrace::optics::fresnel;
use blutrace::optics::surface::{Estimator, Interface, Medium, Outcome, SurfaceModel};
use blutrace::rng::PhotonRng;
use glam::DVec3;
use support::*;

const PMMA: f64 = 1.49;

fn media() -> Vec<Medium> {
    vec![
        Medium::clear("air", 1.0, 0.0),
        Medium::clear("pmma", PMMA, 0.0),
    ]
}

/// Fraction of photons reflected by a flat air/PMMA interface at incidence `theta`,
/// coming from `from` (0 air, 1 pmma), by the same roulette the tracer uses.
fn roulette_reflectance(theta: f64, from_pmma: bool, n: u64) -> f64 {
    let model = SurfaceModel::Dielectric(Interface {
        inside: 1,
        outside: 0,
    });
    let hit = SurfaceHit {
        t: 1.0,
        prim: 0,
        point: DVec3::ZERO,
        normal: DVec3::Z,
    };
    // Outward normal +z: air above, PMMA below.
    let dir = if from_pmma {
        DVec3::new(theta.sin(), 0.0, theta.cos())
    } else {
        DVec3::new(theta.sin(), 0.0, -theta.cos())
    };
    let medium = from_pmma as u16;
    let reflected = (0..n)
        .filter(|&i| {
            let mut rng = PhotonRng::new(11, i);
            match model.interact(&media(), &hit, dir, medium, Estimator::Analog, &mut rng) {
                Outcome::Scattered {
                    dir: d, medium: m, ..
                } => {
                    assert_eq!(
                        d.dot(DVec3::Z) > 0.0,
                        from_pmma != (m == medium),
                        "direction and medium disagree"
                    );
                    m == medium
                }
                Outcome::Absorbed => panic!("a lossless interface absorbed a photon"),
            }
        })
        .count();
    reflected as f64 / n as f64
}

#[test]
fn fresnel_roulette_matches_closed_form_at_every_angle() {
    let n = 200_000;
    let crit = fresnel::critical_angle(PMMA, 1.0).unwrap();
    let cases = [
        (0.0, false),
        (30f64.to_radians(), false),
        (60f64.to_radians(), false),
        (89f64.to_radians(), false),
        (0.0, true),
        (30f64.to_radians(), true),
        (crit - 0.01, true),
        (crit - 1e-6, true),
    ];
    for (theta, from_pmma) in cases {
        let (n1, n2) = if from_pmma { (PMMA, 1.0) } else { (1.0, PMMA) };
        let r = fresnel::reflectance(theta.cos(), n1, n2);
        let got = roulette_reflectance(theta, from_pmma, n);
        let (_, sigma, ok) = within_sigma(got * n as f64, n as f64, r, 4.0);
        assert!(
            ok,
            "theta {:.4} deg from_pmma {from_pmma}: R {r:.5}, roulette {got:.5} (sigma {sigma:.2e})",
            theta.to_degrees()
        );
    }
    // Beyond the critical angle: total internal reflection, every time.
    assert_eq!(roulette_reflectance(crit + 1e-6, true, 10_000), 1.0);
    assert_eq!(roulette_reflectance(80f64.to_radians(), true, 10_000), 1.0);
}

/// A 20 x 20 x 1 mm PMMA slab whose faces are lossless dielectric; its four side edges
/// open onto an index-matched black medium, so photons reaching them are absorbed.
fn slab_scene(name: &str, sources: &str) -> SceneDir {
    let obj = box_obj(
        [-10.0, -10.0, -0.5],
        [10.0, 10.0, 0.5],
        ["edge", "edge", "edge", "edge", "face", "face"],
    );
    let toml = format!(
        r#"
version = 1
[[geometry]]
file = "slab.obj"
[media.pmma]
n = {PMMA}
[media.black]
n = {PMMA}
absorption_per_mm = 1e9
[surfaces.face]
model = "dielectric"
inside = "pmma"
[surfaces.edge]
model = "dielectric"
inside = "pmma"
outside = "black"
{sources}
[detector]
origin = [-10.0, -10.0, 1.0]
u = [1.0, 0.0, 0.0]
v = [0.0, 1.0, 0.0]
size_mm = [20.0, 20.0]
bins = [10, 10]
"#
    );
    write_scene(name, &toml, &[("slab.obj", &obj)])
}

#[test]
fn isotropic_source_in_slab_traps_sqrt_one_minus_inverse_n_squared() {
    // Two back-to-back cos^0 (isotropic) hemispheres make an isotropic point source.
    let src = |nz: f64| {
        format!(
            "[[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, {nz}]\nu = [1.0, 0.0, 0.0]\n\
             width_mm = 1e-6\nheight_mm = 1e-6\npower_w = 1.0\ncos_exponent = 0.0\nmedium = \"pmma\"\n"
        )
    };
    let path = slab_scene("trap", &format!("{}{}", src(1.0), src(-1.0)));
    let scene = load(&path);
    let n = 100_000;
    let r = trace(&scene, n, 5, 2);
    assert_balanced(&r);
    let black = scene.media.iter().position(|m| m.name == "black").unwrap();
    let trapped = r.tally.ledger.absorbed_in_medium[black].value();
    let expect = (1.0 - 1.0 / (PMMA * PMMA)).sqrt();
    let (frac, sigma, ok) = within_sigma(trapped, n as f64, expect, 4.0);
    assert!(
        ok,
        "trapped fraction {frac:.5}, expected {expect:.5} (sigma {sigma:.1e})"
    );
    // The rest leaves through the faces (escaped, or detected above the front face).
    let out = r.tally.ledger.escaped.value() + r.tally.ledger.detected.sum.value();
    assert_eq!(out + trapped, n as f64);
    // The weighted estimator books the same: a photon that leaves the scene inside the
    // black medium leaves all its weight there (exp(-a t) as t goes to infinity).
    let opts = blutrace::run::RunOptions {
        photons: n,
        seed: 5,
        threads: Some(2),
        estimator: Estimator::Weighted,
        ..Default::default()
    };
    let w = trace_opts(&scene, &opts);
    assert_balanced(&w);
    let trapped_w = w.tally.ledger.absorbed_in_medium[black].value();
    let (frac, sigma, ok) = within_sigma(trapped_w, n as f64, expect, 4.0);
    assert!(
        ok,
        "weighted: trapped {frac:.5}, expected {expect:.5} (sigma {sigma:.1e})"
    );
}

#[test]
fn lossless_dot_free_plate_lit_through_its_edge_emits_nothing_through_its_faces() {
    // An LED just outside the -x edge, facing +x, smaller than the edge face: every photon
    // enters through the edge, is refracted within the critical cone, and then meets the
    // faces beyond the critical angle.
    let led = "[[sources]]\ntype = \"led\"\ncenter = [-10.001, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\n\
               u = [0.0, 1.0, 0.0]\nwidth_mm = 10.0\nheight_mm = 0.5\npower_w = 1.0\n";
    let obj = box_obj([-10.0, -10.0, -0.5], [10.0, 10.0, 0.5], ["face"; 6]);
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"plate.obj\"\n[media.pmma]\nn = {PMMA}\n\
         [surfaces.face]\nmodel = \"dielectric\"\ninside = \"pmma\"\n{led}\
         [detector]\norigin = [-10.0, -10.0, 0.6]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [20.0, 20.0]\n\
         [trace]\nmax_bounces = 2000\n"
    );
    let scene = load(&write_scene("edgelit", &toml, &[("plate.obj", &obj)]));
    let r = trace(&scene, 20_000, 3, 2);
    assert_balanced(&r);
    assert_eq!(
        r.tally.ledger.detected.sum.value(),
        0.0,
        "light leaked through the front face"
    );
    // Photons leave only back out through the x edges (escaped, or absorbed by the LED's
    // body when they come back to it), or circulate forever in the box by TIR on all six
    // faces (killed by the cap): nothing else can happen.
    let l = &r.tally.ledger;
    let lamp = l.absorbed_by_source[0].value();
    assert!(lamp > 0.0, "some light returns to the LED");
    assert_eq!(l.escaped.value() + l.killed.value() + lamp, 20_000.0);
}

#[test]
fn beer_lambert_absorption_over_a_path() {
    // A collimated beam (cos^1e7) starts inside a 10 mm PMMA bar with absorption a along
    // +x; all faces open onto an index-matched black medium.
    let a = 0.05;
    let len = 10.0;
    let obj = box_obj([0.0, -1.0, -1.0], [len, 1.0, 1.0], ["edge"; 6]);
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"bar.obj\"\n[media.pmma]\nn = {PMMA}\nabsorption_per_mm = {a}\n\
         [media.black]\nn = {PMMA}\nabsorption_per_mm = 1e9\n\
         [surfaces.edge]\nmodel = \"dielectric\"\ninside = \"pmma\"\noutside = \"black\"\n\
         [[sources]]\ntype = \"led\"\ncenter = [1e-3, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\nu = [0.0, 1.0, 0.0]\n\
         width_mm = 1e-3\nheight_mm = 1e-3\npower_w = 1.0\ncos_exponent = 1e7\nmedium = \"pmma\"\n\
         [detector]\norigin = [0.0, -1.0, 5.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [1.0, 1.0]\n"
    );
    let scene = load(&write_scene("beer", &toml, &[("bar.obj", &obj)]));
    let n = 100_000;
    let r = trace(&scene, n, 9, 2);
    assert_balanced(&r);
    let pmma = scene.media.iter().position(|m| m.name == "pmma").unwrap();
    let absorbed = r.tally.ledger.absorbed_in_medium[pmma].value();
    let expect = 1.0 - (-a * (len - 1e-3)).exp();
    let (frac, sigma, ok) = within_sigma(absorbed, n as f64, expect, 4.0);
    assert!(
        ok,
        "absorbed {frac:.5}, Beer-Lambert {expect:.5} (sigma {sigma:.1e})"
    );
}

#[test]
fn lambertian_led_follows_cosine_law() {
    // A tiny Lambertian LED under a huge target: the theta histogram must follow
    // dP/dtheta = sin(2 theta), i.e. bin fractions cos^2(t0) - cos^2(t1).
    let toml = "version = 1\ngeometry = []\nsurfaces = {}\n\
        [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\nu = [1.0, 0.0, 0.0]\n\
        width_mm = 1e-3\nheight_mm = 1e-3\npower_w = 1.0\n\
        [detector]\norigin = [-1e7, -1e7, 1.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [2e7, 2e7]\n\
        bins = [4, 4]\nangular_bins = [18, 1]\n";
    let scene = load(&write_scene("lambert", toml, &[]));
    let n = 200_000u64;
    let r = trace(&scene, n, 4, 2);
    assert_balanced(&r);
    let nt = 18;
    let mut chi2 = 0.0;
    for it in 0..nt {
        let t0 = std::f64::consts::FRAC_PI_2 * it as f64 / nt as f64;
        let t1 = std::f64::consts::FRAC_PI_2 * (it + 1) as f64 / nt as f64;
        let expected = n as f64 * (t0.cos().powi(2) - t1.cos().powi(2));
        let observed = r.tally.angular.bins[it].hits as f64;
        chi2 += (observed - expected).powi(2) / expected;
    }
    // 17 degrees of freedom: P(chi2 > 40.79) = 0.001.
    assert!(
        chi2 < 40.79,
        "chi-square {chi2:.1} with 17 dof: not Lambertian"
    );
}

#[test]
fn thread_count_and_backend_do_not_change_tallies() {
    let led = "[[sources]]\ntype = \"led\"\ncenter = [-10.001, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\n\
               u = [0.0, 1.0, 0.0]\nwidth_mm = 10.0\nheight_mm = 0.5\npower_w = 1.0\n";
    let obj = box_obj(
        [-10.0, -10.0, -0.5],
        [10.0, 10.0, 0.5],
        ["edge", "edge", "edge", "edge", "dots", "face"],
    );
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"plate.obj\"\n[media.pmma]\nn = {PMMA}\nabsorption_per_mm = 0.001\n\
         [surfaces.face]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.edge]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.dots]\nmodel = \"dots\"\ninside = \"pmma\"\nink_albedo = 0.9\nlattice = \"hex\"\npitch_mm = 0.5\n\
         origin = [-10.0, 0.0, -0.5]\naxis = [1.0, 0.0, 0.0]\nlength_mm = 20.0\ndensity = [0.1, 0.3]\n{led}\
         [detector]\norigin = [-10.0, -10.0, 0.6]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [20.0, 20.0]\n\
         bins = [20, 20]\n"
    );
    let scene = load(&write_scene("determinism", &toml, &[("plate.obj", &obj)]));
    let one = trace(&scene, 30_000, 21, 1);
    let two = trace(&scene, 30_000, 21, 2);
    assert_balanced(&one);
    assert!(
        one.tally.ledger.detected.sum.value() > 1000.0,
        "the dots must extract light"
    );
    assert_eq!(one.tally, two.tally, "1 and 2 threads differ");
    let brute = trace_with(&scene, 30_000, 21, 2, BackendChoice::Brute);
    assert_eq!(one.tally, brute.tally, "BVH and brute force differ");
    let other_seed = trace(&scene, 30_000, 22, 2);
    assert_ne!(one.tally, other_seed.tally, "the seed has no effect");
}

#[test]
fn convex_fast_path_gives_the_same_fates_and_tallies_as_the_mesh_path() {
    use blutrace::run::RunOptions;
    let scene = load(&std::path::PathBuf::from("scenes/notebook14/scene.toml"));
    let pmma = scene.media.iter().position(|m| m.name == "pmma").unwrap() as u16;
    assert!(
        scene.convex_solid(pmma).is_some(),
        "notebook14's guide should take the convex path"
    );
    let o = |convex| RunOptions {
        photons: 100_000,
        seed: 3,
        threads: Some(2),
        backend: BackendChoice::Bvh,
        convex,
        ..RunOptions::default()
    };
    let fast = trace_opts(&scene, &o(true));
    let mesh = trace_opts(&scene, &o(false));
    assert_balanced(&fast);
    // Same photons, same surfaces: the two paths differ only where a photon passes within
    // a spawn offset of a face's edge, so every fate agrees within (far less than) the
    // two-sample counting error, and so does the whole flux map.
    let n = 100_000.0;
    let (a, b) = (&fast.tally.ledger, &mesh.tally.ledger);
    let mut fates = vec![
        (a.detected.sum.value(), b.detected.sum.value()),
        (a.escaped.value(), b.escaped.value()),
    ];
    fates.extend(
        a.absorbed_by_surface
            .iter()
            .zip(&b.absorbed_by_surface)
            .map(|(x, y)| (x.value(), y.value())),
    );
    for (x, y) in fates {
        let p = (x + y) / (2.0 * n);
        let sigma = (2.0 * n * p * (1.0 - p)).sqrt().max(1.0);
        assert!(
            (x - y).abs() <= 4.0 * sigma,
            "fate counts {x} vs {y} (sigma {sigma:.1})"
        );
    }
    let (ma, mb) = (fast.flux_map(), mesh.flux_map());
    let chi2: f64 = (0..ma.value.len())
        .filter(|&i| ma.stderr[i] > 0.0 || mb.stderr[i] > 0.0)
        .map(|i| {
            (ma.value[i] - mb.value[i]).powi(2) / (ma.stderr[i].powi(2) + mb.stderr[i].powi(2))
        })
        .sum();
    assert!(
        chi2 < 10_000.0 * 1.2,
        "flux maps differ: chi-square {chi2:.0} over 10000 bins"
    );
}

#[test]
fn lambertian_source_gives_uniform_luminance_equal_to_flux_over_pi_area() {
    // All light of a Lambertian emitter crosses a huge target: the target's luminance is
    // the same at every viewing angle and equals lumens / (pi * area).
    let toml = "version = 1\ngeometry = []\nsurfaces = {}\n\
        [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\nu = [1.0, 0.0, 0.0]\n\
        width_mm = 1e-3\nheight_mm = 1e-3\npower_w = 1.0\nlumens = 100.0\n\
        [detector]\norigin = [-1e7, -1e7, 1.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [2e7, 2e7]\n\
        bins = [4, 4]\nangular_bins = [9, 4]\n";
    let scene = load(&write_scene("luminance", toml, &[]));
    let r = trace(&scene, 200_000, 8, 2);
    let lum = r.summary().luminance.expect("sources give lumens");
    let area_m2 = 2e7 * 2e7 * 1e-6;
    let expected = 100.0 / (std::f64::consts::PI * area_m2);
    assert!((lum.efficacy_lm_per_w - 100.0).abs() < 1e-12);
    for row in lum.by_theta {
        let (theta, value, se) = (row.theta_deg, row.cd_m2, row.stderr_cd_m2);
        assert!(
            (value - expected).abs() < 4.0 * se,
            "theta {theta}: {value:.4e} ± {se:.1e}, expected {expected:.4e}"
        );
    }
}
