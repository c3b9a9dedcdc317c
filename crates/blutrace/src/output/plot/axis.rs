//! Chart axes: linear and logarithmic ranges, "nice" ticks and their labels.

use super::*;

/// The value `v` in axis units (`log10(v)` on a log axis), or `None` if it cannot be drawn.
pub(super) fn transform(scale: Scale, v: f64) -> Option<f64> {
    match scale {
        Scale::Linear => v.is_finite().then_some(v),
        Scale::Log10 => (v.is_finite() && v > 0.0).then(|| v.log10()),
    }
}

/// An axis: its scale and its range `lo < hi` in axis units (see [`transform`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Axis {
    pub(super) scale: Scale,
    pub(super) lo: f64,
    pub(super) hi: f64,
}

/// A tick mark at `frac` (0..=1 along the axis); major ticks have a label.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Tick {
    pub(super) frac: f64,
    pub(super) label: Option<String>,
}

impl Axis {
    /// The axis covering data from `min` to `max` (in axis units, finite, `min <= max`)
    /// with a margin of 5 % of the span on both sides. A zero (or negligible) span gets
    /// ±10 % of the value (±1 around zero) on a linear axis and ±½ decade on a log axis.
    /// A log axis over data spanning less than a decade is widened to whole decades if it
    /// would show fewer than two powers of ten; data spanning a decade or more keep their
    /// own range, which always holds labelled ticks at 1, 2 or 5 times powers of ten.
    pub(super) fn fit(scale: Scale, min: f64, max: f64) -> Result<Self> {
        let span = max - min;
        let (lo, hi) = match scale {
            Scale::Linear => {
                let size = min.abs().max(max.abs());
                if span <= 1e-12 * size || span == 0.0 {
                    let c = 0.5 * min + 0.5 * max;
                    let half = if c == 0.0 { 1.0 } else { 0.1 * c.abs() };
                    (c - half, c + half)
                } else {
                    let (lo, hi) = (min - 0.05 * span, max + 0.05 * span);
                    if (hi - lo).is_finite() {
                        (lo, hi)
                    } else {
                        (min, max)
                    }
                }
            }
            Scale::Log10 => {
                let (lo, hi) = if span < 1e-9 {
                    (min - 0.5, max + 0.5)
                } else {
                    (min - 0.05 * span, max + 0.05 * span)
                };
                if span < 1.0 && hi.floor() - lo.ceil() < 1.0 {
                    (lo.floor(), hi.ceil())
                } else {
                    (lo, hi)
                }
            }
        };
        ensure!(
            (hi - lo).is_finite() && hi > lo,
            "data range {min:e} to {max:e} is too wide for a linear axis"
        );
        Ok(Self { scale, lo, hi })
    }

    /// Where the data value `v` lies along the axis: 0 at `lo`, 1 at `hi`; `None` if `v`
    /// cannot be drawn on this axis.
    pub(super) fn frac(&self, v: f64) -> Option<f64> {
        transform(self.scale, v).map(|t| (t - self.lo) / (self.hi - self.lo))
    }

    /// Tick marks, with at most about `max_labels` labels.
    pub(super) fn ticks(&self, max_labels: usize) -> Vec<Tick> {
        match self.scale {
            Scale::Linear => self.linear_ticks(),
            Scale::Log10 => self.log_ticks(max_labels),
        }
    }

    /// 4–6 ticks at multiples of a "nice" step, all labelled.
    pub(super) fn linear_ticks(&self) -> Vec<Tick> {
        let (lo, hi) = (self.lo, self.hi);
        let span = hi - lo;
        let range = |step: f64| {
            let eps = 1e-9;
            ((lo / step - eps).ceil(), (hi / step + eps).floor())
        };
        let mag = 10f64.powf((span / 5.0).log10().floor());
        let mut best: Option<(f64, f64)> = None; // (score, step)
        for m in [0.1, 1.0, 10.0] {
            for f in [1.0, 2.0, 5.0, 2.5] {
                let step = f * m * mag;
                let (a, b) = range(step);
                let count = b - a + 1.0;
                let score = (count - 5.0).abs() + if f == 2.5 { 1.0 } else { 0.0 };
                if step.is_finite() && step > 0.0 && best.is_none_or(|(s, _)| score < s) {
                    best = Some((score, step));
                }
            }
        }
        let Some((_, step)) = best else {
            return Vec::new();
        };
        let (a, b) = range(step);
        let values: Vec<f64> = (0..=((b - a) as i64).clamp(0, 100))
            .map(|i| (a + i as f64) * step)
            .collect();
        let labels = linear_labels(&values, step);
        values
            .iter()
            .zip(labels)
            .map(|(&v, label)| Tick {
                frac: (v - lo) / span,
                label: Some(label),
            })
            .collect()
    }

    /// Ticks at powers of ten (labelled, every `stride`-th one if there are many) and minor
    /// ticks at 2–9 times a power of ten when at most 6 decades are shown; when at most 2.5
    /// decades are shown, the ones at 2 and 5 times a power of ten are labelled too.
    pub(super) fn log_ticks(&self, max_labels: usize) -> Vec<Tick> {
        let (lo, hi) = (self.lo, self.hi);
        let eps = 1e-9;
        let (a, b) = ((lo - eps).ceil() as i64, (hi + eps).floor() as i64);
        let decades = (b - a + 1).max(0) as usize;
        let stride = decades.div_ceil(max_labels.max(1)).max(1) as i64;
        let frac = |t: f64| (t - lo) / (hi - lo);
        let mut ticks = Vec::new();
        for k in (lo.floor() as i64)..=(hi.ceil() as i64) {
            let t = k as f64;
            if (a..=b).contains(&k) {
                let labelled = k.rem_euclid(stride) == 0;
                ticks.push(Tick {
                    frac: frac(t),
                    label: labelled.then(|| format!("1e{k}")),
                });
            }
            if hi - lo <= 6.0 {
                for m in 2..=9 {
                    let t = t + f64::from(m).log10();
                    if t > lo - eps && t < hi + eps {
                        let labelled = hi - lo <= 2.5 && (m == 2 || m == 5);
                        ticks.push(Tick {
                            frac: frac(t),
                            label: labelled.then(|| format!("{m}e{k}")),
                        });
                    }
                }
            }
        }
        ticks
    }
}

/// Labels for the linear tick `values` (multiples of `step`): fixed-point with just enough
/// decimals for `step` if that is short, else [`format_label`]'s scientific notation
/// (unless its 4 significant digits cannot tell the ticks apart).
pub(super) fn linear_labels(values: &[f64], step: f64) -> Vec<String> {
    let decimals = (0..=12)
        .find(|&d| {
            let s = step * 10f64.powi(d);
            (s - s.round()).abs() <= 1e-6 * s
        })
        .unwrap_or(12) as usize;
    let fixed: Vec<String> = values
        .iter()
        .map(|&v| {
            let v = if v.abs() < 1e-9 * step { 0.0 } else { v };
            format!("{v:.decimals$}")
        })
        .collect();
    if fixed.iter().all(|s| s.len() <= 8) {
        return fixed;
    }
    let short: Vec<String> = values.iter().map(|&v| format_label(v)).collect();
    if short.windows(2).any(|w| w[0] == w[1]) {
        fixed
    } else {
        short
    }
}
