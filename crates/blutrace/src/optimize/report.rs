//! One line per iteration: the progress report and a row of `history.csv`.

use super::Method;
use serde::Serialize;

/// The state after one iteration, for progress lines and `history.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct IterationReport {
    /// The method.
    pub method: Method,
    /// Iteration (0: the first design, or the initial simplex).
    pub iteration: usize,
    /// Designs evaluated so far (traced or rejected as infeasible).
    pub evaluations: usize,
    /// Photons traced so far.
    pub photons: u64,
    /// Wall time so far (s).
    pub seconds: f64,
    /// The best objective so far (by default the profile cv).
    pub objective: f64,
    /// Its standard error.
    pub noise: f64,
    /// The cv noise alone would give.
    pub noise_floor: f64,
    /// cv of the whole flux map of the best design.
    pub map_cv: f64,
    /// cv of the flux map without the edge margins, of the best design.
    pub area_cv: f64,
    /// 13-point min/max of the best design.
    pub thirteen_point: f64,
    /// Profile cv of the best design.
    pub cv: f64,
    /// Colour non-uniformity Δu'v' 13-point of the best design (NaN: monochrome).
    pub delta_uv_13pt_debiased: f64,
    /// What the iteration did (Nelder-Mead step, or "feedback").
    pub step: String,
    /// The best design's parameters: polynomial coefficients, or knot densities.
    pub params: Vec<f64>,
}

impl std::fmt::Display for IterationReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "iter {:>3}  evals {:>4}  photons {:>7.2}M  {:>6.1} s  ",
            self.iteration,
            self.evaluations,
            self.photons as f64 * 1e-6,
            self.seconds,
        )?;
        if self.delta_uv_13pt_debiased.is_nan() {
            write!(f, "cv {:.4} ± {:.4}", self.objective, self.noise)?;
        } else {
            write!(
                f,
                "objective {:.4} ± {:.4}  cv {:.4}  Δu'v' {:.4}",
                self.objective, self.noise, self.cv, self.delta_uv_13pt_debiased
            )?;
        }
        write!(
            f,
            " (floor {:.4})  area cv {:.3}  map cv {:.3}  13-pt {:.3}  {:<12}",
            self.noise_floor, self.area_cv, self.map_cv, self.thirteen_point, self.step
        )?;
        match self.method {
            Method::NelderMead => {
                let c: Vec<String> = self.params.iter().map(|c| format!("{c:.4}")).collect();
                write!(f, "  c = [{}]", c.join(", "))
            }
            Method::Feedback | Method::Grid => {
                let (lo, hi) = self
                    .params
                    .iter()
                    .fold((f64::INFINITY, 0.0f64), |(l, h), d| (l.min(*d), h.max(*d)));
                write!(f, "  d {lo:.3}..{hi:.3}")
            }
        }
    }
}
