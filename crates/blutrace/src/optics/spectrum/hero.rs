//! Hero-wavelength sampling (Wilkie et al., "Hero wavelength spectral sampling", EGSR
//! 2014; as Mitsuba 3 and pbrt-v4 do with 4): a photon of a spectral scene carries
//! [`WAVELENGTHS`] wavelengths, stratified over its source's spectrum, along one path.
//!
//! The path is the hero's: every model reads its optical quantities at the photon's
//! [`Light`] (the hero) and decides by them. The other wavelengths, the secondaries
//! ([`Secondaries`]), carry per event two ratios to the hero: their throughput (how much
//! of their light the event passes) and the probability the event's decision would have
//! had had they been the hero. A detection scores for each wavelength its throughput
//! over the mean of those probabilities (the balance heuristic over which wavelength is
//! the hero, pbrt-v4's `r_u`): unbiased, because the stratified set is the same whichever
//! of its wavelengths leads, and an event that only one wavelength can take (a hero
//! albedo of 0 where a secondary's is not) is covered by the sets led by the others.
//!
//! - An albedo or reflectance (lambert, phong, mirror, dot ink): analog, the survival
//!   `q(λ)` decided it: both ratios times `q(λᵢ)/q(λₕ)`; weighted, the weight is
//!   `q(λᵢ)/q(λₕ)` and only "survives at all" is decided (`q > 0`).
//! - Clear-medium absorption over a length `t`: both ratios (analog) or the throughput
//!   (weighted) times `exp(-(aᵢ - aₕ) t)`.
//! - Where the path itself depends on the wavelength (refraction between media whose
//!   index is a table or formula, a polarizer's spectral transmittances, volume
//!   scattering of spectral mu_s or g) the secondaries end there (pbrt-v4's
//!   `TerminateSecondary`) and the photon goes on as one wavelength: a refracted hero
//!   goes where no secondary would. Russian roulette on the hero's weight treats every
//!   wavelength alike and needs nothing.
//!
//! With none left, or in a monochrome scene, a photon scores its one wavelength exactly
//! as a photon of one wavelength does.

use super::{Light, Spectral};
use crate::estimator::Estimator;
use crate::sources::spectrum::cmf_at;

/// Wavelengths a photon of a spectral source carries: the hero and three secondaries.
pub const WAVELENGTHS: usize = 4;

/// Secondaries a photon carries besides its hero.
const SECONDARIES: usize = WAVELENGTHS - 1;

/// A photon's secondary wavelengths and their ratios to the hero (see the module
/// header). `NONE` in a monochrome scene, for a ray file's photons (which bring their
/// own one wavelength) and once they ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Secondaries {
    /// Their wavelengths in air (nm).
    nm: [f64; SECONDARIES],
    /// Each one's throughput over the hero's.
    weight: [f64; SECONDARIES],
    /// The probability of the path's decisions had each been the hero, over the hero's.
    pdf: [f64; SECONDARIES],
    /// The hero's cumulative fraction in its source's spectrum, and that source: the
    /// wavelengths are drawn from them when first read ([`Secondaries::draw`]), so a
    /// photon whose secondaries end before any spectral event never draws them.
    u: f64,
    source: u32,
    /// Whether they are carried at all, and whether their wavelengths are drawn.
    live: bool,
    drawn: bool,
}

impl Secondaries {
    /// No secondaries: the photon is its hero alone.
    pub const NONE: Secondaries = Secondaries {
        nm: [0.0; SECONDARIES],
        weight: [0.0; SECONDARIES],
        pdf: [0.0; SECONDARIES],
        u: 0.0,
        source: 0,
        live: false,
        drawn: false,
    };

    /// The secondaries of a hero drawn at cumulative fraction `u` of the spectrum of
    /// source `source`, their wavelengths not drawn yet.
    pub fn deferred(u: f64, source: usize) -> Secondaries {
        Secondaries {
            weight: [1.0; SECONDARIES],
            pdf: [1.0; SECONDARIES],
            u,
            source: source as u32,
            live: true,
            ..Secondaries::NONE
        }
    }

    /// The source whose spectrum their wavelengths are still to be drawn from.
    #[inline(always)]
    pub fn undrawn(&self) -> Option<usize> {
        (self.live && !self.drawn).then_some(self.source as usize)
    }

    /// Draw their wavelengths from the inverse cumulative `sample` of their source's
    /// spectrum: at `u + k / WAVELENGTHS` (mod 1), one per stratum.
    pub fn draw(&mut self, sample: impl Fn(f64) -> f64) {
        self.nm = std::array::from_fn(|k| {
            let v = self.u + (k + 1) as f64 / WAVELENGTHS as f64;
            sample(if v >= 1.0 { v - 1.0 } else { v })
        });
        self.drawn = true;
    }

    /// The secondaries of a hero drawn at cumulative fraction `u` of a spectrum whose
    /// inverse cumulative is `sample`: the wavelengths at `u + k / WAVELENGTHS` (mod 1),
    /// one per stratum.
    pub fn stratified(u: f64, sample: impl Fn(f64) -> f64) -> Secondaries {
        let mut s = Secondaries::deferred(u, 0);
        s.draw(sample);
        s
    }

    /// Whether the photon carries them.
    #[inline(always)]
    pub fn live(&self) -> bool {
        self.live
    }

    /// End them: the path from here is the hero's alone.
    #[inline]
    pub fn end(&mut self) {
        *self = Secondaries::NONE;
    }

    /// The light of the `k`-th (from 0), if they are carried.
    pub fn light(&self, k: usize) -> Option<Light> {
        (self.live && self.drawn && k < SECONDARIES).then(|| Light::at_nm(self.nm[k]))
    }

    /// Their lights.
    fn lights(&self) -> impl Iterator<Item = Light> + '_ {
        self.nm.iter().map(|&nm| Light::at_nm(nm))
    }

    /// The hero survived an event of probability (analog) or factor (weighted) `q`, read
    /// at the hero's `hero` light (positive: it survived). Drawn first.
    pub fn survived(&mut self, estimator: Estimator, q: &Spectral, hero: Light) {
        if !q.is_spectral() {
            return;
        }
        debug_assert!(self.drawn);
        let qh = q.at(hero);
        for k in 0..SECONDARIES {
            let qk = q.at(Light::at_nm(self.nm[k]));
            self.weight[k] *= qk / qh;
            match estimator {
                Estimator::Analog => self.pdf[k] *= qk / qh,
                Estimator::Weighted if qk > 0.0 => {}
                Estimator::Weighted => self.pdf[k] = 0.0,
            }
        }
    }

    /// The hero crossed `t` mm of a medium absorbing `a` per mm (its light `hero`) and
    /// was not absorbed (analog), or was attenuated by `exp(-a t)` (weighted). A photon
    /// that leaves to infinity in an absorbing medium is absorbed there: they end.
    /// Drawn first.
    pub fn crossed(&mut self, estimator: Estimator, a: &Spectral, hero: Light, t: f64) {
        if !a.is_spectral() {
            return;
        }
        debug_assert!(self.drawn);
        if !t.is_finite() {
            self.end();
            return;
        }
        let ah = a.at(hero);
        for k in 0..SECONDARIES {
            let f = (-(a.at(Light::at_nm(self.nm[k])) - ah) * t).exp();
            self.weight[k] *= f;
            if estimator == Estimator::Analog {
                self.pdf[k] *= f;
            }
        }
    }

    /// X, Y, Z a detection of hero `hero` and weight `weight` scores: each wavelength's
    /// x̄, ȳ, z̄ times its throughput, over the mean of the decisions' probabilities
    /// (the hero's alone, `weight` x̄(λₕ) ..., when there are none). Drawn first.
    pub fn xyz(&self, hero: Light, weight: f64) -> [f64; 3] {
        let h = cmf_at(hero.nm());
        if !self.live {
            return h.map(|c| c * weight);
        }
        assert!(
            self.drawn,
            "secondaries scored before their wavelengths were drawn"
        );
        let mut sum = h;
        for (l, w) in self.lights().zip(self.weight) {
            let c = cmf_at(l.nm());
            (0..3).for_each(|i| sum[i] += c[i] * w);
        }
        let pdf = 1.0 + self.pdf.iter().sum::<f64>();
        sum.map(|s| s * weight / pdf)
    }

    /// The largest throughput ratio of a secondary to its hero (1 for none): how far the
    /// ratio weights spread.
    pub fn largest_ratio(&self) -> f64 {
        if !self.live {
            return 1.0;
        }
        self.weight.iter().fold(1.0, |m, &w| m.max(w))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::PhotonRng;

    /// Uniform 400-700 nm, as an inverse cumulative.
    fn flat(u: f64) -> f64 {
        400.0 + 300.0 * u
    }

    /// Untouched secondaries score the mean of the four wavelengths' x̄, ȳ, z̄; ended
    /// ones, the hero's alone.
    #[test]
    fn a_clear_path_scores_the_mean_of_its_wavelengths() {
        let s = Secondaries::stratified(0.9, flat);
        let nm = [0.9, 0.15, 0.4, 0.65].map(flat);
        assert!((s.nm[0] - nm[1]).abs() < 1e-9 && (s.nm[2] - nm[3]).abs() < 1e-9);
        let hero = Light::at_nm(nm[0]);
        let got = s.xyz(hero, 2.0);
        for (i, g) in got.iter().enumerate() {
            let want = nm.iter().map(|&l| cmf_at(l)[i]).sum::<f64>() / 4.0 * 2.0;
            assert!((g - want).abs() < 1e-12, "{i}: {got:?}");
        }
        let mut ended = s;
        ended.end();
        assert_eq!(ended.xyz(hero, 2.0), cmf_at(nm[0]).map(|c| c * 2.0));
    }

    /// Analog survival on an albedo of 0 at 400-550 nm and 1 above, over many photons:
    /// the mean X, Y, Z scored is the albedo-weighted spectrum's (within 4 standard
    /// errors), though a hero in the dark half never survives.
    #[test]
    fn an_albedo_zero_at_the_hero_stays_unbiased() {
        let albedo = Spectral::sampled(|nm| if nm < 550.0 { 0.0 } else { 1.0 });
        let n = 200_000;
        let mut rng = PhotonRng::new(3, 0);
        let mut sums = [[0.0; 2]; 3];
        for _ in 0..n {
            let u = rng.uniform();
            let hero = Light::at_nm(flat(u));
            let mut s = Secondaries::stratified(u, flat);
            let xyz = if rng.uniform() < albedo.at(hero) {
                s.survived(Estimator::Analog, &albedo, hero);
                s.xyz(hero, 1.0)
            } else {
                [0.0; 3]
            };
            for i in 0..3 {
                sums[i][0] += xyz[i];
                sums[i][1] += xyz[i] * xyz[i];
            }
        }
        for (i, [s, s2]) in sums.iter().enumerate() {
            let mean = s / n as f64;
            let err = ((s2 / n as f64 - mean * mean) / n as f64).sqrt();
            let want = (0..30_000)
                .map(|j| flat((j as f64 + 0.5) / 30_000.0))
                .map(|nm| albedo.at(Light::at_nm(nm)) * cmf_at(nm)[i])
                .sum::<f64>()
                / 30_000.0;
            assert!(
                (mean - want).abs() < 4.0 * err,
                "{i}: {mean} vs {want} ± {err}"
            );
        }
    }

    /// Weighted, the same albedo and absorption over a length: the scored X, Y, Z of one
    /// photon is the mean of each wavelength's x̄, ȳ, z̄ times its own attenuation.
    #[test]
    fn weighted_ratios_are_each_wavelengths_own_attenuation() {
        let albedo = Spectral::sampled(|nm| 0.5 + nm / 2000.0);
        let a = Spectral::sampled(|nm| nm / 1e5);
        let s0 = Secondaries::stratified(0.3, flat);
        let hero = Light::at_nm(flat(0.3));
        let mut s = s0;
        s.survived(Estimator::Weighted, &albedo, hero);
        s.crossed(Estimator::Weighted, &a, hero, 70.0);
        let own = |nm: f64| {
            let l = Light::at_nm(nm);
            albedo.at(l) * (-a.at(l) * 70.0).exp()
        };
        let got = s.xyz(hero, own(hero.nm()));
        let nm = [0.3, 0.55, 0.8, 0.05].map(flat);
        for (i, g) in got.iter().enumerate() {
            let want = nm.iter().map(|&l| own(l) * cmf_at(l)[i]).sum::<f64>() / 4.0;
            assert!((g - want).abs() < 1e-12 * want.abs().max(1e-3), "{i}");
        }
        assert!(s.largest_ratio() > 1.0);
    }
}
