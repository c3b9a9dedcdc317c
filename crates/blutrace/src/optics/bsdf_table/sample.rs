//! The geometry and the sampling of a table: the frame about the specular direction its
//! (radial, azimuth) angles are measured in, the cells of its grid, and the importance
//! sampling of a direction from one (rotation, AOI) block.
//!
//! ## Frame
//! A photon arrives along `d` at a face whose normal on its side is `n` (the "facing"
//! normal), at the angle of incidence `theta` (`cos theta = -d . n`); `t` is the unit
//! tangential part of `d` (its direction of travel along the face). The specular
//! direction `s` is the mirror direction `cos theta n + sin theta t` for a BRDF and the
//! straight-through direction `d` for a BTDF (the sample's "direct transmission"). Radial
//! angle `r` is measured from `s`; azimuth 0 points from `s` towards the normal axis on
//! the side the light leaves (`e0`), and azimuths grow towards `e90 = s x e0`:
//! `w = cos r s + sin r (cos phi e0 + sin phi e90)`. At normal incidence `t` is the
//! direction of sample rotation 0 (see [`incidence`]).
//!
//! ## Cells
//! Each grid node is the centre of a cell: radial cells run from one midpoint between
//! nodes to the next (the first from 0, the last half a step beyond the last node, at
//! most 180 degrees), azimuth cells likewise (from 0 to 180 degrees, mirrored, for a
//! plane-symmetric table; around the circle for an asymmetric one). The BSDF is the
//! node's value over its cell and 0 beyond the last radial cell; directions below the
//! surface (on the wrong side of it) carry nothing.
//!
//! ## Sampling
//! The directions of a block are drawn exactly from the density `f cos+ / integral`
//! (`f` the cell's BSDF, `cos+` the cosine to the outgoing normal, 0 below the surface)
//! by rejection: a cell is drawn with probability proportional to `f A c_max` (`A` its
//! solid angle, `c_max` the largest `cos+` over it, in closed form), a direction
//! uniformly over its solid angle, kept with probability `cos+ / c_max`. The power that
//! leaves is the block's TIS: the table's values set the shape only. A block draws its
//! directions in the frame of its own AOI (the photon's plane of incidence and side):
//! a photon between two blocks' AOIs draws one of them in proportion to its share of the
//! interpolated TIS, which is the BSDF interpolated linearly in the angle of incidence at
//! each outgoing direction ([`super::Table::sample`]).

use super::format::ScatterType;
use crate::rng::PhotonRng;
use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// Draws before a block gives up (never reached by a table that passed its build
/// checks: each cell it can draw has directions above the surface).
pub const MAX_TRIES: usize = 10_000;

/// The least share of a block's draws that may land above the surface
/// ([`BlockSampler::kept`]): a block whose values lie (almost) all below the surface
/// would take hundreds of draws a photon, and is refused when the table is read instead.
pub const MIN_KEPT: f64 = 0.01;

/// How a photon meets a face: the angles that pick the table's block and the frame its
/// scattered directions are measured in.
#[derive(Clone, Copy, Debug)]
pub struct Incidence {
    /// Angle of incidence (radians).
    pub theta: f64,
    /// Sample rotation (radians, in [0, 2 pi)): the azimuth of the plane of incidence's
    /// normal `n x t`, from the face's `u` towards `v = n x u`.
    pub rotation: f64,
    /// Unit normal on the side the photon came from.
    pub n: DVec3,
    /// Unit tangential direction of travel.
    pub t: DVec3,
    /// The photon's unit direction.
    pub d: DVec3,
}

impl Incidence {
    /// The same arrival (plane of incidence, side, rotation) at the angle `theta`.
    pub fn at_angle(&self, theta: f64) -> Incidence {
        let (st, ct) = theta.sin_cos();
        Incidence {
            theta,
            d: (st * self.t - ct * self.n).normalize(),
            ..*self
        }
    }
}

/// The [`Incidence`] of a photon along unit `d` at a face of facing unit normal `n`
/// (on the photon's side), whose table frame has unit tangent `u` (perpendicular to `n`).
pub fn incidence(d: DVec3, n: DVec3, u: DVec3) -> Incidence {
    let cos_t = (-d.dot(n)).clamp(0.0, 1.0);
    let v = n.cross(u);
    let tangential = d + cos_t * n;
    let t = if tangential.length_squared() > 1e-24 {
        tangential.normalize()
    } else {
        u.cross(n)
    };
    let m = n.cross(t);
    Incidence {
        theta: cos_t.acos(),
        rotation: m.dot(v).atan2(m.dot(u)).rem_euclid(TAU),
        n,
        t,
        d,
    }
}

/// The frame about the specular direction of one scatter type.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// Specular direction (radial 0).
    pub s: DVec3,
    /// Azimuth 0: from `s` towards the outgoing normal.
    pub e0: DVec3,
    /// Azimuth 90 degrees: `s x e0`.
    pub e90: DVec3,
    /// The unit normal on the side the light leaves.
    pub out: DVec3,
}

impl Frame {
    /// The frame of `kind` for a photon meeting a face as `inc` says.
    pub fn new(kind: ScatterType, inc: &Incidence) -> Frame {
        let (sin_t, cos_t) = inc.theta.sin_cos();
        let (s, e0, out) = match kind {
            ScatterType::Brdf => (
                cos_t * inc.n + sin_t * inc.t,
                sin_t * inc.n - cos_t * inc.t,
                inc.n,
            ),
            ScatterType::Btdf => (inc.d, -sin_t * inc.n - cos_t * inc.t, -inc.n),
        };
        Frame {
            s,
            e0,
            e90: s.cross(e0),
            out,
        }
    }

    /// The unit direction at radial `r` and azimuth `phi` (radians).
    pub fn direction(&self, r: f64, phi: f64) -> DVec3 {
        let (sr, cr) = r.sin_cos();
        let (sp, cp) = phi.sin_cos();
        (cr * self.s + sr * (cp * self.e0 + sp * self.e90)).normalize()
    }

    /// The radial angle (in [0, pi]) and azimuth (in [0, 2 pi)) of unit `w`.
    pub fn angles(&self, w: DVec3) -> (f64, f64) {
        let r = w.dot(self.s).clamp(-1.0, 1.0).acos();
        let phi = w.dot(self.e90).atan2(w.dot(self.e0)).rem_euclid(TAU);
        (r, phi)
    }
}

/// The cells of a table's (radial, azimuth) grid, in radians.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// `n_radial + 1` increasing cell edges from 0.
    pub radial_edges: Vec<f64>,
    /// Each azimuth cell's start.
    pub az_lo: Vec<f64>,
    /// Each azimuth cell's width.
    pub az_width: Vec<f64>,
    /// Azimuths cover [0, pi] and mirror to [pi, 2 pi].
    pub plane_symmetric: bool,
}

impl Grid {
    /// The cells about the nodes `radial` and `azimuth` (degrees).
    pub fn new(radial: &[f64], azimuth: &[f64], plane_symmetric: bool) -> Grid {
        let rad: Vec<f64> = radial.iter().map(|a| a.to_radians()).collect();
        let mut radial_edges = vec![0.0];
        radial_edges.extend(rad.windows(2).map(|w| 0.5 * (w[0] + w[1])));
        let last = match rad.len() {
            1 => PI,
            n => (rad[n - 1] + 0.5 * (rad[n - 1] - rad[n - 2])).min(PI),
        };
        radial_edges.push(last);
        let az: Vec<f64> = azimuth.iter().map(|a| a.to_radians()).collect();
        let (az_lo, az_width) = if plane_symmetric {
            let mut edges = vec![0.0];
            edges.extend(az.windows(2).map(|w| 0.5 * (w[0] + w[1])));
            edges.push(PI);
            (
                edges[..az.len()].to_vec(),
                edges.windows(2).map(|w| w[1] - w[0]).collect(),
            )
        } else if az.len() == 1 {
            (vec![0.0], vec![TAU])
        } else {
            let n = az.len();
            let lo: Vec<f64> = (0..n)
                .map(|i| {
                    let prev = if i == 0 { az[n - 1] - TAU } else { az[i - 1] };
                    0.5 * (prev + az[i])
                })
                .collect();
            let width = (0..n)
                .map(|i| if i + 1 < n { lo[i + 1] } else { lo[0] + TAU } - lo[i])
                .collect();
            (lo, width)
        };
        Grid {
            radial_edges,
            az_lo,
            az_width,
            plane_symmetric,
        }
    }

    /// Number of radial cells.
    pub fn n_radial(&self) -> usize {
        self.radial_edges.len() - 1
    }

    /// The cell `(azimuth, radial)` a direction at `(r, phi)` (radians, `phi` in
    /// [0, 2 pi)) lies in; `None` beyond the last radial cell.
    pub fn cell_of(&self, r: f64, phi: f64) -> Option<(usize, usize)> {
        let n_r = self.n_radial();
        if r > self.radial_edges[n_r] {
            return None;
        }
        let ir = self.radial_edges[1..]
            .partition_point(|&e| e < r)
            .min(n_r - 1);
        let phi = if self.plane_symmetric && phi > PI {
            TAU - phi
        } else {
            phi
        };
        let ia = (0..self.az_lo.len())
            .find(|&i| (phi - self.az_lo[i]).rem_euclid(TAU) <= self.az_width[i])
            .unwrap_or(0);
        Some((ia, ir))
    }

    /// The solid angle of cell `(ia, ir)` (both mirrored halves of a plane-symmetric one).
    pub fn solid_angle(&self, ia: usize, ir: usize) -> f64 {
        let mirror = if self.plane_symmetric { 2.0 } else { 1.0 };
        let (lo, hi) = (self.radial_edges[ir], self.radial_edges[ir + 1]);
        mirror * self.az_width[ia] * (lo.cos() - hi.cos())
    }

    /// The projected solid angle of cell `(ia, ir)`: the integral of `cos+` to the
    /// outgoing normal over it (both halves), by midpoint quadrature on `k x k` points.
    pub fn projected_solid_angle(&self, frame: &Frame, ia: usize, ir: usize, k: usize) -> f64 {
        let (lo, hi) = (self.radial_edges[ir].cos(), self.radial_edges[ir + 1].cos());
        let (alo, aw) = (self.az_lo[ia], self.az_width[ia]);
        let mut sum = 0.0;
        for i in 0..k {
            let r = (lo + (hi - lo) * (i as f64 + 0.5) / k as f64)
                .clamp(-1.0, 1.0)
                .acos();
            for j in 0..k {
                let phi = alo + aw * (j as f64 + 0.5) / k as f64;
                sum += frame.direction(r, phi).dot(frame.out).max(0.0);
                if self.plane_symmetric {
                    sum += frame.direction(r, -phi).dot(frame.out).max(0.0);
                }
            }
        }
        sum * (lo - hi) * aw / (k * k) as f64
    }
}

/// The largest `cos+` to the outgoing normal over a cell `[r_lo, r_hi] x [phi_lo,
/// phi_lo + width]` at angle of incidence `theta`: `cos = cos theta cos r + sin theta
/// sin r cos phi` in the specular frame.
fn max_cos(theta: f64, (r_lo, r_hi): (f64, f64), (phi_lo, width): (f64, f64)) -> f64 {
    let phi_hi = phi_lo + width;
    let wraps = phi_lo.rem_euclid(TAU) + width >= TAU || phi_lo.rem_euclid(TAU) == 0.0;
    let c = if wraps {
        1.0
    } else {
        phi_lo.cos().max(phi_hi.cos())
    };
    let (st, ct) = theta.sin_cos();
    let g = |r: f64| ct * r.cos() + st * c * r.sin();
    let peak = (st * c).atan2(ct);
    let best = if (r_lo..=r_hi).contains(&peak) {
        ct.hypot(st * c)
    } else {
        g(r_lo).max(g(r_hi))
    };
    (best + 1e-12).clamp(0.0, 1.0)
}

/// One (rotation, AOI) block ready to sample.
#[derive(Clone, Debug, PartialEq)]
pub struct BlockSampler {
    /// Its TIS.
    pub tis: f64,
    /// Cumulative cell weights `f A c_max`, cell `ia * n_radial + ir`.
    cdf: Vec<f64>,
    /// Each cell's `c_max`.
    c_max: Vec<f64>,
    /// The expected share of draws kept (landing above the surface): [`Self::sample`]
    /// takes `1 / kept` draws on average.
    pub kept: f64,
}

impl BlockSampler {
    /// The sampler of a block of BSDF `values[azimuth][radial]` on `grid` at its AOI
    /// `theta` (radians); `None` when no cell has directions above the surface.
    pub fn new(grid: &Grid, theta: f64, tis: f64, values: &[Vec<f64>]) -> Option<BlockSampler> {
        let n_r = grid.n_radial();
        let (mut cdf, mut c_max) = (Vec::new(), Vec::new());
        let (mut total, mut above) = (0.0, 0.0);
        // The block's own frame (the sampler draws in it): only its AOI matters here.
        let d = DVec3::new(theta.sin(), 0.0, -theta.cos());
        let frame = Frame::new(ScatterType::Brdf, &incidence(d, DVec3::Z, DVec3::X));
        for (ia, row) in values.iter().enumerate() {
            for (ir, f) in row.iter().enumerate().take(n_r) {
                let r = (grid.radial_edges[ir], grid.radial_edges[ir + 1]);
                let c = max_cos(theta, r, (grid.az_lo[ia], grid.az_width[ia]));
                total += f * grid.solid_angle(ia, ir) * c;
                if *f > 0.0 && c > 0.0 {
                    above += f * grid.projected_solid_angle(&frame, ia, ir, 4);
                }
                cdf.push(total);
                c_max.push(c);
            }
        }
        (total > 0.0).then_some(BlockSampler {
            tis,
            cdf,
            c_max,
            kept: above / total,
        })
    }

    /// A direction drawn from the block's `f cos+` density in `frame` (`None`: gave up
    /// after [`MAX_TRIES`] draws).
    pub fn sample(&self, grid: &Grid, frame: &Frame, rng: &mut PhotonRng) -> Option<DVec3> {
        let total = *self.cdf.last()?;
        let n_r = grid.n_radial();
        for _ in 0..MAX_TRIES {
            let u = rng.uniform() * total;
            let k = self
                .cdf
                .partition_point(|&c| c <= u)
                .min(self.cdf.len() - 1);
            let (ia, ir) = (k / n_r, k % n_r);
            let (lo, hi) = (grid.radial_edges[ir].cos(), grid.radial_edges[ir + 1].cos());
            let r = (hi + (lo - hi) * rng.uniform()).clamp(-1.0, 1.0).acos();
            let mut phi = grid.az_lo[ia] + grid.az_width[ia] * rng.uniform();
            if grid.plane_symmetric && rng.uniform() < 0.5 {
                phi = -phi;
            }
            let w = frame.direction(r, phi);
            if rng.uniform() * self.c_max[k] < w.dot(frame.out) {
                return Some(w);
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frame_is_orthonormal_and_azimuth_zero_leans_to_the_normal() {
        let n = DVec3::Z;
        for theta in [0.0f64, 0.3, 1.2] {
            let d = DVec3::new(theta.sin(), 0.0, -theta.cos());
            let inc = incidence(d, n, DVec3::X);
            assert!((inc.theta - theta).abs() < 1e-12);
            for kind in [ScatterType::Brdf, ScatterType::Btdf] {
                let f = Frame::new(kind, &inc);
                assert!((f.s.dot(f.e0)).abs() < 1e-12 && (f.e0.length() - 1.0).abs() < 1e-12);
                // Azimuth 0 at the incidence angle's radial is the outgoing normal.
                assert!(
                    (f.direction(theta, 0.0) - f.out).length() < 1e-9,
                    "{kind:?} {theta}"
                );
                let w = f.direction(0.4, 2.0);
                let (r, phi) = f.angles(w);
                assert!((r - 0.4).abs() < 1e-9 && (phi - 2.0).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn the_closed_form_bound_is_the_largest_cosine_of_a_cell() {
        let grid = Grid::new(
            &[0.0, 20.0, 50.0, 90.0, 140.0],
            &[0.0, 60.0, 120.0, 180.0],
            true,
        );
        let inc = incidence(DVec3::new(0.6, 0.0, -0.8), DVec3::Z, DVec3::X);
        let frame = Frame::new(ScatterType::Brdf, &inc);
        for ia in 0..4 {
            for ir in 0..5 {
                let (r0, r1) = (grid.radial_edges[ir], grid.radial_edges[ir + 1]);
                let c = max_cos(inc.theta, (r0, r1), (grid.az_lo[ia], grid.az_width[ia]));
                let mut best: f64 = 0.0;
                for i in 0..=60 {
                    for j in 0..=60 {
                        let r = r0 + (r1 - r0) * i as f64 / 60.0;
                        let phi = grid.az_lo[ia] + grid.az_width[ia] * j as f64 / 60.0;
                        best = best.max(frame.direction(r, phi).dot(frame.out));
                    }
                }
                assert!(
                    c >= best - 1e-9 && c <= best + 2e-3,
                    "cell {ia},{ir}: {c} vs {best}"
                );
            }
        }
    }

    #[test]
    fn cells_cover_the_sphere_once() {
        for sym in [true, false] {
            let az: &[f64] = if sym {
                &[0.0, 45.0, 180.0]
            } else {
                &[10.0, 100.0, 300.0]
            };
            let grid = Grid::new(&[0.0, 30.0, 90.0, 180.0], az, sym);
            let total: f64 = (0..az.len())
                .flat_map(|ia| (0..4).map(move |ir| (ia, ir)))
                .map(|(ia, ir)| grid.solid_angle(ia, ir))
                .sum();
            assert!((total - 4.0 * PI).abs() < 1e-9, "{total}");
            assert_eq!(grid.cell_of(0.1, 0.2), Some((0, 0)));
            assert_eq!(grid.cell_of(1.1, 3.5).map(|c| c.1), Some(2));
        }
    }
}
