//! Micro-prism extraction grooves and optical films (issue 7, BLU variants): the bundled
//! scenes `test/prism-plate` (procedural grooves), `test/prism-plate-meshed` (the same
//! grooves meshed) and `bef-stack` (guide + diffuser + crossed prism films), and small
//! scenes built here.
//!
//! Tolerances are in standard errors (4 sigma, or chi-square at P = 0.001): seeded, so
//! repeatable; a correct model fails about once in 10^3..10^4 seeds.

mod support;

use blutrace::run::RunResult;
use blutrace::scene::Scene;
use blutrace::scene::config::SceneFile;
use std::path::{Path, PathBuf};
use support::*;

fn bundled(folder: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(folder)
        .join("scene.toml")
}

fn load_bundled(folder: &str) -> Scene {
    load(&bundled(folder))
}

/// Photons for a test: `default`, or `PRISMS_PHOTONS` from the environment (to probe the
/// models' residual differences with more photons).
fn photons(default: u64) -> u64 {
    std::env::var("PRISMS_PHOTONS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// The ledger's fates as fractions of the photons: detected, escaped, and absorbed per
/// surface tag and per medium (by name), for comparing two scenes with the same tags.
fn fates(r: &RunResult) -> Vec<(String, f64)> {
    let l = &r.tally.ledger;
    let n = l.photons as f64;
    let s = &r.scene;
    let mut v = vec![
        ("detected".to_string(), l.detected.sum.value() / n),
        ("escaped".to_string(), l.escaped.value() / n),
    ];
    for (tag, a) in s.tags.iter().zip(&l.absorbed_by_surface) {
        v.push((format!("surface {tag}"), a.value() / n));
    }
    for (m, a) in s.media.iter().zip(&l.absorbed_in_medium) {
        v.push((format!("medium {}", m.name), a.value() / n));
    }
    v.sort_by(|a, b| a.0.cmp(&b.0));
    v
}

#[test]
fn procedural_grooves_match_the_meshed_grooves() {
    compare_procedural_and_meshed(photons(400_000));
}

/// The same comparison with 2 million photons a side (about 10 s on 2 cores).
#[test]
#[ignore]
fn procedural_grooves_match_the_meshed_grooves_closely() {
    compare_procedural_and_meshed(2_000_000);
}

#[test]
fn new_scenes_trace_and_balance_their_ledgers() {
    use blutrace::optics::surface::Estimator;
    for folder in ["test/prism-plate", "test/prism-plate-meshed", "bef-stack"] {
        let scene = load_bundled(folder);
        assert!(scene.warnings.is_empty(), "{folder}: {:?}", scene.warnings);
        for estimator in [Estimator::Analog, Estimator::Weighted] {
            let opts = blutrace::run::RunOptions {
                photons: 20_000,
                seed: 2,
                threads: Some(2),
                estimator,
                ..Default::default()
            };
            let r = trace_opts(&scene, &opts);
            assert_balanced(&r);
            assert_eq!(r.tally.ledger.killed_photons, 0, "{folder}");
            assert!(r.tally.ledger.detected.sum.value() > 1000.0, "{folder}");
        }
    }
}

/// Procedural against meshed grooves with `n` photons a side: every ledger fraction
/// within 4 combined standard errors, the flux profiles along the plate within a
/// chi-square at P = 0.001.
fn compare_procedural_and_meshed(n: u64) {
    let proc_scene = load_bundled("test/prism-plate");
    let mesh_scene = load_bundled("test/prism-plate-meshed");
    assert!(proc_scene.surfaces.iter().any(|s| s.kind() == "grooves"));
    assert!(mesh_scene.mesh.len() > 20 * proc_scene.mesh.len());
    let a = trace(&proc_scene, n, 17, 2);
    let b = trace(&mesh_scene, n, 18, 2);
    assert_balanced(&a);
    assert_balanced(&b);
    // Ledger fractions: each fate within 4 combined standard errors.
    let (fa, fb) = (fates(&a), fates(&b));
    assert_eq!(
        fa.iter().map(|f| &f.0).collect::<Vec<_>>(),
        fb.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    let mut report = Vec::new();
    for ((name, p), (_, q)) in fa.iter().zip(&fb) {
        let sigma = ((p * (1.0 - p) + q * (1.0 - q)) / n as f64).sqrt();
        let z = if sigma > 0.0 { (p - q) / sigma } else { 0.0 };
        if p + q > 0.0 {
            report.push(format!("{name}: {p:.5} vs {q:.5} ({z:+.2} sigma)"));
        }
        assert!(
            z.abs() < 4.0 || (p - q).abs() < 1e-12,
            "{name}: procedural {p:.5}, meshed {q:.5} ({z:.2} sigma)\n{}",
            report.join("\n")
        );
    }
    println!("{}", report.join("\n"));
    // Flux profile along the guide: chi-square of the bin differences.
    let (ma, mb) = (a.flux_map(), b.flux_map());
    let mut chi2 = 0.0;
    let mut dof = 0;
    for i in 0..ma.value.len() {
        let var = ma.stderr[i].powi(2) + mb.stderr[i].powi(2);
        if var > 0.0 {
            chi2 += (ma.value[i] - mb.value[i]).powi(2) / var;
            dof += 1;
        }
    }
    assert_eq!(dof, 20, "every 1 mm bin along the plate is lit");
    // 20 degrees of freedom: P(chi2 > 45.31) = 0.001.
    println!("flux profile: chi-square {chi2:.1} with {dof} dof");
    assert!(
        chi2 < 45.31,
        "flux profiles differ: chi-square {chi2:.1} with {dof} dof"
    );
    // The grooves do extract: a good part of what enters the plate reaches the detector.
    let detected = a.tally.ledger.detected.sum.value() / n as f64;
    assert!(detected > 0.1, "{fa:?}");
}

/// The bundled `bef-stack` scene, or (`films = false`) the same stack without its two
/// prism films (their geometry file and surfaces dropped).
fn bef_stack(films: bool) -> Scene {
    let path = bundled("bef-stack");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut file: SceneFile = toml::from_str(&text).unwrap();
    if !films {
        file.geometry
            .retain(|g| g.file.to_str() != Some("bef-films.obj"));
        file.surfaces.retain(|tag, _| !tag.starts_with("bef"));
        file.media.retain(|name, _| !name.starts_with("pet_bef"));
    }
    Scene::from_file(&file, &path).unwrap_or_else(|e| panic!("{e:#}"))
}

/// Power-weighted angular statistics of the detected light: on-axis intensity (theta
/// row 0, W/sr) with its standard error, and the fraction of the detected power within
/// 30 deg of the normal.
fn angular_stats(r: &RunResult) -> (f64, f64, f64) {
    let m = r.angular_map(); // x = phi, y = theta
    let np = m.nx;
    let row = |it: usize| (0..np).map(move |ip| it * np + ip);
    // Intensity of the first theta ring (0..5 deg): the mean of its equal-solid-angle bins.
    let i0: f64 = row(0).map(|i| m.value[i]).sum::<f64>() / np as f64;
    let se0 = row(0).map(|i| m.stderr[i].powi(2)).sum::<f64>().sqrt() / np as f64;
    let g = &r.tally.angular;
    let power = |it: usize| -> f64 { (0..g.ny).map(|ip| g.bins[ip * g.nx + it].sum.value()).sum() };
    let total: f64 = (0..g.nx).map(power).sum();
    let within = (0..g.nx / 3).map(power).sum::<f64>() / total;
    (i0, se0, within)
}

#[test]
fn crossed_prism_films_give_on_axis_gain_and_narrow_the_light() {
    let with = bef_stack(true);
    let without = bef_stack(false);
    assert!(with.mesh.len() > without.mesh.len());
    let n = photons(200_000);
    let a = trace(&with, n, 5, 2);
    let b = trace(&without, n, 6, 2);
    assert_balanced(&a);
    assert_balanced(&b);
    let (ia, sa, wa) = angular_stats(&a);
    let (ib, sb, wb) = angular_stats(&b);
    let gain = ia / ib;
    let gain_se = gain * ((sa / ia).powi(2) + (sb / ib).powi(2)).sqrt();
    assert!(
        gain - 1.0 > 4.0 * gain_se,
        "no on-axis gain: {gain:.3} +- {gain_se:.3}"
    );
    // Narrower: much more of the power within 30 deg of the normal (a Lambertian source
    // puts sin^2 30 = 0.25 there), each fraction known to better than 0.01 here.
    assert!(
        wa > wb + 0.1,
        "within 30 deg: {wa:.3} with BEF, {wb:.3} without"
    );
    println!(
        "on-axis intensity {ia:.4e} +- {sa:.1e} W/sr with BEF, {ib:.4e} +- {sb:.1e} without: gain {gain:.3} +- {gain_se:.3}; \
         power within 30 deg: {wa:.3} with, {wb:.3} without; detected {:.4} with, {:.4} without",
        a.tally.ledger.detected.sum.value() / n as f64,
        b.tally.ledger.detected.sum.value() / n as f64
    );
}

/// The bundled `test/prism-plate` scene with its grooves' `apex_deg`, `tilt_deg` and
/// constant fill replaced and, if given, its source replaced by a beam inside the PMMA:
/// written to a temporary folder and loaded.
fn prism_plate_variant(
    name: &str,
    apex: f64,
    tilt: f64,
    fill: f64,
    beam_deg: Option<f64>,
) -> Scene {
    let dir = bundled("test/prism-plate").parent().unwrap().to_path_buf();
    let text = std::fs::read_to_string(dir.join("scene.toml")).unwrap();
    let mut t: toml::Table = toml::from_str(&text).unwrap();
    let back = t["surfaces"]["lgp_back"].as_table().unwrap().clone();
    let mut back = back;
    back.insert("apex_deg".into(), apex.into());
    back.insert("tilt_deg".into(), tilt.into());
    back.insert("density".into(), toml::Value::Array(vec![fill.into()]));
    t["surfaces"]
        .as_table_mut()
        .unwrap()
        .insert("lgp_back".into(), back.into());
    if let Some(beta) = beam_deg {
        // A 0.3 mm wide beam of about 2.5 deg half-width (cos^1000) travelling along +x
        // inside the plate, `beta` towards the back face.
        let b = beta.to_radians();
        let src = format!(
            "type = \"led\"\ncenter = [2.0, 4.0, 0.6]\nnormal = [{}, 0.0, {}]\nu = [0.0, 1.0, 0.0]\n\
             width_mm = 0.3\nheight_mm = 0.3\npower_w = 1.0\ncos_exponent = 1000.0\nmedium = \"pmma\"\n",
            b.cos(),
            -b.sin()
        );
        let src: toml::Table = toml::from_str(&src).unwrap();
        t.insert("sources".into(), toml::Value::Array(vec![src.into()]));
    }
    let obj = std::fs::read_to_string(dir.join("prism-plate.obj")).unwrap();
    let mtl = std::fs::read_to_string(dir.join("prism-plate.mtl")).unwrap();
    let path = write_scene(
        name,
        &toml::to_string(&t).unwrap(),
        &[("prism-plate.obj", &obj), ("prism-plate.mtl", &mtl)],
    );
    load(&path)
}

/// Detected power per theta row (summed over phi) and per phi column (summed over theta).
fn angular_profiles(r: &RunResult) -> (Vec<f64>, Vec<f64>) {
    let g = &r.tally.angular;
    let at = |it: usize, ip: usize| g.bins[ip * g.nx + it].sum.value();
    let theta = (0..g.nx)
        .map(|it| (0..g.ny).map(|ip| at(it, ip)).sum())
        .collect();
    let phi = (0..g.ny)
        .map(|ip| (0..g.nx).map(|it| at(it, ip)).sum())
        .collect();
    (theta, phi)
}

fn argmax(v: &[f64]) -> usize {
    (0..v.len()).max_by(|&a, &b| v[a].total_cmp(&v[b])).unwrap()
}

#[test]
fn asymmetric_grooves_send_light_where_their_lamp_facing_facet_points() {
    // Guided light along +x, 2 deg (+- 2.5) towards the back face, meets each groove's
    // lamp-facing facet (base angle a) from inside and is totally reflected to an
    // elevation of 2a + 2 deg:
    // - a = 45 deg (apex 110, tilt +10): 92 deg, straight up: it leaves the front face
    //   within a few degrees of the normal;
    // - a = 25 deg (tilt -10, the same grooves mirrored): 52 deg, meeting the front face
    //   at 38 deg (inside the 42.2 deg critical angle): it leaves forwards (+x, phi = 0)
    //   at asin(1.49 sin 38) = 66.5 deg (a ray that first reflects off a land rises at
    //   2a - beta = 48 deg and leaves, if at all, nearer grazing).
    // Mirrored facets in the model would swap the two.
    let n = photons(40_000);
    let steep = prism_plate_variant("beam-steep", 110.0, 10.0, 0.5, Some(2.0));
    let shallow = prism_plate_variant("beam-shallow", 110.0, -10.0, 0.5, Some(2.0));
    let (a, b) = (trace(&steep, n, 3, 2), trace(&shallow, n, 4, 2));
    assert_balanced(&a);
    assert_balanced(&b);
    let (theta_a, _) = angular_profiles(&a);
    let (theta_b, phi_b) = angular_profiles(&b);
    println!("theta rows, steep lamp-facing facet: {theta_a:.0?}");
    println!("theta rows, shallow lamp-facing facet: {theta_b:.0?}");
    assert_eq!(
        argmax(&theta_a),
        0,
        "45 deg facets: the peak is at the normal"
    );
    // (Within a bin or two: the beam's spread, and rays that meet the facet after a
    // reflection at a land, rising at -beta, come out a few degrees lower.)
    assert!(
        (11..=14).contains(&argmax(&theta_b)),
        "25 deg facets: the peak should be near 66 deg, it is in row {}",
        argmax(&theta_b)
    );
    let forward: f64 = phi_b[..3].iter().chain(&phi_b[33..]).sum();
    let total: f64 = phi_b.iter().sum();
    assert!(
        forward > 0.8 * total,
        "25 deg facets send the light forwards: {forward} of {total}"
    );

    // Lambertian edge light: a steep lamp-facing facet meets most guided rays (at
    // 45 - beta) inside the critical angle and lets them through the notch and out of the
    // back; a shallow one (65 - beta) totally reflects them up by 50 deg, so more of the
    // light leaves through the front, and forwards.
    let n = photons(100_000);
    let steep = prism_plate_variant("lamb-steep", 110.0, 10.0, 0.3, None);
    let shallow = prism_plate_variant("lamb-shallow", 110.0, -10.0, 0.3, None);
    let (a, b) = (trace(&steep, n, 5, 2), trace(&shallow, n, 6, 2));
    assert_balanced(&a);
    assert_balanced(&b);
    let floor = |r: &RunResult| {
        let t = r.scene.tags.iter().position(|t| t == "floor").unwrap();
        r.tally.ledger.absorbed_by_surface[t].value() / n as f64
    };
    let det = |r: &RunResult| r.tally.ledger.detected.sum.value() / n as f64;
    let (da, db) = (det(&a), det(&b));
    let sigma = ((da * (1.0 - da) + db * (1.0 - db)) / n as f64).sqrt();
    println!(
        "front {da:.4} / back {:.4} with the 45 deg facet facing the lamp, {db:.4} / {:.4} with the 25 deg one",
        floor(&a),
        floor(&b)
    );
    assert!(
        db - da > 4.0 * sigma,
        "front: {da:.4} steep vs {db:.4} shallow"
    );
    assert!(
        floor(&a) > floor(&b) + 0.02,
        "back leak: {} vs {}",
        floor(&a),
        floor(&b)
    );
}

/// Load a one-box scene whose back face has the surface `back` (TOML body after
/// `[surfaces.back]`) and return the loader's error message.
fn back_face_error(name: &str, back: &str) -> String {
    let obj = box_obj(
        [0.0, 0.0, 0.0],
        [10.0, 5.0, 1.0],
        ["edge", "edge", "edge", "edge", "back", "front"],
    );
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"box.obj\"\n[media.pmma]\nn = 1.49\n\
         [surfaces.front]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.edge]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.back]\n{back}\n\
         [[sources]]\ntype = \"led\"\ncenter = [-0.1, 2.5, 0.5]\nnormal = [1.0, 0.0, 0.0]\nu = [0.0, 1.0, 0.0]\n\
         width_mm = 1.0\nheight_mm = 0.5\npower_w = 1.0\n\
         [detector]\norigin = [0.0, 0.0, 1.1]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [10.0, 5.0]\n"
    );
    let path = write_scene(name, &toml, &[("box.obj", &obj)]);
    match Scene::load(&path) {
        Ok(_) => String::new(),
        Err(e) => format!("{e:#}"),
    }
}

#[test]
fn bad_groove_and_diffuser_parameters_are_named() {
    let grooves = |extra: &str| {
        format!(
            "model = \"grooves\"\ninside = \"pmma\"\nrelief = \"cut\"\norigin = [0.0, 0.0, 0.0]\n\
             axis = [1.0, 0.0, 0.0]\n{extra}"
        )
    };
    let ok = grooves("apex_deg = 100.0\npitch_mm = 0.2\nlength_mm = 10.0\ndensity = [0.1, 0.5]\n");
    assert_eq!(back_face_error("grooves-ok", &ok), "");
    let cases = [
        (
            grooves("apex_deg = 100.0\npitch_mm = -0.2\n"),
            "surfaces.back.pitch_mm: must be > 0",
        ),
        (
            grooves("apex_deg = 180.0\npitch_mm = 0.2\n"),
            "surfaces.back.apex_deg: must be within [0.01, 180)",
        ),
        (
            grooves("apex_deg = 0.0\npitch_mm = 0.2\n"),
            "surfaces.back.apex_deg: must be within [0.01, 180)",
        ),
        (
            grooves("apex_deg = 1e-300\npitch_mm = 0.2\n"),
            "surfaces.back.apex_deg: must be within [0.01, 180) degrees (a narrower groove is a slit thousands of pitches deep), got 1e-300",
        ),
        (
            grooves("apex_deg = 100.0\ntilt_deg = 45.0\npitch_mm = 0.2\n"),
            "surfaces.back.tilt_deg: must be within (-40, 40)",
        ),
        (
            grooves("apex_deg = 100.0\npitch_mm = 0.2\nlength_mm = 10.0\ndensity = [0.5, 0.8]\n"),
            "surfaces.back.density: fill f(x) = 1.0",
        ),
        (
            grooves("apex_deg = 100.0\npitch_mm = 0.2\ndensity = [0.1, 0.5]\n"),
            "surfaces.back.length_mm: missing",
        ),
        (
            grooves(
                "apex_deg = 100.0\npitch_mm = 0.2\ndensity = [0.1]\ndensity_table = [[0.0, 0.1]]\n",
            ),
            "surfaces.back.density: give only one of",
        ),
        (
            grooves("apex_deg = 100.0\npitch_mm = 0.2\ndensity_table = [[0.0, 0.1], [0.0, 0.2]]\n"),
            "surfaces.back.density_table: knot x values must increase",
        ),
        (
            "model = \"grooves\"\ninside = \"pmma\"\nrelief = \"cut\"\norigin = [0.0, 0.0, 0.0]\n\
             axis = [0.0, 0.0, 1.0]\napex_deg = 100.0\npitch_mm = 0.2\n"
                .to_string(),
            "surfaces.back.axis: must lie in the face",
        ),
        (
            grooves("apex_deg = 100.0\npitch_mm = 0.2\nrelief2 = 1\n"),
            "unknown field `relief2`",
        ),
        (
            "model = \"diffuser\"\ninside = \"pmma\"\nroughness = -0.1\n".to_string(),
            "surfaces.back.roughness: must be >= 0",
        ),
        (
            "model = \"diffuser\"\ninside = \"pmma\"\nroughness = 7.0\n".to_string(),
            "surfaces.back.roughness: must be at most 4",
        ),
    ];
    for (i, (back, want)) in cases.iter().enumerate() {
        let err = back_face_error(&format!("bad-relief-{i}"), back);
        assert!(
            err.contains("scene.toml"),
            "case {i}: error without file: {err}"
        );
        assert!(err.contains(want), "case {i}: want '{want}', got '{err}'");
    }
}

#[test]
fn diffuser_faces_spread_light_and_lose_none() {
    // A 1 mm PMMA slab with a rough top face, lit from below through its smooth bottom by
    // a collimated beam: lossless (every photon is detected above or escapes), and the
    // light above is spread over the hemisphere instead of leaving straight up. The beam's
    // source is a probe, not a lamp: it has no body.
    let obj = box_obj(
        [-50.0, -50.0, 0.0],
        [50.0, 50.0, 1.0],
        ["edge", "edge", "edge", "edge", "bottom", "top"],
    );
    let scene = |rough: f64, name: &str| {
        let toml = format!(
            "version = 1\n[[geometry]]\nfile = \"slab.obj\"\n[media.pmma]\nn = 1.49\n\
             [surfaces.top]\nmodel = \"diffuser\"\ninside = \"pmma\"\nroughness = {rough}\n\
             [surfaces.bottom]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
             [surfaces.edge]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
             [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, -0.5]\nnormal = [0.0, 0.0, 1.0]\nu = [1.0, 0.0, 0.0]\n\
             width_mm = 0.1\nheight_mm = 0.1\npower_w = 1.0\ncos_exponent = 1e6\nbody = \"transparent\"\n\
             [detector]\norigin = [-500.0, -500.0, 1.5]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [1000.0, 1000.0]\n\
             bins = [2, 2]\nangular_bins = [18, 4]\n"
        );
        load(&write_scene(name, &toml, &[("slab.obj", &obj)]))
    };
    let n = photons(50_000);
    let smooth = scene(0.0, "diffuser-smooth");
    let rough = scene(0.5, "diffuser-rough");
    let (a, b) = (trace(&smooth, n, 8, 2), trace(&rough, n, 9, 2));
    assert_balanced(&a);
    assert_balanced(&b);
    for r in [&a, &b] {
        let l = &r.tally.ledger;
        assert_eq!(
            l.detected.sum.value() + l.escaped.value(),
            n as f64,
            "lossless"
        );
    }
    let (ta, _) = angular_profiles(&a);
    let (tb, _) = angular_profiles(&b);
    let first_row = |t: &[f64]| t[0] / t.iter().sum::<f64>();
    println!("smooth: {ta:.0?}\nrough: {tb:.0?}");
    assert!(first_row(&ta) > 0.999, "smooth top: straight through");
    assert!(
        first_row(&tb) < 0.2,
        "rough top: spread ({})",
        first_row(&tb)
    );
}

/// The relief is self-similar: at the finest pitch the scene bounds allow (1e-6 of the
/// face's reach, `optics::density::PITCH_RANGE`), a million grooves across the plate give
/// the same fates as 80, within 4 standard errors: the bound keeps the lattice
/// representable (at 1e-300 mm it was not, and the grooves extracted nothing).
#[test]
fn grooves_at_the_finest_allowed_pitch_trace_like_coarse_ones() {
    let path = bundled("test/prism-plate");
    let text = std::fs::read_to_string(&path).unwrap();
    let obj = std::fs::read_to_string(path.with_file_name("prism-plate.obj")).unwrap();
    // The back face reaches 21.54 mm from the origin: the bound is 2.154e-5 mm.
    let fine = text.replace("pitch_mm = 0.25", "pitch_mm = 2.2e-5");
    assert_ne!(fine, text);
    let dir = write_scene("fine-grooves", &fine, &[("prism-plate.obj", &obj)]);
    let (coarse, fine) = (load_bundled("test/prism-plate"), load(&dir));
    let n = photons(200_000);
    let (a, b) = (trace(&coarse, n, 7, 2), trace(&fine, n, 8, 2));
    for ((name, p), (_, q)) in fates(&a).into_iter().zip(fates(&b)) {
        let sigma = ((p * (1.0 - p) + q * (1.0 - q)) / n as f64).sqrt();
        assert!(
            (p - q).abs() <= 4.0 * sigma + 1e-12,
            "{name}: pitch 0.25 mm {p:.5}, 2.2e-5 mm {q:.5} (sigma {sigma:.1e})"
        );
    }
    assert!(fates(&b)[0].1 > 0.05, "light is detected: {:?}", fates(&b));
}
