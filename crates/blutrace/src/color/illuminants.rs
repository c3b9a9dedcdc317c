//! The CIE illuminants as [`Spectrum`]s: D65 and the LED series tabulated, A computed.

use super::cie_d65::{D65, D65_FIRST_NM, D65_STEP_NM};
use super::cie_led_b::{LED_B1, LED_B2, LED_B3, LED_B4, LED_B5, LED_FIRST_NM, LED_STEP_NM};
use super::cie_led_other::{LED_BH1, LED_RGB1, LED_V1, LED_V2};
use super::spectrum::Spectrum;

/// The second radiation constant of CIE standard illuminant A, in nm·K: CIE 015:2018 defines A
/// with c2 = 1.435e-2 m·K (the value of 1931), not today's 1.4388e-2, which is why its
/// correlated colour temperature is 2856 K rather than its 2848 K.
const A_C2_NM_K: f64 = 1.435e7;
/// The temperature in illuminant A's formula, in K.
const A_KELVIN: f64 = 2848.0;

/// A CIE illuminant, by the name scene files will give it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CieIlluminant {
    /// CIE standard illuminant D65 (daylight, 300-830 nm at 1 nm).
    D65,
    /// CIE standard illuminant A (incandescent, computed 300-830 nm at 1 nm).
    A,
    /// CIE 015:2018 LED-B1: phosphor-converted white LED, 2700 K.
    LedB1,
    /// LED-B2: phosphor-converted white LED, 3000 K.
    LedB2,
    /// LED-B3: phosphor-converted white LED, 4000 K.
    LedB3,
    /// LED-B4: phosphor-converted white LED, 5000 K.
    LedB4,
    /// LED-B5: phosphor-converted white LED, 6500 K.
    LedB5,
    /// LED-BH1: hybrid of phosphor-converted and red LEDs, 2800 K.
    LedBh1,
    /// LED-RGB1: mixture of red, green and blue LEDs, 2800 K.
    LedRgb1,
    /// LED-V1: violet-pumped phosphor LED, 2700 K.
    LedV1,
    /// LED-V2: violet-pumped phosphor LED, 2700 K.
    LedV2,
    /// FL11: narrow-band tri-phosphor fluorescent lamp, 4000 K (CIE 015:2018 Table 10.1,
    /// 380-780 nm at 5 nm).
    Fl11,
}

impl CieIlluminant {
    /// Every illuminant, in the order of this enum.
    pub const ALL: [CieIlluminant; 12] = [
        CieIlluminant::D65,
        CieIlluminant::A,
        CieIlluminant::LedB1,
        CieIlluminant::LedB2,
        CieIlluminant::LedB3,
        CieIlluminant::LedB4,
        CieIlluminant::LedB5,
        CieIlluminant::LedBh1,
        CieIlluminant::LedRgb1,
        CieIlluminant::LedV1,
        CieIlluminant::LedV2,
        CieIlluminant::Fl11,
    ];

    /// The name: `"cie-d65"`, `"cie-a"`, `"cie-led-b1"` ... `"cie-led-v2"`.
    pub fn name(self) -> &'static str {
        match self {
            CieIlluminant::D65 => "cie-d65",
            CieIlluminant::A => "cie-a",
            CieIlluminant::LedB1 => "cie-led-b1",
            CieIlluminant::LedB2 => "cie-led-b2",
            CieIlluminant::LedB3 => "cie-led-b3",
            CieIlluminant::LedB4 => "cie-led-b4",
            CieIlluminant::LedB5 => "cie-led-b5",
            CieIlluminant::LedBh1 => "cie-led-bh1",
            CieIlluminant::LedRgb1 => "cie-led-rgb1",
            CieIlluminant::LedV1 => "cie-led-v1",
            CieIlluminant::LedV2 => "cie-led-v2",
            CieIlluminant::Fl11 => "cie-fl11",
        }
    }

    /// The illuminant called `name` (see [`CieIlluminant::name`]).
    pub fn from_name(name: &str) -> Option<CieIlluminant> {
        CieIlluminant::ALL.into_iter().find(|i| i.name() == name)
    }

    /// Its relative spectral power distribution (D65 and A: 100 at 560 nm; the LEDs as the
    /// CIE tabulates them).
    pub fn spectrum(self) -> Spectrum {
        let led = |values: &[f64]| uniform(LED_FIRST_NM, LED_STEP_NM, values);
        match self {
            CieIlluminant::D65 => uniform(D65_FIRST_NM, D65_STEP_NM, &D65),
            CieIlluminant::A => illuminant_a(),
            CieIlluminant::LedB1 => led(&LED_B1),
            CieIlluminant::LedB2 => led(&LED_B2),
            CieIlluminant::LedB3 => led(&LED_B3),
            CieIlluminant::LedB4 => led(&LED_B4),
            CieIlluminant::LedB5 => led(&LED_B5),
            CieIlluminant::LedBh1 => led(&LED_BH1),
            CieIlluminant::LedRgb1 => led(&LED_RGB1),
            CieIlluminant::LedV1 => led(&LED_V1),
            CieIlluminant::LedV2 => led(&LED_V2),
            CieIlluminant::Fl11 => uniform(380.0, 5.0, &FL11),
        }
    }
}

/// CIE illuminant FL11 (CIE 015:2018 Table 10.1, the values of CIE 15.2-1986 Table 1.5), at
/// 5 nm from 380 to 780 nm: a tri-band lamp of the rare-earth phosphors backlight CCFLs use
/// (Eu³⁺ red near 611 nm, Tb³⁺ green near 544 nm, Eu²⁺ blue) with the mercury lines.
#[rustfmt::skip]
const FL11: [f64; 81] = [
    0.91, 0.63, 0.46, 0.37, 1.29, 12.68, 1.59, 1.79, 2.46, 3.33,
    4.49, 33.94, 12.13, 6.95, 7.19, 7.12, 6.72, 6.13, 5.46, 4.79,
    5.66, 14.29, 14.96, 8.97, 4.72, 2.33, 1.47, 1.10, 0.89, 0.83,
    1.18, 4.90, 39.59, 72.84, 32.61, 7.52, 2.83, 1.96, 1.67, 4.43,
    11.28, 14.76, 12.73, 9.74, 7.33, 9.72, 55.27, 42.58, 13.18, 13.16,
    12.26, 5.11, 2.07, 2.34, 3.58, 3.01, 2.48, 2.14, 1.54, 1.33,
    1.46, 1.94, 2.00, 1.20, 1.35, 4.10, 5.58, 2.51, 0.57, 0.27,
    0.23, 0.21, 0.24, 0.24, 0.20, 0.24, 0.32, 0.26, 0.16, 0.12,
    0.09,
];

fn uniform(first_nm: f64, step_nm: f64, values: &[f64]) -> Spectrum {
    Spectrum::uniform(first_nm, step_nm, values).expect("the CIE tables are valid")
}

/// CIE standard illuminant A at every 1 nm from 300 to 830 nm, by CIE 015:2018's formula
/// S_A(λ) = 100 (560/λ)⁵ (exp(c2/(2848·560)) − 1) / (exp(c2/(2848 λ)) − 1), λ in nm,
/// c2 = 1.435e7 nm·K.
pub fn illuminant_a() -> Spectrum {
    let s = |nm: f64| {
        100.0 * (560.0 / nm).powi(5) * (A_C2_NM_K / (A_KELVIN * 560.0)).exp_m1()
            / (A_C2_NM_K / (A_KELVIN * nm)).exp_m1()
    };
    let values: Vec<f64> = (300..=830).map(|nm| s(f64::from(nm))).collect();
    uniform(300.0, 1.0, &values)
}
