//! Dot-density optimization: Nelder-Mead on known functions, the tabulated density in
//! scene files, and optimizers that provably improve a small fast scene. The notebook14
//! acceptance runs are `#[ignore]`d (minutes each). Dot exports: tests/dot_exports.rs.

mod support;

use blutrace::optics::dots::{Density, DotPattern, Lattice};
use blutrace::optimize::export;
use blutrace::optimize::nelder_mead::{self, Settings, Termination};
use blutrace::optimize::{Method, OptimizeOptions, optimize};
use blutrace::scene::Scene;
use glam::DVec2;
use std::f64::consts::PI;
use support::{box_obj, load, write_scene};

fn rosenbrock(x: &[f64]) -> f64 {
    (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2)
}

#[test]
fn nelder_mead_minimizes_rosenbrock() {
    let settings = Settings {
        max_iter: 2000,
        x_tol: 1e-9,
        ..Settings::default()
    };
    let mut steps_seen = 0;
    let out = nelder_mead::minimize(
        &mut |x| Ok(rosenbrock(x)),
        &[-1.2, 1.0],
        &[0.1, 0.1],
        &settings,
        &mut |_| steps_seen += 1,
    )
    .unwrap();
    assert_eq!(out.termination, Termination::SimplexSize);
    assert!(
        (out.x[0] - 1.0).abs() < 1e-6 && (out.x[1] - 1.0).abs() < 1e-6,
        "{:?}",
        out.x
    );
    assert!(out.value < 1e-12, "f = {}", out.value);
    assert_eq!(
        steps_seen,
        out.iterations + 1,
        "one report per iteration, plus the start"
    );
    assert!(out.iterations < 400, "{} iterations", out.iterations);
}

#[test]
fn nelder_mead_minimizes_a_quadratic_and_honours_the_tests() {
    // f = sum w_i (x_i - i)^2 in 4-D, a scaled bowl like the density coefficients.
    let f = |x: &[f64]| -> f64 {
        x.iter()
            .enumerate()
            .map(|(i, v)| (1.0 + i as f64) * (v - i as f64).powi(2))
            .sum()
    };
    let x0 = [3.0, -2.0, 0.5, 1.0];
    let steps = [0.5; 4];
    let out = nelder_mead::minimize(
        &mut |x| Ok(f(x)),
        &x0,
        &steps,
        &Settings {
            max_iter: 5000,
            x_tol: 1e-8,
            ..Settings::default()
        },
        &mut |_| {},
    )
    .unwrap();
    for (i, v) in out.x.iter().enumerate() {
        assert!((v - i as f64).abs() < 1e-5, "x = {:?}", out.x);
    }
    // The objective bound stops early.
    let bound = nelder_mead::minimize(
        &mut |x| Ok(f(x)),
        &x0,
        &steps,
        &Settings {
            target: Some(0.5),
            ..Settings::default()
        },
        &mut |_| {},
    )
    .unwrap();
    assert_eq!(bound.termination, Termination::ObjectiveBound);
    assert!(bound.value <= 0.5 && bound.iterations < out.iterations);
    // The iteration cap stops too.
    let capped = nelder_mead::minimize(
        &mut |x| Ok(f(x)),
        &x0,
        &steps,
        &Settings {
            max_iter: 5,
            ..Settings::default()
        },
        &mut |_| {},
    )
    .unwrap();
    assert_eq!(capped.termination, Termination::MaxIterations);
    assert_eq!(capped.iterations, 5);
    // Rejected points (infinite, NaN) never win, and errors come back as errors.
    let walled = nelder_mead::minimize(
        &mut |x| Ok(if x[0] < 1.5 { f64::NAN } else { f(x) }),
        &x0,
        &steps,
        &Settings {
            max_iter: 500,
            ..Settings::default()
        },
        &mut |_| {},
    )
    .unwrap();
    assert!(walled.x[0] >= 1.5 && walled.value.is_finite());
    let failed = nelder_mead::minimize(
        &mut |_| anyhow::bail!("trace failed"),
        &x0,
        &steps,
        &Settings::default(),
        &mut |_| {},
    );
    assert!(failed.is_err());
}

const LED: &str = "[[sources]]\ntype = \"led\"\ncenter = [-20.001, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\n\
                   u = [0.0, 1.0, 0.0]\nwidth_mm = 10.0\nheight_mm = 0.9\npower_w = 1.0\n";

/// A 40 x 10 x 1 mm PMMA plate lit from its -x end, dots on the back face.
/// The dot pattern of the scene's (first) dots surface.
fn dots_of(scene: &Scene) -> &DotPattern {
    scene
        .surfaces
        .iter()
        .find_map(|s| match s {
            blutrace::optics::surface::SurfaceModel::Dots(d) => Some(&d.pattern),
            _ => None,
        })
        .expect("the scene has a dots surface")
}

fn small_scene(name: &str, density: &str) -> support::SceneDir {
    let obj = box_obj(
        [-20.0, -5.0, -0.5],
        [20.0, 5.0, 0.5],
        ["edge", "edge", "edge", "edge", "dots", "face"],
    );
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"plate.obj\"\n[media.pmma]\nn = 1.49\nabsorption_per_mm = 0.001\n\
         [surfaces.face]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.edge]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.dots]\nmodel = \"dots\"\ninside = \"pmma\"\nink_albedo = 0.9\nlattice = \"square\"\npitch_mm = 0.5\n\
         origin = [-20.0, 0.0, -0.5]\naxis = [1.0, 0.0, 0.0]\nlength_mm = 40.0\n{density}\n{LED}\
         [detector]\norigin = [-20.0, -5.0, 0.6]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [40.0, 10.0]\n\
         bins = [20, 5]\n"
    );
    write_scene(name, &toml, &[("plate.obj", &obj)])
}

#[test]
fn density_table_in_scene_files() {
    let table = load(&small_scene(
        "opt-table",
        "density_table = [[0.0, 0.1], [0.5, 0.3], [1.0, 0.2]]",
    ));
    let dots = dots_of(&table);
    assert!((dots.density_at(10.0) - 0.2).abs() < 1e-12);
    let both = small_scene(
        "opt-both",
        "density = [0.1]\ndensity_table = [[0.0, 0.1], [1.0, 0.2]]",
    );
    let msg = format!("{:#}", Scene::load(&both).unwrap_err());
    assert!(
        msg.contains("surfaces.dots.density") && msg.contains("only one of"),
        "{msg}"
    );
    let neither = small_scene("opt-neither", "");
    let msg = format!("{:#}", Scene::load(&neither).unwrap_err());
    assert!(
        msg.contains("density_table") && msg.contains("missing"),
        "{msg}"
    );
    let unordered = small_scene("opt-unordered", "density_table = [[0.5, 0.1], [0.2, 0.2]]");
    let msg = format!("{:#}", Scene::load(&unordered).unwrap_err());
    assert!(
        msg.contains("surfaces.dots.density_table") && msg.contains("increase"),
        "{msg}"
    );
    let packing = small_scene("opt-packing", "density_table = [[0.0, 0.1], [1.0, 0.9]]");
    let msg = format!("{:#}", Scene::load(&packing).unwrap_err());
    assert!(
        msg.contains("density_table") && msg.contains("packing"),
        "{msg}"
    );
}

#[test]
fn density_grid_in_scene_files() {
    let grid = load(&small_scene(
        "opt-grid",
        "density_grid = { width_mm = 10.0, v_min_mm = -5.0, values = [[0.1, 0.2], [0.3, 0.4]] }",
    ));
    let dots = dots_of(&grid);
    assert!(
        matches!(&dots.grade.density, Density::Grid(g) if g.x_max == 1.0 && g.shape() == (2, 2))
    );
    // Mid-span, mid-width: the mean of the four knots.
    assert!((dots.density_at_point(DVec2::new(20.0, 0.0)) - 0.25).abs() < 1e-12);
    for (name, text, words) in [
        (
            "opt-grid-both",
            "density = [0.1]\ndensity_grid = { width_mm = 10.0, values = [[0.1]] }",
            &["surfaces.dots.density", "only one of"][..],
        ),
        (
            "opt-grid-ragged",
            "density_grid = { width_mm = 10.0, values = [[0.1, 0.2], [0.3]] }",
            &["surfaces.dots.density_grid", "rectangular"][..],
        ),
        (
            "opt-grid-nan",
            "density_grid = { width_mm = 10.0, values = [[0.1, nan]] }",
            &["surfaces.dots.density_grid", "finite"][..],
        ),
        (
            "opt-grid-packing",
            "density_grid = { width_mm = 10.0, values = [[0.1, 0.2], [0.3, 0.9]] }",
            &["surfaces.dots.density_grid", "packing"][..],
        ),
        (
            "opt-grid-width",
            "density_grid = { width_mm = -1.0, values = [[0.1], [0.2]] }",
            &["surfaces.dots.density_grid", "width_mm"][..],
        ),
        (
            "opt-grid-width-one-row",
            "density_grid = { width_mm = -3.0, values = [[0.1, 0.2]] }",
            &["surfaces.dots.density_grid", "width_mm"][..],
        ),
    ] {
        let path = small_scene(name, text);
        let msg = format!("{:#}", Scene::load(&path).unwrap_err());
        for w in words {
            assert!(msg.contains(w), "{name}: {msg}");
        }
        assert!(msg.contains("scene.toml"), "{name}: {msg}");
    }
}

fn small_options(method: Method) -> OptimizeOptions {
    OptimizeOptions {
        method,
        photons: 40_000,
        seed: 5,
        max_iter: if method == Method::Feedback { 4 } else { 25 },
        verify_photons: 80_000,
        threads: Some(2),
        ..OptimizeOptions::default()
    }
}

#[test]
fn optimizers_improve_a_small_scene_and_write_a_traceable_result() {
    let dir = small_scene("opt-small", "density = [0.3]");
    let scene = load(&dir);
    for method in [Method::NelderMead, Method::Feedback] {
        let opts = small_options(method);
        let mut lines = Vec::new();
        let r = optimize(&scene, &opts, &mut |it| lines.push(it.to_string())).unwrap();
        assert_eq!(lines.len(), r.history.len());
        assert!(r.photons >= opts.photons * r.history.len() as u64 / 2);
        // Better on the search's own (common random number) traces, by many sigma...
        let (a, b) = (&r.initial, &r.best);
        println!(
            "{method}: {} iterations, {} designs, {} photons: {:.4} ± {:.4} -> {:.4} ± {:.4}",
            r.iterations, r.evaluations, r.photons, a.objective, a.noise, b.objective, b.noise
        );
        assert!(
            b.objective < a.objective - 5.0 * (a.noise + b.noise),
            "{method}: {:.4} ± {:.4} -> {:.4} ± {:.4}",
            a.objective,
            a.noise,
            b.objective,
            b.noise
        );
        // ...and on the fresh-seed re-trace.
        let v = r.verification.as_ref().unwrap();
        let (a, b) = (&v.initial.evaluation, &v.final_design.evaluation);
        assert!(
            b.objective < 0.7 * a.objective,
            "{method} re-trace: {:.4} -> {:.4}",
            a.objective,
            b.objective
        );
        // The density stays printable.
        let min = opts.min_density - 1e-12;
        let max = Lattice::Square.max_packing() + 1e-12;
        let dots = r.dots.as_ref().expect("a lattice pattern is printable");
        assert!(dots.iter().all(|d| {
            let frac = PI * d.diameter * d.diameter / 4.0 / 0.25;
            frac >= min * 0.999 && frac <= max
        }));
        // The written scene traces as it is, with the new density.
        let tmp = support::temp_folder(&format!("opt-out-{method}"));
        let out = tmp.path().join("out");
        let files = r.write(&out).unwrap();
        for f in [
            "optimized.toml",
            "history.csv",
            "density.png",
            "profile.png",
            "dots.csv",
            "dots.svg",
            "dots.dxf",
            "optimize.json",
            "initial/flux.exr",
            "initial/summary.json",
            "final/flux.exr",
            "final/summary.json",
        ] {
            assert!(out.join(f).is_file(), "{method}: missing {f} in {files:?}");
        }
        // Besides the set, only its manifest; no staging folder beside it.
        let hidden = |dir: &std::path::Path| -> Vec<String> {
            std::fs::read_dir(dir)
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .filter(|n| n.starts_with('.'))
                .collect()
        };
        assert_eq!(hidden(&out), [blutrace::output::atomic::MANIFEST]);
        assert_eq!(hidden(tmp.path()), Vec::<String>::new(), "staging left");
        let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
        assert_eq!(history.lines().count(), r.history.len() + 1);
        let again = Scene::load(&out.join("optimized.toml")).unwrap();
        let d = dots_of(&again);
        assert_eq!(d.grade.density, r.final_density);
        let csv = std::fs::read_to_string(out.join("dots.csv")).unwrap();
        assert_eq!(export::parse_csv(&csv).unwrap().len(), dots.len());
    }
}

#[test]
fn infeasible_designs_are_penalized_not_traced() {
    let dir = small_scene("opt-infeasible", "density = [0.3]");
    let scene = load(&dir);
    let opts = OptimizeOptions {
        photons: 5_000,
        max_iter: 6,
        // A huge first step leaves the printable range: penalties, never a panic.
        initial_step: 5.0,
        verify_photons: 0,
        threads: Some(1),
        ..OptimizeOptions::default()
    };
    let r = optimize(&scene, &opts, &mut |_| {}).unwrap();
    assert!(
        r.evaluations > r.photons as usize / opts.photons as usize,
        "some designs were rejected untraced"
    );
    assert!(r.best.objective.is_finite());
    assert!(r.verification.is_none());
    // Bad options are errors.
    for bad in [
        OptimizeOptions {
            min_density: 0.95,
            ..opts.clone()
        },
        OptimizeOptions {
            photons: 0,
            ..opts.clone()
        },
        OptimizeOptions {
            tag: Some("face".into()),
            ..opts.clone()
        },
        OptimizeOptions {
            tag: Some("nope".into()),
            ..opts.clone()
        },
        OptimizeOptions {
            method: Method::Feedback,
            alpha: -1.0,
            ..opts.clone()
        },
    ] {
        assert!(optimize(&scene, &bad, &mut |_| {}).is_err());
    }
}

/// Weighting the objective changes no step of the search (audit 3, item 2): infeasible
/// designs rank after every feasible one, not at a fixed penalty that an objective
/// weighted by 1e6 overtakes. The first simplex leaves the printable range on purpose.
#[test]
fn weighting_the_objective_leaves_the_search_unchanged() {
    let dir = small_scene("opt-weight", "density = [0.3]");
    let scene = load(&dir);
    let search = |objective: &str| {
        let opts = OptimizeOptions {
            photons: 4_000,
            max_iter: 10,
            initial_step: 0.5,
            verify_photons: 0,
            threads: Some(1),
            objective: objective.parse().unwrap(),
            ..OptimizeOptions::default()
        };
        optimize(&scene, &opts, &mut |_| {}).unwrap()
    };
    let (a, b) = (search("cv=1"), search("cv=1e6"));
    let traced = a.photons as usize / 4_000;
    assert!(a.evaluations > traced, "no design was infeasible");
    assert_eq!(a.evaluations, b.evaluations);
    assert_eq!(a.final_density, b.final_density);
    let steps = |r: &blutrace::optimize::OptimizeResult| -> Vec<(String, Vec<f64>)> {
        r.history
            .iter()
            .map(|h| (h.step.clone(), h.params.clone()))
            .collect()
    };
    assert_eq!(steps(&a), steps(&b));
    let rel = (b.best.objective / a.best.objective - 1e6).abs() / 1e6;
    assert!(rel < 1e-12, "{} vs {}", a.best.objective, b.best.objective);
}

/// The constrained simplex ranks by feasibility first: the same points for an objective
/// and for it times 1e6, infeasible ones never the best.
#[test]
fn nelder_mead_ranks_infeasible_points_after_feasible_ones() {
    use nelder_mead::Cost;
    let points = |scale: f64| {
        let mut seen = Vec::new();
        let out = nelder_mead::minimize_ranked(
            &mut |x| {
                seen.push(x.to_vec());
                let outside = (x[0] - 1.0).max(0.0);
                Ok(match outside > 0.0 {
                    true => Cost::Infeasible(outside),
                    false => Cost::Feasible(scale * ((x[0] - 3.0).powi(2) + x[1] * x[1])),
                })
            },
            &[0.0, 1.0],
            &[0.5, 0.5],
            &Settings {
                max_iter: 60,
                ..Settings::default()
            },
            &mut |_| {},
        )
        .unwrap();
        (seen, out.x)
    };
    let (a, xa) = points(1.0);
    let (b, xb) = points(1e6);
    assert_eq!(a, b);
    assert_eq!(xa, xb);
    assert!((xa[0] - 1.0).abs() < 1e-3 && xa[0] <= 1.0, "{xa:?}");
    assert!(Cost::Feasible(1e300) < Cost::Infeasible(0.0));
    assert!(Cost::Feasible(f64::NAN) > Cost::Infeasible(1e300));
}

/// A design that puts no light on the profile has no uniformity (audit 3, item 3): no
/// dots search takes it for the best, not even the 2-D feedback, whose debiased area cv
/// made it 0 (perfect).
#[test]
fn a_dark_design_is_never_the_best_dots_design() {
    let dir = small_scene("opt-dark", "density = [0.3]");
    let text = std::fs::read_to_string(&*dir).unwrap();
    std::fs::write(
        &*dir,
        text.replace("normal = [1.0, 0.0, 0.0]", "normal = [-1.0, 0.0, 0.0]"),
    )
    .unwrap();
    let scene = load(&dir);
    for (method, dims) in [
        (Method::NelderMead, 1),
        (Method::Feedback, 1),
        (Method::Feedback, 2),
    ] {
        let opts = OptimizeOptions {
            photons: 2_000,
            max_iter: 2,
            dims,
            verify_photons: 0,
            threads: Some(1),
            method,
            ..OptimizeOptions::default()
        };
        let e = match optimize(&scene, &opts, &mut |_| {}) {
            Ok(r) => panic!(
                "{method} {dims}-D picked a dark design: {:?}",
                r.best.objective
            ),
            Err(e) => format!("{e:#}"),
        };
        assert!(e.contains("no feasible design"), "{method} {dims}-D: {e}");
    }
}

/// Acceptance on notebook14 (minutes): Nelder-Mead from the constant density.
#[test]
#[ignore = "minutes: cargo test --release --test optimize -- --ignored"]
fn notebook14_nelder_mead_acceptance() {
    let scene = load(std::path::Path::new("scenes/notebook14/scene.toml"));
    let opts = OptimizeOptions {
        method: Method::NelderMead,
        edge_margin_mm: 6.0,
        verify_photons: 20_000_000,
        ..OptimizeOptions::default()
    };
    let r = optimize(&scene, &opts, &mut |it| println!("{it}")).unwrap();
    let v = r.verification.unwrap();
    let s = &v.final_design.summary;
    println!("{:?}", s.uniformity);
    assert!(s.uniformity.thirteen_point_min_over_max >= 0.8);
    assert!(v.final_design.evaluation.area_cv < 0.10);
}

/// Acceptance on notebook14 (minutes): the feedback method.
#[test]
#[ignore = "minutes: cargo test --release --test optimize -- --ignored"]
fn notebook14_feedback_acceptance() {
    let scene = load(std::path::Path::new("scenes/notebook14/scene.toml"));
    let opts = OptimizeOptions {
        method: Method::Feedback,
        max_iter: 15,
        smoothing: 0.3,
        edge_margin_mm: 6.0,
        verify_photons: 20_000_000,
        ..OptimizeOptions::default()
    };
    let r = optimize(&scene, &opts, &mut |it| println!("{it}")).unwrap();
    let v = r.verification.unwrap();
    let e = &v.final_design.evaluation;
    let debiased = (e.area_cv.powi(2) - e.area_noise_floor.powi(2))
        .max(0.0)
        .sqrt();
    assert!(
        debiased < 0.05,
        "area cv {} (floor {})",
        e.area_cv,
        e.area_noise_floor
    );
    assert!(
        v.final_design
            .summary
            .uniformity
            .thirteen_point_min_over_max
            >= 0.8
    );
}

/// cv (with its standard error) of the flux map's bins within `band` mm of the lamp edge
/// along x (the phone-led detector starts at x = 2 with 1 mm bins).
fn band_cv(map: &blutrace::run::metrics::Map, band: f64) -> (f64, f64) {
    let (mut v, mut e) = (Vec::new(), Vec::new());
    for iy in 0..map.ny {
        for ix in 0..map.nx {
            if 2.0 + ix as f64 + 0.5 < band {
                v.push(map.value[iy * map.nx + ix]);
                e.push(map.stderr[iy * map.nx + ix]);
            }
        }
    }
    let (cv, se, _) = blutrace::optimize::objective::cv_with_noise(&v, &e);
    (cv, se)
}

/// phone-led (six side-view LEDs on a short edge: hot spots and dark corners, a 2-D
/// non-uniformity): under the same budget the per-cell feedback over a density grid
/// lowers the map's cv (debiased by its noise floor) and the cv of the 20 mm band in front
/// of the LEDs more than the per-strip feedback does, by several standard errors.
#[test]
fn options_of_one_method_are_refused_by_the_other() {
    let scene = load(std::path::Path::new("scenes/phone-led/scene.toml"));
    let base = OptimizeOptions {
        photons: 1000,
        verify_photons: 0,
        ..OptimizeOptions::default()
    };
    for (options, words) in [
        (
            OptimizeOptions {
                method: Method::NelderMead,
                dims: 2,
                ..base.clone()
            },
            "option `dims` 2 needs option `method` feedback",
        ),
        (
            OptimizeOptions {
                method: Method::Feedback,
                dims: 3,
                ..base.clone()
            },
            "option `dims` must be 1 or 2",
        ),
        (
            OptimizeOptions {
                method: Method::Feedback,
                cells: Some((4, 4)),
                ..base.clone()
            },
            "option `cells` needs option `method` feedback option `dims` 2",
        ),
        (
            OptimizeOptions {
                method: Method::Feedback,
                dims: 2,
                cells: Some((1, 4)),
                ..base.clone()
            },
            "option `cells` needs at least 2 knots each way",
        ),
    ] {
        let err = optimize(&scene, &options, &mut |_| {}).err();
        let msg = format!("{:#}", err.expect("refused"));
        assert!(msg.contains(words), "{msg}");
    }
}

#[test]
fn feedback_2d_beats_1d_on_phone_led() {
    let scene = load(std::path::Path::new("scenes/phone-led/scene.toml"));
    let base = OptimizeOptions {
        method: Method::Feedback,
        photons: 200_000,
        seed: 1,
        max_iter: 4,
        verify_photons: 700_000,
        ..OptimizeOptions::default()
    };
    let one = optimize(&scene, &base, &mut |_| {}).unwrap();
    let two = optimize(
        &scene,
        &OptimizeOptions {
            dims: 2,
            cells: Some((12, 14)),
            ..base.clone()
        },
        &mut |_| {},
    )
    .unwrap();
    assert!(matches!(&two.final_density, Density::Grid(g) if g.shape() == (12, 14)));
    assert_eq!(one.photons, two.photons, "same budget");
    let (v1, v2) = (
        one.verification.as_ref().unwrap(),
        two.verification.as_ref().unwrap(),
    );
    let map_cv = |v: &blutrace::optimize::VerifiedDesign| {
        (v.summary.cv_debiased, v.summary.cv_debiased_stderr)
    };
    let (c0, e0) = map_cv(&v2.initial);
    let (c1, e1) = map_cv(&v1.final_design);
    let (c2, e2) = map_cv(&v2.final_design);
    let band = |v: &blutrace::optimize::VerifiedDesign| band_cv(&v.evaluation.map, 20.0);
    let (b0, f0) = band(&v2.initial);
    let (b1, f1) = band(&v1.final_design);
    let (b2, f2) = band(&v2.final_design);
    println!(
        "debiased map cv: initial {c0:.4} ± {e0:.4}, 1-D {c1:.4} ± {e1:.4}, 2-D {c2:.4} ± {e2:.4}; \
         20 mm band cv: initial {b0:.4} ± {f0:.4}, 1-D {b1:.4} ± {f1:.4}, 2-D {b2:.4} ± {f2:.4}"
    );
    let sigma = (e1 * e1 + e2 * e2).sqrt();
    assert!(
        c2 < c1 - 3.0 * sigma,
        "2-D {c2:.4} ± {e2:.4} vs 1-D {c1:.4} ± {e1:.4}"
    );
    assert!(c2 < c0 - 3.0 * (e0 * e0 + e2 * e2).sqrt());
    assert!(
        b2 < b1 - 3.0 * (f1 * f1 + f2 * f2).sqrt(),
        "band: 1-D {b1:.4} ± {f1:.4}, 2-D {b2:.4} ± {f2:.4}"
    );
    assert!(
        b2 < b0 - 3.0 * (f0 * f0 + f2 * f2).sqrt(),
        "band: initial {b0:.4} ± {f0:.4}, 2-D {b2:.4} ± {f2:.4}"
    );
    // The written scene carries the grid as it is, and the grid gets its own map.
    let tmp = tempfile::Builder::new()
        .prefix("blutrace-opt-2d-")
        .tempdir()
        .unwrap();
    let out = tmp.path().join("out");
    two.write(&out).unwrap();
    assert!(out.join("density_map.png").is_file());
    let again = load(&out.join("optimized.toml"));
    let reloaded = dots_of(&again);
    assert_eq!(reloaded.grade.density, two.final_density);
}

/// An interrupt during a search keeps the designs fully traced before it: the design
/// being traced when it came is dropped (a part-traced design has fewer photons and is not
/// comparable), the verification is not traced, and the result says it was interrupted.
/// The interrupt is requested from the progress callback after the third iteration, so the
/// stop point is deterministic.
#[test]
fn an_interrupted_search_keeps_the_designs_traced_before_it() {
    let dir = small_scene("opt-interrupt", "density = [0.3]");
    let scene = load(&dir);
    for method in [Method::NelderMead, Method::Feedback] {
        let opts = OptimizeOptions {
            max_iter: 50,
            ..small_options(method)
        };
        let stop = opts.interrupt.clone();
        let mut reports = 0;
        let r = optimize(&scene, &opts, &mut |it| {
            reports += 1;
            if it.iteration == 2 {
                stop.request();
            }
        })
        .unwrap();
        assert!(r.interrupted, "{method}");
        assert!(r.termination.contains("interrupted"), "{}", r.termination);
        assert!(
            r.verification.is_none(),
            "{method}: verified after an interrupt"
        );
        assert_eq!(reports, r.history.len());
        assert_eq!(r.history.last().unwrap().iteration, 2, "{method}");
        // Every design kept was traced in full: the best is one of them.
        assert_eq!(r.best.photons, opts.photons, "{method}");
        assert_eq!(
            r.photons % opts.photons,
            0,
            "{method}: a part-traced design counted"
        );
        let written = support::temp_folder("opt-interrupt-out");
        let files = r.write(written.path()).unwrap();
        assert!(files.iter().any(|f| f.ends_with("optimize.json")));
        let json: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(written.path().join("optimize.json")).unwrap(),
        )
        .unwrap();
        assert_eq!(json["interrupted"], true);
    }
}
