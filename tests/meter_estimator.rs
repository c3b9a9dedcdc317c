//! The luminance meter's estimator (peel-off, `--luminance-estimator meter`, the default)
//! against a closed form, against the cone count it replaces (the same quantity: every
//! bin of every view within its errors), and its bookkeeping: the photons' own paths and
//! every other output are the same bits under either estimator, and its maps the same on
//! any thread count.

mod support;

use blutrace::estimator::LuminanceEstimator;
use blutrace::run::metrics::cone::luminance_cone_map;
use blutrace::run::{RunOptions, RunResult};
use blutrace::scene::Scene;
use support::{chi2_quantile, load, trace_opts, write_scene};

fn run(scene: &Scene, photons: u64, threads: usize, e: LuminanceEstimator) -> RunResult {
    run_seeded(scene, (photons, 7), threads, e)
}

fn run_seeded(
    scene: &Scene,
    (photons, seed): (u64, u64),
    threads: usize,
    e: LuminanceEstimator,
) -> RunResult {
    let opts = RunOptions {
        photons,
        seed,
        threads: Some(threads),
        backend: blutrace::accel::BackendChoice::Bvh,
        luminance_estimator: e,
        ..RunOptions::default()
    };
    trace_opts(scene, &opts)
}

/// A 100 x 100 mm Lambertian floor (albedo 0.8) under a 60 x 60 mm Lambertian panel
/// facing it from 2 mm (1 W, 100 lm), seen from a 40 x 40 mm target at z = 0.5 over the
/// middle along the normal and at 40 degrees.
fn floor_scene() -> Scene {
    let v = |x: f64, y: f64| format!("v {x} {y} 0\n");
    let obj = v(-50.0, -50.0) + &v(50.0, -50.0) + &v(50.0, 50.0) + &v(-50.0, 50.0);
    let obj = format!("{obj}usemtl floor\nf 1 2 3\nf 1 3 4\n");
    let toml = "version = 1\n[[geometry]]\nfile = \"floor.obj\"\n\
         [surfaces.floor]\nmodel = \"lambert\"\nalbedo = 0.8\n\
         [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, 2.0]\nnormal = [0.0, 0.0, -1.0]\n\
         u = [1.0, 0.0, 0.0]\nwidth_mm = 60.0\nheight_mm = 60.0\npower_w = 1.0\nlumens = 100.0\n\
         [detector]\norigin = [-20.0, -20.0, 0.5]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [40.0, 40.0]\nbins = [2, 2]\nviews = [[0.0, 0.0], [40.0, 30.0]]\n";
    load(&write_scene("meter-floor", toml, &[("floor.obj", &obj)]))
}

/// The view factor from a point of a plane to a parallel `a` x `b` rectangle `h` above
/// it with a corner over the point (the standard configuration factor).
fn corner_view_factor(a: f64, b: f64, h: f64) -> f64 {
    let (x, y) = (a / h, b / h);
    let term = |p: f64, q: f64| p / (1.0 + p * p).sqrt() * (q / (1.0 + p * p).sqrt()).atan();
    (term(x, y) + term(y, x)) / std::f64::consts::TAU
}

/// The floor's luminance is `albedo E / pi`, the same from every direction, `E` the
/// panel's exitance times the view factor to the panel (four corner rectangles),
/// averaged over the target (the midpoint rule on a 200 x 200 grid). The meter reads it
/// in both views within 3 standard errors of 0.5 %; the cone count of the same photons
/// is noise beside it.
#[test]
fn a_lambertian_floor_reads_albedo_e_over_pi_from_every_view() {
    let scene = floor_scene();
    let n = 200;
    let mut factor = 0.0;
    for i in 0..n {
        for j in 0..n {
            let (x, y) = ([i, j])
                .map(|k| -20.0 + 40.0 * (k as f64 + 0.5) / n as f64)
                .into();
            let f: f64 = [
                (30.0 - x, 30.0 - y),
                (30.0 + x, 30.0 - y),
                (30.0 - x, 30.0 + y),
                (30.0 + x, 30.0 + y),
            ]
            .iter()
            .map(|&(a, b)| corner_view_factor(a, b, 2.0))
            .sum();
            factor += f / (n * n) as f64;
        }
    }
    let expected = 0.8 * (100.0 / 0.0036) * factor / std::f64::consts::PI;
    let meter = run_seeded(&scene, (200_000, 1), 2, LuminanceEstimator::Meter).summary();
    let cone = run(&scene, 200_000, 2, LuminanceEstimator::Cone).summary();
    assert_eq!(meter.luminance_views.len(), 2);
    for (m, c) in meter.luminance_views.iter().zip(&cone.luminance_views) {
        let (v, e) = (m.mean_cd_m2.value, m.mean_cd_m2.stderr);
        println!(
            "view {:?}: meter {v:.3} ± {e:.3}, cone {:.3} ± {:.3}, expected {expected:.3} (view factor {factor:.5})",
            m.view_deg, c.mean_cd_m2.value, c.mean_cd_m2.stderr
        );
        assert!((v - expected).abs() < 3.0 * e, "{m:?}");
        assert!(e < 0.005 * expected, "{m:?}");
        // The cone count's error is far larger, or undefined (no photon in the cone).
        let cone_error = c.mean_cd_m2.stderr;
        assert!(cone_error.is_nan() || cone_error >= 5.0 * e, "{m:?} {c:?}");
        assert!(m.cone_counted_fraction < 1e-12, "{m:?}");
        assert_eq!(c.cone_counted_fraction, 1.0, "{c:?}");
    }
}

/// `name` at a reduced size (`bins`, a 10 degree cone so the cone count converges at a
/// million photons, the normal and a slanted view): the meter and the cone count agree
/// in the mean and bin by bin (chi-square at 4 sigma over the bins, each difference over
/// both errors), and the meter's error of the mean is `gain` times smaller or more.
fn agrees_with_the_cone_count(name: &str, bins: [usize; 2], slant: f64, photons: u64, gain: f64) {
    let mut scene = support::load(&support::repo_scene(name));
    scene.detector.bins = bins;
    scene.detector.views = vec![[0.0, 0.0], [slant, 0.0]];
    scene.detector.set_luminance_cone(10.0).unwrap();
    let meter = run(&scene, photons, 2, LuminanceEstimator::Meter);
    let cone = run(&scene, photons, 2, LuminanceEstimator::Cone);
    for k in 0..2 {
        let m = luminance_cone_map(&meter.scene, &meter.tally, k).unwrap();
        let c = luminance_cone_map(&cone.scene, &cone.tally, k).unwrap();
        let chi2: f64 = (0..m.value.len())
            .map(|i| {
                (m.value[i] - c.value[i]).powi(2) / (m.stderr[i].powi(2) + c.stderr[i].powi(2))
            })
            .sum();
        let bins = m.value.len() as f64;
        println!("{name} view {k}: chi2 {chi2:.1} over {bins} bins");
        assert!(
            chi2 < chi2_quantile(bins, 4.0),
            "{name} view {k}: chi2 {chi2}"
        );
        let (ms, cs) = (meter.summary(), cone.summary());
        let (a, b) = (
            &ms.luminance_views[k].mean_cd_m2,
            &cs.luminance_views[k].mean_cd_m2,
        );
        println!("{name} view {k}: meter {a:?}, cone {b:?}");
        let z = (a.value - b.value) / (a.stderr.powi(2) + b.stderr.powi(2)).sqrt();
        assert!(z.abs() < 4.0, "{name} view {k}: {a:?} vs {b:?}");
        assert!(
            a.stderr < b.stderr / gain,
            "{name} view {k}: {a:?} vs {b:?}"
        );
    }
}

/// Dots under flat layers: the flat-layer peel-off.
#[test]
fn the_meter_agrees_with_the_cone_count_on_notebook14() {
    agrees_with_the_cone_count("notebook14", [10, 10], 40.0, 1_000_000, 3.0);
}

/// A rough diffuser under two crossed prism films: the backward walk, polarized (its
/// walks, which succeed or not, make the mean's error less small than the bins').
#[test]
fn the_meter_agrees_with_the_cone_count_on_bef_stack() {
    agrees_with_the_cone_count("bef-stack", [8, 6], 30.0, 600_000, 1.5);
}

/// The peel-off draws from the photons' side streams: under either estimator the
/// photons' paths, and so the ledger, flux and angular tallies, are the same bits; the
/// meter's maps are the same bits on 1 and 2 threads.
#[test]
fn the_meter_changes_no_other_output_and_no_bit_with_threads() {
    for name in ["notebook14", "bef-stack"] {
        same_bits(name);
    }
}

fn same_bits(name: &str) {
    let mut scene = support::load(&support::repo_scene(name));
    scene.detector.bins = [20, 20];
    let meter = run(&scene, 30_000, 2, LuminanceEstimator::Meter);
    let cone = run(&scene, 30_000, 2, LuminanceEstimator::Cone);
    assert_eq!(meter.tally.ledger, cone.tally.ledger);
    assert_eq!(meter.tally.flux, cone.tally.flux);
    assert_eq!(meter.tally.angular, cone.tally.angular);
    assert_ne!(meter.tally.meter, cone.tally.meter);
    let one = run(&scene, 30_000, 1, LuminanceEstimator::Meter);
    assert_eq!(one.tally.meter, meter.tally.meter);
}

/// The full comparison of the README: notebook14 at its default 6M photons under the
/// meter against the cone count of 2e8 photons, 10 x 10 blocks of its 100 x 100 map and
/// the mean within their errors. Hours of CPU on 2 cores' share: ignored.
#[test]
#[ignore]
fn full_size_notebook14_meter_matches_a_long_cone_count() {
    full_size("notebook14", 6_000_000, 200_000_000);
}

/// The same for bef-stack: its default 200k photons against 3e7 (an hour on 2 cores).
#[test]
#[ignore]
fn full_size_bef_stack_meter_matches_a_long_cone_count() {
    full_size("bef-stack", 200_000, 30_000_000);
}

fn full_size(name: &str, photons: u64, cone_photons: u64) {
    let scene = support::load(&support::repo_scene(name));
    let meter = run(&scene, photons, 2, LuminanceEstimator::Meter);
    let cone = run(&scene, cone_photons, 2, LuminanceEstimator::Cone);
    let blocks = |r: &RunResult| {
        let m = luminance_cone_map(&r.scene, &r.tally, 0).unwrap();
        let mut sums = vec![(0.0, 0.0); 100];
        for iy in 0..m.ny {
            for ix in 0..m.nx {
                let b = (iy * 10 / m.ny) * 10 + ix * 10 / m.nx;
                let i = iy * m.nx + ix;
                sums[b].0 += m.value[i];
                sums[b].1 += m.stderr[i].powi(2);
            }
        }
        sums
    };
    let (a, b) = (blocks(&meter), blocks(&cone));
    let chi2: f64 = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x.0 - y.0).powi(2) / (x.1 + y.1))
        .sum();
    let (ms, cs) = (meter.summary(), cone.summary());
    let (m, c) = (ms.luminance_map.unwrap(), cs.luminance_map.unwrap());
    println!(
        "{name}: meter {:?} floor {} ({} s), cone {:?} floor {} ({} s), blocks chi2 {chi2:.1}/100",
        m.mean_cd_m2,
        m.cv_noise_floor,
        meter.runtime_s,
        c.mean_cd_m2,
        c.cv_noise_floor,
        cone.runtime_s
    );
    assert!(chi2 < chi2_quantile(100.0, 4.0), "{chi2}");
    assert!(m.cv_noise_floor <= 0.15, "{m:?}");
    let z = (m.mean_cd_m2.value - c.mean_cd_m2.value)
        / (m.mean_cd_m2.stderr.powi(2) + c.mean_cd_m2.stderr.powi(2)).sqrt();
    assert!(z.abs() < 4.0, "{m:?} vs {c:?}");
}
