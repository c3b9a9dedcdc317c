//! Polarized light: Stokes vectors in a frame tied to the direction of travel, and the
//! Mueller matrices of the events that change them (Fresnel reflection and refraction with
//! the phase retardance of total internal reflection, mirrors, dichroic and reflective
//! polarizers), checked against closed forms. The tracer does not carry Stokes vectors
//! yet (it averages Fresnel over s and p at every event): that is issue 46's tracer work.
//!
//! Conventions (those of the detector's `polarization` output): a photon travelling along
//! unit `d` carries a Stokes vector `S = (S0, S1, S2, S3)` referred to a unit vector `u`
//! perpendicular to `d`, with `v = d x u`. `S1 > 0` is linear polarization along `u`, `S2 > 0`
//! along `(u + v)/sqrt 2`, `S3 > 0` the circular state whose field turns from `u` towards
//! `v` (time dependence `exp(-i w t)`, as in Born & Wolf).
//!
//! At an interface the frame is turned to `u = s`, the normal to the plane of incidence,
//! for both the incident and the outgoing light (so `v` is the p direction of each). The
//! amplitude coefficients are Born & Wolf's (section 1.5.2):
//! `r_s = (n1 cos_i - n2 cos_t)/(n1 cos_i + n2 cos_t)`,
//! `r_p = (n2 cos_i - n1 cos_t)/(n2 cos_i + n1 cos_t)`,
//! `t_s = 2 n1 cos_i/(n1 cos_i + n2 cos_t)`, `t_p = 2 n1 cos_i/(n2 cos_i + n1 cos_t)`,
//! whose p basis is `v = d x s` for every wave: at normal incidence `r_p = -r_s`, the
//! reflected wave's `v` being the incident one's reversed, so a reflection turns the
//! handedness of circular light, as it must. Beyond the critical angle `cos_t = i k` with
//! `k = sqrt(sin_t^2 - 1)` (the evanescent wave decays), `|r_s| = |r_p| = 1` and the
//! phase difference between them is the retardance of total internal reflection.

use glam::DVec3;
use num_complex::Complex64;

/// A Stokes vector `(S0, S1, S2, S3)` (in the frame of the module header).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stokes(pub [f64; 4]);

/// A 4 x 4 Mueller matrix, row-major: `S_out = M S_in`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mueller(pub [[f64; 4]; 4]);

impl Stokes {
    /// Unpolarized light of unit power.
    pub const UNPOLARIZED: Stokes = Stokes([1.0, 0.0, 0.0, 0.0]);

    /// Fully linearly polarized light of unit power at `deg` degrees from `u` towards `v`.
    pub fn linear_deg(deg: f64) -> Stokes {
        let a = 2.0 * deg.to_radians();
        Stokes([1.0, a.cos(), a.sin(), 0.0])
    }

    /// The power `S0`.
    pub fn power(self) -> f64 {
        self.0[0]
    }

    /// The degree of polarization `sqrt(S1^2 + S2^2 + S3^2) / S0` (0 for no power).
    pub fn dop(self) -> f64 {
        let [s0, s1, s2, s3] = self.0;
        if s0 > 0.0 {
            (s1 * s1 + s2 * s2 + s3 * s3).sqrt() / s0
        } else {
            0.0
        }
    }

    /// The same state scaled to unit power (unchanged when it has none).
    pub fn normalized(self) -> Stokes {
        let s0 = self.0[0];
        if s0 > 0.0 {
            Stokes(self.0.map(|c| c / s0))
        } else {
            self
        }
    }

    /// The state referred to a frame turned by `psi` radians about the direction of
    /// travel (from `u` towards `v`): a linear state at angle `a` is then at `a - psi`.
    pub fn rotated_frame(self, psi: f64) -> Stokes {
        let [s0, s1, s2, s3] = self.0;
        let (s, c) = (2.0 * psi).sin_cos();
        Stokes([s0, c * s1 + s * s2, c * s2 - s * s1, s3])
    }

    /// The state referred to the frame `to` instead of `from` (both unit vectors
    /// perpendicular to the unit direction `d`).
    pub fn reframed(self, d: DVec3, from: DVec3, to: DVec3) -> Stokes {
        self.rotated_frame(frame_angle(d, from, to))
    }
}

/// The angle (radians) that turns the unit vector `from` into `to` about the unit `d`,
/// both perpendicular to it (positive from `u` towards `v = d x u`).
pub fn frame_angle(d: DVec3, from: DVec3, to: DVec3) -> f64 {
    d.dot(from.cross(to)).atan2(from.dot(to))
}

/// A unit vector perpendicular to the unit `d` (the frame of light whose frame does not
/// matter yet: unpolarized light, a fresh photon).
pub fn any_frame(d: DVec3) -> DVec3 {
    d.any_orthonormal_vector()
}

/// The s direction of light travelling along unit `d` meeting a face of unit normal `n`:
/// `d x n` normalized, or (at normal incidence, where every direction is an s direction)
/// `fallback` made perpendicular to `d`.
pub fn s_axis(d: DVec3, n: DVec3, fallback: DVec3) -> DVec3 {
    let s = d.cross(n);
    let len = s.length();
    if len > 1e-12 {
        s / len
    } else {
        let f = fallback - fallback.dot(d) * d;
        f.try_normalize().unwrap_or_else(|| any_frame(d))
    }
}

impl Mueller {
    /// The identity (no change).
    pub const IDENTITY: Mueller = Mueller([
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]);

    /// `self` applied to `s`.
    pub fn apply(&self, s: Stokes) -> Stokes {
        let m = &self.0;
        let row = |r: &[f64; 4]| r[0] * s.0[0] + r[1] * s.0[1] + r[2] * s.0[2] + r[3] * s.0[3];
        Stokes([row(&m[0]), row(&m[1]), row(&m[2]), row(&m[3])])
    }

    /// The power `self` passes of the state `s`, without the rest of the product (a
    /// roulette's probability).
    pub fn power_of(&self, s: Stokes) -> f64 {
        let r = &self.0[0];
        r[0] * s.0[0] + r[1] * s.0[1] + r[2] * s.0[2] + r[3] * s.0[3]
    }

    /// The matrix of an element that passes power `a` of light polarized along `u` and `b`
    /// of light along `v` (intensities), with the complex amplitude product
    /// `c = amp_u conj(amp_v)` (whose real part keeps `S2`, imaginary part mixes `S2` and
    /// `S3`): every Fresnel event, polarizer and mirror in its own frame is one.
    pub fn diattenuator(a: f64, b: f64, c: Complex64) -> Mueller {
        let (p, m) = (0.5 * (a + b), 0.5 * (a - b));
        Mueller([
            [p, m, 0.0, 0.0],
            [m, p, 0.0, 0.0],
            [0.0, 0.0, c.re, c.im],
            [0.0, 0.0, -c.im, c.re],
        ])
    }
}

/// The complex Fresnel amplitude coefficients `(r_s, r_p)` of light going from index `n1`
/// to `n2` at incidence cosine `cos_i` (in `[0, 1]`), total internal reflection included.
pub fn reflection_amplitudes(cos_i: f64, n1: f64, n2: f64) -> (Complex64, Complex64) {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let eta = n1 / n2;
    let cos2_t = (1.0 - eta) * (1.0 + eta) + eta * eta * cos_i * cos_i;
    let cos_t = if cos2_t >= 0.0 {
        Complex64::new(cos2_t.sqrt(), 0.0)
    } else {
        Complex64::new(0.0, (-cos2_t).sqrt())
    };
    let (a, b) = (Complex64::from(n1 * cos_i), n2 * cos_t);
    let (c, d) = (Complex64::from(n2 * cos_i), n1 * cos_t);
    ((a - b) / (a + b), (c - d) / (c + d))
}

/// The Mueller matrix of Fresnel reflection (frame `u = s` on both sides), total internal
/// reflection's retardance included.
pub fn fresnel_reflection(cos_i: f64, n1: f64, n2: f64) -> Mueller {
    let (rs, rp) = reflection_amplitudes(cos_i, n1, n2);
    Mueller::diattenuator(rs.norm_sqr(), rp.norm_sqr(), rs * rp.conj())
}

/// The Mueller matrix of Fresnel refraction (frame `u = s` on both sides), the power
/// factor `n2 cos_t / (n1 cos_i)` included; `None` under total internal reflection.
pub fn fresnel_transmission(cos_i: f64, n1: f64, n2: f64) -> Option<Mueller> {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let cos_t = super::fresnel::cos_transmitted(cos_i, n1, n2)?;
    if cos_i == 0.0 || cos_t == 0.0 {
        return None; // grazing, or at the critical angle: nothing passes
    }
    let ts = 2.0 * n1 * cos_i / (n1 * cos_i + n2 * cos_t);
    let tp = 2.0 * n1 * cos_i / (n2 * cos_i + n1 * cos_t);
    let k = n2 * cos_t / (n1 * cos_i);
    Some(Mueller::diattenuator(
        k * ts * ts,
        k * tp * tp,
        Complex64::from(k * ts * tp),
    ))
}

/// A mirror of reflectance `r` for every state, as a perfect conductor reflects (frame
/// `u = s`): the field's s part keeps its sign and its p part turns with the wave, so
/// `S2` and `S3` change sign. A stand-in for a metal, whose retardance it leaves out.
pub fn mirror(r: f64) -> Mueller {
    Mueller::diattenuator(r, r, Complex64::from(-r))
}

/// A polarizer's transmission in the frame `u = block` (the field direction it blocks):
/// power `t_block` of the blocked state and `t_pass` of the passed one, coherent between
/// them (a dichroic sheet is a diattenuator without retardance).
pub fn polarizer_transmission(t_pass: f64, t_block: f64) -> Mueller {
    Mueller::diattenuator(t_block, t_pass, Complex64::from((t_block * t_pass).sqrt()))
}

/// A polarizer's reflection in the frame `u = block` of the reflected light: power
/// `r_block` of the blocked state and `r_pass` of the passed one, reflected as a mirror
/// reflects (the p-like part turns with the wave, see [`mirror`]).
pub fn polarizer_reflection(r_pass: f64, r_block: f64) -> Mueller {
    Mueller::diattenuator(r_block, r_pass, Complex64::from(-(r_block * r_pass).sqrt()))
}

/// The block direction, for light along unit `d`, of a polarizer whose face has unit
/// normal `n` and whose block axis in the face is the unit `block`: `block` made
/// perpendicular to `d` (the field the absorbing chains or wires of the sheet see, as in
/// Korger et al. 2013's dichroic model); `None` when `d` runs along `block`, where every
/// field is perpendicular to the chains and passes.
pub fn block_direction(d: DVec3, block: DVec3) -> Option<DVec3> {
    (block - block.dot(d) * d).try_normalize()
}

/// A photon's polarization: its Stokes vector, of unit power, referred to the unit
/// vector `u` perpendicular to its direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Polarization {
    /// The state, `S0 = 1`.
    pub stokes: Stokes,
    /// The frame's `u` (perpendicular to the direction of travel).
    pub u: DVec3,
}

impl Polarization {
    /// Unpolarized light travelling along unit `d`.
    pub fn unpolarized(d: DVec3) -> Polarization {
        Polarization {
            stokes: Stokes::UNPOLARIZED,
            u: any_frame(d),
        }
    }

    /// The state of light along unit `d` referred to the unit `to` (perpendicular to `d`).
    pub fn stokes_in(&self, d: DVec3, to: DVec3) -> Stokes {
        self.stokes.reframed(d, self.u, to)
    }

    /// The state after `m` (in the frame `u`), scaled back to unit power.
    fn after(m: &Mueller, s: Stokes, u: DVec3) -> Polarization {
        Polarization {
            stokes: m.apply(s).normalized(),
            u,
        }
    }
}

/// [`super::fresnel::roulette`] for polarized light: reflected with probability
/// `R(S)`, the power the reflection Mueller matrix passes of the photon's state (always
/// under total internal reflection), else refracted; `pol` becomes the state of the
/// light that leaves, in the frame `u = s`. `None` for `pol` is the averaged roulette,
/// with the same random numbers.
#[inline]
pub fn fresnel_roulette(
    dir: DVec3,
    facing: DVec3,
    (n1, n2): (f64, f64),
    pol: Option<&mut Polarization>,
    rng: &mut crate::rng::PhotonRng,
) -> Option<DVec3> {
    let Some(pol) = pol else {
        return super::fresnel::roulette(dir, facing, n1, n2, rng);
    };
    let s = s_axis(dir, facing, pol.u);
    let stokes = pol.stokes_in(dir, s);
    let cos_i = -dir.dot(facing);
    let reflection = fresnel_reflection(cos_i, n1, n2);
    let r = reflection.power_of(stokes);
    let transmission = fresnel_transmission(cos_i, n1, n2);
    let refracted = match transmission {
        Some(t) if r < 1.0 && rng.uniform() >= r => Some(t),
        _ => None,
    };
    match refracted {
        Some(t) => {
            *pol = Polarization::after(&t, stokes, s);
            super::fresnel::refract(dir, facing, n1, n2)
        }
        None => {
            *pol = Polarization::after(&reflection, stokes, s);
            None
        }
    }
}

/// The light of state `pol` along unit `dir` meeting the unit normal `facing` (from
/// index `n1` to `n2`) and leaving by reflection (`reflect`) or by refraction: the
/// fraction of its power that does (as [`fresnel_roulette`] draws it) and its state
/// then, in the frame `u = s`; `None` for refraction beyond the critical angle.
pub fn fresnel_branch(
    dir: DVec3,
    facing: DVec3,
    (n1, n2): (f64, f64),
    pol: &Polarization,
    reflect: bool,
) -> Option<(f64, Polarization)> {
    let s = s_axis(dir, facing, pol.u);
    let stokes = pol.stokes_in(dir, s);
    let cos_i = -dir.dot(facing);
    let r = fresnel_reflection(cos_i, n1, n2);
    let m = match (reflect, fresnel_transmission(cos_i, n1, n2)) {
        (true, _) => r,
        (false, Some(t)) => t,
        (false, None) => return None,
    };
    // The roulette's complement, so the two branches sum to one exactly.
    let power = match reflect {
        true => r.power_of(stokes).min(1.0),
        false => 1.0 - r.power_of(stokes).min(1.0),
    };
    Some((power, Polarization::after(&m, stokes, s)))
}

/// What a detector's response `importance` (a Stokes-like vector carried backwards from
/// the detector, along unit `-d`, in the frame `u`) makes of light of state `light`
/// travelling along `d`: `sum I_i S_i` after the time reversal that turns the backward
/// frame into the forward one (`v` and the phase reversed: `Q = diag(1, 1, -1, 1)`, for
/// which a Fresnel matrix `M` of this module has the reversed light's matrix `Q M^T Q`: tested for Fresnel reflection, refraction and total
/// internal reflection).
pub fn response(importance: &Polarization, light: &Polarization, d: DVec3) -> f64 {
    let s = light.stokes_in(d, importance.u).0;
    let i = importance.stokes.0;
    i[0] * s[0] + i[1] * s[1] - i[2] * s[2] + i[3] * s[3]
}

/// The state of light after a mirror of reflectance `r` (any `r`: the state is scaled
/// back to unit power), reflected from unit `dir` at the unit normal `facing`.
pub fn mirrored(pol: &Polarization, dir: DVec3, facing: DVec3) -> Polarization {
    let s = s_axis(dir, facing, pol.u);
    Polarization::after(&mirror(1.0), pol.stokes_in(dir, s), s)
}

#[cfg(test)]
#[path = "polarization_tests.rs"]
mod tests;
