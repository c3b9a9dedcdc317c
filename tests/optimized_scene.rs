//! `optimized.toml` names every file the scene reads so that it loads from the output
//! folder (audit 3, item 4): ray files, spectrum files and BSDF tables as well as the
//! geometry, for the dot-density search and the layout search alike; `blutrace check`
//! and a trace of the written file succeed.

mod support;

use blutrace::optimize::{Method, OptimizeOptions, optimize, optimize_layout};
use std::path::Path;
use support::bsdf::lambert_table;
use support::{box_obj, load, temp_folder, trace, write_scene};

/// Text rays in a 30-degree cone about the file's +z (the lamp's axis), from a 1 mm square.
fn cone_rays() -> String {
    let mut s = String::from("# x y z kx ky kz flux\n");
    for i in 0..64 {
        let (theta, phi) = (0.5 * (i % 8) as f64 / 8.0, (i / 8) as f64 * 0.785);
        let (x, y) = (((i % 5) as f64 - 2.0) * 0.2, ((i % 3) as f64 - 1.0) * 0.2);
        let k = [
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        ];
        s += &format!("{x} {y} 0 {} {} {} 1\n", k[0], k[1], k[2]);
    }
    s
}

const SPECTRUM: &str = "400, 0.5\n500, 1.0\n600, 1.0\n700, 0.5\n";

/// `[[sources]]`: the ray file with the spectrum file, placed by `placement`.
fn ray_source(placement: &str) -> String {
    format!(
        "[[sources]]\ntype = \"rayfile\"\nfile = \"rays/led.rays\"\n{placement}\n\
         power_w = 1.0\nspectrum = {{ file = \"led.csv\" }}\n"
    )
}

/// `blutrace check` of the written scene succeeds, and a trace of it detects light.
fn assert_loads_from(out: &Path) {
    let file = out.join("optimized.toml");
    let text = std::fs::read_to_string(&file).unwrap();
    for name in ["led.rays", "led.csv"] {
        let line = text.lines().find(|l| l.contains(name)).unwrap();
        assert!(!line.contains(&format!("\"{name}\"")), "relative: {line}");
    }
    let check = std::process::Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .args(["check", file.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&check.stderr);
    assert!(check.status.success(), "check: {err}");
    let run = trace(&load(&file), 5_000, 1, 1);
    assert!(run.tally.ledger.detected.sum.value() > 0.0);
}

/// The dot-density search of a plate lit by a ray file with a spectrum file.
#[test]
fn the_dots_search_writes_a_scene_that_loads_from_its_output_folder() {
    let obj = box_obj(
        [-20.0, -5.0, -0.5],
        [20.0, 5.0, 0.5],
        ["edge", "edge", "edge", "edge", "dots", "face"],
    );
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"plate.obj\"\n[media.pmma]\nn = 1.49\n\
         [surfaces.face]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.edge]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.dots]\nmodel = \"dots\"\ninside = \"pmma\"\nink_albedo = 0.9\nlattice = \"square\"\n\
         pitch_mm = 0.5\norigin = [-20.0, 0.0, -0.5]\naxis = [1.0, 0.0, 0.0]\nlength_mm = 40.0\n\
         density = [0.3]\n{}\
         [detector]\norigin = [-20.0, -5.0, 0.6]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [40.0, 10.0]\nbins = [10, 2]\n",
        ray_source("rotate_deg = [0.0, 90.0, 0.0]\ntranslate = [-20.01, 0.0, 0.0]")
    );
    let dir = write_scene(
        "optimized-dots",
        &toml,
        &[("plate.obj", &obj), ("led.csv", SPECTRUM)],
    );
    write_rays(&dir);
    let scene = load(&dir);
    let opts = OptimizeOptions {
        method: Method::Feedback,
        photons: 5_000,
        max_iter: 1,
        verify_photons: 0,
        threads: Some(1),
        ..OptimizeOptions::default()
    };
    let r = optimize(&scene, &opts, &mut |_| {}).unwrap();
    let tmp = temp_folder("optimized-dots-out");
    let out = tmp.path().join("out");
    r.write(&out).unwrap();
    assert_loads_from(&out);
}

/// The layout search of a BSDF-table sheet under a ray file with a spectrum file.
#[test]
fn the_layout_search_writes_a_scene_that_loads_from_its_output_folder() {
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"sheet.obj\"\n\
         [surfaces.sheet]\nmodel = \"bsdf_table\"\nfile = \"tables/white.bsdf\"\n{}\
         [detector]\norigin = [-100.0, -100.0, 10.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [200.0, 200.0]\nbins = [4, 4]\nangular_bins = [3, 4]\n",
        ray_source("rotate_deg = [180.0, 0.0, 0.0]\ntranslate = [0.0, 0.0, 5.0]")
    );
    let obj =
        "v -100 -100 0\nv 100 -100 0\nv 100 100 0\nv -100 100 0\nusemtl sheet\nf 1 2 3\nf 1 3 4\n";
    let dir = write_scene(
        "optimized-layout",
        &toml,
        &[("sheet.obj", obj), ("led.csv", SPECTRUM)],
    );
    write_rays(&dir);
    let tables = dir.parent().unwrap().join("tables");
    std::fs::create_dir_all(&tables).unwrap();
    std::fs::write(tables.join("white.bsdf"), lambert_table(0.8)).unwrap();
    let scene = load(&dir);
    let opts = OptimizeOptions {
        method: Method::Grid,
        vary: vec!["sources.0.translate.2=3..6".parse().unwrap()],
        grid_points: 2,
        photons: 5_000,
        verify_photons: 0,
        threads: Some(1),
        ..OptimizeOptions::default()
    };
    let r = optimize_layout(&scene, &opts, &mut |_, _| {}).unwrap();
    let tmp = temp_folder("optimized-layout-out");
    let out = tmp.path().join("out");
    r.write(&out).unwrap();
    assert_loads_from(&out);
    let text = std::fs::read_to_string(out.join("optimized.toml")).unwrap();
    assert!(!text.contains("\"tables/white.bsdf\""), "{text}");
}

/// The ray file in a `rays/` folder beside the scene file.
fn write_rays(scene: &Path) {
    let rays = scene.parent().unwrap().join("rays");
    std::fs::create_dir_all(&rays).unwrap();
    std::fs::write(rays.join("led.rays"), cone_rays()).unwrap();
}

/// A file the written scene would name but that is gone is found before the search, not
/// after it: the search stops at once, naming the key.
#[test]
fn a_missing_file_stops_the_search_before_it_starts() {
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"sheet.obj\"\n[surfaces.sheet]\nmodel = \"lambert\"\nalbedo = 0.8\n{}\
         [detector]\norigin = [-100.0, -100.0, 10.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [200.0, 200.0]\nbins = [4, 4]\nangular_bins = [3, 4]\n",
        ray_source("rotate_deg = [180.0, 0.0, 0.0]\ntranslate = [0.0, 0.0, 5.0]")
    );
    let obj =
        "v -100 -100 0\nv 100 -100 0\nv 100 100 0\nv -100 100 0\nusemtl sheet\nf 1 2 3\nf 1 3 4\n";
    let dir = write_scene(
        "optimized-gone",
        &toml,
        &[("sheet.obj", obj), ("led.csv", SPECTRUM)],
    );
    write_rays(&dir);
    let scene = load(&dir);
    std::fs::remove_file(dir.parent().unwrap().join("rays/led.rays")).unwrap();
    let opts = OptimizeOptions {
        method: Method::Grid,
        vary: vec!["sources.0.translate.2=3..6".parse().unwrap()],
        grid_points: 2,
        photons: 5_000,
        verify_photons: 0,
        threads: Some(1),
        ..OptimizeOptions::default()
    };
    let mut traced = 0;
    let e = optimize_layout(&scene, &opts, &mut |_, _| traced += 1).unwrap_err();
    let e = format!("{e:#}");
    assert!(
        e.contains("sources[0].file") && e.contains("led.rays"),
        "{e}"
    );
    assert_eq!(traced, 0, "designs were traced before the error");
}
