//! Where the dots of a [`super::dots`] pattern sit, and whether a hit meets ink.
//!
//! ```toml
//! [surfaces.lgp_back]
//! model = "dots"
//! placement = "stochastic"   # "lattice" (default), "jittered", "stochastic" or "virtual"
//! placement_seed = 7         # jittered, stochastic: which random screen (default 0)
//! ```
//!
//! With `d` the local density, `p` the pitch and `A` the lattice's cell area:
//!
//! - `lattice`: one dot per cell at the cell centre, radius `sqrt(d A / pi)`.
//! - `jittered`: the lattice's dot moved by a pseudo-random offset, uniform in the disc of
//!   radius `p/2 - r` around the cell centre. The dot stays inside the circle inscribed in
//!   its cell, so dots never overlap, they cover the fraction `d` exactly and a point can
//!   only be covered by the dot of the cell it lies in (one lookup per hit). The price: the
//!   jitter shrinks as the dots grow (at `d = 0.6` on a square lattice it is `0.06 p`).
//! - `stochastic`: a coverage-corrected random screen (a Boolean model: Poisson germs,
//!   disc grains). The face is cut into square buckets of side `p`; bucket `(i, j)` holds
//!   a Poisson number of dots of mean `p^2 / A` (one per lattice cell on average), uniform
//!   in the bucket. Dots may overlap, so their radius is `sqrt(-ln(1 - d) A / pi)`: the
//!   probability that a point is covered, `1 - exp(-lambda pi r^2)`, is then `d` at every
//!   point, not only on average over a cell. Up to the packing limit `r < 0.82 p`, so the
//!   dots that can cover a point all sit in its bucket and the 8 around it (O(1) per hit;
//!   a neighbour farther from the point than the largest radius is not even drawn).
//! - `virtual`: no printed dots: each hit meets ink with probability `d` at the hit point
//!   (the grid's `d(x, y)` for a density grid), drawn from the photon's own random stream.
//!   This is the "virtual dots" model of Lee et al. 2005 that other tracers use. It cannot
//!   be printed: exports refuse it (optimize can export a printable placement instead).
//!
//! A lattice correlates the hits of a photon trapped by total internal reflection: its
//! hits step by the same vector every bounce, so one that falls between dots tends to
//! fall between dots again (see the README, "Dot placement and correlated extraction").
//! The random placements draw each cell's dots from `(placement_seed, cell)` only, so the
//! same seed always gives the same sheet, whatever is traced.

use super::density::Density;
use super::dots::{DotPattern, Lattice};
use super::placement::Placement;
use crate::rng::PhotonRng;
use crate::rounding::{floor_i64, round_i64};
use glam::{DVec2, DVec3};
use std::f64::consts::{PI, TAU};

/// Keeps the dots' random numbers apart from the photons' streams of the same seed.
const PLACEMENT_KEY: u64 = 0x6a09_e667_f3bc_c908;

/// One printed dot in face coordinates (mm along `axis`, mm along `across`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacedDot {
    /// Centre.
    pub centre: DVec2,
    /// Radius (mm).
    pub radius: f64,
}

impl DotPattern {
    /// The cell (column `i`, row `j`) whose lattice point is nearest to `q` (face
    /// coordinates): the cell `q` lies in.
    pub fn nearest_cell(&self, q: DVec2) -> (i64, i64) {
        let (i, j, _) = self.nearest_cell_centre(q);
        (i, j)
    }

    /// [`DotPattern::nearest_cell`] and that cell's centre (one lookup per ink test).
    fn nearest_cell_centre(&self, q: DVec2) -> (i64, i64, DVec2) {
        let p = self.pitch;
        // Reciprocals, not divisions by q's coordinates: they do not wait for the hit
        // point, so only a multiplication stays on the hit's chain of dependent steps.
        let per_pitch = 1.0 / p;
        match self.lattice {
            Lattice::Square => {
                let (i, j) = (floor_i64(q.x * per_pitch), floor_i64(q.y * per_pitch));
                (i, j, self.cell_centre(i, j))
            }
            Lattice::Hex => {
                // The two rows around q; in each, the column nearest q; the nearer wins
                // (the first on a tie).
                let per_row = 1.0 / self.row_spacing();
                let j0 = floor_i64(q.y * per_row - 0.5);
                let candidate = |j: i64| {
                    let shift = if j.rem_euclid(2) == 1 { 0.5 * p } else { 0.0 };
                    let i = round_i64((q.x - shift) * per_pitch - 0.5);
                    let c = self.cell_centre(i, j);
                    (i, j, c, c.distance_squared(q))
                };
                let (a, b) = (candidate(j0), candidate(j0 + 1));
                let nearer = if b.3 < a.3 { b } else { a };
                (nearer.0, nearer.1, nearer.2)
            }
        }
    }

    /// Radius of a dot of the stochastic screen where the density is `d`: the Boolean
    /// model covers `1 - exp(-pi r^2 / A)` of the face, which this makes `d`.
    /// The density is clamped to the lattice's packing limit (which the load checks at
    /// 4097 points; a polynomial may stray beyond it between them), so no dot is larger
    /// than [`DotPattern::stochastic_reach`].
    fn stochastic_radius(&self, d: f64) -> f64 {
        let a = self.lattice.cell_area(self.pitch);
        let d = d.clamp(0.0, self.lattice.max_packing());
        (-(1.0 - d).ln() * a / PI).max(0.0).sqrt()
    }

    /// The largest radius of a stochastic dot: `0.70 p` (square), `0.81 p` (hex).
    fn stochastic_reach(&self) -> f64 {
        self.stochastic_radius(1.0)
    }

    /// True when a stochastic dot of bucket `(i, j)` could cover `q`: the bucket lies
    /// within the largest dot radius of `q`.
    fn bucket_reaches(&self, i: i64, j: i64, q: DVec2) -> bool {
        let p = self.pitch;
        let lo = DVec2::new(i as f64, j as f64) * p;
        let gap = (lo - q).max(q - (lo + p)).max(DVec2::ZERO);
        let reach = self.stochastic_reach();
        gap.length_squared() < reach * reach
    }

    /// The random numbers of cell or bucket `(i, j)`.
    fn cell_rng(&self, i: i64, j: i64) -> PhotonRng {
        let key = ((i as u32 as u64) << 32) | j as u32 as u64;
        PhotonRng::new(self.placement_seed ^ PLACEMENT_KEY, key)
    }

    /// The dot of lattice cell `(i, j)`, placed as the lattice or the jitter says.
    fn cell_dot(&self, i: i64, j: i64) -> PlacedDot {
        let c = self.cell_centre(i, j);
        let radius = self.dot_radius_at_cell(c);
        if self.placement != Placement::Jittered {
            return PlacedDot { centre: c, radius };
        }
        let mut g = self.cell_rng(i, j);
        let reach = (0.5 * self.pitch - radius).max(0.0) * g.uniform().sqrt();
        let angle = TAU * g.uniform();
        PlacedDot {
            centre: c + reach * DVec2::new(angle.cos(), angle.sin()),
            radius,
        }
    }

    /// The dots of the stochastic screen's bucket `(i, j)` (square, side `pitch`).
    fn bucket_dots(&self, i: i64, j: i64) -> BucketDots<'_> {
        let mut rng = self.cell_rng(i, j);
        let mean = self.pitch * self.pitch / self.lattice.cell_area(self.pitch);
        let count = poisson(mean, rng.uniform());
        BucketDots {
            pattern: self,
            rng,
            corner: DVec2::new(i as f64, j as f64) * self.pitch,
            left: count,
        }
    }

    /// Every dot of cell `(i, j)`: the lattice cell (lattice, jittered) or the bucket
    /// (stochastic); none for `virtual`.
    pub fn dots_of_cell(&self, i: i64, j: i64) -> Vec<PlacedDot> {
        match self.placement {
            Placement::Lattice | Placement::Jittered => vec![self.cell_dot(i, j)],
            Placement::Stochastic => self.bucket_dots(i, j).collect(),
            Placement::Virtual => Vec::new(),
        }
    }

    /// The cells `(i, j)` whose dots may have their centre in the face-coordinate box
    /// `lo..hi` (lattice cells, or the stochastic screen's buckets).
    pub fn cells_over(&self, lo: DVec2, hi: DVec2) -> impl Iterator<Item = (i64, i64)> {
        let (sx, sy) = match self.placement {
            Placement::Stochastic => (self.pitch, self.pitch),
            _ => (self.pitch, self.row_spacing()),
        };
        let (j0, j1) = (
            (lo.y / sy).floor() as i64 - 1,
            (hi.y / sy).ceil() as i64 + 1,
        );
        let (i0, i1) = (
            (lo.x / sx).floor() as i64 - 1,
            (hi.x / sx).ceil() as i64 + 1,
        );
        (j0..=j1).flat_map(move |j| (i0..=i1).map(move |i| (i, j)))
    }

    /// True when the face point `p` lies inside a printed dot (never for `virtual`,
    /// which prints none: see [`DotPattern::meets_ink`]).
    pub fn covers(&self, p: DVec3) -> bool {
        let q = self.face_coords(p);
        let inside = |d: PlacedDot| q.distance_squared(d.centre) < d.radius * d.radius;
        match self.placement {
            Placement::Lattice => {
                // As `cell_dot` places it, compared by squared radius (no square root).
                let (_, _, c) = self.nearest_cell_centre(q);
                let density = self.density_at_point(c);
                q.distance_squared(c) < self.lattice.dot_radius_squared(self.pitch, density)
            }
            Placement::Jittered => {
                let (i, j) = self.nearest_cell(q);
                inside(self.cell_dot(i, j))
            }
            Placement::Stochastic => {
                let (bi, bj) = (floor_i64(q.x / self.pitch), floor_i64(q.y / self.pitch));
                // Its own bucket first, then the neighbours a dot could reach across from.
                let near = (bj - 1..=bj + 1).flat_map(|j| (bi - 1..=bi + 1).map(move |i| (i, j)));
                self.bucket_dots(bi, bj).any(inside)
                    || near
                        .filter(|&(i, j)| (i, j) != (bi, bj) && self.bucket_reaches(i, j, q))
                        .any(|(i, j)| self.bucket_dots(i, j).any(inside))
            }
            Placement::Virtual => false,
        }
    }

    /// Whether a photon hitting the face at `p` meets ink: a printed dot there, or for
    /// `virtual` a draw from the photon's stream with probability `d` at `p`.
    pub fn meets_ink(&self, p: DVec3, rng: &mut PhotonRng) -> bool {
        match self.placement {
            Placement::Virtual => rng.uniform() < self.density_at_point(self.face_coords(p)),
            _ => self.covers(p),
        }
    }
}

/// The squared dot radius of every column of a `lattice` pattern whose density varies
/// along the axis only (a polynomial or a table; hex lattices: per column and row
/// parity), computed once as [`DotPattern::covers`] computes it at every hit: the same
/// numbers, without evaluating the density and the radius per hit. The tracer builds it
/// per run ([`DotPattern::column_radii`]), so it always matches the pattern it traces.
#[derive(Clone, Debug)]
pub struct ColumnRadii {
    /// Column of the first entry.
    first: i64,
    /// Index of the last entry's column, counted from `first`.
    last: i64,
    /// Entries per column: 1 (square) or 2 (hex, even and odd rows).
    per_column: usize,
    /// Squared radii, column-major.
    r2: Vec<f64>,
}

/// Most columns a [`ColumnRadii`] holds (8 MB, 16 MB on a hex lattice): beyond, the lookup
/// computes per hit.
const MAX_TABLED_COLUMNS: f64 = 1e6;

impl ColumnRadii {
    /// The squared radius of the dot of cell `(i, j)`. Columns beyond the table's ends
    /// have the end's radius: the density is taken at the span's ends there.
    fn get(&self, i: i64, j: i64) -> f64 {
        let col = (i - self.first).clamp(0, self.last) as usize;
        let row = if self.per_column == 2 {
            (j & 1) as usize
        } else {
            0
        };
        self.r2[col * self.per_column + row]
    }
}

impl DotPattern {
    /// The column table of this pattern, when it has one: `lattice` placement, a density
    /// along the axis only, at most a million columns.
    pub fn column_radii(&self) -> Option<ColumnRadii> {
        let along_axis = !matches!(self.grade.density, Density::Grid(_));
        let columns = self.grade.length / self.pitch;
        // (NaN columns do not fit.)
        let fits = columns <= MAX_TABLED_COLUMNS;
        if !(self.placement == Placement::Lattice && along_axis && fits) {
            return None;
        }
        // Two columns either side of the span: beyond them every cell centre lies off
        // the span, where the density is the end's (graded_x clamps to the span).
        let (first, last) = (-2, columns.ceil() as i64 + 2);
        let per_column = match self.lattice {
            Lattice::Square => 1,
            Lattice::Hex => 2,
        };
        let r2 = (first..=last)
            .flat_map(|i| (0..per_column as i64).map(move |j| (i, j)))
            .map(|(i, j)| {
                let density = self.density_at_point(self.cell_centre(i, j));
                self.lattice.dot_radius_squared(self.pitch, density)
            })
            .collect();
        Some(ColumnRadii {
            first,
            last: last - first,
            per_column,
            r2,
        })
    }

    /// [`DotPattern::covers`] for a pattern with a column table `radii` (from
    /// [`DotPattern::column_radii`]): the same answer at every point (but points exactly
    /// half-way between two cells, where the two take different cells).
    #[inline]
    pub fn covers_tabled(&self, p: DVec3, radii: &ColumnRadii) -> bool {
        self.first_covered(p, DVec3::ZERO, 1, radii) == 0
    }

    /// The first `j` in `0..n` whose point `start + j step` on the face meets ink, or `n`:
    /// [`DotPattern::covers_tabled`] at each point (a run of landings along a line). The
    /// face coordinates go up by the same step in cell units, and the nearest cell centre
    /// is found by float rounding, so the points' tests do not wait on each other or on
    /// float-integer conversions (but the table's index): 1.10x on bench-box against
    /// `nearest_cell_centre`'s `floor`.
    #[inline]
    pub fn first_covered(&self, start: DVec3, step: DVec3, n: u32, radii: &ColumnRadii) -> u32 {
        let (p, rows) = (self.pitch, self.row_spacing());
        // Pitches along the axis, rows across, from the centre of cell (0, 0).
        let per_cell = DVec2::new(1.0 / p, 1.0 / rows);
        let q0 = self.face_coords(start) * per_cell - 0.5;
        let dq = DVec2::new(step.dot(self.axis), step.dot(self.across)) * per_cell;
        let at = |j: u32| q0 + dq * f64::from(j);
        let first = match self.lattice {
            Lattice::Square => (0..n).find(|&j| square_covered(at(j), p * p, radii)),
            Lattice::Hex => (0..n).find(|&j| hex_covered(at(j), p, rows, radii)),
        };
        first.unwrap_or(n)
    }
}

/// Whether the point `q` (in cells from the centre of cell (0, 0)) of a square lattice of
/// pitch squared `p2` lies in its cell's dot.
#[inline(always)]
fn square_covered(q: DVec2, p2: f64, radii: &ColumnRadii) -> bool {
    let centre = DVec2::new(round_to_integer(q.x), round_to_integer(q.y));
    (q - centre).length_squared() * p2 < radii.get(centre.x as i64, 0)
}

/// Whether the point `q` (in pitches `p` along the axis and rows `rows` across, from the
/// centre of cell (0, 0)) of a hex lattice lies in the dot of its nearest cell: the
/// nearer of the centres of the two rows around it, the lower on a tie (as
/// `nearest_cell_centre`).
#[inline(always)]
fn hex_covered(q: DVec2, p: f64, rows: f64, radii: &ColumnRadii) -> bool {
    let candidate = |j: f64| {
        // Odd rows sit half a pitch along.
        let half = 0.5 * j;
        let x = q.x
            - if half == round_to_integer(half) {
                0.0
            } else {
                0.5
            };
        let i = round_to_integer(x);
        let off = DVec2::new((x - i) * p, (q.y - j) * rows);
        (i, j, off.length_squared())
    };
    let low = round_to_integer(q.y - 0.5);
    let (a, b) = (candidate(low), candidate(low + 1.0));
    let (i, j, d2) = if b.2 < a.2 { b } else { a };
    d2 < radii.get(i as i64, j as i64)
}

/// `x` rounded to an integer (halves to even) for `|x| < 2^51`, in two additions: no
/// libm call (x86-64's baseline has no rounding instruction) and no round trip through an
/// integer.
#[inline(always)]
fn round_to_integer(x: f64) -> f64 {
    const SHIFT: f64 = 6_755_399_441_055_744.0; // 1.5 * 2^52: its ulp is 1
    (x + SHIFT) - SHIFT
}

/// The dots of one bucket of the stochastic screen, drawn as they are asked for.
struct BucketDots<'a> {
    pattern: &'a DotPattern,
    rng: PhotonRng,
    corner: DVec2,
    left: u32,
}

impl Iterator for BucketDots<'_> {
    type Item = PlacedDot;

    fn next(&mut self) -> Option<PlacedDot> {
        if self.left == 0 {
            return None;
        }
        self.left -= 1;
        let p = self.pattern;
        let centre = self.corner + DVec2::new(self.rng.uniform(), self.rng.uniform()) * p.pitch;
        let radius = p.stochastic_radius(p.density_at_point(centre));
        Some(PlacedDot { centre, radius })
    }
}

/// The Poisson variate of mean `mean` at the uniform `u` (inversion; at most 64).
fn poisson(mean: f64, u: f64) -> u32 {
    let mut term = (-mean).exp();
    let mut cdf = term;
    let mut k = 0;
    while u >= cdf && k < 64 {
        k += 1;
        term *= mean / k as f64;
        cdf += term;
    }
    k
}

#[cfg(test)]
mod tests {
    use super::super::dots::{Gradation, XUnit, test_pattern};
    use super::*;

    #[test]
    fn poisson_inversion_has_the_poisson_probabilities() {
        // Stratified uniforms: the share of each count is its probability to 1/n.
        let n = 100_000;
        for mean in [0.3, 1.0, 2.0 / 3f64.sqrt()] {
            let mut counts = [0usize; 12];
            for i in 0..n {
                counts[poisson(mean, (i as f64 + 0.5) / n as f64) as usize] += 1;
            }
            let mut pmf = (-mean).exp();
            for (k, &c) in counts.iter().enumerate() {
                if k > 0 {
                    pmf *= mean / k as f64;
                }
                let got = c as f64 / n as f64;
                assert!(
                    (got - pmf).abs() <= 1.0 / n as f64,
                    "mean {mean} k {k}: {got} vs {pmf}"
                );
            }
        }
    }

    /// The column table answers as the per-hit lookup does, everywhere on and off the
    /// span, for both lattices, graded (polynomial, table; normalized, mm; mirrored) and
    /// constant densities, and a pattern origin off the face's corner; patterns it cannot
    /// hold get none.
    #[test]
    fn column_table_covers_as_the_lookup_does() {
        use super::super::dots::{Density, XUnit};
        let densities = [
            (
                Density::Polynomial(vec![0.05, 0.2, 0.4]),
                XUnit::Normalized,
                false,
            ),
            (
                Density::Table(vec![[0.0, 0.1], [20.0, 0.7]]),
                XUnit::Mm,
                true,
            ),
            (Density::Polynomial(vec![0.2]), XUnit::Normalized, false),
        ];
        let mut g = PhotonRng::new(4, 9);
        let mut inked = 0;
        for lattice in [Lattice::Square, Lattice::Hex] {
            for (density, x_unit, mirror) in densities.clone() {
                let p = DotPattern {
                    pitch: 0.37,
                    origin: DVec3::new(-3.0, 1.0, 0.0),
                    grade: Gradation {
                        density,
                        length: 41.3,
                        x_unit,
                        mirror,
                    },
                    ..test_pattern(lattice, 0.0)
                };
                let radii = p.column_radii().expect("a lattice graded along its axis");
                for _ in 0..50_000 {
                    let x = 50.0 * g.uniform() - 7.0;
                    let point = DVec3::new(x, 20.0 * g.uniform() - 10.0, 0.0);
                    let want = p.covers(point);
                    assert_eq!(p.covers_tabled(point, &radii), want, "{lattice:?} {point}");
                    inked += usize::from(want);
                }
            }
        }
        assert!(inked > 10_000, "the points meet ink: {inked}");
        let base = DotPattern {
            placement: Placement::Jittered,
            ..test_pattern(Lattice::Square, 0.3)
        };
        assert!(base.column_radii().is_none(), "jittered dots move");
        let dense = DotPattern {
            pitch: 1e-6,
            placement: Placement::Lattice,
            ..base
        };
        assert!(dense.column_radii().is_none(), "too many columns");
    }

    /// The lattice lookup agrees with a brute-force search for the nearest cell centre.
    #[test]
    fn lattice_lookup_finds_the_nearest_dot() {
        use super::super::dots::Density;
        for lattice in [Lattice::Square, Lattice::Hex] {
            let p = DotPattern {
                pitch: 0.3,
                grade: Gradation {
                    density: Density::Polynomial(vec![0.1, 0.6]),
                    length: 50.0,
                    x_unit: XUnit::Normalized,
                    mirror: false,
                },
                ..test_pattern(lattice, 0.0)
            };
            let mut g = PhotonRng::new(1, 2);
            for _ in 0..20_000 {
                let q = DVec2::new(50.0 * g.uniform(), 7.0 * g.uniform() - 3.0);
                let (i0, j0) = (
                    (q.x / p.pitch) as i64,
                    (q.y / p.row_spacing()).floor() as i64,
                );
                let nearest = (j0 - 2..=j0 + 2)
                    .flat_map(|j| (i0 - 2..=i0 + 2).map(move |i| (i, j)))
                    .map(|(i, j)| p.cell_centre(i, j))
                    .min_by(|a, b| a.distance_squared(q).total_cmp(&b.distance_squared(q)))
                    .unwrap();
                let r = p.dot_radius_at_cell(nearest);
                let by_hand = q.distance_squared(nearest) < r * r;
                assert_eq!(p.covers(q.extend(0.0)), by_hand, "{lattice:?} at {q}");
            }
        }
    }

    /// `first_covered` along a line is the first point of it `covers` answers yes for.
    #[test]
    fn first_covered_is_the_first_covered_point() {
        let mut g = PhotonRng::new(5, 1);
        for lattice in [Lattice::Square, Lattice::Hex] {
            let p = DotPattern {
                pitch: 0.41,
                origin: DVec3::new(-3.0, 1.0, 0.0),
                ..test_pattern(lattice, 0.3)
            };
            let radii = p.column_radii().expect("a lattice graded along its axis");
            let (mut found, mut none) = (0, 0);
            for _ in 0..20_000 {
                let start = DVec3::new(50.0 * g.uniform() - 7.0, 20.0 * g.uniform() - 10.0, 0.0);
                let step = DVec3::new(3.0 * g.uniform() - 1.5, 3.0 * g.uniform() - 1.5, 0.0);
                let n = (g.uniform() * 8.0) as u32;
                let want = (0..n)
                    .find(|&j| p.covers(start + step * f64::from(j)))
                    .unwrap_or(n);
                assert_eq!(p.first_covered(start, step, n, &radii), want, "{lattice:?}");
                (found, none) = (
                    found + u32::from(want < n),
                    none + u32::from(want == n && n > 0),
                );
            }
            assert!(found > 5000 && none > 2000, "{lattice:?}: {found} {none}");
        }
    }
}
