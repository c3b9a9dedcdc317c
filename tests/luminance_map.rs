//! The luminance map (`luminance.exr`, `summary.json`'s `luminance_map`): cd/m² within the
//! detector's cone against the closed form of a Lambertian panel, against the angular
//! output for the same photons, the same bits on any thread count, and its checks.

mod support;

use blutrace::run::metrics::cone::luminance_cone_map;
use support::{load, temp_folder, trace, write_scene};

/// A 400 x 400 mm Lambertian panel (1 W, 100 lm) at z = 0, a 100 x 100 mm target at
/// z = 0.5 over its middle, the luminance cone `cone` (a `[detector]` line, or nothing).
fn panel(name: &str, cone: &str) -> blutrace::scene::Scene {
    let toml = format!(
        "version = 1\ngeometry = []\nsurfaces = {{}}\n\
         [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\nu = [1.0, 0.0, 0.0]\n\
         width_mm = 400.0\nheight_mm = 400.0\npower_w = 1.0\nlumens = 100.0\n\
         [detector]\norigin = [-50.0, -50.0, 0.5]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [100.0, 100.0]\n\
         bins = [10, 10]\nangular_bins = [18, 8]\n{cone}"
    );
    load(&write_scene(name, &toml, &[]))
}

/// A Lambertian panel's luminance is lumens / (pi area) in every direction, so the map
/// reads it for any cone: the target mean within 3 standard errors, for a meter's 2
/// degrees and for 30.
#[test]
fn a_lambertian_panel_reads_flux_over_pi_area_in_any_cone() {
    let expected = 100.0 / (std::f64::consts::PI * 0.4 * 0.4);
    for cone in [2.0, 30.0] {
        let scene = panel("lum-lambert", &format!("luminance_cone_deg = {cone}\n"));
        let run = trace(&scene, 4_000_000, 3, 2);
        let s = run
            .summary()
            .luminance_map
            .expect("the sources give lumens");
        assert_eq!(s.cone_deg, cone);
        let m = s.mean_cd_m2;
        println!(
            "cone {cone}: {:.3} ± {:.3} cd/m², expected {expected:.3}",
            m.value, m.stderr
        );
        assert!(
            (m.value - expected).abs() < 3.0 * m.stderr,
            "{m:?} vs {expected}"
        );
        assert!(m.stderr < 0.1 * expected, "{m:?}");
        // Every bin sees the same panel: the map is uniform within its noise.
        assert!(
            s.cv_debiased.value < 3.0 * s.cv_debiased.stderr.max(0.01),
            "{s:?}"
        );
    }
}

/// With a cone as wide as the angular grid's first theta row (90/18 = 5 degrees), the
/// map holds exactly that row's photons: its mean is the angular output's on-axis
/// luminance, to rounding.
#[test]
fn the_maps_mean_is_the_angular_outputs_on_axis_luminance() {
    let scene = panel("lum-axis", "luminance_cone_deg = 5.0\n");
    let run = trace(&scene, 300_000, 4, 2);
    let s = run.summary();
    let (map, axis) = (s.luminance_map.unwrap(), s.luminance.unwrap());
    let rel = (map.mean_cd_m2.value - axis.on_axis_cd_m2).abs() / axis.on_axis_cd_m2;
    assert!(rel < 1e-9, "{:?} vs {}", map.mean_cd_m2, axis.on_axis_cd_m2);
    let cone_hits: u64 = luminance_cone_map(&run.scene, &run.tally, 0)
        .unwrap()
        .hits
        .iter()
        .sum();
    let row: u64 = (0..8).map(|ip| run.tally.angular.bins[ip * 18].hits).sum();
    assert_eq!(cone_hits, row);
}

/// The map and its summary are the same bits on one and three threads, and are written.
#[test]
fn the_map_does_not_depend_on_threads_and_is_written() {
    let scene = panel("lum-threads", "");
    let (a, b) = (trace(&scene, 100_000, 9, 1), trace(&scene, 100_000, 9, 3));
    assert_eq!(a.tally.meter, b.tally.meter);
    assert_eq!(a.summary().luminance_map, b.summary().luminance_map);
    assert_eq!(a.summary().luminance_map.unwrap().cone_deg, 2.0);
    let dir = temp_folder("lum-out");
    let out = dir.path().join("out");
    a.write(&out).unwrap();
    for f in ["luminance.exr", "luminance.png"] {
        assert!(out.join(f).is_file(), "{f}");
    }
}

/// A cone outside [0.001, 90] degrees is an error naming the field (narrower, its solid
/// angle is lost in rounding: 1e-300 made a map of 0/0); without lumens or spectra there
/// is no map.
#[test]
fn cones_are_checked_and_a_run_without_lumens_has_no_map() {
    for bad in ["0.0", "-1.0", "90.5", "nan", "1e-300", "1e-5", "0.000999"] {
        let toml = format!(
            "version = 1\ngeometry = []\nsurfaces = {{}}\n\
             [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\nu = [1.0, 0.0, 0.0]\n\
             width_mm = 1.0\nheight_mm = 1.0\npower_w = 1.0\n\
             [detector]\norigin = [-5.0, -5.0, 0.5]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [10.0, 10.0]\n\
             luminance_cone_deg = {bad}\n"
        );
        let dir = write_scene("lum-bad", &toml, &[]);
        let e = format!("{:#}", blutrace::scene::Scene::load(&dir).unwrap_err());
        assert!(e.contains("detector.luminance_cone_deg"), "{bad}: {e}");
        assert!(e.contains("[0.001, 90]") && e.len() < 400, "{bad}: {e}");
    }
    let toml = "version = 1\ngeometry = []\nsurfaces = {}\n\
        [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\nu = [1.0, 0.0, 0.0]\n\
        width_mm = 1.0\nheight_mm = 1.0\npower_w = 1.0\n\
        [detector]\norigin = [-5.0, -5.0, 0.5]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [10.0, 10.0]\n";
    let run = trace(&load(&write_scene("lum-none", toml, &[])), 1000, 1, 1);
    assert!(run.tally.meter.is_none() && run.summary().luminance_map.is_none());
}

/// `trace --luminance-cone-deg` replaces the scene's cone, is checked, and is refused with
/// `--shard` (shards and their merge must share one cone: the scene file's).
#[test]
fn the_command_lines_cone_replaces_the_scenes_and_is_checked() {
    let dir = temp_folder("lum-cli");
    let out = dir.path().join("out");
    let run = |extra: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_blutrace"))
            .args(["trace", "scenes/phone-led", "--photons", "20000", "--quiet"])
            .args(["--out", out.to_str().unwrap()])
            .args(extra)
            .output()
            .unwrap()
    };
    assert!(run(&["--luminance-cone-deg", "10"]).status.success());
    let text = std::fs::read_to_string(out.join("summary.json")).unwrap();
    let s: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(s["luminance_map"]["cone_deg"], 10.0);
    // No photon in the narrowest cone: the cone count measured nothing, and says so.
    let empty = run(&[
        "--luminance-cone-deg",
        "0.001",
        "--luminance-estimator",
        "cone",
    ]);
    let said = String::from_utf8_lossy(&empty.stdout);
    assert!(empty.status.success(), "{said}");
    assert!(
        said.contains("no photon left the target within the 0.001° cone"),
        "{said}"
    );
    let text = std::fs::read_to_string(out.join("summary.json")).unwrap();
    let s: serde_json::Value = serde_json::from_str(&text).unwrap();
    let m = &s["luminance_map"];
    assert_eq!(m["photons_in_cone"], 0, "{m}");
    assert!(m["mean_cd_m2"]["value"].is_null() && m["mean_cd_m2"]["stderr"].is_null());
    // How many it would need, from the photons near the normal: more than a trillion
    // (the cone holds 3e-10 of the light's projected solid angle).
    let needed = m["photons_needed"].as_f64().unwrap();
    assert!(needed > 1e12 && needed.is_finite(), "{m}");
    assert!(said.contains("a noise floor of 0.1 needs about"), "{said}");
    for (extra, says) in [
        (
            &["--luminance-cone-deg", "95"][..],
            "--luminance-cone-deg must be within [0.001, 90]",
        ),
        (
            &["--luminance-cone-deg", "1e-300"][..],
            "--luminance-cone-deg must be within [0.001, 90]",
        ),
        (
            &["--luminance-cone-deg", "5", "--shard", "0/2"][..],
            "cannot be given with --shard",
        ),
    ] {
        let bad = run(extra);
        let e = String::from_utf8_lossy(&bad.stderr);
        assert!(!bad.status.success() && e.contains(says), "{e}");
    }
}
