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
    let cone_hits: u64 = luminance_cone_map(&run.scene, &run.tally)
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
    assert_eq!(a.tally.cone, b.tally.cone);
    assert_eq!(a.summary().luminance_map, b.summary().luminance_map);
    assert_eq!(a.summary().luminance_map.unwrap().cone_deg, 2.0);
    let dir = temp_folder("lum-out");
    let out = dir.path().join("out");
    a.write(&out).unwrap();
    for f in ["luminance.exr", "luminance.png"] {
        assert!(out.join(f).is_file(), "{f}");
    }
}

/// A cone outside (0, 90] degrees is an error naming the field; without lumens or
/// spectra there is no map.
#[test]
fn cones_are_checked_and_a_run_without_lumens_has_no_map() {
    for bad in ["0.0", "-1.0", "90.5", "nan"] {
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
    }
    let toml = "version = 1\ngeometry = []\nsurfaces = {}\n\
        [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\nu = [1.0, 0.0, 0.0]\n\
        width_mm = 1.0\nheight_mm = 1.0\npower_w = 1.0\n\
        [detector]\norigin = [-5.0, -5.0, 0.5]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [10.0, 10.0]\n";
    let run = trace(&load(&write_scene("lum-none", toml, &[])), 1000, 1, 1);
    assert!(run.tally.cone.is_none() && run.summary().luminance_map.is_none());
}
