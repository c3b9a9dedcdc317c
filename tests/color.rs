//! Spectral transport and the colour outputs, against closed forms.
//!
//! The slab: a Lambertian source inside an index-matched slab (n = 1 on both sides, so no
//! Fresnel reflection) of thickness t and absorption a(λ). A photon leaving at cos θ = μ
//! (density 2μ) crosses it with probability exp(-a t / μ), so the transmitted spectrum is
//! S(λ) 2 E3(a(λ) t), with E3(x) = ∫₀¹ μ e^(-x/μ) dμ: the target's X, Y, Z and u'v' are
//! closed forms.

mod support;

use blutrace::color::{CieIlluminant, Spectrum, Xyz, observer};
use blutrace::output::exr::read_channels;
use blutrace::run::RunResult;
use support::{assert_balanced, box_obj, load, trace, write_scene};

/// 2 E3(x) = 2 ∫₀¹ μ e^(-x/μ) dμ, by composite Simpson on 20000 intervals (the integrand
/// is smooth and vanishes at 0).
fn two_e3(x: f64) -> f64 {
    let n = 20_000;
    let h = 1.0 / n as f64;
    let f = |mu: f64| if mu > 0.0 { mu * (-x / mu).exp() } else { 0.0 };
    let inner: f64 = (1..n)
        .map(|i| f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    2.0 * h / 3.0 * (f(0.0) + inner + f(1.0))
}

/// A 1 mm slab (absorption `absorption`, a scene-file value) over 400 x 400 mm, a 2 x 2 mm
/// LED of spectrum `spectrum` at its bottom face, the target just above its top.
fn slab_run(
    name: &str,
    spectrum: &str,
    absorption: &str,
    photons: u64,
    threads: usize,
) -> RunResult {
    let spectrum = match spectrum {
        "" => String::new(),
        s => format!("spectrum = {s}\n"),
    };
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"slab.obj\"\n\
         [media.slab]\nn = 1.0\nabsorption_per_mm = {absorption}\n\
         [surfaces.face]\nmodel = \"dielectric\"\ninside = \"slab\"\n\
         [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n\
         u = [1.0, 0.0, 0.0]\nwidth_mm = 2.0\nheight_mm = 2.0\npower_w = 1.0\n\
         medium = \"slab\"\n{spectrum}\
         [detector]\norigin = [-200.0, -200.0, 1.001]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [400.0, 400.0]\nbins = [9, 9]\nangular_bins = [6, 4]\n"
    );
    let slab = box_obj([-200.0, -200.0, -0.001], [200.0, 200.0, 1.0], ["face"; 6]);
    let scene = load(&write_scene(name, &toml, &[("slab.obj", &slab)]));
    let run = trace(&scene, photons, 11, threads);
    assert_balanced(&run);
    run
}

/// X, Y, Z per watt of `s` transmitted with probability `t(λ)`, by the trapezoid rule on
/// 0.25 nm over 360-830 nm.
fn transmitted_xyz(s: &Spectrum, t: impl Fn(f64) -> f64) -> (Xyz, f64) {
    let o = observer();
    let (mut acc, mut power, mut total) = ([0.0; 3], 0.0, 0.0);
    for i in 0..=1880 {
        let nm = 360.0 + 0.25 * i as f64;
        let w = if i == 0 || i == 1880 { 0.5 } else { 1.0 } * s.at(nm);
        let tw = w * t(nm);
        acc[0] += tw * o.x_bar.at(nm);
        acc[1] += tw * o.y_bar.at(nm);
        acc[2] += tw * o.z_bar.at(nm);
        power += tw;
        total += w;
    }
    let xyz = Xyz {
        x: acc[0] / total,
        y: acc[1] / total,
        z: acc[2] / total,
    };
    (xyz, power / total)
}

fn assert_within(what: &str, got: f64, se: f64, want: f64, k: f64) {
    assert!(se > 0.0 && se.is_finite(), "{what}: stderr {se}");
    assert!(
        (got - want).abs() <= k * se,
        "{what}: {got} +- {se}, closed form {want} ({:.1} standard errors)",
        (got - want) / se
    );
}

const ABSORPTION: &str = "{ table = [[380, 1.5], [480, 0.6], [580, 0.2], [780, 0.05]] }";

fn absorption_at(nm: f64) -> f64 {
    let rows = [[380.0, 1.5], [480.0, 0.6], [580.0, 0.2], [780.0, 0.05]];
    Spectrum::from_rows(&rows)
        .unwrap()
        .at(nm.clamp(380.0, 780.0))
}

#[test]
fn an_absorbing_slab_colours_the_light_as_2_e3_says() {
    let run = slab_run("slab", "\"cie-led-b3\"", ABSORPTION, 400_000, 2);
    let s = CieIlluminant::LedB3.spectrum();
    let (xyz, transmitted) = transmitted_xyz(&s, |nm| two_e3(absorption_at(nm)));
    let uv = xyz.uv_prime().unwrap();
    let summary = run.summary();
    let c = summary.color.expect("a spectral run has a colour summary");
    assert_within("u'", c.u_prime.value, c.u_prime.stderr, uv.u, 3.0);
    assert_within("v'", c.v_prime.value, c.v_prime.stderr, uv.v, 3.0);
    let l = &run.tally.ledger;
    let (eff, eff_se) = l.detected.mean_and_stderr(l.photons);
    assert_within("transmitted power", eff, eff_se, transmitted, 3.0);
    // Y in lux: 683 lm/W times the transmitted ȳ-weighted power over the target's area.
    let lux = 683.0 * xyz.y / 0.16;
    assert_within(
        "illuminance",
        c.illuminance_lux.value,
        c.illuminance_lux.stderr,
        lux,
        3.0,
    );
    // The source's own colour is far from the transmitted one: the test can tell.
    let source = Xyz::of(&s).uv_prime().unwrap();
    assert!(source.delta(uv) > 20.0 * c.u_prime.stderr.hypot(c.v_prime.stderr));
    // Longer paths at grazing angles absorb more blue: v' grows with theta.
    let rows = &c.by_theta;
    assert!(rows[rows.len() - 2][3] > rows[0][3] + 3.0 * rows[0][4].hypot(rows[rows.len() - 2][4]));
}

#[test]
fn spectrally_flat_scenes_keep_the_sources_chromaticity() {
    for (name, illuminant) in [
        ("\"cie-led-b1\"", CieIlluminant::LedB1),
        ("\"ccfl-triphosphor\"", CieIlluminant::Fl11),
    ] {
        let run = slab_run("flat", name, "0.0", 100_000, 1);
        let want = Xyz::of(&illuminant.spectrum()).uv_prime().unwrap();
        let c = run.summary().color.unwrap();
        assert_within(name, c.u_prime.value, c.u_prime.stderr, want.u, 3.0);
        assert_within(name, c.v_prime.value, c.v_prime.stderr, want.v, 3.0);
    }
}

#[test]
fn colour_tallies_do_not_depend_on_threads_and_outputs_are_written() {
    let one = slab_run("threads1", "\"cie-led-b5\"", ABSORPTION, 20_000, 1);
    let two = slab_run("threads2", "\"cie-led-b5\"", ABSORPTION, 20_000, 2);
    assert!(one.tally.color.is_some());
    assert_eq!(one.tally, two.tally);
    assert_eq!(one.summary().color, two.summary().color);
    let out = support::temp_folder("color-out");
    let files = one.write(&out.path().join("run")).unwrap();
    let names: Vec<String> = files
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    for f in ["color.exr", "color.png", "delta_uv.png", "summary.json"] {
        assert!(names.iter().any(|n| n == f), "{f} missing from {names:?}");
    }
    let img = read_channels(&out.path().join("run/color.exr")).unwrap();
    let channel = |n: &str| {
        img.2
            .iter()
            .find(|(name, _)| name == n)
            .unwrap_or_else(|| panic!("no channel {n}"))
            .1
            .clone()
    };
    let (y, r) = (channel("Y"), channel("R"));
    assert_eq!(y.len(), 81);
    assert!(y.iter().sum::<f32>() > 0.0 && r.iter().any(|&v| v > 0.0));
    // u', v' per bin with their jackknife errors: finite and small where light fell.
    let (u, ue) = (channel("u_prime"), channel("stderr.u_prime"));
    let ve = channel("stderr.v_prime");
    let lit: Vec<usize> = (0..81).filter(|&i| y[i] > 0.0).collect();
    assert!(!lit.is_empty());
    for &i in &lit {
        assert!(u[i] > 0.0 && u[i] < 0.7, "u' {} in bin {i}", u[i]);
    }
    let mean = |e: &[f32]| lit.iter().map(|&i| e[i]).sum::<f32>() / lit.len() as f32;
    assert!(
        mean(&ue) > 0.0 && mean(&ue) < 0.05,
        "mean u' error {}",
        mean(&ue)
    );
    assert!(
        mean(&ve) > 0.0 && mean(&ve) < 0.05,
        "mean v' error {}",
        mean(&ve)
    );
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("run/summary.json")).unwrap())
            .unwrap();
    for key in [
        "x",
        "y",
        "u_prime",
        "v_prime",
        "cct_k",
        "delta_uv_13pt",
        "delta_uv_max",
    ] {
        assert!(json["color"][key]["stderr"].is_number(), "color.{key}");
    }
}

#[test]
fn monochrome_runs_have_no_colour() {
    let r = slab_run("mono", "", "0.1", 2_000, 1);
    assert!(r.tally.color.is_none());
    assert!(r.summary().color.is_none());
    let out = support::temp_folder("mono-out");
    let files = r.write(&out.path().join("run")).unwrap();
    assert!(!files.iter().any(|p| p.ends_with("color.exr")));
}

/// A source spectrum's scale is free: traced at 1e200, 1e306 or a subnormal 1e-310 times
/// the same table, the target's colour is the table's at 1 (the draws agree to ~1e-13 nm;
/// a scale at 1e200 drew every photon at the table's first row).
#[test]
fn a_spectrum_traces_the_same_colour_at_any_scale() {
    let table = |s: &str| {
        format!(
            "{{ table = [[380, 0.2{s}], [450, 1.0{s}], [470, 0.3{s}], [560, 0.7{s}], [780, 0.1{s}]] }}"
        )
    };
    let colour = |s: &str| {
        let c = slab_run("scale", &table(s), "0.0", 20_000, 1)
            .summary()
            .color
            .unwrap();
        (c.x.value, c.y.value)
    };
    let want = colour("");
    for s in ["e200", "e306", "e-310"] {
        let got = colour(s);
        assert!(
            (got.0 - want.0).abs() < 1e-10 && (got.1 - want.1).abs() < 1e-10,
            "scale 1{s}: x, y {got:?} against {want:?}"
        );
    }
}
