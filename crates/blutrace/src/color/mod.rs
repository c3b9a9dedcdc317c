//! Colorimetry: CIE tables, tabulated spectra and the colour of light (the tracer's home of
//! wavelength is [`crate::optics::spectrum`]; sources draw from these spectra in
//! [`crate::sources::spectrum`], the detector scores X, Y, Z in [`crate::tally::color`]).
//!
//! Conventions, as colour-science (`colour.colorimetry`) and CIE 015:2018 (Colorimetry, 4th
//! ed., DOI 10.25039/TR.015.2018) have them:
//! - **Observer**: the CIE 1931 2-degree standard observer, x̄ ȳ z̄ at 1 nm from 360 to 830 nm
//!   ([`cie_cmf`]); ȳ is the photopic luminous efficiency V(λ).
//! - **Spectra** ([`Spectrum`]): rows `[nm, value]`, wavelengths in air, linear between rows
//!   and zero outside. Integrals are exact integrals of the product of the linear
//!   interpolants on the union of both tables' knots ([`Spectrum::integrate_product`]); the
//!   CIE's summation at a fixed interval, with which CIE 15 computed its published values at
//!   5 nm, is [`Spectrum::sum_product`]. For tables at 1 nm the two agree to ~1e-5 in x, y.
//! - **Normalisation**: absolute photometric Y uses K_m = 683 lm/W ([`KM_LM_PER_W`]), so a
//!   radiant spectrum in W/nm gives Y in lumens ([`Xyz::photometric`]); an illuminant's
//!   relative values are scaled to Y = 100 ([`Xyz::relative`]).
//! - **Chromaticity**: x = X/(X+Y+Z), y = Y/(X+Y+Z); CIE 1976 UCS u' = 4X/(X+15Y+3Z),
//!   v' = 9Y/(X+15Y+3Z); colour differences are Δu'v' = √(Δu'² + Δv'²) ([`UvPrime::delta`]).
//! - **CCT** ([`cct()`]): the temperature of the Planckian radiator nearest in the CIE 1960
//!   (u, v) = (u', 2/3 v') diagram, found by Ohno's (2014) cascade on a locus computed from
//!   Planck's law (c2 = 1.4388e-2 m·K, [`C2_NM_K`]) and the 1 nm CMFs, with Δuv signed
//!   positive above the locus; 1000-100000 K, to 0.001 K of search precision.
//! - **Illuminants** ([`CieIlluminant`]): D65 (1 nm, 300-830 nm) and the CIE 015:2018 LED
//!   illuminants LED-B1..B5, BH1, RGB1, V1, V2 (1 nm, 380-780 nm) are the CIE's tables; A is
//!   computed from its defining formula (c2 = 1.435e-2 m·K, 300-830 nm at 1 nm).
//!
//! Ohno, Y. (2014). Practical use and calculation of CCT and Duv. LEUKOS 10(1), 47-55.

pub mod cct;
pub mod cie_cmf;
pub mod cie_d65;
pub mod cie_led_b;
pub mod cie_led_other;
pub mod illuminants;
pub mod spectrum;
pub mod tristimulus;

pub use cct::{Cct, cct};
pub use illuminants::{CieIlluminant, illuminant_a};
pub use spectrum::{C2_NM_K, Spectrum, SpectrumError};
pub use tristimulus::{KM_LM_PER_W, UvPrime, Xy, Xyz, luminous_efficacy, observer};

#[cfg(test)]
mod tests;
