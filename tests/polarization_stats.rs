//! The statistics of polarized runs: the `polarization` errors of summary.json are
//! calibrated (independent seeds scatter as the errors say), and the bias the averaged
//! Fresnel (`[trace] polarization = false`) costs on the bundled scenes, measured.

mod support;

use blutrace::run::{RunOptions, RunResult};
use blutrace::scene::Scene;
use support::{chi2_quantile, load, trace_opts, write_scene};

/// A recycling cavity: an LED on a Lambertian floor under a reflective polarizer at 20
/// degrees, whose light leaves partly polarized (each photon's S1 varies with its
/// direction and its path).
fn cavity() -> Scene {
    let sheet = |tag: &str, z: f64, first: usize| {
        let v = |x: f64, y: f64| format!("v {x} {y} {z}\n");
        let c = v(-50.0, -50.0) + &v(50.0, -50.0) + &v(50.0, 50.0) + &v(-50.0, 50.0);
        let [a, b, cc, d] = [1, 2, 3, 4].map(|i| i + first);
        format!("{c}usemtl {tag}\nf {a} {b} {cc}\nf {a} {cc} {d}\n")
    };
    let obj = sheet("floor", 0.0, 0) + &sheet("film", 1.0, 4);
    let (s, c) = 20f64.to_radians().sin_cos();
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"cavity.obj\"\n\
         [surfaces.floor]\nmodel = \"lambert\"\nalbedo = 0.8\n\
         [surfaces.film]\nmodel = \"polarizer\"\naxis = [{c}, {s}, 0.0]\n\
         pass_transmittance = 0.9\nblock_transmittance = 0.05\nblock_reflectance = 0.9\n\
         [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, 0.01]\nnormal = [0.0, 0.0, 1.0]\n\
         u = [1.0, 0.0, 0.0]\nwidth_mm = 0.5\nheight_mm = 0.5\npower_w = 1.0\n\
         [detector]\norigin = [-50.0, -50.0, 2.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [100.0, 100.0]\nbins = [4, 4]\n"
    );
    load(&write_scene(
        "pol-jackknife",
        &toml,
        &[("cavity.obj", obj.as_str())],
    ))
}

fn run(scene: &Scene, photons: u64, seed: u64) -> RunResult {
    let options = RunOptions {
        photons,
        seed,
        threads: Some(2),
        ..RunOptions::default()
    };
    trace_opts(scene, &options)
}

/// 20 independent seeds of 32 full chunks (the jackknife's 32 groups, equal): the scatter of each Stokes component about their mean agrees
/// with the mean stated jackknife error, `sum (x_i - mean)^2 / mean(se^2)` being a
/// chi-square of 19 degrees of freedom (within its 0.1 % and 99.9 % quantiles, z = 3.1).
/// An error twice too large or too small fails (the sum moves by 4x).
#[test]
#[ignore = "slow: 20 runs of 131072 photons"]
fn the_stokes_errors_are_calibrated_across_seeds() {
    let scene = cavity();
    let runs: Vec<_> = (0..20)
        .map(|seed| {
            let photons = 32 * blutrace::tracer::CHUNK;
            let p = run(&scene, photons, 100 + seed)
                .summary()
                .polarization
                .unwrap();
            [p.s1, p.s2, p.dop].map(|e| (e.value, e.stderr))
        })
        .collect();
    let k = runs.len() as f64;
    for (c, name) in ["s1", "s2", "dop"].into_iter().enumerate() {
        let mean = runs.iter().map(|r| r[c].0).sum::<f64>() / k;
        let var_stated = runs.iter().map(|r| r[c].1.powi(2)).sum::<f64>() / k;
        let chi2 = runs.iter().map(|r| (r[c].0 - mean).powi(2)).sum::<f64>() / var_stated;
        let (lo, hi) = (chi2_quantile(k - 1.0, -3.1), chi2_quantile(k - 1.0, 3.1));
        println!(
            "{name}: mean {mean:.5}, stated error {:.5}, chi2 {chi2:.1} (19 dof: {lo:.1}..{hi:.1})",
            var_stated.sqrt()
        );
        assert!(
            mean.abs() > 5.0 * var_stated.sqrt() || name == "s2",
            "{name}: no polarization to measure"
        );
        assert!(
            (lo..hi).contains(&chi2),
            "{name}: chi2 {chi2} outside {lo}..{hi}"
        );
    }
}

/// The bias of the averaged Fresnel on the bundled scenes: each traced polarized (its
/// default) and averaged, with the same photons (the scene's, at most 1M), printing the extraction efficiency of
/// both, their difference in standard errors, and the speeds. The README's table.
#[test]
#[ignore = "slow: measures the README's bias table (4 full runs)"]
fn the_averaged_fresnels_bias_on_bundled_scenes() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for name in ["notebook14", "bef-stack"] {
        let mut scene = load(&root.join(name).join("scene.toml"));
        assert!(scene.polarized, "{name} traces polarization by default");
        let photons = scene.default_photons.min(1_000_000);
        let polarized = run(&scene, photons, 1).summary();
        scene.polarized = false;
        let averaged = run(&scene, photons, 1).summary();
        let (p, sp) = (
            polarized.extraction_efficiency,
            polarized.extraction_efficiency_stderr,
        );
        let (a, sa) = (
            averaged.extraction_efficiency,
            averaged.extraction_efficiency_stderr,
        );
        let z = (p - a) / (sp * sp + sa * sa).sqrt();
        println!(
            "{name} ({photons} photons): polarized {p:.5} ± {sp:.5} ({:.0}/s), averaged {a:.5} ± {sa:.5} ({:.0}/s): averaged - polarized {:+.5} ({:+.1} sigma, {:+.2} %)",
            polarized.photons_per_s,
            averaged.photons_per_s,
            a - p,
            -z,
            100.0 * (a - p) / p
        );
    }
}
