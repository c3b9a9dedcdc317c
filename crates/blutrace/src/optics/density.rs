//! A quantity graded along a light guide: the dot density of [`super::dots`] and the
//! groove fill fraction of [`super::grooves`].
//!
//! The value is a [`Density`] function of `x`, the distance from the lamp edge along the
//! pattern's axis, either in millimetres or normalized by the span (`x_unit`), measured
//! from the nearer edge when lamps sit at both ends (`mirror`): a polynomial, a table of
//! knots, or (dots only) a grid of knots over the face that also varies across the axis.
//!
//! ```toml
//! density = [0.05, 0.0, 0.0, 0.0]   # d(x) = c0 + c1 x + c2 x^2 + c3 x^3
//! # density_table = [[0.0, 0.02], [0.5, 0.2], [1.0, 0.6]]   # [x, d] knots, linear
//! # density_grid = { width_mm = 68.0, values = [[0.02, 0.1], [0.03, 0.12]] }   # dots
//! x_unit = "normalized"   # x in [0, 1] ("mm": x in millimetres)
//! mirror = true           # lamps on both edges: x measured from the nearer edge
//! ```
//!
//! Dots and grooves measure `x` with the same [`graded_x`] and check the range of their
//! value with the same [`Gradation::first_outside`], and their pitch with the same
//! [`check_pitch`].

use crate::spec_check::Ctx;
use anyhow::Result;
use serde::{Deserialize, Serialize};

/// The pitch of a dot or groove lattice, relative to the face's reach (the farthest vertex
/// of the face from the pattern's origin), is kept within `[1e-6, 1e6]`: positions on the
/// face are then resolved to 2e-10 of a cell or better (f64 carries 16 digits), and the
/// cell index of any point stays a small integer. Finer lattices are not representable
/// (at `pitch_mm = 1e-300` dots vanish and grooves fall back to the smooth plane, slowly),
/// and are sub-wavelength long before that, where ray optics does not hold anyway.
pub const PITCH_RANGE: [f64; 2] = [1e-6, 1e6];

/// Check the lattice `pitch` (mm) against the face's `reach` (mm), see [`PITCH_RANGE`].
pub fn check_pitch(ctx: &Ctx, field: &str, pitch: f64, reach: f64) -> Result<()> {
    let [lo, hi] = PITCH_RANGE.map(|k| k * reach);
    if pitch < lo || pitch > hi {
        return Err(ctx.err(
            field,
            format!(
                "{pitch:e} mm is out of range for a face reaching {reach:.4} mm from the pattern's origin: \
                 the pitch must be within [{lo:.3e}, {hi:.3e}] mm ({:e} to {:e} times the reach) for the \
                 lattice to be representable",
                PITCH_RANGE[0], PITCH_RANGE[1]
            ),
        ));
    }
    Ok(())
}

/// A pattern's span (`length_mm` along its axis, a density grid's `width_mm` across it)
/// is at most this many times the face's reach: a longer span puts the whole face within
/// its first few per cent, where a graded density reads as a constant (at `length_mm =
/// 1e20` every groove vanishes), so it is a unit or typing mistake.
pub const SPAN_PER_REACH: f64 = 10.0;

/// Most lattice cells along a groove pattern's span (`length_mm / pitch_mm`): its deepest
/// groove is found cell by cell, so the span bounds the loading time (2^27 cells, a
/// fraction of a second; a 300 mm guide at a 1 um pitch has 3e5).
pub const MAX_SPAN_CELLS: f64 = (1u64 << 27) as f64;

/// Check a pattern's span (mm, named by `field`) against the face's `reach` (mm), see
/// [`SPAN_PER_REACH`].
pub fn check_span(ctx: &Ctx, field: &str, span: f64, reach: f64) -> Result<()> {
    let max = SPAN_PER_REACH * reach;
    if span > max {
        return Err(ctx.err(
            field,
            format!(
                "{} mm is more than {SPAN_PER_REACH} times the face's reach ({} mm from the pattern's origin): the face would see only the first {:.2e} of the span",
                crate::spec_check::short(span),
                crate::spec_check::short(reach),
                reach / span
            ),
        ));
    }
    Ok(())
}

/// Check that a groove pattern's span (`length_mm`, named by `field`) holds at most
/// [`MAX_SPAN_CELLS`] cells of `pitch` (mm).
pub fn check_cells(ctx: &Ctx, field: &str, span: f64, pitch: f64) -> Result<()> {
    let cells = span / pitch;
    if cells > MAX_SPAN_CELLS {
        return Err(ctx.err(
            field,
            format!(
                "{} mm holds {} cells of pitch_mm = {} mm, more than the {} a pattern may have",
                crate::spec_check::short(span),
                crate::spec_check::short(cells.floor()),
                crate::spec_check::short(pitch),
                MAX_SPAN_CELLS
            ),
        ));
    }
    Ok(())
}

/// How the polynomial's variable is measured.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    serde::Deserialize,
    serde::Serialize,
    Default,
    schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum XUnit {
    /// Distance divided by the span from the lamp edge to the far edge (or to the centre
    /// line when mirrored): x in `[0, 1]`.
    #[default]
    Normalized,
    /// Distance in millimetres.
    Mm,
}

/// The density function d(x): the area fraction of a cell covered by its dot.
///
/// The same value from the scene file (see [`Density::from_keys`]) through the optimizer
/// (which writes it back with [`Density::keys`]) to `result.json`, where it serializes
/// as `{"polynomial": [...]}`, `{"table": [[x, d], ...]}` or `{"grid": {...}}`.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Density {
    /// Polynomial coefficients, lowest degree first: `d(x) = c0 + c1 x + c2 x^2 + ...`.
    Polynomial(Vec<f64>),
    /// Knots `[x, d]`, `x` strictly increasing: linear between knots, constant beyond
    /// the first and the last.
    Table(Vec<[f64; 2]>),
    /// Knots on a regular grid over the face (along the axis and across it), bilinear.
    Grid(DensityGrid),
}

/// A density on a regular grid of knots: along the axis in the polynomial variable
/// `x` (`0..=x_max`), across it in mm (`v_min..=v_min + width`). In a scene file,
/// `density_grid = { width_mm = W, v_min_mm = V, values = [[...], ...] }`: rows across
/// the axis, columns along it; `x_max` follows from the pattern (see [`graded_x_max`]).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DensityGrid {
    /// The polynomial variable at the last column of knots (set when the pattern is
    /// built: not a key of the file).
    #[serde(skip)]
    pub x_max: f64,
    /// Position across the axis (mm from the origin along `across`) of the first row.
    #[serde(rename = "v_min_mm", default)]
    pub v_min: f64,
    /// Span across the axis (mm) from the first to the last row.
    #[serde(rename = "width_mm")]
    pub width: f64,
    /// `values[j][i]`: row `j` across the axis, column `i` along it.
    pub values: Vec<Vec<f64>>,
}

/// The scene-file keys a density is given by (exactly one of them): `density`
/// (polynomial), `density_table` (knots) or `density_grid` (dots only).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DensityKeys {
    /// `density`: polynomial coefficients.
    pub density: Option<Vec<f64>>,
    /// `density_table`: `[x, d]` knots.
    pub density_table: Option<Vec<[f64; 2]>>,
    /// `density_grid`: knots over the face.
    pub density_grid: Option<DensityGrid>,
}

impl DensityKeys {
    /// The names of the keys given.
    fn given(&self) -> Vec<&'static str> {
        [
            ("density", self.density.is_some()),
            ("density_table", self.density_table.is_some()),
            ("density_grid", self.density_grid.is_some()),
        ]
        .into_iter()
        .filter_map(|(k, given)| given.then_some(k))
        .collect()
    }
}

impl Density {
    /// The density the keys of table `at` give (exactly one of them; `default` when
    /// none is and the model has one), checked, with the field that gave it. `x_max`
    /// places a grid's last column (see [`graded_x_max`]).
    pub fn from_keys(
        ctx: &Ctx,
        at: &str,
        keys: DensityKeys,
        default: Option<Density>,
        x_max: f64,
    ) -> Result<(Density, String)> {
        let f = |k: &str| format!("{at}.{k}");
        let (density, field) = match keys {
            DensityKeys {
                density: Some(c),
                density_table: None,
                density_grid: None,
            } => (Density::Polynomial(c), f("density")),
            DensityKeys {
                density: None,
                density_table: Some(k),
                density_grid: None,
            } => (Density::Table(k), f("density_table")),
            DensityKeys {
                density: None,
                density_table: None,
                density_grid: Some(g),
            } => (
                Density::Grid(Self::placed_grid(ctx, at, g, x_max)?),
                f("density_grid"),
            ),
            DensityKeys {
                density: None,
                density_table: None,
                density_grid: None,
            } => match default {
                Some(d) => (d, f("density")),
                None => {
                    return Err(ctx.err(
                        &f("density"),
                        "missing: give density (polynomial coefficients), density_table ([x, d] knots) or density_grid",
                    ));
                }
            },
            keys => {
                let given = keys.given().join(" and ");
                let msg = format!("give only one of the density keys ({given} are given)");
                return Err(ctx.err(&f("density"), msg));
            }
        };
        Ok((density.checked(ctx, &field)?, field))
    }

    /// `g` with its last column at `x_max`, its width checked.
    fn placed_grid(ctx: &Ctx, at: &str, mut g: DensityGrid, x_max: f64) -> Result<DensityGrid> {
        let field = format!("{at}.density_grid.width_mm");
        ctx.non_negative(&field, g.width)?;
        if g.width > crate::spec_check::MAX_COORDINATE {
            ctx.length(&field, g.width)?;
        }
        g.x_max = x_max;
        Ok(g)
    }

    /// The scene-file keys that give this density (the inverse of [`Density::from_keys`]).
    pub fn keys(&self) -> DensityKeys {
        let mut keys = DensityKeys::default();
        match self {
            Density::Polynomial(c) => keys.density = Some(c.clone()),
            Density::Table(k) => keys.density_table = Some(k.clone()),
            Density::Grid(g) => keys.density_grid = Some(g.clone()),
        }
        keys
    }
}

impl DensityGrid {
    /// Columns (knots along the axis) and rows (across it).
    pub fn shape(&self) -> (usize, usize) {
        (self.values.first().map_or(0, Vec::len), self.values.len())
    }

    /// Fractional knot coordinates of `(x, v)`, clamped to the grid.
    fn knot_coords(&self, x: f64, v: f64) -> (f64, f64) {
        let (nx, ny) = self.shape();
        let fx = if nx > 1 && self.x_max > 0.0 {
            (x / self.x_max * (nx - 1) as f64).clamp(0.0, (nx - 1) as f64)
        } else {
            0.0
        };
        let fy = if ny > 1 && self.width > 0.0 {
            ((v - self.v_min) / self.width * (ny - 1) as f64).clamp(0.0, (ny - 1) as f64)
        } else {
            0.0
        };
        (fx, fy)
    }

    /// The knot nearest to `(x, v)`: (column, row).
    pub fn nearest_knot(&self, x: f64, v: f64) -> (usize, usize) {
        let (fx, fy) = self.knot_coords(x, v);
        (fx.round() as usize, fy.round() as usize)
    }

    /// Bilinear interpolation at `(x, v)`, constant beyond the grid.
    pub fn at(&self, x: f64, v: f64) -> f64 {
        let (nx, ny) = self.shape();
        if nx == 0 || ny == 0 {
            return 0.0;
        }
        let (fx, fy) = self.knot_coords(x, v);
        let (i0, j0) = (
            (fx.floor() as usize).min(nx - 1),
            (fy.floor() as usize).min(ny - 1),
        );
        let (i1, j1) = ((i0 + 1).min(nx - 1), (j0 + 1).min(ny - 1));
        let (tx, ty) = (fx - i0 as f64, fy - j0 as f64);
        let g = |i: usize, j: usize| self.values[j][i];
        let a = g(i0, j0) + (g(i1, j0) - g(i0, j0)) * tx;
        let b = g(i0, j1) + (g(i1, j1) - g(i0, j1)) * tx;
        a + (b - a) * ty
    }

    /// The mean over the rows at `x` (the density averaged across the axis).
    fn row_mean(&self, x: f64) -> f64 {
        let (_, ny) = self.shape();
        if ny == 0 {
            return 0.0;
        }
        (0..ny)
            .map(|j| {
                let v = self.v_min + self.width * j as f64 / (ny - 1).max(1) as f64;
                self.at(x, v)
            })
            .sum::<f64>()
            / ny as f64
    }
}

impl Density {
    /// The density at the polynomial variable `x` and `v` mm across the axis: a grid
    /// uses both, the other densities only `x`.
    pub fn at(&self, x: f64, v: f64) -> f64 {
        match self {
            Density::Grid(g) => g.at(x, v),
            other => other.eval(x),
        }
    }

    /// The density at the polynomial variable `x` (a grid's mean across the axis).
    pub fn eval(&self, x: f64) -> f64 {
        match self {
            Density::Polynomial(c) => c.iter().rev().fold(0.0, |acc, c| acc * x + c),
            Density::Table(knots) => interpolate(knots, x),
            Density::Grid(g) => g.row_mean(x),
        }
    }

    /// This density, if usable (see [`Density::problem`]); else an error at `field`.
    pub fn checked(self, ctx: &Ctx, field: &str) -> Result<Density> {
        match self.problem() {
            Some(problem) => Err(ctx.err(field, problem)),
            None => Ok(self),
        }
    }

    /// Why this density cannot be used (empty, non-finite, knots not increasing), if so.
    pub fn problem(&self) -> Option<String> {
        match self {
            Density::Polynomial(c) if c.is_empty() => Some("needs at least one coefficient".into()),
            Density::Polynomial(c) => c
                .iter()
                .position(|v| !v.is_finite())
                .map(|i| format!("coefficient {i} is not a finite number")),
            Density::Table(k) if k.is_empty() => Some("needs at least one knot".into()),
            Density::Table(k) => {
                if let Some(i) = k
                    .iter()
                    .position(|p| !p[0].is_finite() || !p[1].is_finite())
                {
                    return Some(format!("knot {i} is not a pair of finite numbers"));
                }
                k.windows(2).position(|w| w[1][0] <= w[0][0]).map(|i| {
                    format!(
                        "knot x values must increase strictly (knots {i} and {})",
                        i + 1
                    )
                })
            }
            Density::Grid(g) => {
                let (nx, ny) = g.shape();
                if nx == 0 || ny == 0 {
                    return Some("needs at least one row of values".into());
                }
                if let Some(j) = g.values.iter().position(|r| r.len() != nx) {
                    return Some(format!(
                        "values must be rectangular: row {j} has {} values, row 0 has {nx}",
                        g.values[j].len()
                    ));
                }
                // One row needs no span across; more rows need a positive one.
                if !(g.width.is_finite() && (g.width > 0.0 || (ny == 1 && g.width == 0.0))) {
                    return Some(format!(
                        "width_mm must be positive, got {}",
                        crate::spec_check::short(g.width)
                    ));
                }
                if !g.v_min.is_finite() {
                    return Some("v_min_mm is not a finite number".into());
                }
                for (j, r) in g.values.iter().enumerate() {
                    if let Some(i) = r.iter().position(|v| !v.is_finite()) {
                        return Some(format!("values[{j}][{i}] is not a finite number"));
                    }
                }
                None
            }
        }
    }
}

/// Piecewise-linear interpolation through `knots` (x increasing), constant outside.
fn interpolate(knots: &[[f64; 2]], x: f64) -> f64 {
    let Some(first) = knots.first() else {
        return 0.0;
    };
    let last = knots[knots.len() - 1];
    if x <= first[0] {
        return first[1];
    }
    if x >= last[0] {
        return last[1];
    }
    // First knot strictly right of x; exists and is > 0 because first[0] < x < last[0].
    let i = knots.partition_point(|k| k[0] <= x);
    let (a, b) = (knots[i - 1], knots[i]);
    a[1] + (b[1] - a[1]) * (x - a[0]) / (b[0] - a[0])
}

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

    /// Positions (mm) along the span with the value there, as the range checks see
    /// them: a grid's knots (bilinear values lie between them), else `samples + 1`
    /// evenly spaced values (one for a constant).
    fn span_values(&self, samples: usize) -> Box<dyn Iterator<Item = (f64, f64)> + '_> {
        if let Density::Grid(g) = &self.density {
            let (nx, _) = g.shape();
            return Box::new(g.values.iter().flatten().enumerate().map(move |(k, &d)| {
                let i = k % nx.max(1);
                let u = self.length * i as f64 / (nx - 1).max(1) as f64;
                (if self.mirror { 0.5 * u } else { u }, d)
            }));
        }
        let samples = if self.is_constant() { 0 } else { samples };
        Box::new(
            (0..=samples)
                .map(move |i| self.length * i as f64 / samples.max(1) as f64)
                .map(|u| (u, self.at(u))),
        )
    }

    /// The first position (mm) along the span where the value is not finite or outside
    /// `[lo, hi]`, with that value (at 4097 evenly spaced positions).
    pub fn first_outside(&self, lo: f64, hi: f64) -> Option<(f64, f64)> {
        self.span_values(4096)
            .find(|&(_, v)| !v.is_finite() || !(lo..=hi).contains(&v))
    }

    /// How far the value leaves `[lo, hi]` anywhere on the span (0: within; infinite
    /// where it is not finite), from `samples + 1` evenly spaced values.
    pub fn worst_excess(&self, lo: f64, hi: f64, samples: usize) -> f64 {
        self.span_values(samples)
            .map(|(_, v)| {
                if v.is_finite() {
                    (lo - v).max(v - hi).max(0.0)
                } else {
                    f64::INFINITY
                }
            })
            .fold(0.0, f64::max)
    }

    #[cfg(test)]
    /// Largest value over the span (sampled as [`Gradation::first_outside`] does).
    fn max_over_span(&self) -> f64 {
        self.span_values(4096)
            .map(|(_, v)| v)
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
