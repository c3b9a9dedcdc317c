//! The colour objective (`--objective cv=W,delta-uv-13pt=W`): both searches read the
//! traced colour non-uniformity exactly as `summary.json` reports it, weigh it as asked,
//! steer the design by it, and refuse it where it cannot work.

mod support;

use blutrace::optimize::{Method, ObjectiveSpec, OptimizeOptions, optimize, optimize_layout};
use blutrace::run::metrics::color::Estimate;
use support::{box_obj, load, trace_opts, write_scene};

/// A 60 x 10 x 1 mm guide lit from its -x end by a white LED (CIE LED-B5), whose medium
/// absorbs the blue strongly (0.04 /mm at 400 nm, none from 600 nm), so the light turns
/// yellow along the guide; dots on the back face.
fn yellowing_guide(name: &str, density: &str, spectrum: bool) -> support::SceneDir {
    let obj = box_obj(
        [-30.0, -5.0, -0.5],
        [30.0, 5.0, 0.5],
        ["edge", "edge", "edge", "edge", "dots", "face"],
    );
    let spectrum = if spectrum {
        "spectrum = \"cie-led-b5\"\n"
    } else {
        ""
    };
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"plate.obj\"\n[media.pmma]\nn = 1.49\n\
         absorption_per_mm = {{ table = [[380, 0.04], [400, 0.04], [500, 0.012], [600, 0.0], [830, 0.0]] }}\n\
         [surfaces.face]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.edge]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.dots]\nmodel = \"dots\"\ninside = \"pmma\"\nink_albedo = 0.9\nlattice = \"square\"\npitch_mm = 0.5\n\
         origin = [-30.0, 0.0, -0.5]\naxis = [1.0, 0.0, 0.0]\nlength_mm = 60.0\n{density}\n\
         [[sources]]\ntype = \"led\"\ncenter = [-30.001, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\n\
         u = [0.0, 1.0, 0.0]\nwidth_mm = 10.0\nheight_mm = 0.9\npower_w = 1.0\n{spectrum}\
         [detector]\norigin = [-30.0, -5.0, 0.6]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [60.0, 10.0]\n\
         bins = [24, 6]\nangular_bins = [6, 4]\n"
    );
    write_scene(name, &toml, &[("plate.obj", &obj)])
}

fn options(objective: &str, photons: u64, max_iter: usize) -> OptimizeOptions {
    OptimizeOptions {
        objective: objective.parse().unwrap(),
        photons,
        seed: 7,
        max_iter,
        verify_photons: 0,
        threads: Some(2),
        ..OptimizeOptions::default()
    }
}

/// The search's Δu'v' of its first design is the summary's of the same trace, bit for bit,
/// and the objective weighs it and the profile cv as asked.
#[test]
fn the_dots_objective_reads_and_weighs_the_traced_colour() {
    let dir = yellowing_guide("colobj-reads", "density = [0.3]", true);
    let scene = load(&dir);
    let opts = options("cv=2,delta-uv-13pt=10", 20_000, 1);
    let r = optimize(&scene, &opts, &mut |_| {}).unwrap();
    let first = &r.initial;
    let run = trace_opts(&scene, &opts.search_run());
    let color = run.summary().color.expect("a spectral run has colour");
    let duv: Estimate = first
        .delta_uv_13pt_debiased
        .expect("the search read the colour");
    assert_eq!(duv, color.delta_uv_13pt_debiased);
    assert!(duv.value > 0.0 && duv.stderr > 0.0, "{duv:?}");
    assert_eq!(first.objective, 2.0 * first.cv + 10.0 * duv.value);
    let noise = (2.0 * first.cv_noise).hypot(10.0 * duv.stderr);
    assert!((first.noise - noise).abs() <= 1e-15 * noise);
    // The history names the colour of the best design per iteration.
    assert!(
        r.history
            .iter()
            .all(|h| h.delta_uv_13pt_debiased.is_finite())
    );
}

/// A 60 x 10 x 1 mm clear guide lit from its -x end by a warm white LED (CIE LED-B1,
/// 2700 K) and from its +x end by a cool one (LED-B5, 6500 K), dots on the back face:
/// dense dots extract each LED's light near its own end (a colour gradient along the
/// guide), sparse dots let the two mix.
fn two_colour_guide(name: &str, density: &str, spectra: [&str; 2]) -> support::SceneDir {
    let obj = box_obj(
        [-30.0, -5.0, -0.5],
        [30.0, 5.0, 0.5],
        ["edge", "edge", "edge", "edge", "dots", "face"],
    );
    let led = |x: f64, nx: f64, spectrum: &str| {
        format!(
            "[[sources]]\ntype = \"led\"\ncenter = [{x}, 0.0, 0.0]\nnormal = [{nx}, 0.0, 0.0]\n\
             u = [0.0, 1.0, 0.0]\nwidth_mm = 10.0\nheight_mm = 0.9\npower_w = 1.0\nspectrum = \"{spectrum}\"\n"
        )
    };
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"plate.obj\"\n[media.pmma]\nn = 1.49\n\
         [surfaces.face]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.edge]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.dots]\nmodel = \"dots\"\ninside = \"pmma\"\nink_albedo = 0.9\nlattice = \"square\"\npitch_mm = 0.5\n\
         origin = [-30.0, 0.0, -0.5]\naxis = [1.0, 0.0, 0.0]\nlength_mm = 60.0\nmirror = true\n{density}\n{}{}\
         [detector]\norigin = [-30.0, -5.0, 0.6]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [60.0, 10.0]\n\
         bins = [24, 6]\nangular_bins = [6, 4]\n",
        led(-30.001, 1.0, spectra[0]),
        led(30.001, -1.0, spectra[1]),
    );
    write_scene(name, &toml, &[("plate.obj", &obj)])
}

/// Weighted mostly on colour, Nelder-Mead lowers the colour spread by many standard errors,
/// below both the first design's and the design a cv-only search finds (which makes the
/// flux uniform and leaves the colour gradient); compared on fresh-seed re-traces, free
/// of the search's selection of its luckiest trace.
#[test]
fn a_colour_weighted_search_lowers_the_colour_spread() {
    let dir = two_colour_guide(
        "colobj-steers",
        "density = [0.6]",
        ["cie-led-b1", "cie-led-b5"],
    );
    let scene = load(&dir);
    let opts = OptimizeOptions {
        verify_photons: 200_000,
        ..options("cv=0.01,delta-uv-13pt=1", 40_000, 20)
    };
    let retraced = |objective: &str| {
        let opts = OptimizeOptions {
            objective: objective.parse().unwrap(),
            ..opts.clone()
        };
        let r = optimize(&scene, &opts, &mut |_| {}).unwrap();
        let v = r.verification.unwrap();
        let (a, b) = (
            v.initial.evaluation.delta_uv_13pt_debiased.unwrap(),
            v.final_design.evaluation.delta_uv_13pt_debiased.unwrap(),
        );
        println!(
            "{objective}: re-traced Δu'v' 13-pt {:.4} ± {:.4} -> {:.4} ± {:.4}, cv {:.4} -> {:.4}",
            a.value,
            a.stderr,
            b.value,
            b.stderr,
            v.initial.evaluation.cv,
            v.final_design.evaluation.cv
        );
        (a, b)
    };
    let (a, b) = retraced("cv=0.01,delta-uv-13pt=1");
    let (_, c) = retraced("cv");
    for (from, what) in [(a, "the first design"), (c, "the cv search's design")] {
        assert!(
            b.value < from.value - 5.0 * from.stderr.hypot(b.stderr),
            "Δu'v' {b:?} is not below {what}'s {from:?}"
        );
    }
}

/// Lit in one colour from both ends, every spot has the LEDs' colour: the raw Δu'v'
/// 13-point is noise alone, as large as its noise floor predicts, and the debiased one
/// (what the objective reads) is near 0; lit in two colours, the debiased spread is the
/// raw one, many errors above 0.
#[test]
fn the_debiased_colour_spread_removes_the_noise() {
    let spread = |name: &str, spectra: [&str; 2], seed: u64| {
        let scene = load(&two_colour_guide(name, "density = [0.3]", spectra));
        let opts = OptimizeOptions {
            seed,
            ..options("cv", 100_000, 1)
        };
        let c = trace_opts(&scene, &opts.search_run())
            .summary()
            .color
            .unwrap();
        println!(
            "{spectra:?}: Δu'v' 13-pt {:?}, floor {:.4}, debiased {:?}",
            c.delta_uv_13pt, c.delta_uv_13pt_noise_floor, c.delta_uv_13pt_debiased
        );
        c
    };
    for seed in [1, 2, 3] {
        let c = spread("colobj-one", ["cie-led-b5", "cie-led-b5"], seed);
        let (raw, floor) = (c.delta_uv_13pt, c.delta_uv_13pt_noise_floor);
        assert!(
            (raw.value - floor).abs() < 3.0 * raw.stderr,
            "{raw:?} floor {floor}"
        );
        assert!(c.delta_uv_13pt_debiased.value < 0.5 * raw.value, "{c:?}");
    }
    let c = spread("colobj-two", ["cie-led-b1", "cie-led-b5"], 1);
    let (raw, debiased) = (c.delta_uv_13pt, c.delta_uv_13pt_debiased);
    assert!(debiased.value > 0.9 * raw.value, "{debiased:?} vs {raw:?}");
    assert!(debiased.value > 10.0 * debiased.stderr, "{debiased:?}");
}

/// `--vary` reads the same colour, with the jackknife error of the whole weighted sum.
#[test]
fn the_layout_objective_reads_the_traced_colour() {
    let dir = yellowing_guide("colobj-layout", "density = [0.1]", true);
    let scene = load(&dir);
    let opts = OptimizeOptions {
        vary: vec!["surfaces.dots.density.0=0.1..0.5".parse().unwrap()],
        method: Method::Grid,
        grid_points: 3,
        ..options("delta-uv-13pt", 20_000, 1)
    };
    let r = optimize_layout(&scene, &opts, &mut |_, _| {}).unwrap();
    let run = trace_opts(&scene, &opts.search_run());
    let color = run.summary().color.unwrap();
    let first = r.history[0].result.as_ref().unwrap();
    assert_eq!(
        first.delta_uv_13pt_debiased,
        Some(color.delta_uv_13pt_debiased.value)
    );
    assert_eq!(first.objective, color.delta_uv_13pt_debiased.value);
    // The objective is Δu'v' alone, so its jackknife error is Δu'v''s.
    assert_eq!(first.delta_uv_13pt_debiased_stderr, Some(first.noise));
    assert!((first.noise - color.delta_uv_13pt_debiased.stderr).abs() <= 1e-15);
    assert_eq!(r.history.len(), 3);
}

/// Where the colour objective cannot work it is refused, naming the option.
#[test]
fn the_colour_objective_is_refused_where_it_cannot_work() {
    let mono = load(&yellowing_guide("colobj-mono", "density = [0.3]", false));
    let spectral = load(&yellowing_guide("colobj-bad", "density = [0.3]", true));
    let feedback = OptimizeOptions {
        method: Method::Feedback,
        ..options("cv=1,delta-uv-13pt=10", 1000, 1)
    };
    for (scene, opts, says) in [
        (
            &mono,
            options("delta-uv-13pt", 1000, 1),
            "delta-uv-13pt needs a spectral scene",
        ),
        (&spectral, feedback, "needs option `method` nelder-mead"),
        (
            &spectral,
            options("cv=1,efficiency=1", 1000, 1),
            "efficiency is for --vary searches",
        ),
    ] {
        let e = format!("{:#}", optimize(scene, &opts, &mut |_| {}).unwrap_err());
        assert!(e.contains(says), "{e}");
        assert!(
            e.contains("option `objective`") || e.contains("option `method`"),
            "{e}"
        );
    }
    let vary = OptimizeOptions {
        vary: vec!["surfaces.dots.density.0=0.1..0.5".parse().unwrap()],
        ..options("cv=1,delta-uv-13pt=5", 1000, 1)
    };
    let e = format!(
        "{:#}",
        optimize_layout(&mono, &vary, &mut |_, _| {}).unwrap_err()
    );
    assert!(e.contains("needs a spectral scene"), "{e}");
    assert!("delta-uv-13pt=0".parse::<ObjectiveSpec>().is_err());
}
