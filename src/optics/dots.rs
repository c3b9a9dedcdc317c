//! Procedural ink-dot extraction patterns, never meshed.
//!
//! Dots sit at the centres of a square or hexagonal cell lattice on a tagged face. The
//! dot in a cell covers the fraction `d(x)` of the cell's area, where `d` is a polynomial
//! in the distance `x` of the cell centre from the lamp edge, measured along `axis`.
//!
//! ```toml
//! [surfaces.lgp_back]
//! model = "dots"
//! inside = "pmma"
//! ink_albedo = 0.92
//! lattice = "hex"            # or "square"
//! pitch_mm = 0.8
//! origin = [0.0, 0.0, 0.0]   # a point on the lamp edge, on the face
//! axis = [1.0, 0.0, 0.0]     # direction of propagation (away from the lamp)
//! length_mm = 300.0          # lamp edge to opposite edge
//! density = [0.05, 0.0, 0.0, 0.0]  # d(x) = c0 + c1 x + c2 x^2 + c3 x^3
//! x_unit = "normalized"      # x in [0, 1] ("mm": x in millimetres)
//! mirror = true              # lamps on both edges: x measured from the nearer edge
//! ```
//!
//! Instead of `density`, a tabulated density (what `blutrace optimize --method feedback`
//! writes) gives knots `[x, d]` with `x` increasing, in the same unit as the polynomial's
//! variable; `d` is linear between knots and constant beyond the first and last:
//!
//! ```toml
//! density_table = [[0.0, 0.02], [0.5, 0.2], [1.0, 0.6]]
//! ```
//!
//! For non-uniformity that varies across the axis too (LEDs on an edge, corner-lit
//! guides), a density grid (what `blutrace optimize --method feedback --dims 2` writes)
//! gives knots on a regular grid: `values[j][i]` is the density at `x = i / (nx - 1) x_max`
//! (the polynomial variable as `x_unit` and `mirror` say; `x_max` is its value at the far
//! end) and at `v = v_min_mm + j / (ny - 1) width_mm` across the axis (mm from `origin`
//! along `across`); `d` is bilinear between knots, constant beyond the grid, and is
//! evaluated at each dot cell's centre:
//!
//! ```toml
//! density_grid = { width_mm = 68.0, values = [[0.02, 0.1, 0.5], [0.03, 0.12, 0.6]] }
//! ```

use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// Cell lattice of the dot grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Lattice {
    /// Square cells of side `pitch`.
    Square,
    /// Hexagonal (triangular) lattice with nearest-neighbour distance `pitch`.
    Hex,
}

impl Lattice {
    /// Largest area fraction round dots can cover without overlapping.
    pub fn max_packing(self) -> f64 {
        match self {
            Lattice::Square => PI / 4.0,
            Lattice::Hex => PI / (2.0 * 3f64.sqrt()),
        }
    }

    /// Area of one cell for a given pitch.
    pub fn cell_area(self, pitch: f64) -> f64 {
        match self {
            Lattice::Square => pitch * pitch,
            Lattice::Hex => 0.5 * 3f64.sqrt() * pitch * pitch,
        }
    }

    /// Radius of a round dot covering the fraction `density` of its cell.
    pub fn dot_radius(self, pitch: f64, density: f64) -> f64 {
        (density.max(0.0) * self.cell_area(pitch) / PI).sqrt()
    }
}

/// How the polynomial's variable is measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize, Default)]
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
#[derive(Clone, Debug, PartialEq)]
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
/// `x` (`0..=x_max`), across it in mm (`v_min..=v_min + width`).
#[derive(Clone, Debug, PartialEq)]
pub struct DensityGrid {
    /// The polynomial variable at the last column of knots.
    pub x_max: f64,
    /// Position across the axis (mm from the origin along `across`) of the first row.
    pub v_min: f64,
    /// Span across the axis (mm) from the first to the last row.
    pub width: f64,
    /// `values[j][i]`: row `j` across the axis, column `i` along it.
    pub values: Vec<Vec<f64>>,
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
    pub fn row_mean(&self, x: f64) -> f64 {
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
                    return Some(format!("width_mm must be positive, got {}", g.width));
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

/// A dot pattern placed on a face.
#[derive(Clone, Debug, PartialEq)]
pub struct DotPattern {
    /// Cell lattice.
    pub lattice: Lattice,
    /// Cell pitch (mm).
    pub pitch: f64,
    /// A point on the lamp edge, in the face.
    pub origin: DVec3,
    /// Unit propagation direction (density varies along it).
    pub axis: DVec3,
    /// Unit in-face direction across the propagation axis.
    pub across: DVec3,
    /// Span along `axis` covered by the pattern (mm).
    pub length: f64,
    /// The density function of the polynomial variable.
    pub density: Density,
    /// Unit of the polynomial variable.
    pub x_unit: XUnit,
    /// Measure from the nearer of the two edges (lamps on both ends).
    pub mirror: bool,
}

impl DotPattern {
    /// The polynomial variable at distance `u` (mm) along the axis from the origin.
    pub fn x_of(&self, u: f64) -> f64 {
        super::gradation::graded_x(u, self.length, self.x_unit, self.mirror)
    }

    /// The density (area fraction) at distance `u` (mm) along the axis.
    pub fn density_at(&self, u: f64) -> f64 {
        self.density.eval(self.x_of(u))
    }

    /// The polynomial variable at the far end of the span (1 when normalized, else the
    /// span in mm: the length, or half of it when mirrored).
    pub fn x_max(&self) -> f64 {
        super::gradation::graded_x_max(self.length, self.x_unit, self.mirror)
    }

    /// Check that the density is finite and within `[0, max packing]` along the whole
    /// span. Returns the first offending position (mm) and value.
    pub fn first_out_of_range(&self) -> Option<(f64, f64)> {
        let max = self.lattice.max_packing();
        if let Density::Grid(g) = &self.density {
            // Bilinear values lie between the knots': checking the knots is enough.
            let (nx, _) = g.shape();
            return g.values.iter().flatten().enumerate().find_map(|(k, &d)| {
                let i = k % nx.max(1);
                let u = self.length * i as f64 / (nx - 1).max(1) as f64;
                let u = if self.mirror { 0.5 * u } else { u };
                (!d.is_finite() || !(0.0..=max).contains(&d)).then_some((u, d))
            });
        }
        let samples = 4096;
        (0..=samples)
            .map(|i| self.length * i as f64 / samples as f64)
            .map(|u| (u, self.density_at(u)))
            .find(|&(_, d)| !d.is_finite() || !(0.0..=max).contains(&d))
    }

    /// Distance (mm) between lattice rows: the pitch for square cells, `pitch sqrt(3)/2`
    /// for hex cells.
    pub fn row_spacing(&self) -> f64 {
        match self.lattice {
            Lattice::Square => self.pitch,
            Lattice::Hex => 0.5 * 3f64.sqrt() * self.pitch,
        }
    }

    /// Centre of cell `i` of row `j` in face coordinates (mm along `axis`, mm along
    /// `across`, from `origin`); hex rows of odd `j` are shifted by half a pitch.
    pub fn cell_centre(&self, i: i64, j: i64) -> DVec2 {
        let p = self.pitch;
        let shift = match self.lattice {
            Lattice::Hex if j.rem_euclid(2) == 1 => 0.5 * p,
            _ => 0.0,
        };
        DVec2::new(
            (i as f64 + 0.5) * p + shift,
            (j as f64 + 0.5) * self.row_spacing(),
        )
    }

    /// Radius (mm) of the dot centred at face coordinate `u` along the axis.
    pub fn dot_radius_at(&self, u: f64) -> f64 {
        self.lattice.dot_radius(self.pitch, self.density_at(u))
    }

    /// The density at face coordinates `c` (mm along `axis`, mm along `across`): a grid
    /// uses both, the other densities only the first.
    pub fn density_at_point(&self, c: DVec2) -> f64 {
        self.density.at(self.x_of(c.x), c.y)
    }

    /// Radius (mm) of the dot of the cell centred at face coordinates `c`.
    pub fn dot_radius_at_cell(&self, c: DVec2) -> f64 {
        self.lattice
            .dot_radius(self.pitch, self.density_at_point(c))
    }

    /// In-face lattice coordinates of a point (mm along `axis`, mm along `across`).
    pub fn face_coords(&self, p: DVec3) -> DVec2 {
        let r = p - self.origin;
        DVec2::new(r.dot(self.axis), r.dot(self.across))
    }

    /// The lattice point nearest to `q` (lattice coordinates).
    fn nearest_centre(&self, q: DVec2) -> DVec2 {
        let p = self.pitch;
        match self.lattice {
            Lattice::Square => ((q / p).floor() + 0.5) * p,
            Lattice::Hex => {
                let h = 0.5 * 3f64.sqrt() * p;
                let j0 = (q.y / h - 0.5).floor();
                [j0, j0 + 1.0]
                    .map(|j| {
                        let shift = if (j as i64).rem_euclid(2) == 1 {
                            0.5 * p
                        } else {
                            0.0
                        };
                        let i = ((q.x - shift) / p - 0.5).round();
                        DVec2::new((i + 0.5) * p + shift, (j + 0.5) * h)
                    })
                    .into_iter()
                    .min_by(|a, b| a.distance_squared(q).total_cmp(&b.distance_squared(q)))
                    .expect("two candidates")
            }
        }
    }

    /// True when the face point `p` lies inside a printed dot.
    pub fn covers(&self, p: DVec3) -> bool {
        let q = self.face_coords(p);
        let c = self.nearest_centre(q);
        let r = self
            .lattice
            .dot_radius(self.pitch, self.density_at_point(c));
        q.distance_squared(c) < r * r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pattern(lattice: Lattice, density: f64) -> DotPattern {
        DotPattern {
            lattice,
            pitch: 0.5,
            origin: DVec3::ZERO,
            axis: DVec3::X,
            across: DVec3::Y,
            length: 100.0,
            density: Density::Polynomial(vec![density]),
            x_unit: XUnit::Normalized,
            mirror: false,
        }
    }

    /// Stratified coverage over a patch equals the density (deterministic, so tight).
    fn coverage(p: &DotPattern) -> f64 {
        let n = 600;
        let mut inside = 0usize;
        for i in 0..n {
            for j in 0..n {
                let x = 20.0 + 10.0 * (i as f64 + 0.5) / n as f64;
                let y = 20.0 + 10.0 * (j as f64 + 0.5) / n as f64;
                inside += p.covers(DVec3::new(x, y, 0.0)) as usize;
            }
        }
        inside as f64 / (n * n) as f64
    }

    #[test]
    fn area_fraction_equals_density_square_and_hex() {
        for lattice in [Lattice::Square, Lattice::Hex] {
            for d in [0.05, 0.3, 0.7] {
                let got = coverage(&pattern(lattice, d));
                assert!((got - d).abs() < 0.01, "{lattice:?} d={d}: covered {got}");
            }
        }
    }

    #[test]
    fn mirror_measures_from_nearer_edge() {
        let mut p = pattern(Lattice::Square, 0.0);
        p.density = Density::Polynomial(vec![0.0, 1.0]);
        p.mirror = true;
        assert!((p.x_of(10.0) - 0.2).abs() < 1e-12);
        assert!((p.x_of(90.0) - 0.2).abs() < 1e-12);
        assert!((p.x_of(50.0) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn table_interpolates_linearly_and_clamps() {
        let d = Density::Table(vec![[0.0, 0.1], [0.5, 0.3], [1.0, 0.2]]);
        assert_eq!(d.eval(-1.0), 0.1);
        assert!((d.eval(0.25) - 0.2).abs() < 1e-12);
        assert!((d.eval(0.75) - 0.25).abs() < 1e-12);
        assert_eq!(d.eval(0.5), 0.3);
        assert_eq!(d.eval(3.0), 0.2);
        assert_eq!(d.problem(), None);
        assert!(
            Density::Table(vec![[0.0, 0.1], [0.0, 0.2]])
                .problem()
                .is_some()
        );
        assert!(Density::Table(vec![]).problem().is_some());
        assert!(Density::Polynomial(vec![f64::NAN]).problem().is_some());
        let mut p = pattern(Lattice::Square, 0.0);
        p.density = Density::Table(vec![[0.0, 0.05], [1.0, 0.65]]);
        let got = coverage(&p); // patch x 20..30 of 100: mean x = 0.25
        assert!((got - 0.2).abs() < 0.01, "covered {got}");
    }

    #[test]
    fn cell_centres_are_lattice_points() {
        for lattice in [Lattice::Square, Lattice::Hex] {
            let p = pattern(lattice, 0.3);
            for (i, j) in [(0, 0), (3, 1), (-2, -3), (7, 4)] {
                let c = p.cell_centre(i, j);
                assert!(
                    p.nearest_centre(c).distance(c) < 1e-9,
                    "{lattice:?} {i} {j}"
                );
                let off = c + DVec2::new(0.1, 0.05) * p.pitch;
                assert!(p.nearest_centre(off).distance(c) < 1e-9);
            }
        }
    }

    #[test]
    fn out_of_range_density_is_found() {
        let mut p = pattern(Lattice::Square, 0.1);
        assert_eq!(p.first_out_of_range(), None);
        p.density = Density::Polynomial(vec![0.1, 1.0]);
        let (u, d) = p.first_out_of_range().unwrap();
        assert!(d > PI / 4.0 && u > 60.0 && u < 70.0, "u={u} d={d}");
        p.density = Density::Polynomial(vec![-0.01]);
        assert!(p.first_out_of_range().is_some());
    }
}
