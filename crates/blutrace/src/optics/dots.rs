//! Procedural ink-dot extraction patterns, never meshed.
//!
//! A square or hexagonal cell lattice on a tagged face sets the dots' size and number:
//! the dot of a cell covers the fraction `d(x)` of the cell's area, where `d` is a
//! polynomial in the distance `x` of the cell centre from the lamp edge, measured along
//! `axis`. By default each dot sits at its cell centre; `placement` jitters them, puts
//! them on a coverage-corrected random screen, or replaces them by virtual dots (ink with
//! probability `d` per hit): see [`super::dot_placement`].
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
//! placement = "lattice"      # or "jittered", "stochastic", "virtual" (see dot_placement)
//! placement_seed = 0         # jittered, stochastic: which random screen
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
//!
//! The density functions and their checks live in [`super::density`], shared with the
//! groove fill of [`super::grooves`]; this module owns the lattice and the dot sizes,
//! [`super::dot_placement`] where the dots sit and whether a hit meets ink.

use super::density::graded_x_max;
pub use super::density::{Density, DensityGrid, DensityKeys, Gradation, XUnit};
use super::density::{check_pitch, check_span};
use super::medium::{Interface, Medium, air};
use super::model::{Arrival, Face, Feature, MeterVertex, Outcome, Surface, SurfaceSpecOf};
pub use super::placement::Placement;
use super::spectrum::{Range, Spectral, SpectralValue};
use super::{dielectric, lambert};
use crate::rng::PhotonRng;
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// `[surfaces.TAG]` with `model = "dots"`: a dielectric face printed with ink dots.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DotsSpec {
    /// Medium behind the face.
    pub inside: String,
    /// Medium in front of the face.
    #[serde(default = "air")]
    pub outside: String,
    /// Ink albedo (Lambertian).
    pub ink_albedo: SpectralValue,
    /// Cell lattice.
    pub lattice: Lattice,
    /// Cell pitch (mm).
    pub pitch_mm: f64,
    /// A point on the lamp edge, in the face (mm).
    pub origin: [f64; 3],
    /// Propagation direction.
    pub axis: [f64; 3],
    /// In-face direction across `axis` (default: face normal x axis, found at load).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub across: Option<[f64; 3]>,
    /// Span along `axis` (mm).
    pub length_mm: f64,
    /// Density polynomial coefficients, lowest degree first (or `density_table`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<Vec<f64>>,
    /// Tabulated density: knots `[x, d]`, x increasing, linear between (or `density`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density_table: Option<Vec<[f64; 2]>>,
    /// Density on a grid of knots over the face, bilinear (or `density`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density_grid: Option<DensityGrid>,
    /// Unit of the polynomial variable.
    #[serde(default)]
    pub x_unit: XUnit,
    /// Lamps on both edges: measure from the nearer.
    #[serde(default)]
    pub mirror: bool,
    /// Where the dots sit: "lattice" (default), "jittered", "stochastic", "virtual".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placement: Option<String>,
    /// Which random screen (jittered, stochastic); 0 when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placement_seed: Option<i64>,
}

impl DotsSpec {
    /// The density keys as the file gives them.
    pub fn density_keys(&self) -> DensityKeys {
        DensityKeys {
            density: self.density.clone(),
            density_table: self.density_table.clone(),
            density_grid: self.density_grid.clone(),
        }
    }

    /// Give the density by `density` (its keys, [`Density::keys`]), in place of the
    /// file's.
    pub fn set_density(&mut self, density: &Density) {
        let keys = density.keys();
        (self.density, self.density_table, self.density_grid) =
            (keys.density, keys.density_table, keys.density_grid);
    }
}

/// A dielectric face with printed Lambertian ink dots.
#[derive(Clone, Debug, PartialEq)]
pub struct Dots {
    /// The interface outside the dots.
    pub interface: Interface,
    /// The dot layout (its `across` zero until [`DotPattern::fit_to_face`] when the file
    /// leaves it to the face).
    pub pattern: DotPattern,
    /// Albedo of the ink (the rest is absorbed).
    pub ink_albedo: Spectral,
}

impl Surface for Dots {
    #[inline]
    fn interact(&self, at: &Arrival, rng: &mut PhotonRng) -> (Outcome, Feature) {
        if self.pattern.meets_ink(at.hit.point, rng) {
            let ink = at.reflect(&self.ink_albedo, rng, |rng| lambert::back(at, rng));
            return (ink, Feature::Ink);
        }
        (dielectric::smooth(at, &self.interface, rng), Feature::Plain)
    }

    fn interface(&self) -> Option<Interface> {
        Some(self.interface)
    }

    fn meter_vertex(&self, feature: Feature) -> MeterVertex {
        match feature {
            Feature::Ink => MeterVertex::Diffuse,
            _ => MeterVertex::Specular,
        }
    }

    fn meter_density(&self, at: &Arrival, _feature: Feature, out: DVec3) -> f64 {
        self.ink_albedo.at(at.light) * lambert::density(at.facing(), out)
    }

    fn translate(&mut self, by: DVec3) {
        self.pattern.origin += by;
    }

    /// The pattern's axes in the face; its pitch and spans against the face's reach
    /// ([`check_pitch`], [`check_span`]).
    fn fit_to_face(&mut self, ctx: &Ctx, at: &str, face: &Face) -> Result<()> {
        let pattern = &mut self.pattern;
        let n = face.normals().next().expect("used tag has triangles");
        pattern.fit_to_face(ctx, at, n)?;
        let r = face.reach(pattern.origin);
        check_pitch(ctx, &format!("{at}.pitch_mm"), pattern.pitch, r)?;
        let graded = &pattern.grade;
        if !graded.is_constant() || graded.mirror {
            check_span(ctx, &format!("{at}.length_mm"), graded.length, r)?;
        }
        if let Density::Grid(g) = &graded.density {
            check_span(ctx, &format!("{at}.density_grid.width_mm"), g.width, r)?;
        }
        Ok(())
    }
}

impl SurfaceSpecOf for DotsSpec {
    /// Check `[surfaces.TAG]` and build its model.
    type Model = Dots;

    fn build(&self, ctx: &Ctx, at: &str, media: &[Medium]) -> Result<Dots> {
        let f = |k: &str| format!("{at}.{k}");
        let length = ctx.length(&f("length_mm"), self.length_mm)?;
        let x_max = graded_x_max(length, self.x_unit, self.mirror);
        let (density, field) = Density::from_keys(ctx, at, self.density_keys(), None, x_max)?;
        let lattice = self.lattice;
        let placement = Placement::parse(ctx, &f("placement"), self.placement.as_deref())?;
        let pattern = DotPattern {
            placement,
            placement_seed: placement.seed(ctx, &f("placement_seed"), self.placement_seed)?,
            lattice,
            pitch: ctx.positive(&f("pitch_mm"), self.pitch_mm)?,
            origin: ctx.point(&f("origin"), self.origin)?,
            axis: ctx.direction(&f("axis"), self.axis)?,
            across: match self.across {
                Some(a) => ctx.direction(&f("across"), a)?,
                None => DVec3::ZERO,
            },
            grade: Gradation {
                density,
                length,
                x_unit: self.x_unit,
                mirror: self.mirror,
            },
        };
        if let Some((u, d)) = pattern.first_out_of_range() {
            return Err(ctx.err(&field, format!(
                "d(x) = {d:.4} at {u:.3} mm from the origin is outside [0, {:.4}] (the {:?} lattice's packing limit)",
                lattice.max_packing(), lattice
            )));
        }
        Ok(Dots {
            interface: Interface::build(ctx, at, &self.inside, &self.outside, media)?,
            pattern,
            ink_albedo: self
                .ink_albedo
                .build(ctx, &f("ink_albedo"), Range::Fraction)?,
        })
    }
}

/// Cell lattice of the dot grid.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize, schemars::JsonSchema,
)]
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
        self.dot_radius_squared(pitch, density).sqrt()
    }

    /// The square of [`Lattice::dot_radius`] (what an ink test compares with).
    pub fn dot_radius_squared(self, pitch: f64, density: f64) -> f64 {
        density.max(0.0) * self.cell_area(pitch) / PI
    }
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
    /// The density graded along `axis`, over the pattern's span.
    pub grade: Gradation,
    /// Where the dots sit (see [`super::dot_placement`]).
    pub placement: Placement,
    /// Which random screen (jittered, stochastic placements).
    pub placement_seed: u64,
}

impl DotPattern {
    /// The polynomial variable at distance `u` (mm) along the axis from the origin.
    pub fn x_of(&self, u: f64) -> f64 {
        self.grade.x_of(u)
    }

    /// The density (area fraction) at distance `u` (mm) along the axis.
    pub fn density_at(&self, u: f64) -> f64 {
        self.grade.at(u)
    }

    /// The polynomial variable at the far end of the span (1 when normalized, else the
    /// span in mm: the length, or half of it when mirrored).
    pub fn x_max(&self) -> f64 {
        graded_x_max(self.grade.length, self.grade.x_unit, self.grade.mirror)
    }

    /// Check that the density is finite and within `[0, max packing]` along the whole
    /// span. Returns the first offending position (mm) and value.
    pub fn first_out_of_range(&self) -> Option<(f64, f64)> {
        self.grade.first_outside(0.0, self.lattice.max_packing())
    }

    /// Fit the pattern to its face, of unit normal `normal` (its table `at`,
    /// `surfaces.TAG`): `axis` must lie in the face; `across`, when the file left it out,
    /// becomes `normal x axis`, else it must lie in the face, perpendicular to `axis`.
    pub fn fit_to_face(&mut self, ctx: &Ctx, at: &str, normal: DVec3) -> Result<()> {
        let n = normal;
        if self.axis.dot(n).abs() > 1e-6 {
            return Err(ctx.err(
                &format!("{at}.axis"),
                "must lie in the face (it is not perpendicular to the face normal)",
            ));
        }
        if self.across == DVec3::ZERO {
            self.across = n.cross(self.axis).normalize();
        } else if self.across.dot(n).abs() > 1e-6 || self.across.dot(self.axis).abs() > 1e-6 {
            return Err(ctx.err(
                &format!("{at}.across"),
                "must lie in the face, perpendicular to axis",
            ));
        }
        Ok(())
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

    /// The density at face coordinates `c` (mm along `axis`, mm along `across`): a grid
    /// uses both, the other densities only the first.
    pub fn density_at_point(&self, c: DVec2) -> f64 {
        self.grade.density.at(self.x_of(c.x), c.y)
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
    #[cfg(test)]
    fn nearest_centre(&self, q: DVec2) -> DVec2 {
        let (i, j) = self.nearest_cell(q);
        self.cell_centre(i, j)
    }
}

/// A lattice pattern for tests: pitch 0.5 mm on the plane z = 0 from the origin along x,
/// 100 mm long, constant `density`.
#[cfg(test)]
pub(crate) fn test_pattern(lattice: Lattice, density: f64) -> DotPattern {
    DotPattern {
        lattice,
        pitch: 0.5,
        origin: DVec3::ZERO,
        axis: DVec3::X,
        across: DVec3::Y,
        grade: Gradation {
            density: Density::Polynomial(vec![density]),
            length: 100.0,
            x_unit: XUnit::Normalized,
            mirror: false,
        },
        placement: Placement::Lattice,
        placement_seed: 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
                let got = coverage(&test_pattern(lattice, d));
                assert!((got - d).abs() < 0.01, "{lattice:?} d={d}: covered {got}");
            }
        }
    }

    #[test]
    fn mirror_measures_from_nearer_edge() {
        let mut p = test_pattern(Lattice::Square, 0.0);
        p.grade.density = Density::Polynomial(vec![0.0, 1.0]);
        p.grade.mirror = true;
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
        let mut p = test_pattern(Lattice::Square, 0.0);
        p.grade.density = Density::Table(vec![[0.0, 0.05], [1.0, 0.65]]);
        let got = coverage(&p); // patch x 20..30 of 100: mean x = 0.25
        assert!((got - 0.2).abs() < 0.01, "covered {got}");
    }

    #[test]
    fn cell_centres_are_lattice_points() {
        for lattice in [Lattice::Square, Lattice::Hex] {
            let p = test_pattern(lattice, 0.3);
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
        let mut p = test_pattern(Lattice::Square, 0.1);
        assert_eq!(p.first_out_of_range(), None);
        p.grade.density = Density::Polynomial(vec![0.1, 1.0]);
        let (u, d) = p.first_out_of_range().unwrap();
        assert!(d > PI / 4.0 && u > 60.0 && u < 70.0, "u={u} d={d}");
        p.grade.density = Density::Polynomial(vec![-0.01]);
        assert!(p.first_out_of_range().is_some());
    }
}
