//! Polarizers: sheets that pass one linear polarization and absorb (a dichroic sheet, the
//! panel's polarizer) or reflect (a reflective polarizer: DBEF, APF, a wire grid) the
//! other.
//!
//! ```toml
//! [surfaces.dbef]
//! model = "polarizer"            # a face (an open sheet is fine) with the same medium on both sides
//! axis = [1.0, 0.0, 0.0]         # pass axis, projected into the face
//! pass_transmittance = 0.95      # number or spectrum table
//! block_transmittance = 0.001    # of light across the axis (extinction)
//! block_reflectance = 0.97       # 0 for an absorbing (iodine/dye) polarizer; DBEF ~0.9-0.97
//! # pass_reflectance = 0.0       # optional
//! ```
//!
//! The face-plane direction across `axis` is the block axis, the direction of the
//! absorbing chains of a dichroic sheet or the wires of a grid. Light along `d` has its
//! block state polarized along the block axis made perpendicular to `d`, its pass state
//! perpendicular to that and to `d` (the dichroic model of Mitsuba 3's `polarizer`
//! plugin after Korger et al., Opt. Express 21, 27032 (2013)). Each state passes its
//! transmittance and reflects its reflectance (into the mirror direction), the rest is
//! absorbed; an ideal reflective polarizer (pass 1, block reflected 1) loses nothing at
//! any angle. The light stays in its medium: the sheet has no thickness and no index.
//!
//! A stand-in for the real films: the transmittances and reflectances are the same at
//! every angle of incidence (a DBEF stack's fall off beyond 60 degrees and its colour
//! with angle are left out), the sheet does not retard (DBEF's birefringent layers turn
//! the phase of oblique light a little), and the reflection is specular (a DBEF with a
//! diffusing skin scatters it). Needs polarization traced: a scene with a polarizer
//! traces it.

use super::medium::Medium;
use super::model::{
    Arrival, Face, Feature, MeterLayer, MeterVertex, Outcome, Surface, SurfaceSpecOf,
};
use super::polarization::{
    Polarization, any_frame, block_direction, polarizer_reflection, polarizer_transmission,
};
use super::spectrum::{Range, Spectral, SpectralValue};
use crate::rng::PhotonRng;
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// `[surfaces.TAG]` with `model = "polarizer"`.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PolarizerSpec {
    /// The pass axis, projected into the face.
    pub axis: [f64; 3],
    /// Transmittance of light polarized along the pass axis.
    pub pass_transmittance: SpectralValue,
    /// Transmittance of light polarized along the block axis.
    pub block_transmittance: SpectralValue,
    /// Reflectance of light polarized along the block axis.
    pub block_reflectance: SpectralValue,
    /// Reflectance of light polarized along the pass axis.
    #[serde(default = "zero")]
    pub pass_reflectance: SpectralValue,
}

fn zero() -> SpectralValue {
    SpectralValue::Constant(0.0)
}

/// A polarizer sheet.
#[derive(Clone, Debug, PartialEq)]
pub struct Polarizer {
    /// The pass axis as the file gives it (unit).
    axis: DVec3,
    /// Transmittance and reflectance of the pass state.
    pass: (Spectral, Spectral),
    /// Transmittance and reflectance of the block state.
    block: (Spectral, Spectral),
}

impl SurfaceSpecOf for PolarizerSpec {
    type Model = Polarizer;

    fn build(&self, ctx: &Ctx, at: &str, _media: &[Medium]) -> Result<Polarizer> {
        let field = |f: &str| format!("{at}.{f}");
        let axis = ctx.direction(&field("axis"), self.axis)?;
        let build = |v: &SpectralValue, f: &str| v.build(ctx, &field(f), Range::Fraction);
        let pass = (
            build(&self.pass_transmittance, "pass_transmittance")?,
            build(&self.pass_reflectance, "pass_reflectance")?,
        );
        let block = (
            build(&self.block_transmittance, "block_transmittance")?,
            build(&self.block_reflectance, "block_reflectance")?,
        );
        for (state, (t, r)) in [("pass", &pass), ("block", &block)] {
            let (_, most) = t.plus(r).range();
            if most > 1.0 + 1e-12 {
                return Err(ctx.err(
                    &field(&format!("{state}_transmittance")),
                    format!(
                        "{state}_transmittance + {state}_reflectance reaches {}, more than 1: the sheet would make light",
                        crate::spec_check::short(most)
                    ),
                ));
            }
        }
        Ok(Polarizer { axis, pass, block })
    }
}

impl Surface for Polarizer {
    fn meter_vertex(&self, _feature: Feature) -> MeterVertex {
        MeterVertex::Specular
    }

    /// The same everywhere and reciprocal (tested in `polarization`): the meter's
    /// backward walk crosses it.
    fn meter_layer(&self) -> MeterLayer {
        MeterLayer::Flat
    }

    fn interact(&self, at: &Arrival, rng: &mut PhotonRng) -> (Outcome, Feature) {
        let normal = at.hit.normal;
        let pol = at.pol.unwrap_or_else(|| Polarization::unpolarized(at.dir));
        let (tp, rp) = (self.pass.0.at(at.light), self.pass.1.at(at.light));
        let (tb, rb) = (self.block.0.at(at.light), self.block.1.at(at.light));
        let block = self.block_axis(normal);
        let (d, mirrored) = (at.dir, super::fresnel::reflect(at.dir, normal));
        let frame = |d: DVec3| block_direction(d, block).unwrap_or_else(|| any_frame(d));
        let s = pol.stokes_in(d, frame(d));
        let (t, r) = (polarizer_transmission(tp, tb), polarizer_reflection(rp, rb));
        let (pt, pr) = (t.power_of(s), r.power_of(s));
        let Some(weight) = at.est.survive(pt + pr, rng) else {
            return (Outcome::Absorbed, Feature::Plain);
        };
        let through = rng.uniform() * (pt + pr) < pt;
        let (dir, m) = if through { (d, t) } else { (mirrored, r) };
        at.pol_out.set(Some(Polarization {
            stokes: m.apply(s).normalized(),
            u: frame(dir),
        }));
        let outcome = Outcome::Scattered {
            dir,
            medium: at.medium,
            weight,
        };
        (outcome, Feature::Plain)
    }

    /// The axis must not be normal to any triangle of the face (it would have no
    /// direction in the face).
    fn fit_to_face(&mut self, ctx: &Ctx, at: &str, face: &Face) -> Result<()> {
        for n in face.normals() {
            if (self.axis - self.axis.dot(n) * n).length() < 1e-6 {
                return Err(ctx.err(
                    &format!("{at}.axis"),
                    "is normal to the face: the pass axis must have a direction in it",
                ));
            }
        }
        Ok(())
    }
}

impl Polarizer {
    /// Whether a transmittance or reflectance varies with wavelength (then which way the
    /// light goes does too).
    pub fn is_spectral(&self) -> bool {
        [&self.pass.0, &self.pass.1, &self.block.0, &self.block.1]
            .iter()
            .any(|q| q.is_spectral())
    }

    /// The block axis on a face of unit normal `normal`: the face-plane direction across
    /// the pass axis.
    fn block_axis(&self, normal: DVec3) -> DVec3 {
        let pass = (self.axis - self.axis.dot(normal) * normal).normalize();
        normal.cross(pass)
    }
}
