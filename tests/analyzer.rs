//! `[detector] analyzer_deg`: an ideal absorbing polarizer in front of the target (the
//! panel's rear polarizer) weights every detection by the power it passes of the photon's
//! state. Malus's law through a polarized source, half of unpolarized light, and the s and
//! p transmittances of the 60-degree slab apart; each fails without the analyzer's factor.

mod support;

use blutrace::run::RunResult;
use support::{assert_balanced, load, trace, write_scene};

/// A detector at z = -3, counting light going down (-z), its frame u = x, v = -y.
const DOWN: &str = "[detector]\norigin = [-300.0, 300.0, -3.0]\nu = [1.0, 0.0, 0.0]\n\
                    v = [0.0, -1.0, 0.0]\nsize_mm = [600.0, 600.0]\nbins = [2, 2]\n";

/// A beam going straight down from z = 5 in state `state` (a source's `polarization = `
/// line, or none) onto the target with an analyzer at `analyzer_deg`; a Lambertian chip
/// lies beyond the target, out of the beam's way.
fn beam(state: &str, analyzer_deg: f64, photons: u64) -> RunResult {
    let obj = support::box_obj([-1.0, -1.0, -11.0], [1.0, 1.0, -10.0], ["chip"; 6]);
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"chip.obj\"\n\
         [surfaces.chip]\nmodel = \"lambert\"\nalbedo = 0.5\n\
         [[sources]]\ntype = \"rayfile\"\nfile = \"beam.rays\"\nbody = \"transparent\"\n{state}\n\
         {DOWN}analyzer_deg = {analyzer_deg}\n"
    );
    let files = [
        ("chip.obj", obj.as_str()),
        ("beam.rays", "0 0 5  0 0 -1  1.0\n"),
    ];
    let scene = load(&write_scene("analyzer-beam", &toml, &files));
    trace(&scene, photons, 3, 2)
}

fn efficiency(r: &RunResult) -> (f64, f64) {
    let s = r.summary();
    (s.extraction_efficiency, s.extraction_efficiency_stderr)
}

/// Malus: light polarized along u through an analyzer at theta passes `cos^2 theta`
/// (every photon the same weight: exact), leaves polarized along the analyzer's axis,
/// and the ledger books the rest to the analyzer.
#[test]
fn an_analyzer_passes_malus_law_of_a_polarized_source() {
    for theta in [0.0, 30.0, 60.0, 90.0] {
        let r = beam("polarization = { linear_deg = 0.0 }", theta, 2_000);
        let (t, _) = efficiency(&r);
        let want = f64::to_radians(theta).cos().powi(2);
        assert!((t - want).abs() < 1e-9, "{theta}: {t}, want {want}");
        let s = r.summary();
        assert!(
            (s.ledger.absorbed_by_analyzer_w - (1.0 - want)).abs() < 1e-9,
            "{theta}: {:?}",
            s.ledger
        );
        assert_balanced(&r);
        if theta < 90.0 {
            // The analyzer's axis is at theta from u towards v in the detector's frame.
            let p = s.polarization.expect("an analyzer traces polarization");
            let two = 2.0 * f64::to_radians(theta);
            assert!((p.s1.value - two.cos()).abs() < 1e-9, "{theta}: {p:?}");
            assert!((p.s2.value - two.sin()).abs() < 1e-9, "{theta}: {p:?}");
        }
    }
}

/// Unpolarized light passes half of any analyzer, without a polarizer or polarized
/// source in the scene (the analyzer alone turns polarization on).
#[test]
fn an_analyzer_passes_half_of_unpolarized_light() {
    for theta in [0.0, 37.0, 90.0] {
        let r = beam("", theta, 2_000);
        let (t, _) = efficiency(&r);
        assert!((t - 0.5).abs() < 1e-9, "{theta}: {t}");
        assert_balanced(&r);
    }
}

/// The 60-degree slab (1 mm PMMA, n 1.49, the beam in the x-z plane) under an analyzer:
/// along u = x (made perpendicular to the beam: the p direction) it passes half of
/// `Tp = (1 - Rp)/(1 + Rp)`, across it (y: the s direction) half of `Ts`.
#[test]
fn an_analyzer_over_the_sixty_degree_slab_separates_s_and_p() {
    let (n, cos_i) = (1.49f64, 0.5f64);
    let sin_i = (1.0 - cos_i * cos_i).sqrt();
    let cos_t = (1.0 - (sin_i / n).powi(2)).sqrt();
    let rs = ((cos_i - n * cos_t) / (cos_i + n * cos_t)).powi(2);
    let rp = ((n * cos_i - cos_t) / (n * cos_i + cos_t)).powi(2);
    let slab = |r: f64| (1.0 - r) / (1.0 + r);
    let rays = format!("0 0 5  {sin_i} 0 {}  1.0\n", -cos_i);
    let obj = support::box_obj([-250.0, -250.0, -0.5], [250.0, 250.0, 0.5], ["slab"; 6]);
    let files = [("slab.obj", obj.as_str()), ("beam.rays", rays.as_str())];
    for (theta, want) in [(0.0, 0.5 * slab(rp)), (90.0, 0.5 * slab(rs))] {
        let toml = format!(
            "version = 1\n[[geometry]]\nfile = \"slab.obj\"\n[media.pmma]\nn = 1.49\n\
             [surfaces.slab]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
             [[sources]]\ntype = \"rayfile\"\nfile = \"beam.rays\"\nbody = \"transparent\"\n\
             {DOWN}analyzer_deg = {theta}\n"
        );
        let scene = load(&write_scene("analyzer-slab", &toml, &files));
        let r = trace(&scene, 100_000, 3, 2);
        let (t, se) = efficiency(&r);
        assert!(
            (t - want).abs() < 4.0 * se + 1e-4,
            "analyzer {theta}: {t} ± {se}, want {want}"
        );
        assert_balanced(&r);
    }
}

/// A TM-25 ray file's Stokes columns (4.7.2.6) give each ray's photons their state:
/// a ray going down polarized at 30 degrees from its axis x passes `cos^2 30` of an
/// analyzer along x; one polarized along its axis y (given at length 2) nothing of it and
/// all of one along y; a circular one half. Every photon of a one-ray file is the same:
/// the efficiencies are exact.
#[test]
fn a_tm25_files_stokes_columns_polarize_its_rays() {
    use blutrace::sources::rayfile::{FileSpectrum, FluxUnit, RaySet, RayStokes, check_ray, tm25};
    let obj = support::box_obj([-1.0, -1.0, -11.0], [1.0, 1.0, -10.0], ["chip"; 6]);
    let (s60, c60) = (60f32.to_radians().sin(), 60f32.to_radians().cos());
    let cases = [
        ([c60, s60, 0.0], [1.0, 0.0, 0.0], 0.0, 0.75),
        ([1.0, 0.0, 0.0], [0.0, 2.0, 0.0], 0.0, 0.0),
        ([1.0, 0.0, 0.0], [0.0, 2.0, 0.0], 90.0, 1.0),
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], 0.0, 0.5),
    ];
    for (s, axis, analyzer, want) in cases {
        let set = RaySet {
            text: Default::default(),
            rays: vec![check_ray([0.0, 0.0, 5.0], [0.0, 0.0, -1.0], 0.25, None).unwrap()],
            nm: Vec::new(),
            table: Vec::new(),
            stokes: vec![RayStokes { s, axis }],
            spectrum: FileSpectrum::None,
            unit: FluxUnit::Watt,
            header_flux: [f64::NAN; 2],
        };
        let toml = format!(
            "version = 1\n[[geometry]]\nfile = \"chip.obj\"\n\
             [surfaces.chip]\nmodel = \"lambert\"\nalbedo = 0.5\n\
             [[sources]]\ntype = \"rayfile\"\nfile = \"beam.TM25RAY\"\nbody = \"transparent\"\n\
             {DOWN}analyzer_deg = {analyzer}\n"
        );
        let dir = write_scene("analyzer-tm25", &toml, &[("chip.obj", obj.as_str())]);
        let folder = dir.parent().unwrap();
        tm25::write(&folder.join("beam.TM25RAY"), &set).unwrap();
        let r = trace(&load(&dir), 1_000, 3, 2);
        let (t, _) = efficiency(&r);
        assert!(
            (t - want).abs() < 1e-6,
            "Stokes {s:?} about {axis:?}, analyzer {analyzer}: {t}, want {want}"
        );
    }
}

/// The bundled `bef-stack-dbef` and the same scene without its reflective polarizer sheet
/// (dropping `dbef.obj`: the absorbing rear polarizer alone), traced with `photons` each:
/// the sheet's gain and its standard error.
fn dbef_gain(photons: u64) -> (f64, f64) {
    let folder = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bef-stack-dbef");
    let with = load(&folder.join("scene.toml"));
    let text = std::fs::read_to_string(folder.join("scene.toml")).unwrap();
    let sheet = "\n[[geometry]]\nfile = \"dbef.obj\"\n";
    assert!(text.contains(sheet));
    let files: Vec<(&str, String)> = ["bef-stack.obj", "bef-films.obj", "bef-stack.mtl"]
        .into_iter()
        .map(|f| (f, std::fs::read_to_string(folder.join(f)).unwrap()))
        .collect();
    let files: Vec<(&str, &str)> = files.iter().map(|(f, t)| (*f, t.as_str())).collect();
    let without = load(&write_scene("no-dbef", &text.replace(sheet, ""), &files));
    assert!(without.detector.analyzer.is_some());
    let (a, sa) = efficiency(&trace(&with, photons, 1, 2));
    let (b, sb) = efficiency(&trace(&without, photons, 2, 2));
    let gain = a / b;
    let se = gain * ((sa / a).powi(2) + (sb / b).powi(2)).sqrt();
    println!(
        "bef-stack-dbef: with DBEF {a:.4} ± {sa:.4}, rear polarizer alone {b:.4} ± {sb:.4}: gain {gain:.3} ± {se:.3}"
    );
    (gain, se)
}

/// The reflective polarizer recycles the state the rear polarizer absorbs: its gain is
/// above 1 by many standard errors and within the range published for DBEF-like films
/// (1.3x-1.6x; 1.2-1.8 here, the sheet's values being assumed).
#[test]
fn a_dbef_sheet_brightens_bef_stack_under_its_rear_polarizer() {
    let (gain, se) = dbef_gain(30_000);
    assert!(gain > 1.0 + 5.0 * se, "gain {gain} ± {se}");
    assert!((1.2..1.8).contains(&gain), "gain {gain} ± {se}");
}

/// The README's figure: bef-stack-dbef's gain at the scene's 200000 photons.
#[test]
#[ignore = "slow: the full-size bef-stack-dbef gain of the README"]
fn dbef_gain_full_size() {
    let (gain, se) = dbef_gain(200_000);
    assert!(gain > 1.0 + 5.0 * se && (1.2..1.8).contains(&gain));
}
