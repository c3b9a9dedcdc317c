//! Tests against published values. Where CIE 015:2018 publishes chromaticities computed by
//! summation at 5 nm, the 1 nm integral differs from them by up to ~1e-5 (colour-science's
//! own 1 nm computation gives the same differences), which sets the tolerances.

use super::*;

fn xy_of(illuminant: CieIlluminant) -> Xy {
    Xyz::of(&illuminant.spectrum()).xy().unwrap()
}

/// X, Y, Z by the CIE's summation at 5 nm over 380-780 nm, as CIE 15 computes its tables.
fn xy_summed_5nm(spd: &Spectrum) -> Xy {
    let o = observer();
    let sum = |cmf: &Spectrum| spd.sum_product(cmf, 380.0, 5.0, 780.0);
    let xyz = Xyz {
        x: sum(&o.x_bar),
        y: sum(&o.y_bar),
        z: sum(&o.z_bar),
    };
    xyz.xy().unwrap()
}

fn assert_near(what: &str, got: f64, want: f64, tolerance: f64) {
    assert!(
        (got - want).abs() <= tolerance,
        "{what}: {got} vs {want} ± {tolerance}"
    );
}

#[test]
fn d65_white_point_is_cie_15s_at_1nm_and_at_5nm() {
    // CIE 015:2018: D65 x = 0.31272, y = 0.32903 (summed at 5 nm). At 5 nm: half a unit of
    // the fifth decimal plus table rounding (1e-5); at 1 nm the integral is 0.312727, 0.329023.
    let summed = xy_summed_5nm(&CieIlluminant::D65.spectrum());
    assert_near("D65 x, 5 nm", summed.x, 0.31272, 5e-6);
    assert_near("D65 y, 5 nm", summed.y, 0.32903, 5e-6);
    let xy = xy_of(CieIlluminant::D65);
    assert_near("D65 x, 1 nm", xy.x, 0.31272, 1e-5);
    assert_near("D65 y, 1 nm", xy.y, 0.32903, 1e-5);
}

#[test]
fn d65_is_6504_k_just_above_the_planckian_locus() {
    // CIE 015:2018 gives D65's CCT as about 6504 K (6500 K × 1.4388/1.4380, the change of
    // c2). The minimum-distance CCT on the 1 nm tables is 6502.7 K (colour-science's Ohno
    // 2013 gives 6502.68 K, a brute-force golden-section search 6502.71 K); Δuv +0.0032.
    let d65 = Xyz::of(&CieIlluminant::D65.spectrum()).uv_prime().unwrap();
    let c = cct(d65).unwrap();
    assert_near("D65 CCT vs CIE", c.kelvin, 6504.0, 2.0);
    assert_near("D65 CCT vs colour-science", c.kelvin, 6502.7, 0.1);
    assert_near("D65 Δuv", c.delta_uv, 0.0032, 1e-4);
}

#[test]
fn illuminant_a_is_cie_15s_chromaticity_and_2856_k() {
    // CIE 015:2018: A x = 0.44757, y = 0.40745 (5 nm); the 1 nm integral is 0.447574,
    // 0.407439. CCT 2856 K = 2848 K × 1.4388/1.435 (2855.54 K computed).
    let summed = xy_summed_5nm(&illuminant_a());
    assert_near("A x, 5 nm", summed.x, 0.44757, 1e-5);
    assert_near("A y, 5 nm", summed.y, 0.40745, 1e-5);
    let xy = xy_of(CieIlluminant::A);
    assert_near("A x, 1 nm", xy.x, 0.44757, 1.5e-5);
    assert_near("A y, 1 nm", xy.y, 0.40745, 1.5e-5);
    assert_near("A CCT", cct(xy.uv_prime()).unwrap().kelvin, 2856.0, 1.0);
    assert_near("A at 560 nm", illuminant_a().at(560.0), 100.0, 1e-12);
}

#[test]
fn the_cie_led_illuminants_have_cie_15s_chromaticities() {
    // CIE 015:2018 Table 10 (4 decimals, as colour-science's chromaticity_coordinates.py
    // transcribes it); tolerance one unit of the fourth decimal (the 1 nm integral differs
    // from the published values by up to 6e-5).
    let published = [
        (CieIlluminant::LedB1, 0.4560, 0.4078),
        (CieIlluminant::LedB2, 0.4357, 0.4012),
        (CieIlluminant::LedB3, 0.3756, 0.3723),
        (CieIlluminant::LedB4, 0.3422, 0.3502),
        (CieIlluminant::LedB5, 0.3118, 0.3236),
        (CieIlluminant::LedBh1, 0.4474, 0.4066),
        (CieIlluminant::LedRgb1, 0.4557, 0.4211),
        (CieIlluminant::LedV1, 0.4548, 0.4044),
        (CieIlluminant::LedV2, 0.3781, 0.3775),
    ];
    for (illuminant, x, y) in published {
        let xy = xy_of(illuminant);
        assert_near(illuminant.name(), xy.x, x, 1e-4);
        assert_near(illuminant.name(), xy.y, y, 1e-4);
        assert_eq!(
            CieIlluminant::from_name(illuminant.name()),
            Some(illuminant)
        );
    }
}

#[test]
fn fl11_the_tri_phosphor_lamp_has_cie_15s_chromaticity() {
    // CIE 015:2018 Table 10.3: FL11 x = 0.3805, y = 0.3769 (5 nm summation, as published).
    let xy = xy_summed_5nm(&CieIlluminant::Fl11.spectrum());
    assert_near("cie-fl11", xy.x, 0.3805, 1e-4);
    assert_near("cie-fl11", xy.y, 0.3769, 1e-4);
    assert_eq!(
        CieIlluminant::from_name("cie-fl11"),
        Some(CieIlluminant::Fl11)
    );
}

#[test]
fn equal_energy_is_at_one_third() {
    // The CMFs' integrals are equal to 4e-4 relative (106.8655, 106.8569, 106.8923), so
    // illuminant E lands within 5e-5 of 1/3 (0.333314, 0.333288); a swapped or wrong column
    // would move it by far more than 1e-4.
    let e = Spectrum::from_rows(&[[360.0, 1.0], [830.0, 1.0]]).unwrap();
    let xy = Xyz::of(&e).xy().unwrap();
    assert_near("E x", xy.x, 1.0 / 3.0, 1e-4);
    assert_near("E y", xy.y, 1.0 / 3.0, 1e-4);
}

#[test]
fn blackbodies_lie_on_the_locus_at_their_temperature() {
    // The search on the locus recovers the temperature to its 0.001 K bracket (tolerance
    // 0.01 K) and Δuv = 0 to rounding, across 2000-20000 K.
    for kelvin in [2000.0, 2856.0, 4000.0, 6500.0, 10_000.0, 20_000.0] {
        let uv = Xyz::of(&Spectrum::blackbody(kelvin)).uv_prime().unwrap();
        let c = cct(uv).unwrap();
        assert_near("blackbody CCT", c.kelvin, kelvin, 0.01);
        assert_near("blackbody Δuv", c.delta_uv, 0.0, 1e-7);
    }
}

#[test]
fn blackbody_radiance_is_plancks_law() {
    // The Stefan-Boltzmann check is out of the 360-830 nm range; instead Wien's peak: at
    // 5000 K the spectral radiance peaks at 2.8978e6 nm·K / 5000 K = 579.6 nm (Wien's
    // displacement constant b = 2.897771955e-3 m·K, CODATA 2018), so the 1 nm table's
    // maximum is at 579 or 580 nm; and L(500 nm, 5000 K) = 2hc²/λ⁵/(e^(c2/λT) − 1).
    let bb = Spectrum::blackbody(5000.0);
    let peak = bb.rows().max_by(|a, b| a[1].total_cmp(&b[1])).unwrap()[0];
    assert!((579.0..=580.0).contains(&peak), "peak at {peak} nm");
    let expected = 2.0 * 6.626_070_15e-34 * 299_792_458.0_f64.powi(2)
        / (500e-9_f64).powi(5)
        / (1.4388e7_f64 / (500.0 * 5000.0)).exp_m1()
        * 1e-9;
    assert_near("L(500 nm)", bb.at(500.0), expected, expected * 1e-12);
    assert!(
        expected > 1.0e4 && expected < 1.3e4,
        "{expected} W/(m² sr nm)"
    );
}

#[test]
fn monochromatic_555_nm_light_has_683_lm_per_w() {
    // ȳ(555 nm) = 1.0000 in the CIE table, so K_m ȳ(555) = 683 lm/W; a 0.2 nm wide triangle
    // averages ȳ over ±0.1 nm, a change below 1e-5 of it.
    assert_eq!(super::cie_cmf::Y_BAR[555 - 360], 1.0);
    let line = Spectrum::from_rows(&[[554.9, 0.0], [555.0, 1.0], [555.1, 0.0]]).unwrap();
    assert_near(
        "K(555 nm)",
        luminous_efficacy(&line).unwrap(),
        683.0,
        683.0 * 1e-5,
    );
    let watt = line.scaled(1.0 / line.integral());
    assert_near(
        "lm of 1 W at 555 nm",
        Xyz::photometric(&watt).y,
        683.0,
        683.0 * 1e-5,
    );
}

#[test]
fn y_bar_integrates_to_the_published_sum() {
    // Σ ȳ Δλ = 106.857 at 1 nm (106.856917) and at 5 nm (106.857039): CIE 015:2018's
    // normalising sums for the 2-degree observer; 1e-3 is the fourth significant figure.
    let y_bar = &observer().y_bar;
    let one = Spectrum::from_rows(&[[360.0, 1.0], [830.0, 1.0]]).unwrap();
    assert_near(
        "∫ȳ, 1 nm",
        y_bar.sum_product(&one, 360.0, 1.0, 830.0),
        106.857,
        1e-3,
    );
    assert_near(
        "∫ȳ, 5 nm",
        y_bar.sum_product(&one, 360.0, 5.0, 830.0),
        106.857,
        1e-3,
    );
    assert_near("∫ȳ exact", y_bar.integral(), 106.857, 1e-3);
}

#[test]
fn uv_prime_and_delta_follow_cie_1976() {
    // D65 (0.31272, 0.32903): u' = 4x/(−2x+12y+3) = 0.19783, v' = 9y/(…) = 0.46834
    // (CIE 015:2018 §8.1); the same from X, Y, Z; and Δu'v' is the Euclidean distance.
    let uv = Xy {
        x: 0.31272,
        y: 0.32903,
    }
    .uv_prime();
    assert_near("u'", uv.u, 0.19783, 1e-5);
    assert_near("v'", uv.v, 0.46834, 1e-5);
    let xyz = Xyz::relative(&CieIlluminant::D65.spectrum()).unwrap();
    assert_near("Y", xyz.y, 100.0, 1e-12);
    let from_xyz = xyz.uv_prime().unwrap();
    let from_xy = xyz.xy().unwrap().uv_prime();
    assert_near("u' both ways", from_xyz.u, from_xy.u, 1e-14);
    assert_near("v' both ways", from_xyz.v, from_xy.v, 1e-14);
    let other = UvPrime {
        u: uv.u + 0.003,
        v: uv.v - 0.004,
    };
    assert_near("Δu'v'", uv.delta(other), 0.005, 1e-15);
    assert_near("1960 v", uv.uv_1960()[1], uv.v * 2.0 / 3.0, 0.0);
}

#[test]
fn spectra_interpolate_linearly_and_are_zero_outside() {
    let s = Spectrum::from_rows(&[[400.0, 1.0], [500.0, 3.0], [600.0, 0.0]]).unwrap();
    assert_eq!(s.at(450.0), 2.0);
    assert_eq!(s.at(500.0), 3.0);
    assert_eq!(s.at(400.0), 1.0);
    assert_eq!(s.at(600.0), 0.0);
    assert_eq!(s.at(399.9), 0.0);
    assert_eq!(s.at(650.0), 0.0);
    assert_eq!(s.integral(), 100.0 * 2.0 + 100.0 * 1.5);
}

#[test]
fn the_product_integral_is_exact_for_linear_tables() {
    // ∫₀¹ λ·λ dλ = 1/3 (a trapezoid would give 1/2), and tables with different knots
    // integrate only over their overlap: ∫ from 0.5 to 1 of λ·1 = 3/8.
    let ramp = Spectrum::from_rows(&[[1.0, 0.0], [2.0, 1.0]]).unwrap();
    assert_near("∫λ²", ramp.integrate_product(&ramp), 1.0 / 3.0, 1e-15);
    let flat = Spectrum::from_rows(&[[1.5, 1.0], [1.7, 1.0], [3.0, 1.0]]).unwrap();
    assert_near("overlap", ramp.integrate_product(&flat), 0.375, 1e-15);
    let apart = Spectrum::from_rows(&[[5.0, 1.0], [6.0, 1.0]]).unwrap();
    assert_eq!(ramp.integrate_product(&apart), 0.0);
}

#[test]
fn bad_tables_are_refused_with_the_row_named() {
    let message = |rows: &[[f64; 2]]| Spectrum::from_rows(rows).unwrap_err().to_string();
    assert!(message(&[[400.0, 1.0]]).contains("at least two rows"));
    assert!(message(&[[400.0, 1.0], [400.0, 2.0]]).contains("row 2: wavelengths must increase"));
    assert!(message(&[[500.0, 1.0], [400.0, 2.0]]).contains("400 nm follows 500 nm"));
    assert!(message(&[[400.0, 1.0], [f64::NAN, 2.0]]).contains("row 2: wavelength NaN"));
    assert!(message(&[[400.0, -1.0], [500.0, 2.0]]).contains("row 1 (400 nm): value -1"));
    assert!(message(&[[400.0, 1.0], [500.0, f64::INFINITY]]).contains("not a finite"));
    assert!(message(&[[0.0, 1.0], [500.0, 1.0]]).contains("positive"));
}

/// Efficacy and relative tristimulus values are ratios: a spectrum at 1e306 (whose
/// integral overflows) or a subnormal 1e-310 gives those of the same spectrum at 1.
#[test]
fn ratios_of_a_spectrum_do_not_depend_on_its_scale() {
    let d65 = CieIlluminant::D65.spectrum();
    let peak = d65.rows().map(|r| r[1]).fold(0.0, f64::max);
    let unit = d65.normalized().unwrap();
    assert_eq!(unit.rows().map(|r| r[1]).fold(0.0, f64::max), 1.0);
    let lm_w = luminous_efficacy(&unit).unwrap();
    let xyz = Xyz::relative(&unit).unwrap();
    for scale in [1e306, 1e-310] {
        let rows: Vec<[f64; 2]> = d65.rows().map(|[nm, v]| [nm, v / peak * scale]).collect();
        let s = Spectrum::from_rows(&rows).unwrap();
        assert_near(
            "efficacy",
            luminous_efficacy(&s).unwrap(),
            lm_w,
            1e-12 * lm_w,
        );
        let got = Xyz::relative(&s).unwrap();
        assert_near("X", got.x, xyz.x, 1e-10);
        assert_near("Z", got.z, xyz.z, 1e-10);
    }
    let dark = Spectrum::from_rows(&[[400.0, 0.0], [500.0, 0.0]]).unwrap();
    assert!(dark.normalized().is_none() && luminous_efficacy(&dark).is_none());
}
