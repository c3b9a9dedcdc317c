use super::*;
use std::path::Path;

fn ctx() -> Ctx<'static> {
    Ctx(Path::new("scene.toml"))
}

fn parse(text: &str) -> std::result::Result<SpectralValue, String> {
    #[derive(Deserialize)]
    struct Doc {
        v: SpectralValue,
    }
    toml::from_str::<Doc>(&format!("v = {text}"))
        .map(|d| d.v)
        .map_err(|e| e.to_string())
}

fn build(text: &str, range: Range) -> std::result::Result<Spectral, String> {
    parse(text)?
        .build(&ctx(), "media.pmma.n", range)
        .map_err(|e| e.to_string())
}

#[test]
fn a_constant_reads_the_same_for_every_light() {
    let n = Spectral::constant(1.49);
    assert_eq!(n.at(Light::MONOCHROME), 1.49);
    assert_eq!(n.at(Light::at_nm(400.0)), 1.49);
    assert_eq!(n.nominal(), 1.49);
    assert_eq!(Light::MONOCHROME.detected(0.25), 0.25);
    assert_eq!(Light::MONOCHROME.nm(), MONOCHROME_NM);
}

#[test]
fn a_table_is_linear_between_rows_and_holds_its_ends() {
    let a = build("{ table = [[400, 0.2], [500, 0.6]] }", Range::Fraction).unwrap();
    assert!(a.is_spectral());
    let at = |nm| a.at(Light::at_nm(nm));
    assert!((at(450.0) - 0.4).abs() < 1e-12);
    assert!((at(425.5) - 0.302).abs() < 1e-12);
    assert_eq!(at(380.0), 0.2);
    assert_eq!(at(300.0), 0.2);
    assert_eq!(at(700.0), 0.6);
    assert_eq!(at(2000.0), 0.6);
    assert_eq!(a.range(), (0.2, 0.6));
}

#[test]
fn sellmeier_pmma_matches_the_published_index() {
    // Sultanova et al. (2009), PMMA: n(589.3 nm) = 1.4905 from their one-term fit.
    let n = build(
        "{ sellmeier = { b = [1.1819], c_um2 = [0.011313] } }",
        Range::Index,
    )
    .unwrap();
    let l2 = 0.5893f64.powi(2);
    let exact = (1.0 + 1.1819 * l2 / (l2 - 0.011313)).sqrt();
    assert!((n.at(Light::at_nm(589.3)) - exact).abs() < 1e-6);
    assert!((exact - 1.4905).abs() < 2e-4);
    assert!(n.at(Light::at_nm(450.0)) > n.at(Light::at_nm(650.0)));
}

#[test]
fn cauchy_is_a_polynomial_in_the_inverse_square_wavelength() {
    let n = build("{ cauchy = [1.5, 0.004] }", Range::Index).unwrap();
    assert!((n.at(Light::at_nm(500.0)) - (1.5 + 0.004 / 0.25)).abs() < 1e-12);
}

#[test]
fn bad_values_name_the_field_and_what_is_wrong() {
    let e = build("{ table = [[400, 0.2], [500, 1.2]] }", Range::Fraction).unwrap_err();
    assert!(
        e.contains("scene.toml: media.pmma.n") && e.contains("within [0, 1]"),
        "{e}"
    );
    let e = build("{ table = [[500, 0.2], [400, 0.3]] }", Range::Fraction).unwrap_err();
    assert!(e.contains("increase strictly"), "{e}");
    let e = build("{ cauchy = [1.5] }", Range::Fraction).unwrap_err();
    assert!(e.contains("dispersion formulas"), "{e}");
    let e = build("-0.9", Range::Index).unwrap_err();
    assert!(e.contains("must be > 0"), "{e}");
    let e = build(
        "{ sellmeier = { b = [1.0], c_um2 = [0.25] } }",
        Range::Index,
    )
    .unwrap_err();
    assert!(e.contains("resonance"), "{e}");
    let e = parse("{ tabel = [[400, 0.2]] }").unwrap_err();
    assert!(e.contains("unknown key 'tabel'"), "{e}");
    let e = parse("\"white\"").unwrap_err();
    assert!(e.contains("expected a number"), "{e}");
    let e = parse("{ table = 3 }").unwrap_err();
    assert!(e.contains("table"), "{e}");
}

#[test]
fn a_number_round_trips_as_a_number() {
    let v = parse("0.5").unwrap();
    assert_eq!(v, SpectralValue::Constant(0.5));
    assert_eq!(serde_json::to_string(&v).unwrap(), "0.5");
}

/// Huge values are written short, in reports and in errors (not as 301 digits), and a
/// precision given to the formatter still holds for a constant.
#[test]
fn huge_values_print_short() {
    let n = build("{ cauchy = [1e300] }", Range::Index).unwrap();
    assert_eq!(n.to_string(), "1e300..1e300 over 360-830 nm");
    assert_eq!(Spectral::constant(1e300).to_string(), "1e300");
    assert_eq!(Spectral::constant(1.49).to_string(), "1.49");
    assert_eq!(format!("{:.3}", Spectral::constant(1.49)), "1.490");
    let e = build("{ cauchy = [-1e300] }", Range::Index).unwrap_err();
    assert!(
        e.contains("media.pmma.n: must be positive") && e.contains("ranges -1e300..-1e300"),
        "{e}"
    );
}
