//! CIE 1931 tristimulus values, chromaticities (x, y and CIE 1976 u', v'), Δu'v' and
//! luminous efficacy.

use std::sync::OnceLock;

use super::cie_cmf::{CMF_FIRST_NM, CMF_STEP_NM, X_BAR, Y_BAR, Z_BAR};
use super::spectrum::Spectrum;

/// The maximum luminous efficacy K_m of photopic vision, in lm/W: the factor from a radiant
/// quantity weighted by ȳ = V(λ) to the photometric one.
pub const KM_LM_PER_W: f64 = 683.0;

/// The three CIE 1931 2-degree colour-matching functions as spectra.
pub struct Observer {
    /// x̄(λ).
    pub x_bar: Spectrum,
    /// ȳ(λ), which is V(λ).
    pub y_bar: Spectrum,
    /// z̄(λ).
    pub z_bar: Spectrum,
}

/// The CIE 1931 2-degree standard observer, 360-830 nm at 1 nm (built once).
pub fn observer() -> &'static Observer {
    static OBSERVER: OnceLock<Observer> = OnceLock::new();
    OBSERVER.get_or_init(|| {
        let table = |v: &[f64]| {
            Spectrum::uniform(CMF_FIRST_NM, CMF_STEP_NM, v).expect("the CIE table is valid")
        };
        Observer {
            x_bar: table(&X_BAR),
            y_bar: table(&Y_BAR),
            z_bar: table(&Z_BAR),
        }
    })
}

/// CIE 1931 tristimulus values X, Y, Z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Xyz {
    /// X.
    pub x: f64,
    /// Y (luminance-like).
    pub y: f64,
    /// Z.
    pub z: f64,
}

impl std::ops::Add for Xyz {
    type Output = Xyz;

    /// Channel by channel: the tristimulus values of two lights together.
    fn add(self, o: Xyz) -> Xyz {
        Xyz {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

/// CIE 1931 chromaticity coordinates x, y.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Xy {
    /// x = X / (X + Y + Z).
    pub x: f64,
    /// y = Y / (X + Y + Z).
    pub y: f64,
}

/// CIE 1976 UCS chromaticity coordinates u', v'.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvPrime {
    /// u' = 4X / (X + 15Y + 3Z).
    pub u: f64,
    /// v' = 9Y / (X + 15Y + 3Z).
    pub v: f64,
}

impl Xyz {
    /// ∫ S x̄, ∫ S ȳ, ∫ S z̄ (k = 1) of `spd`, by [`Spectrum::integrate_product`].
    pub fn of(spd: &Spectrum) -> Xyz {
        let o = observer();
        Xyz {
            x: spd.integrate_product(&o.x_bar),
            y: spd.integrate_product(&o.y_bar),
            z: spd.integrate_product(&o.z_bar),
        }
    }

    /// Absolute photometric tristimulus values of a radiant spectrum: k = [`KM_LM_PER_W`], so
    /// a spectrum in W/nm gives Y in lm (W/(m²·nm) gives lux, W/(m²·sr·nm) gives cd/m²).
    pub fn photometric(spd: &Spectrum) -> Xyz {
        Xyz::of(spd).scaled(KM_LM_PER_W)
    }

    /// Relative tristimulus values of an illuminant, normalised to Y = 100 (None if Y = 0).
    pub fn relative(spd: &Spectrum) -> Option<Xyz> {
        let xyz = Xyz::of(&spd.normalized()?);
        (xyz.y > 0.0).then(|| xyz.scaled(100.0 / xyz.y))
    }

    /// Zero in every channel.
    pub const ZERO: Xyz = Xyz {
        x: 0.0,
        y: 0.0,
        z: 0.0,
    };

    /// These values times `k`.
    pub fn scaled(self, k: f64) -> Xyz {
        Xyz {
            x: self.x * k,
            y: self.y * k,
            z: self.z * k,
        }
    }

    /// The chromaticity x, y (None if X + Y + Z is not positive).
    pub fn xy(self) -> Option<Xy> {
        let sum = self.x + self.y + self.z;
        (sum > 0.0).then(|| Xy {
            x: self.x / sum,
            y: self.y / sum,
        })
    }

    /// The CIE 1976 chromaticity u', v' (None if X + 15Y + 3Z is not positive).
    pub fn uv_prime(self) -> Option<UvPrime> {
        let d = self.x + 15.0 * self.y + 3.0 * self.z;
        (d > 0.0).then(|| UvPrime {
            u: 4.0 * self.x / d,
            v: 9.0 * self.y / d,
        })
    }
}

impl Xy {
    /// u' = 4x / (−2x + 12y + 3), v' = 9y / (−2x + 12y + 3), the same as from X, Y, Z.
    pub fn uv_prime(self) -> UvPrime {
        let d = -2.0 * self.x + 12.0 * self.y + 3.0;
        UvPrime {
            u: 4.0 * self.x / d,
            v: 9.0 * self.y / d,
        }
    }
}

impl UvPrime {
    /// Δu'v' = √((Δu')² + (Δv')²), the distance of two chromaticities in the CIE 1976 UCS
    /// diagram (the measure of a display's colour non-uniformity).
    pub fn delta(self, other: UvPrime) -> f64 {
        (self.u - other.u).hypot(self.v - other.v)
    }

    /// The CIE 1960 UCS coordinates (u, v) = (u', 2/3 v') that CCT is defined in.
    pub fn uv_1960(self) -> [f64; 2] {
        [self.u, self.v * 2.0 / 3.0]
    }
}

/// The luminous efficacy of radiation of `spd`, in lm/W: K_m ∫ S ȳ dλ / ∫ S dλ, the radiant
/// power counted over the spectrum's whole table (None if that is zero).
pub fn luminous_efficacy(spd: &Spectrum) -> Option<f64> {
    let spd = &spd.normalized()?;
    let radiant = spd.integral();
    (radiant > 0.0).then(|| KM_LM_PER_W * spd.integrate_product(&observer().y_bar) / radiant)
}
