//! Materials over wavelength against closed forms and published values: dispersion
//! through a PMMA prism (Snell's law with the Sellmeier index, per wavelength), the Mie
//! tabulation of a spectral scene (the direct Mie sum, Bohren & Huffman's worked example
//! and the Rayleigh limit at each wavelength), Beer-Lambert with an absorption table,
//! a narrow-band source against a monochrome run, and the material library
//! (`materials/`) against the paper its dispersion comes from.

mod support;

use blutrace::optics::medium::Medium;
use blutrace::optics::mie;
use blutrace::optics::spectrum::{Light, Spectral};
use blutrace::optics::surface::Estimator;
use blutrace::run::RunResult;
use blutrace::scene::Scene;
use blutrace::tally::Ledger;
use num_complex::Complex64;
use std::f64::consts::PI;
use support::*;

/// PMMA's Sellmeier index (Sultanova, Kasarova & Nikolov 2009), computed here
/// independently of the loader: n² = 1 + 1.1819 λ²/(λ² − 0.011313), λ in µm.
fn pmma_n(nm: f64) -> f64 {
    let l2 = (nm * 1e-3).powi(2);
    (1.0 + 1.1819 * l2 / (l2 - 0.011313)).sqrt()
}

const PMMA_SELLMEIER: &str = "{ sellmeier = { b = [1.1819], c_um2 = [0.011313] } }";

/// A source spectrum 1 nm wide centred on `nm`.
fn narrow_band(nm: f64) -> String {
    format!(
        "spectrum = {{ table = [[{}, 1.0], [{}, 1.0]] }}",
        nm - 0.5,
        nm + 0.5
    )
}

/// A collimated beam: a 1 um LED at `center` facing `normal`, transparent to light
/// coming back, with `extra` lines (its spectrum).
fn beam(center: [f64; 3], normal: [f64; 3], u: [f64; 3], extra: &str) -> String {
    format!(
        "[[sources]]\ntype = \"led\"\ncenter = {center:?}\nnormal = {normal:?}\nu = {u:?}\n\
         width_mm = 1e-3\nheight_mm = 1e-3\npower_w = 1.0\ncos_exponent = 1e9\n\
         body = \"transparent\"\n{extra}\n"
    )
}

/// Picks a power out of a ledger.
type Pick<'a> = &'a dyn Fn(&Ledger) -> f64;

fn medium_named<'a>(scene: &'a Scene, name: &str) -> &'a Medium {
    scene.media.iter().find(|m| m.name == name).unwrap()
}

// ---------------------------------------------------------------------------------
// Dispersion: a PMMA prism

/// Prism height (z) and apex geometry: the beam enters the x = 0 face at normal
/// incidence and meets the slanted face at 30 degrees inside.
const PRISM_H: f64 = 20.0;
const PRISM_APEX_DEG: f64 = 30.0;
/// The detector plane x (mm), its z range and bins along z.
const SCREEN_X: f64 = 200.0;
const SCREEN_Z: (f64, f64) = (-100.0, 20.0);
const SCREEN_BINS: usize = 2400;
/// The beam's height.
const BEAM_Z: f64 = 10.0;

/// A right prism, cross-section (x, z) = (0, 0), (L, 0), (0, H) with L = H tan 30°,
/// extruded over y in [-20, 20], faces wound outward.
fn prism_obj() -> String {
    let l = PRISM_H * PRISM_APEX_DEG.to_radians().tan();
    let h = PRISM_H;
    format!(
        "v 0 -20 0\nv {l} -20 0\nv 0 -20 {h}\nv 0 20 0\nv {l} 20 0\nv 0 20 {h}\n\
         usemtl prism\nf 1 2 3\nf 4 6 5\nf 1 3 6\nf 1 6 4\nf 1 4 5\nf 1 5 2\nf 2 5 6\nf 2 6 3\n"
    )
}

/// The prism lit by a narrow band at `nm`; the detector is a screen at x = 200 facing
/// the prism, 0.05 mm bins along z.
fn prism_scene(nm: f64, n: &str) -> SceneDir {
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"prism.obj\"\n[media.pmma]\nn = {n}\n\
         [surfaces.prism]\nmodel = \"dielectric\"\ninside = \"pmma\"\n{}\
         [detector]\norigin = [{SCREEN_X}, -20.0, {}]\nu = [0.0, 1.0, 0.0]\nv = [0.0, 0.0, 1.0]\n\
         size_mm = [40.0, {}]\nbins = [1, {SCREEN_BINS}]\n",
        beam(
            [-5.0, 0.0, BEAM_Z],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            &narrow_band(nm)
        ),
        SCREEN_Z.0,
        SCREEN_Z.1 - SCREEN_Z.0,
    );
    write_scene(
        &format!("prism-{nm}"),
        &toml,
        &[("prism.obj", &prism_obj())],
    )
}

/// The deviation (degrees, below the x axis) of the brightest spot on the screen, seen
/// from where the beam leaves the slanted face.
fn traced_deviation_deg(r: &RunResult) -> f64 {
    let bins = &r.tally.flux.bins;
    let (iy, _) = bins
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.sum.value().total_cmp(&b.1.sum.value()))
        .unwrap();
    let dz = (SCREEN_Z.1 - SCREEN_Z.0) / SCREEN_BINS as f64;
    let z_hit = SCREEN_Z.0 + (iy as f64 + 0.5) * dz;
    let l = PRISM_H * PRISM_APEX_DEG.to_radians().tan();
    let x_exit = l * (1.0 - BEAM_Z / PRISM_H);
    (BEAM_Z - z_hit).atan2(SCREEN_X - x_exit).to_degrees()
}

/// Snell's law at the slanted face: n sin 30° = sin(theta_t), deviation theta_t − 30°.
fn snell_deviation_deg(n: f64) -> f64 {
    let a = PRISM_APEX_DEG.to_radians();
    ((n * a.sin()).asin() - a).to_degrees()
}

#[test]
fn a_pmma_prism_disperses_blue_and_red_as_snell_and_sellmeier_say() {
    // One screen bin (0.05 mm at about 195 mm) is 0.015 degrees; 450 and 650 nm part by
    // 0.43 degrees (n 1.4981 against 1.4887).
    let mut seen = Vec::new();
    for nm in [450.0, 650.0] {
        let dir = prism_scene(nm, PMMA_SELLMEIER);
        let r = trace_balanced(&load(&dir), 4000, 11, Estimator::Analog);
        let (got, want) = (traced_deviation_deg(&r), snell_deviation_deg(pmma_n(nm)));
        eprintln!("{nm} nm: traced {got:.4} deg, Snell {want:.4} deg");
        assert!(
            (got - want).abs() < 0.02,
            "{nm} nm: traced deviation {got:.4} deg, Snell with n = {:.5}: {want:.4} deg",
            pmma_n(nm)
        );
        seen.push(got);
    }
    assert!(
        seen[0] - seen[1] > 0.4,
        "blue must bend more than red: {seen:?}"
    );
}

// ---------------------------------------------------------------------------------
// Mie over wavelength

/// A 1 mm slab of medium `slab` (lines `medium`) in air, lit from above by a collimated
/// beam with source lines `source` (its spectrum, or nothing for a monochrome scene);
/// the detector just below catches what goes through.
fn slab(name: &str, medium: &str, source: &str) -> SceneDir {
    let obj = box_obj(
        [-100.0, -100.0, -1.0],
        [100.0, 100.0, 0.0],
        ["side", "side", "side", "side", "bottom", "top"],
    );
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"slab.obj\"\n[media.slab]\n{medium}\n\
         [media.beside]\nn = 1.0\nabsorption_per_mm = 1e9\n\
         [surfaces.top]\nmodel = \"dielectric\"\ninside = \"slab\"\n\
         [surfaces.bottom]\nmodel = \"dielectric\"\ninside = \"slab\"\n\
         [surfaces.side]\nmodel = \"dielectric\"\ninside = \"slab\"\noutside = \"beside\"\n{}\
         [detector]\norigin = [-1000.0, 1000.0, -1.001]\nu = [1.0, 0.0, 0.0]\nv = [0.0, -1.0, 0.0]\n\
         size_mm = [2000.0, 2000.0]\nbins = [1, 1]\n[trace]\nmax_bounces = 100000\n",
        beam([0.0, 0.0, 0.05], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0], source)
    );
    write_scene(name, &toml, &[("slab.obj", &obj)])
}

#[test]
fn the_mie_tables_are_the_mie_sum_at_each_wavelength() {
    // Silicone-like spheres whose index falls with wavelength, in Sellmeier PMMA: at
    // each tabulation node the medium holds the direct Mie evaluation with both indices
    // read there; between nodes it is within the linear interpolation's error.
    let n_p = |nm: f64| 1.43 + (1.41 - 1.43) * (nm - 400.0) / 300.0;
    let medium = format!(
        "n = {PMMA_SELLMEIER}\nparticles = {{ radius_um = 1.0, n = {{ table = [[400, 1.43], [700, 1.41]] }}, volume_fraction = 0.01 }}"
    );
    let dir = slab("mie-tables", &medium, &narrow_band(550.0));
    let scene = load(&dir);
    let s = &medium_named(&scene, "slab").scattering;
    assert!(s.per_mm.is_spectral() && s.anisotropy.is_spectral());
    for (nm, tol) in [
        (400.0, 1e-9),
        (450.0, 1e-9),
        (555.0, 1e-9),
        (700.0, 1e-9),
        (523.0, 2e-3),
    ] {
        let l = Light::at_nm(nm);
        let b = mie::bulk(1.0, n_p(nm), 0.0, 0.01, nm, pmma_n(nm));
        let (mu_s, g) = (s.per_mm.at(l), s.anisotropy.at(l));
        assert!(
            (mu_s / b.scattering_per_mm - 1.0).abs() < tol && (g - b.anisotropy).abs() < tol,
            "{nm} nm: table mu_s {mu_s}, g {g}; Mie {} and {}",
            b.scattering_per_mm,
            b.anisotropy
        );
    }
    // Blue scatters more than red off 1 um spheres of small contrast (x from 11 to 26).
    assert!(s.per_mm.at(Light::at_nm(450.0)) > s.per_mm.at(Light::at_nm(650.0)));
    assert!(
        scene.warnings.iter().all(|w| !w.contains("wavelength_nm")),
        "{:?}",
        scene.warnings
    );
}

#[test]
fn bohren_huffmans_worked_example_holds_at_every_wavelength_it_is_scaled_to() {
    // B&H appendix A: m = 1.55, x = 2 pi 0.525 / 0.6328: Q_sca = 3.10543, g = 0.63314.
    // A sphere of radius 0.525 nm / 632.8 um in a medium of n = 1 has that x at
    // wavelength nm: mu_s = 3 f Q / (4 r) there.
    for nm in [400.0, 550.0, 700.0] {
        let r = 0.525 * nm / 632.8;
        let medium = format!(
            "n = 1.0\nparticles = {{ radius_um = {r}, n = 1.55, volume_fraction = 0.001 }}"
        );
        let dir = slab("bhmie", &medium, &narrow_band(550.0));
        let scene = load(&dir);
        let s = &medium_named(&scene, "slab").scattering;
        let l = Light::at_nm(nm);
        let want = 3.0 * 0.001 * 3.10543 / (4.0 * r * 1e-3);
        let (mu_s, g) = (s.per_mm.at(l), s.anisotropy.at(l));
        assert!(
            (mu_s / want - 1.0).abs() < 5e-6 && (g - 0.63314).abs() < 5e-6,
            "{nm} nm: mu_s {mu_s} (B&H {want}), g {g} (B&H 0.63314)"
        );
    }
}

/// Rayleigh's small-sphere limit: Q_sca = 8/3 x⁴ |L|², Q_abs = 4 x Im L, with
/// L = (m² − 1)/(m² + 2).
fn rayleigh(m: Complex64, x: f64) -> (f64, f64) {
    let l = (m * m - 1.0) / (m * m + 2.0);
    (8.0 / 3.0 * x.powi(4) * l.norm_sqr(), 4.0 * x * l.im)
}

#[test]
fn small_absorbing_spheres_follow_rayleigh_at_each_wavelength() {
    // 1 nm spheres (x about 0.02) whose k falls tenfold from 400 to 700 nm, in
    // dispersive PMMA: mu_s and the particles' absorption at each wavelength are
    // Rayleigh's with m = (n_p + i k_p(lambda)) / n_host(lambda).
    let (r, f) = (0.001, 0.01);
    let k_p = |nm: f64| 0.1 + (0.01 - 0.1) * (nm - 400.0) / 300.0;
    let medium = format!(
        "n = {PMMA_SELLMEIER}\nparticles = {{ radius_um = {r}, n = 2.0, k = {{ table = [[400, 0.1], [700, 0.01]] }}, volume_fraction = {f} }}"
    );
    let dir = slab("rayleigh", &medium, &narrow_band(550.0));
    let scene = load(&dir);
    let m = medium_named(&scene, "slab");
    for nm in [400.0, 500.0, 600.0, 700.0] {
        let n_host = pmma_n(nm);
        let x = 2.0 * PI * r * 1e3 * n_host / nm;
        let (q_sca, q_abs) = rayleigh(Complex64::new(2.0, k_p(nm)) / n_host, x);
        let per_q = 3.0 * f / (4.0 * r * 1e-3);
        let l = Light::at_nm(nm);
        let (mu_s, mu_a) = (m.scattering.per_mm.at(l), m.absorption(l));
        eprintln!(
            "{nm} nm: mu_s {mu_s:.4e} (Rayleigh {:.4e}), mu_a {mu_a:.4e} (Rayleigh {:.4e})",
            per_q * q_sca,
            per_q * q_abs
        );
        assert!(
            (mu_s / (per_q * q_sca) - 1.0).abs() < 3e-3,
            "{nm} nm: mu_s {mu_s}"
        );
        assert!(
            (mu_a / (per_q * q_abs) - 1.0).abs() < 3e-3,
            "{nm} nm: mu_a {mu_a}"
        );
    }
}

#[test]
fn monochrome_particles_stay_one_evaluation_at_their_wavelength() {
    // No source spectrum: the coefficients are constants, the Mie sum at wavelength_nm
    // with every index read there (bit for bit what the monochrome tracer used).
    let medium = format!(
        "n = {PMMA_SELLMEIER}\nparticles = {{ radius_um = 1.0, n = 1.42, volume_fraction = 0.01, wavelength_nm = 480.0 }}"
    );
    let dir = slab("mono-mie", &medium, "");
    let scene = load(&dir);
    let s = &medium_named(&scene, "slab").scattering;
    let host = medium_named(&scene, "slab").index(Light::at_nm(480.0));
    let b = mie::bulk(1.0, 1.42, 0.0, 0.01, 480.0, host);
    assert_eq!(s.per_mm, Spectral::constant(b.scattering_per_mm));
    assert_eq!(s.anisotropy, Spectral::constant(b.anisotropy));
    // The same medium in a spectral scene: tabulated, and the unused wavelength_nm is
    // named in a warning.
    let dir = slab("spectral-mie", &medium, &narrow_band(480.0));
    let scene = load(&dir);
    assert!(medium_named(&scene, "slab").scattering.per_mm.is_spectral());
    assert_warns(
        &scene,
        "media.slab.particles.wavelength_nm = 480 is not used",
    );
}

#[test]
fn bad_spectral_particle_input_names_the_field() {
    for (particles, want) in [
        (
            "{ radius_um = 1.0, n = { table = [[400, 1.4], [700, 0.0]] }, volume_fraction = 0.01 }",
            "media.slab.particles.n: must be positive at every wavelength",
        ),
        (
            "{ radius_um = 1.0, n = 1.4, k = { table = [[400, -0.1], [700, 0.0]] }, volume_fraction = 0.01 }",
            "media.slab.particles.k: row 1 (400 nm): value -0.1 is not",
        ),
        (
            "{ radius_um = 1.0, n = 1.4, k = { cauchy = [0.1] }, volume_fraction = 0.01 }",
            "media.slab.particles.k: cauchy and sellmeier are dispersion formulas",
        ),
        (
            "{ radius_um = 1200.0, n = 1.4, volume_fraction = 0.01 }",
            "at 360 nm) is beyond 2e4",
        ),
    ] {
        let medium = format!("n = 1.49\nparticles = {particles}");
        let dir = slab("bad-particles", &medium, &narrow_band(550.0));
        let e = format!("{:#}", Scene::load(&dir).expect_err(particles));
        assert!(
            e.contains("scene.toml") && e.contains(want),
            "{particles}: {e}"
        );
    }
}

// ---------------------------------------------------------------------------------
// Beer-Lambert with an absorption table

#[test]
fn an_absorption_table_attenuates_each_wavelength_as_beer_lambert_says() {
    // An index-matched 1 mm slab (no Fresnel), a = 2.0, 1.0, 0.25 /mm at 400, 550,
    // 700 nm, linear between; the weighted estimator carries exp(-a t) exactly, so a
    // narrow band within a linear stretch transmits exp(-a(lambda)) up to the spread of a
    // over its 1 nm (2e-6 relative).
    let medium = "n = 1.0\nabsorption_per_mm = { table = [[400, 2.0], [550, 1.0], [700, 0.25]] }";
    for (nm, a) in [
        (410.0, 2.0 - 10.0 / 150.0),
        (475.0, 1.5),
        (620.0, 0.65),
        (690.0, 0.3_f64),
    ] {
        let dir = slab("beer", medium, &narrow_band(nm));
        let r = trace_balanced(&load(&dir), 2000, 5, Estimator::Weighted);
        let (t, _) = ledger_fraction(&r, &|l| l.detected.sum.value());
        let want = (-a).exp();
        assert!(
            (t / want - 1.0).abs() < 1e-4,
            "{nm} nm: transmitted {t}, Beer-Lambert exp(-{a}) = {want}"
        );
    }
}

#[test]
fn a_broad_spectrum_transmits_the_mean_of_beer_lambert_over_it() {
    // A flat source over 400-700 nm through the same slab: T = mean over lambda of
    // exp(-a(lambda)), a closed form of the piecewise-linear a; the analog estimator
    // (absorbed or not) within 3 standard errors.
    let medium = "n = 1.0\nabsorption_per_mm = { table = [[400, 2.0], [550, 1.0], [700, 0.25]] }";
    let source = "spectrum = { table = [[400, 1.0], [700, 1.0]] }";
    let dir = slab("beer-broad", medium, source);
    let r = trace_balanced(&load(&dir), 200_000, 9, Estimator::Analog);
    let (t, err) = ledger_fraction(&r, &|l| l.detected.sum.value());
    // The mean of exp(-a) over a segment where a goes linearly from a0 to a1.
    let seg = |a0: f64, a1: f64| ((-a1).exp() - (-a0).exp()) / (a0 - a1);
    let want = 0.5 * seg(2.0, 1.0) + 0.5 * seg(1.0, 0.25);
    eprintln!("broad: {t:.5} ± {err:.1e}, closed form {want:.5}");
    assert!((t - want).abs() < 3.0 * err, "{t} ± {err} against {want}");
    // Not what a wavelength-blind tracer would give (a at 555 nm for every photon).
    assert!(((-0.975_f64).exp() - want).abs() > 10.0 * err);
}

// ---------------------------------------------------------------------------------
// A narrow band reproduces a monochrome run

/// A bead-filled, absorbing, dispersive slab: spectral (tables) or monochrome
/// (constants equal to the tables' values at `nm`, the particles evaluated there).
fn bead_slab_medium(spectral: bool, nm: f64) -> String {
    // The absorption table [[530, 0.1], [570, 0.5]] at nm (held beyond its rows).
    let a = 0.1 + 0.4 * ((nm - 530.0) / 40.0).clamp(0.0, 1.0);
    let (n, absorption, wl) = if spectral {
        (
            PMMA_SELLMEIER.to_string(),
            "{ table = [[530, 0.1], [570, 0.5]] }".to_string(),
            String::new(),
        )
    } else {
        (
            format!("{:.17}", pmma_n(nm)),
            format!("{a}"),
            format!(", wavelength_nm = {nm}"),
        )
    };
    format!(
        "n = {n}\nabsorption_per_mm = {absorption}\n\
         particles = {{ radius_um = 0.3, n = 1.6, volume_fraction = 0.01{wl} }}"
    )
}

#[test]
fn a_narrow_band_reproduces_the_monochrome_run_at_its_wavelength() {
    // Reflection and transmission of the slab lit at nm ± 0.5 against the monochrome
    // slab whose constants are the tables at nm (its particles evaluated there), within
    // 3 standard errors of the difference. Read at 555 nm instead (the monochrome
    // wavelength): at 550 the absorption would be 0.35 /mm, not 0.3; at 450, 0.35, not
    // 0.1, and mu_s and g those of 555 nm: many sigma away.
    for nm in [550.0, 450.0] {
        narrow_band_against_monochrome(nm);
    }
}

fn narrow_band_against_monochrome(nm: f64) {
    let photons = 100_000;
    let spectral = slab("narrow", &bead_slab_medium(true, nm), &narrow_band(nm));
    let mono = slab("mono", &bead_slab_medium(false, nm), "");
    let (rs, rm) = (
        trace_balanced(&load(&spectral), photons, 21, Estimator::Analog),
        trace_balanced(&load(&mono), photons, 22, Estimator::Analog),
    );
    let ledgers: [(&str, Pick); 2] = [
        ("reflected", &|l: &Ledger| l.escaped.value()),
        ("transmitted", &|l: &Ledger| l.detected.sum.value()),
    ];
    for (what, f) in ledgers {
        let ((a, ea), (b, eb)) = (ledger_fraction(&rs, f), ledger_fraction(&rm, f));
        let z = (a - b) / (ea * ea + eb * eb).sqrt();
        eprintln!(
            "{nm} nm, {what}: narrow band {a:.5} ± {ea:.1e}, monochrome {b:.5} ± {eb:.1e} ({z:.1} sigma)"
        );
        assert!(
            z.abs() < 3.0,
            "{nm} nm, {what}: {a} ± {ea} against {b} ± {eb}"
        );
    }
}

// ---------------------------------------------------------------------------------
// The material library

/// The snippet `materials/NAME`.
fn snippet(name: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("materials")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The spectral slab scene with its medium replaced by snippet `file`'s medium `header`.
fn slab_with_snippet(file: &str, header: &str) -> SceneDir {
    let text = snippet(file).replace(header, "[media.slab]");
    let dir = slab(file, "n = 1.0", &narrow_band(550.0));
    let scene = std::fs::read_to_string(&*dir)
        .unwrap()
        .replace("[media.slab]\nn = 1.0\n", &format!("{text}\n"));
    std::fs::write(&*dir, scene).unwrap();
    dir
}

#[test]
fn the_pmma_snippet_matches_sultanovas_measured_indices_and_its_sources() {
    // The snippet's medium replaces the slab's; the dispersion must agree with the
    // paper's measured indices (quoted to 0.001), the absorption with the fibre data
    // scaled to 1.97e-4 /mm over 400-700 nm.
    for (file, mean_400_700) in [
        ("pmma-lgp.toml", -(1.0_f64 - 0.005).ln() / 25.4),
        ("pmma-fibre-grade.toml", f64::NAN),
    ] {
        let dir = slab_with_snippet(file, "[media.pmma]");
        let scene = load(&dir);
        let m = medium_named(&scene, "slab");
        for (nm, measured) in [
            (436.8, 1.502),
            (486.1, 1.497),
            (587.6, 1.491),
            (632.8, 1.489),
        ] {
            let n = m.index(Light::at_nm(nm));
            assert!(
                (n - measured).abs() < 1e-3,
                "{file}: n({nm}) = {n}, paper {measured}"
            );
        }
        let mean = (400..=700)
            .map(|nm| m.absorption(Light::at_nm(nm as f64)))
            .sum::<f64>()
            / 301.0;
        if mean_400_700.is_finite() {
            assert!(
                (mean / mean_400_700 - 1.0).abs() < 0.01,
                "{file}: mean {mean}"
            );
        } else {
            // Fibre grade: 0.08 dB/m at 500 nm.
            let a = m.absorption(Light::at_nm(500.0));
            let want = 0.08 * 10f64.ln() / 10.0 / 1000.0;
            assert!((a / want - 1.0).abs() < 0.01, "{file}: a(500) = {a}");
        }
        // Blue is absorbed more than green, the 623 nm C-H overtone more than both.
        let at = |nm: f64| m.absorption(Light::at_nm(nm));
        assert!(at(400.0) > at(500.0) && at(623.0) > at(400.0), "{file}");
    }
}

#[test]
fn the_pc_bead_snippet_disperses_as_sultanova_measured_and_tabulates_its_beads() {
    let dir = slab_with_snippet("pc-bead-diffuser.toml", "[media.pc]");
    let scene = load(&dir);
    let m = medium_named(&scene, "slab");
    for (nm, measured) in [
        (436.8, 1.612),
        (486.1, 1.599),
        (587.6, 1.585),
        (632.8, 1.580),
    ] {
        let n = m.index(Light::at_nm(nm));
        assert!(
            (n - measured).abs() < 1e-3,
            "n({nm}) = {n}, paper {measured}"
        );
    }
    assert!(m.scattering.per_mm.is_spectral());
    let mu_s = |nm: f64| m.scattering.per_mm.at(Light::at_nm(nm));
    // The bundled direct-lit plate's beads: about 20 /mm at 550 nm.
    assert!((15.0..25.0).contains(&mu_s(550.0)), "{}", mu_s(550.0));
}
