//! One free flight through a scattering medium: how far a photon gets before its next
//! event, and what that event is (see `optics::medium` for the scene-file entry).
//!
//! Along a segment that would reach the next surface (or the target) at `t_next`:
//! - analog: a free path from `mu_t = mu_a + mu_s`; beyond `t_next` the photon reaches the
//!   surface, otherwise it is absorbed with probability `mu_a / mu_t` (roulette on the
//!   single-scattering albedo) or scatters;
//! - weighted: a free path from `mu_s` alone, the weight attenuated by `exp(-mu_a t)` over
//!   the distance flown, the loss booked to the medium. Absorption never kills a photon
//!   here, exactly as in a clear medium (where `mu_s = 0` leaves plain Beer-Lambert), and
//!   the expected weight per path is the analog's.
//!
//! mu_a, mu_s and g are read at the photon's light (tables only in spectral scenes; a
//! constant is one branch).
//!
//! Clear media never come here (the tracer keeps its Beer-Lambert step for them), so a
//! scene without scattering draws the same random numbers as before the feature.

use crate::estimator::Estimator;
use crate::optics::medium::Medium;
use crate::optics::spectrum::Light;
use crate::rng::PhotonRng;
use crate::tally::{ExactSum, Ledger};
use glam::DVec3;

/// How a free flight ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Flight {
    /// The photon reached the end of the segment (`t_next`).
    Reached,
    /// Absorbed in the medium (analog only).
    Absorbed,
    /// Scattered at distance `t`, into `dir`.
    Scattered {
        /// Distance along the segment.
        t: f64,
        /// The new direction.
        dir: DVec3,
    },
}

/// Fly a photon of `weight` and light `light` along unit `dir` through scattering `medium` towards an
/// event at `t_next` (infinite when nothing is ahead); `absorbed` is the medium's
/// ledger entry. A scattering point is kept at least `eps` (the scene's spawn offset)
/// from both ends of the segment, so the next search starts clear of the surfaces it
/// lies between (a shift of at most `eps`, far below any optical length).
#[allow(clippy::too_many_arguments)]
pub(super) fn fly(
    medium: &Medium,
    estimator: Estimator,
    weight: &mut f64,
    light: Light,
    dir: DVec3,
    t_next: f64,
    eps: f64,
    rng: &mut PhotonRng,
    absorbed: &mut ExactSum,
) -> Flight {
    let (mu_a, mu_s) = (
        medium.absorption(light),
        medium.scattering.coefficient(light),
    );
    let path = |rng: &mut PhotonRng, mu: f64| -(1.0 - rng.uniform()).ln() / mu;
    let t = match estimator {
        Estimator::Analog => {
            let t = path(rng, mu_a + mu_s);
            if t >= t_next {
                return Flight::Reached;
            }
            if rng.uniform() * (mu_a + mu_s) < mu_a {
                return Flight::Absorbed;
            }
            t
        }
        Estimator::Weighted => {
            let t = path(rng, mu_s);
            let flown = t.min(t_next);
            if mu_a > 0.0 && flown.is_finite() {
                let w = *weight * (-mu_a * flown).exp();
                Ledger::lose(absorbed, *weight, w);
                *weight = w;
            }
            if t >= t_next {
                return Flight::Reached;
            }
            t
        }
    };
    let t = if t_next > 4.0 * eps {
        t.clamp(eps, t_next - eps)
    } else {
        t.min(t_next * 0.5)
    };
    let (u1, u2) = (rng.uniform(), rng.uniform());
    Flight::Scattered {
        t,
        dir: medium.scattering.scatter(dir, light, u1, u2),
    }
}
