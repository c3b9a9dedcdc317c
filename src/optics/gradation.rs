//! A quantity graded along a light guide, as the dot density of [`super::dots`] is.
//!
//! The value is a [`Density`] function (polynomial `c0 + c1 x + c2 x^2 + ...` or a table of
//! knots) of `x`, the distance from the lamp edge along the pattern's axis, either in
//! millimetres or normalized by the span (`x_unit`), measured from the nearer edge when
//! lamps sit at both ends (`mirror`). [`super::grooves`] grades its groove fill fraction
//! with it.
//!
//! Dots and grooves measure `x` with the same [`graded_x`].

use super::dots::{Density, XUnit};

/// The grading variable at distance `u` (mm) from the lamp edge along a span of `length`
/// (mm): clamped to the span, from the nearer edge when `mirror`, in mm or normalized by
/// the span (the half span when mirrored).
pub fn graded_x(u: f64, length: f64, unit: XUnit, mirror: bool) -> f64 {
    let u = u.clamp(0.0, length);
    let (dist, span) = if mirror {
        (u.min(length - u), 0.5 * length)
    } else {
        (u, length)
    };
    match unit {
        XUnit::Normalized => dist / span,
        XUnit::Mm => dist,
    }
}

/// The grading variable at the far end of a span of `length` (mm): 1 when normalized,
/// else the span in mm (the length, or half of it when `mirror`).
pub fn graded_x_max(length: f64, unit: XUnit, mirror: bool) -> f64 {
    let end = if mirror { 0.5 * length } else { length };
    graded_x(end, length, unit, mirror)
}

/// A function graded along an axis of span `length` (mm).
#[derive(Clone, Debug, PartialEq)]
pub struct Gradation {
    /// The function of the variable `x`.
    pub density: Density,
    /// Span along the axis from the lamp edge to the far edge (mm).
    pub length: f64,
    /// Unit of the polynomial variable.
    pub x_unit: XUnit,
    /// Measure from the nearer of the two edges (lamps on both ends).
    pub mirror: bool,
}

impl Gradation {
    /// A constant value (no grading).
    pub fn constant(value: f64) -> Self {
        Self {
            density: Density::Polynomial(vec![value]),
            length: 1.0,
            x_unit: XUnit::Mm,
            mirror: false,
        }
    }

    /// True when the value does not depend on position.
    pub fn is_constant(&self) -> bool {
        match &self.density {
            Density::Polynomial(c) => c.iter().skip(1).all(|&c| c == 0.0),
            Density::Table(k) => k.iter().all(|p| p[1] == k[0][1]),
            Density::Grid(g) => g.values.iter().flatten().all(|v| *v == g.values[0][0]),
        }
    }

    /// The polynomial variable at distance `u` (mm) along the axis from the lamp edge
    /// (clamped to the span).
    pub fn x_of(&self, u: f64) -> f64 {
        graded_x(u, self.length, self.x_unit, self.mirror)
    }

    /// The graded value at distance `u` (mm) along the axis.
    pub fn at(&self, u: f64) -> f64 {
        self.density.eval(self.x_of(u))
    }

    /// The first position (mm) along the span, sampled finely, where the value is not
    /// finite or outside `[lo, hi]`, with that value.
    pub fn first_outside(&self, lo: f64, hi: f64) -> Option<(f64, f64)> {
        let samples = if self.is_constant() { 0 } else { 4096 };
        (0..=samples)
            .map(|i| self.length * i as f64 / samples.max(1) as f64)
            .map(|u| (u, self.at(u)))
            .find(|&(_, g)| !g.is_finite() || !(lo..=hi).contains(&g))
    }

    /// Largest value over the span (sampled as [`Gradation::first_outside`] does).
    pub fn max_over_span(&self) -> f64 {
        let samples = if self.is_constant() { 0 } else { 4096 };
        (0..=samples)
            .map(|i| self.at(self.length * i as f64 / samples.max(1) as f64))
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::dots::{DotPattern, Lattice};
    use glam::DVec3;

    #[test]
    fn agrees_with_the_dot_density_convention() {
        for (x_unit, mirror) in [
            (XUnit::Normalized, false),
            (XUnit::Normalized, true),
            (XUnit::Mm, false),
            (XUnit::Mm, true),
        ] {
            let density = Density::Polynomial(vec![0.05, 0.2, -0.1, 0.03]);
            let g = Gradation {
                density: density.clone(),
                length: 37.0,
                x_unit,
                mirror,
            };
            let d = DotPattern {
                lattice: Lattice::Square,
                pitch: 0.5,
                origin: DVec3::ZERO,
                axis: DVec3::X,
                across: DVec3::Y,
                length: 37.0,
                density,
                x_unit,
                mirror,
            };
            for k in -3..=40 {
                let u = k as f64;
                assert_eq!(g.at(u), d.density_at(u), "{x_unit:?} {mirror} u={u}");
            }
        }
    }

    #[test]
    fn range_checks_find_the_bad_spot() {
        let g = Gradation {
            density: Density::Polynomial(vec![0.2, 1.0]),
            length: 10.0,
            x_unit: XUnit::Normalized,
            mirror: false,
        };
        let (u, v) = g.first_outside(0.0, 1.0).unwrap();
        assert!(u > 7.9 && u < 8.1 && v > 1.0, "u={u} v={v}");
        assert!((g.max_over_span() - 1.2).abs() < 1e-12);
        assert_eq!(Gradation::constant(0.5).first_outside(0.0, 1.0), None);
        assert!(Gradation::constant(-0.1).first_outside(0.0, 1.0).is_some());
    }
}
