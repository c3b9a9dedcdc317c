use super::*;
use crate::color::observer;

fn ctx() -> Ctx<'static> {
    Ctx(Path::new("scene.toml"))
}

fn spec(text: &str) -> std::result::Result<SpectrumSpec, String> {
    #[derive(Deserialize)]
    struct Doc {
        spectrum: SpectrumSpec,
    }
    toml::from_str::<Doc>(&format!("spectrum = {text}"))
        .map(|d| d.spectrum)
        .map_err(|e| e.to_string())
}

fn build(text: &str) -> std::result::Result<EmissionSpectrum, String> {
    spec(text)?
        .build(&ctx(), "sources[0].spectrum")
        .map_err(|e| e.to_string())
}

/// The sampler inverts the cumulative integral: drawn wavelengths fall in 5 nm bins as
/// often as the spectrum's integral over each bin says (chi-square over 94 bins, 1e6
/// draws of a stratified uniform, so the statistic is far below its 0.999 quantile
/// only when the inversion is right).
#[test]
fn drawn_wavelengths_follow_the_spectrum() {
    let s = CieIlluminant::LedB3.spectrum();
    let e = EmissionSpectrum::new(&s).unwrap();
    let n = 1_000_000;
    let mut counts = vec![0u64; 94];
    for k in 0..n {
        let nm = e.sample((k as f64 + 0.5) / n as f64);
        counts[((nm - 360.0) / 5.0).min(93.0) as usize] += 1;
    }
    let total = s.integral();
    let mut chi2 = 0.0;
    for (b, &c) in counts.iter().enumerate() {
        let lo = 360.0 + 5.0 * b as f64;
        let box_ = Spectrum::from_rows(&[[lo, 1.0], [lo + 5.0, 1.0]]).unwrap();
        let want = s.integrate_product(&box_) / total * n as f64;
        if want > 0.0 {
            chi2 += (c as f64 - want).powi(2) / want.max(1.0);
        } else {
            assert_eq!(c, 0, "bin {lo} nm has no power");
        }
    }
    assert!(
        chi2 < 1.0,
        "stratified draws should match closely: chi2 {chi2}"
    );
}

#[test]
fn a_linear_ramp_inverts_in_closed_form() {
    // S = nm - 400 on [400, 500]: CDF = (x-400)^2 / 100^2, so x = 400 + 100 sqrt(u).
    let e = build("{ table = [[400, 0], [500, 100]] }").unwrap();
    for u in [0.0, 0.01, 0.25, 0.5, 0.81, 0.999] {
        assert!(
            (e.sample(u) - (400.0 + 100.0 * f64::sqrt(u))).abs() < 1e-9,
            "{u}"
        );
    }
}

#[test]
fn efficacy_and_colour_follow_from_the_spectrum() {
    let e = build("\"cie-led-b5\"").unwrap();
    let s = CieIlluminant::LedB5.spectrum();
    let want = 683.0 * s.integrate_product(&observer().y_bar) / s.integral();
    assert!((e.efficacy_lm_per_w() - want).abs() < 1e-9 * want);
    let xy = e.xyz_per_w().xy().unwrap();
    assert!((xy.x - 0.3118).abs() < 1e-4 && (xy.y - 0.3236).abs() < 1e-4);
    let tri = build("\"ccfl-triphosphor\"").unwrap();
    assert_eq!(tri, build("\"cie-fl11\"").unwrap());
}

#[test]
fn the_observer_reads_the_same_fast_and_slow() {
    let o = observer();
    for nm in [359.0, 360.0, 360.5, 555.0, 612.3, 829.9, 830.0, 831.0] {
        let [x, y, z] = cmf_at(nm);
        assert!((x - o.x_bar.at(nm)).abs() < 1e-15, "{nm}");
        assert!((y - o.y_bar.at(nm)).abs() < 1e-15, "{nm}");
        assert!((z - o.z_bar.at(nm)).abs() < 1e-15, "{nm}");
    }
}

#[test]
fn a_blackbody_keeps_its_visible_part() {
    let e = build("{ blackbody_k = 6500 }").unwrap();
    assert_eq!(e.range_nm(), VISIBLE_NM);
    let xy = e.xyz_per_w().xy().unwrap();
    // The Planckian locus at 6500 K: x 0.3135, y 0.3236 (CIE 015:2018 locus, c2 1.4388e-2).
    assert!(
        (xy.x - 0.3135).abs() < 5e-4 && (xy.y - 0.3236).abs() < 5e-4,
        "{xy:?}"
    );
}

#[test]
fn spectrum_files_read_with_a_header_and_comments() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(
        dir.path().join("led.csv"),
        "nm,relative\n# measured\n450, 1.0\n550 0.5\n650,0.25\n",
    )
    .unwrap();
    let c = Ctx(&scene);
    let s = spec("{ file = \"led.csv\" }").unwrap();
    assert_eq!(s.file(), Some(Path::new("led.csv")));
    let e = s.build(&c, "sources[0].spectrum").unwrap();
    assert_eq!(e.range_nm(), (450.0, 650.0));
    std::fs::write(dir.path().join("led.csv"), "450, 1.0\n550, x\n").unwrap();
    let err = s.build(&c, "sources[0].spectrum").unwrap_err().to_string();
    assert!(
        err.contains("led.csv line 2") && err.contains("sources[0].spectrum"),
        "{err}"
    );
}

/// A spectrum file is read as every input is: a FIFO or a link to /dev/zero is refused
/// at once, naming the field and the file (not a read that blocks or fills memory).
#[test]
fn spectrum_files_must_be_regular_files() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    let c = Ctx(&scene);
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("zero.csv")).unwrap();
    let fifo = dir.path().join("fifo.csv");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.unwrap().success());
    for name in ["zero.csv", "fifo.csv"] {
        let s = spec(&format!("{{ file = \"{name}\" }}")).unwrap();
        let e = format!("{:#}", s.build(&c, "sources[2].spectrum").unwrap_err());
        assert!(
            e.contains("scene.toml: sources[2].spectrum")
                && e.contains(name)
                && e.contains("cannot read spectrum file: not a regular file"),
            "{e}"
        );
    }
}

#[test]
fn bad_spectra_are_named() {
    let e = build("\"cie-led-b9\"").unwrap_err();
    assert!(
        e.contains("unknown spectrum 'cie-led-b9'") && e.contains("cie-led-b5"),
        "{e}"
    );
    let e = build("{ table = [[900, 1], [1000, 1]] }").unwrap_err();
    assert!(e.contains("no power within 360-830 nm"), "{e}");
    let e = build("{ blackbody_k = -5 }").unwrap_err();
    assert!(e.contains("blackbody_k"), "{e}");
    let e = spec("{ tabel = [] }").unwrap_err();
    assert!(e.contains("unknown key 'tabel'"), "{e}");
    let e = build("{ file = \"missing.csv\" }").unwrap_err();
    assert!(e.contains("cannot read"), "{e}");
}

#[test]
fn a_mixture_weighs_its_parts_colour_and_table_by_their_weights() {
    let part = |rows: &[[f64; 2]]| EmissionSpectrum::new(&Spectrum::from_rows(rows).unwrap());
    let blue = part(&[[440.0, 0.0], [460.0, 1.0], [480.0, 0.0]]).unwrap();
    // Steps up at 500 nm and down at 600 nm.
    let yellow = part(&[[500.0, 1.0], [600.0, 1.0]]).unwrap();
    let mix = EmissionSpectrum::mixture(&[(3.0, &blue), (1.0, &yellow), (0.0, &blue)]).unwrap();
    let want = 0.75 * blue.efficacy_lm_per_w() + 0.25 * yellow.efficacy_lm_per_w();
    assert!((mix.efficacy_lm_per_w() - want).abs() < 1e-12 * want);
    assert_eq!(mix.range_nm(), (440.0, 600.0));
    // Its table: three quarters of the power below 490 nm, the rest flat over 500-600 nm.
    let n = 10_000;
    let draws: Vec<f64> = (0..n)
        .map(|k| mix.sample((k as f64 + 0.5) / n as f64))
        .collect();
    assert_eq!(draws.iter().filter(|&&w| w < 490.0).count(), 7500);
    let above_550 = draws.iter().filter(|&&w| w > 550.0).count();
    assert!((1249..=1251).contains(&above_550), "{above_550}");
    assert!(EmissionSpectrum::mixture(&[(0.0, &blue)]).is_none());
}

/// A spectrum's absolute scale says nothing of its colour or its photons' wavelengths:
/// the same table at 1e200, 1e306, 1e-200 and a subnormal 1e-310 gives the colour and the
/// draws of the table at 1 (products of values and squares of values would overflow or
/// lose their digits at those scales).
#[test]
fn a_spectrum_scale_changes_neither_colour_nor_wavelengths() {
    let rows: Vec<[f64; 2]> = CieIlluminant::LedB3
        .spectrum()
        .rows()
        .map(|[nm, v]| [nm, v / 2.0])
        .collect();
    let at = |scale: f64| {
        let scaled: Vec<[f64; 2]> = rows.iter().map(|&[nm, v]| [nm, v * scale]).collect();
        let e = EmissionSpectrum::new(&Spectrum::from_rows(&scaled).unwrap()).unwrap();
        let xy = e.xyz_per_w().xy().unwrap();
        let draws: Vec<f64> = (0..1000)
            .map(|k| e.sample((k as f64 + 0.5) / 1000.0))
            .collect();
        (xy, e.efficacy_lm_per_w(), draws)
    };
    let (xy, lm_w, draws) = at(1.0);
    for scale in [1e200, 1e306, 1e-200, 1e-310] {
        let (xy_s, lm_w_s, draws_s) = at(scale);
        assert!(
            (xy_s.x - xy.x).abs() < 1e-12 && (xy_s.y - xy.y).abs() < 1e-12,
            "scale {scale:e}: {xy_s:?} against {xy:?}"
        );
        assert!(
            (lm_w_s - lm_w).abs() < 1e-12 * lm_w,
            "scale {scale:e}: {lm_w_s} lm/W"
        );
        for (a, b) in draws.iter().zip(&draws_s) {
            assert!(
                (a - b).abs() < 1e-12 * a,
                "scale {scale:e}: drew {b} nm, not {a}"
            );
        }
    }
}

/// A spectrum file's scale is as free as a table's: the file at 1e306 (whose integral
/// overflows) or a subnormal 1e-310 times the values gives the same colour.
#[test]
fn a_spectrum_file_scale_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    let c = Ctx(&scene);
    let s = spec("{ file = \"led.csv\" }").unwrap();
    let colour = |scale: f64| {
        let text: String = (400..=700)
            .step_by(10)
            .map(|nm| format!("{nm}, {:e}\n", (1.0 + (nm as f64 / 37.0).sin()) * scale))
            .collect();
        std::fs::write(dir.path().join("led.csv"), text).unwrap();
        s.build(&c, "sources[0].spectrum")
            .unwrap()
            .xyz_per_w()
            .xy()
            .unwrap()
    };
    let xy = colour(1.0);
    for scale in [1e306, 1e-300, 1e-310] {
        let xy_s = colour(scale);
        assert!(
            (xy_s.x - xy.x).abs() < 1e-12 && (xy_s.y - xy.y).abs() < 1e-12,
            "scale {scale:e}: {xy_s:?} against {xy:?}"
        );
    }
}

/// A mixture's weights count by their ratios: weights whose sum overflows mix as the same
/// weights at a small scale.
#[test]
fn a_mixture_of_huge_weights_is_the_mixture_of_their_ratios() {
    let part = |rows: &[[f64; 2]]| EmissionSpectrum::new(&Spectrum::from_rows(rows).unwrap());
    let blue = part(&[[440.0, 0.0], [460.0, 1.0], [480.0, 0.0]]).unwrap();
    let yellow = part(&[[500.0, 1.0], [600.0, 1.0]]).unwrap();
    let small = EmissionSpectrum::mixture(&[(3.0, &blue), (1.0, &yellow)]).unwrap();
    let huge = EmissionSpectrum::mixture(&[(1.5e308, &blue), (0.5e308, &yellow)]).unwrap();
    assert_eq!(huge, small);
}
