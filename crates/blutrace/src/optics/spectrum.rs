//! The home of wavelength: what a photon carries of its source's light ([`Light`]) and the
//! optical quantities read at it ([`Spectral`]).
//!
//! blutrace is monochrome today: every photon is the same light, so [`Light`] holds
//! nothing and a [`Spectral`] quantity is one number, the same for every photon. The
//! quantities that will depend on wavelength are already read through
//! [`Spectral::at`] with the photon's [`Light`]: a medium's refractive index and
//! absorption ([`super::medium::Medium::index`], [`super::medium::Medium::absorption`]),
//! every reflectance and albedo of the surface models (lambert `albedo`, dots
//! `ink_albedo`, mirror and phong `reflectance`), and the weight a detection scores
//! ([`Light::detected`]). A spectral scene gives `Light` a wavelength drawn from its
//! source's spectrum and `Spectral` a table; the call sites stay as they are.
//!
//! Not yet read through here: a scattering medium's coefficient and phase function
//! (Mie particles are evaluated at one `wavelength_nm` at load).

use serde::Serialize;

/// What a photon carries of its source's emission, besides its weight: nothing while
/// blutrace is monochrome (a zero-sized value, free to carry).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Light {}

impl Light {
    /// The one light of a monochrome scene.
    pub const MONOCHROME: Light = Light {};

    /// The weight a detection of a photon of this light and weight `weight` scores in the
    /// radiant tallies (all of it: radiant power does not depend on the wavelength).
    #[inline]
    pub fn detected(self, weight: f64) -> f64 {
        weight
    }
}

/// An optical quantity that may depend on wavelength: one value for every [`Light`]
/// while blutrace is monochrome. Written to reports as that number.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(transparent)]
pub struct Spectral(f64);

impl Spectral {
    /// The same `value` at every wavelength.
    pub const fn constant(value: f64) -> Spectral {
        Spectral(value)
    }

    /// The value for a photon of light `light`.
    #[inline]
    pub fn at(self, _light: Light) -> f64 {
        self.0
    }

    /// This quantity times `factor` at every wavelength.
    pub fn scaled(self, factor: f64) -> Spectral {
        Spectral(self.0 * factor)
    }

    /// The value reports show (`check`, summaries): the constant's.
    pub fn nominal(self) -> f64 {
        self.0
    }
}

impl std::fmt::Display for Spectral {
    /// The nominal value, formatted as an `f64` is.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Display::fmt(&self.0, f)
    }
}

impl From<f64> for Spectral {
    fn from(value: f64) -> Spectral {
        Spectral::constant(value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_reads_the_same_for_every_light_and_costs_nothing_to_carry() {
        let n = Spectral::constant(1.49);
        assert_eq!(n.at(Light::MONOCHROME), 1.49);
        assert_eq!(n.nominal(), 1.49);
        assert_eq!(Light::MONOCHROME.detected(0.25), 0.25);
        assert_eq!(std::mem::size_of::<Light>(), 0);
        assert_eq!(std::mem::size_of::<Spectral>(), std::mem::size_of::<f64>());
    }
}
