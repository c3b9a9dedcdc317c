//! Procedural reflectors in scene files: the direct-lit box generated at load traces as
//! the meshed box `tools/scenegen` writes, and its shape is an `optimize --vary` variable.

mod support;

use blutrace::optimize::{Method, OptimizeOptions, optimize_layout};
use blutrace::run::metrics::{Metric, with_errors};
use support::{box_obj, load, write_scene};

/// The bundled direct-lit scene with its box generated (`[[procedural]]`) instead of read
/// from the OBJ, and the diffuser plate from a plain box OBJ.
fn procedural_direct_lit(name: &str, ridge: f64) -> support::SceneDir {
    let bundled = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/direct-lit/scene.toml"),
    )
    .unwrap();
    let box_part = format!(
        "[[geometry]]\nfile = \"plate.obj\"\n\n[[procedural]]\ntype = \"direct_lit_box\"\n\
         tag = \"box_reflector\"\norigin = [0.0, 0.0, 0.0]\nsize_mm = [400.0, 250.0, 25.0]\n\
         ridge_height_mm = {ridge:?}\n"
    );
    let toml = bundled.replace("[[geometry]]\nfile = \"direct-lit.obj\"\n", &box_part);
    assert_ne!(toml, bundled);
    let plate = box_obj(
        [0.0, 0.0, 25.0],
        [400.0, 250.0, 27.0],
        [
            "diffuser_edge",
            "diffuser_edge",
            "diffuser_edge",
            "diffuser_edge",
            "diffuser_back",
            "diffuser_top",
        ],
    );
    write_scene(name, &toml, &[("plate.obj", &plate)])
}

/// Same photons (seed), same geometry up to the OBJ's 6 decimals and the plate's
/// triangulation: efficiency and area cv agree within 3 combined standard errors.
#[test]
fn the_generated_box_traces_as_the_meshed_one() {
    let meshed = load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/direct-lit/scene.toml"),
    );
    let dir = procedural_direct_lit("proc-dl", 6.0);
    let generated = load(&dir);
    let report = generated
        .geometry
        .iter()
        .find(|g| g.file == "procedural[0]")
        .unwrap();
    assert_eq!(report.tags["box_reflector"].triangles, 88 - 12);
    let a = support::trace(&meshed, 100_000, 7, 2);
    let b = support::trace(&generated, 100_000, 7, 2);
    let (va, ea) = with_errors(&meshed, &a.tally, &a.groups);
    let (vb, eb) = with_errors(&generated, &b.tally, &b.groups);
    for m in [Metric::Efficiency, Metric::Cv, Metric::ThirteenPoint] {
        let (d, s) = (va[m] - vb[m], ea[m].hypot(eb[m]));
        println!("{}: {:.5} vs {:.5} (± {s:.5})", m.name(), va[m], vb[m]);
        assert!(
            d.abs() < 3.0 * s,
            "{}: {} vs {} ± {s}",
            m.name(),
            va[m],
            vb[m]
        );
    }
}

/// The ridge height as a variable: the grid scan re-generates the box for every design.
#[test]
fn the_ridge_height_is_a_variable() {
    let dir = procedural_direct_lit("proc-vary", 6.0);
    let scene = load(&dir);
    let o = OptimizeOptions {
        method: Method::Grid,
        vary: vec!["procedural.0.ridge_height_mm=0..12".parse().unwrap()],
        grid_points: 3,
        photons: 20_000,
        verify_photons: 0,
        threads: Some(2),
        ..OptimizeOptions::default()
    };
    let r = optimize_layout(&scene, &o, &mut |_, _| {}).unwrap();
    let xs: Vec<f64> = r.history.iter().map(|h| h.values[0]).collect();
    assert_eq!(xs, vec![6.0, 0.0, 12.0]);
    let objectives: Vec<f64> = r
        .history
        .iter()
        .map(|h| h.result.as_ref().unwrap().objective)
        .collect();
    // Different shapes, different maps.
    assert!(
        objectives[0] != objectives[1] && objectives[1] != objectives[2],
        "{objectives:?}"
    );
}

/// The bundled `direct-lit-rows` (a lamp row and a generated box) is `direct-lit` (six lamp
/// entries and a meshed box): the same metrics within 3 combined standard errors.
#[test]
fn direct_lit_rows_is_direct_lit() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let meshed = load(&root.join("direct-lit/scene.toml"));
    let rows = load(&root.join("direct-lit-rows/scene.toml"));
    assert_eq!(rows.sources.list.len(), 6);
    let a = support::trace(&meshed, 100_000, 9, 2);
    let b = support::trace(&rows, 100_000, 9, 2);
    let (va, ea) = with_errors(&meshed, &a.tally, &a.groups);
    let (vb, eb) = with_errors(&rows, &b.tally, &b.groups);
    for m in [Metric::Efficiency, Metric::Cv, Metric::ThirteenPoint] {
        let s = ea[m].hypot(eb[m]);
        assert!(
            (va[m] - vb[m]).abs() < 3.0 * s,
            "{}: {} vs {} ± {s}",
            m.name(),
            va[m],
            vb[m]
        );
    }
}
