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
    /// Polynomial coefficients, lowest degree first.
    pub density: Vec<f64>,
    /// Unit of the polynomial variable.
    pub x_unit: XUnit,
    /// Measure from the nearer of the two edges (lamps on both ends).
    pub mirror: bool,
}

impl DotPattern {
    /// The polynomial variable at distance `u` (mm) along the axis from the origin.
    pub fn x_of(&self, u: f64) -> f64 {
        let u = u.clamp(0.0, self.length);
        let (dist, span) = if self.mirror {
            (u.min(self.length - u), 0.5 * self.length)
        } else {
            (u, self.length)
        };
        match self.x_unit {
            XUnit::Normalized => dist / span,
            XUnit::Mm => dist,
        }
    }

    /// The density (area fraction) at distance `u` (mm) along the axis.
    pub fn density_at(&self, u: f64) -> f64 {
        let x = self.x_of(u);
        self.density.iter().rev().fold(0.0, |acc, c| acc * x + c)
    }

    /// Check that the density is finite and within `[0, max packing]` along the whole
    /// span. Returns the first offending position (mm) and value.
    pub fn first_out_of_range(&self) -> Option<(f64, f64)> {
        let max = self.lattice.max_packing();
        let samples = 4096;
        (0..=samples)
            .map(|i| self.length * i as f64 / samples as f64)
            .map(|u| (u, self.density_at(u)))
            .find(|&(_, d)| !d.is_finite() || !(0.0..=max).contains(&d))
    }

    /// In-face lattice coordinates of a point (mm along `axis`, mm along `across`).
    fn face_coords(&self, p: DVec3) -> DVec2 {
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
        let r = self.lattice.dot_radius(self.pitch, self.density_at(c.x));
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
            density: vec![density],
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
        p.density = vec![0.0, 1.0];
        p.mirror = true;
        assert!((p.x_of(10.0) - 0.2).abs() < 1e-12);
        assert!((p.x_of(90.0) - 0.2).abs() < 1e-12);
        assert!((p.x_of(50.0) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn out_of_range_density_is_found() {
        let mut p = pattern(Lattice::Square, 0.1);
        assert_eq!(p.first_out_of_range(), None);
        p.density = vec![0.1, 1.0];
        let (u, d) = p.first_out_of_range().unwrap();
        assert!(d > PI / 4.0 && u > 60.0 && u < 70.0, "u={u} d={d}");
        p.density = vec![-0.01];
        assert!(p.first_out_of_range().is_some());
    }
}
