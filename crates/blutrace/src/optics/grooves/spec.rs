//! The `grooves` entry of the scene file and its checks (the format is shown in
//! [`super`]).

use super::pattern::{GroovePattern, Relief};
use crate::optics::density::{
    Density, DensityKeys, Gradation, XUnit, check_cells, check_pitch, check_span,
};
use crate::optics::dielectric;
use crate::optics::medium::{Interface, Medium, air};
use crate::optics::model::{
    Arrival, Face, Feature, MeterLayer, MeterVertex, Outcome, Surface, SurfaceSpecOf,
};
use crate::rng::PhotonRng;
use crate::spec_check::{Ctx, short};

/// Narrowest accepted apex angle (degrees): a groove 5730 pitches deep. Below about 1e-15
/// degrees the slit's depth left a run of 2000 photons taking 18 s instead of 1.4 s.
pub const MIN_APEX_DEG: f64 = 0.01;
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// `[surfaces.TAG]` with `model = "grooves"`.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GroovesSpec {
    /// Medium behind the face.
    pub inside: String,
    /// Medium in front of the face.
    #[serde(default = "air")]
    pub outside: String,
    /// Notches cut into `inside`, or prisms raised out of the face.
    pub relief: Relief,
    /// Angle between the two facets (deg), in [0.01, 180): a finer V would be a groove
    /// thousands of pitches deep, whose paths the tracer cannot follow in bounded time.
    pub apex_deg: f64,
    /// Tilt of the V (deg): the facet on the `-axis` side gets base angle
    /// `90 - apex/2 + tilt`, the other `90 - apex/2 - tilt`.
    #[serde(default)]
    pub tilt_deg: f64,
    /// Groove pitch (mm).
    pub pitch_mm: f64,
    /// A point on the lamp edge (mm), where the first cell starts.
    pub origin: [f64; 3],
    /// In-face direction across the grooves (away from the lamp).
    pub axis: [f64; 3],
    /// Span along `axis` (mm); needed when the fill varies or is mirrored.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length_mm: Option<f64>,
    /// Fill fraction polynomial, lowest degree first (default `[1.0]`; or
    /// `density_table`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<Vec<f64>>,
    /// Tabulated fill fraction: knots `[x, f]`, x increasing (or `density`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density_table: Option<Vec<[f64; 2]>>,
    /// Unit of the polynomial variable.
    #[serde(default)]
    pub x_unit: XUnit,
    /// Lamps on both edges: measure from the nearer.
    #[serde(default)]
    pub mirror: bool,
}

/// A dielectric face carrying procedural V-grooves or prisms.
#[derive(Clone, Debug, PartialEq)]
pub struct Grooves {
    /// The two media either side of the relief.
    pub interface: Interface,
    /// The groove layout.
    pub pattern: GroovePattern,
}

impl Surface for Grooves {
    /// Facets and the flat between them are specular; a facet turns the light's
    /// direction across the face, which the flat-layer peel-off path notices and leaves
    /// to the cone count, and which the backward walk crosses.
    fn meter_vertex(&self, _feature: Feature) -> MeterVertex {
        MeterVertex::Specular
    }

    /// Uniform grooves (a prism film) are the same at every point on the scale of a
    /// map's bins (many pitches to a bin): the backward walk crosses them, meeting them
    /// at whatever phase its path has. Graded ones are a pattern.
    fn meter_layer(&self) -> MeterLayer {
        match self.pattern.fill.is_constant() {
            true => MeterLayer::Turning,
            false => MeterLayer::Not,
        }
    }

    #[inline]
    fn interact(&self, at: &Arrival, rng: &mut PhotonRng) -> (Outcome, Feature) {
        let i = &self.interface;
        let p = &self.pattern;
        let mut pol = at.pol;
        let (point, normal) = (at.hit.point, at.hit.normal);
        match p.scatter_met(at.indices(i), point, normal, at.dir, pol.as_mut(), rng) {
            Some((d, inside, met, shift)) => {
                at.pol_out.set(pol);
                at.shift_out.set(p.axis * shift);
                let feature = if met { Feature::Groove } else { Feature::Plain };
                (at.lossless(i, (d, inside)), feature)
            }
            None => (dielectric::smooth(at, i, rng), Feature::Plain),
        }
    }

    fn interface(&self) -> Option<Interface> {
        Some(self.interface)
    }

    fn translate(&mut self, by: DVec3) {
        self.pattern.origin += by;
    }

    /// The pattern's axis in the (flat) face; its pitch and span against the face's
    /// reach ([`check_pitch`], [`check_span`]).
    fn fit_to_face(&mut self, ctx: &Ctx, at: &str, face: &Face) -> Result<()> {
        let pattern = &mut self.pattern;
        pattern.fit_to_face(ctx, at, face.normals())?;
        let r = face.reach(pattern.origin);
        check_pitch(ctx, &format!("{at}.pitch_mm"), pattern.pitch, r)?;
        if !pattern.fill.is_constant() || pattern.fill.mirror {
            check_span(ctx, &format!("{at}.length_mm"), pattern.fill.length, r)?;
        }
        Ok(())
    }
}

impl SurfaceSpecOf for GroovesSpec {
    /// Check `[surfaces.TAG]` and build its model: the interface and the groove layout
    /// (its axis still to be fitted to the face, see [`GroovePattern::fit_to_face`]).
    type Model = Grooves;

    fn build(&self, ctx: &Ctx, at: &str, media: &[Medium]) -> Result<Grooves> {
        let f = |k: &str| format!("{at}.{k}");
        let pitch = ctx.positive(&f("pitch_mm"), self.pitch_mm)?;
        let apex = ctx.finite(&f("apex_deg"), self.apex_deg)?;
        if !(MIN_APEX_DEG..180.0).contains(&apex) {
            return Err(ctx.err(
                &f("apex_deg"),
                format!(
                    "must be within [{MIN_APEX_DEG}, 180) degrees (a narrower groove is a slit \
                     thousands of pitches deep), got {}",
                    short(apex)
                ),
            ));
        }
        let tilt = ctx.finite(&f("tilt_deg"), self.tilt_deg)?;
        let limit = (0.5 * apex).min(90.0 - 0.5 * apex);
        if tilt.abs() >= limit {
            return Err(ctx.err(
                &f("tilt_deg"),
                format!(
                    "must be within (-{limit}, {limit}) for apex_deg = {apex}, got {}: both facets must lean \
                     away from the apex (base angles 90 - apex/2 +- tilt within (0, 90) degrees)",
                    short(tilt)
                ),
            ));
        }
        let keys = DensityKeys {
            density: self.density.clone(),
            density_table: self.density_table.clone(),
            density_grid: None,
        };
        let constant = Some(Density::Polynomial(vec![1.0]));
        let (fill, field) = Density::from_keys(ctx, at, keys, constant, 1.0)?;
        let mut gradation = Gradation {
            density: fill,
            length: 1.0,
            x_unit: self.x_unit,
            mirror: self.mirror,
        };
        match self.length_mm {
            Some(l) => gradation.length = ctx.length(&f("length_mm"), l)?,
            None if !gradation.is_constant() || self.mirror => {
                return Err(ctx.err(
                    &f("length_mm"),
                    "missing: needed when the fill varies along axis or mirror = true",
                ));
            }
            None => {}
        }
        if let Some((u, v)) = gradation.first_outside(0.0, 1.0) {
            return Err(ctx.err(
                &field,
                format!(
                    "fill f(x) = {v:.4} at {u:.3} mm from the origin is outside [0, 1] \
                     (the fraction of each pitch taken by its groove)"
                ),
            ));
        }
        if !gradation.is_constant() {
            check_cells(ctx, &f("length_mm"), gradation.length, pitch)?;
        }
        let angles = GroovePattern::base_angles(apex.to_radians(), tilt.to_radians());
        Ok(Grooves {
            interface: Interface::build(ctx, at, &self.inside, &self.outside, media)?,
            pattern: GroovePattern::new(
                self.relief,
                pitch,
                angles,
                ctx.point(&f("origin"), self.origin)?,
                ctx.direction(&f("axis"), self.axis)?,
                gradation,
            ),
        })
    }
}

impl GroovePattern {
    /// Fit the pattern to its face, given the unit normals of the tag's triangles: the
    /// face must be flat with `axis` in it (the profile is traced in the plane of `axis`
    /// and the face normal); `axis` is made exactly perpendicular to the face normal.
    /// Runs after the faces are oriented.
    pub fn fit_to_face(
        &mut self,
        ctx: &Ctx,
        at: &str,
        normals: impl IntoIterator<Item = DVec3>,
    ) -> Result<()> {
        let mut normal = None;
        for n in normals {
            let first = *normal.get_or_insert(n);
            if n.dot(first).abs() < 1.0 - 1e-9 {
                return Err(ctx.err(
                    at,
                    "model grooves needs flat faces: the tag's triangles are not all parallel",
                ));
            }
        }
        let Some(n) = normal else { return Ok(()) };
        if self.axis.dot(n).abs() > 1e-6 {
            return Err(ctx.err(
                &format!("{at}.axis"),
                "must lie in the face (it is not perpendicular to the face normal)",
            ));
        }
        self.axis = (self.axis - n * self.axis.dot(n)).normalize();
        Ok(())
    }
}
