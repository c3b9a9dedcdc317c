//! Where each lamp sits relative to the geometry: in which medium its emitting surface
//! lies, which parts come so close to that surface that emitted photons would start
//! beyond them, and which parts cut through it (light would be emitted inside a part).
//!
//! ```toml
//! [[sources]]
//! type = "ccfl"
//! center = [-3.0, 100.0, 1.5]
//! medium = "air"   # must be the medium the emitting surface really lies in
//! ```
//!
//! A source inside a closed solid (a CCFL bored into the PMMA, an LED potted in
//! silicone) must name that solid's medium, and a source in air must not name a solid's
//! medium: otherwise its photons would be traced with the wrong refractive index and
//! absorption until their first surface, without a word.

use super::geometry_report::Plane;
use super::solids;
use crate::geometry::{Aabb, Mesh};
use crate::optics::medium::{Interface, Medium};
use crate::sources::body_shape::BodyShape;
use crate::sources::{Emitter, Source};
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use std::collections::BTreeMap;

/// Points per side of the grid on each emitting surface that is tested.
const GRID: usize = 16;

/// Check that every source names the medium its emitting surface lies in (positions in
/// the scene file's frame, before recentring). The medium of a point is the innermost
/// closed solid around it (winding number), air outside them all.
pub(super) fn check_source_media(
    ctx: &Ctx,
    mesh: &Mesh,
    interface_of: &dyn Fn(usize) -> Option<Interface>,
    media: &[Medium],
    sources: &[Source],
) -> Result<()> {
    let solids = solids::closed_solids(mesh, interface_of, media.len());
    if solids.is_empty() {
        return Ok(());
    }
    let hair = 1e-6 * mesh.bounds().diagonal().max(1.0);
    for (i, s) in sources.iter().enumerate() {
        let mut found: Option<(usize, DVec3)> = None;
        for (p, n) in s.emitter.surface_grid(GRID) {
            let q = p + n * hair;
            let m = solids::medium_at(mesh, &solids, q);
            match found {
                None => found = Some((m, p)),
                Some((m0, p0)) if m0 != m => {
                    return Err(ctx.err(
                        &format!("sources[{i}].center"),
                        format!(
                            "the emitting surface of '{}' crosses the boundary between media '{}' (near {}) and '{}' (near {}); a lamp must lie wholly in one medium",
                            s.name,
                            media[m0].name,
                            mm(p0),
                            media[m].name,
                            mm(p)
                        ),
                    ));
                }
                Some(_) => {}
            }
        }
        let (m, p) = found.expect("the grid has points");
        if m != s.medium as usize {
            return Err(ctx.err(
                &format!("sources[{i}].medium"),
                format!(
                    "the emitting surface of '{}' lies in medium '{}' (near {}), but the source names '{}'",
                    s.name,
                    media[m].name,
                    mm(p),
                    media[s.medium as usize].name
                ),
            ));
        }
    }
    Ok(())
}

/// Warnings for parts whose faces come within `reach` (mm) of a lamp's emitting
/// surface: emitted photons start a spawn offset off that surface, so such a face may be
/// skipped by part of the emission. Positions in the scene file's frame (`offset` added).
pub(super) fn contact_warnings(
    mesh: &Mesh,
    tags: &[String],
    sources: &[Source],
    reach: f64,
    offset: DVec3,
) -> Vec<String> {
    let mut out = Vec::new();
    for s in sources {
        let grid = s.emitter.surface_grid(2 * GRID);
        let span = Aabb::of(grid.iter().map(|g| g.0)).grown(reach);
        let mut near: BTreeMap<u32, DVec3> = BTreeMap::new();
        for (p, &tag) in mesh.tri_tag.iter().enumerate() {
            let c = mesh.corners(p as u32);
            if near.contains_key(&tag) || !Aabb::of(c).overlaps(&span) {
                continue;
            }
            if let Some(at) = touches(mesh, p as u32, c, s, &grid, reach) {
                near.insert(tag, at + offset);
            }
        }
        out.extend(near.into_iter().map(|(tag, at)| {
            format!(
                "source '{}': tag '{}' lies within {reach:.1e} mm of its emitting surface (near {}); emitted photons start that far off the lamp and may skip it: move the part off the lamp, or make it the lamp's body",
                s.name,
                tags[tag as usize],
                mm(at)
            )
        }));
    }
    out
}

/// A point where triangle `prim` (corners `c`) comes within `reach` of the emitting
/// surface: a point of the triangle near the surface, or a point of the surface near
/// the triangle.
fn touches(
    mesh: &Mesh,
    prim: u32,
    c: [DVec3; 3],
    s: &Source,
    grid: &[(DVec3, DVec3)],
    reach: f64,
) -> Option<DVec3> {
    const STEPS: usize = 8;
    for i in 0..=STEPS {
        for j in 0..=STEPS - i {
            let (a, b) = (i as f64 / STEPS as f64, j as f64 / STEPS as f64);
            let p = c[0] + (c[1] - c[0]) * a + (c[2] - c[0]) * b;
            if s.emitter.surface_distance(p) <= reach {
                return Some(p);
            }
        }
    }
    over_triangle(mesh, prim, grid)
        .find(|&(_, h)| h.abs() <= reach)
        .map(|(g, _)| g)
}

/// The points of an emitting surface's `grid` whose foot on the plane of triangle `prim`
/// lies inside it, each with its signed height above that plane: what both the contact
/// and the "cuts" warnings look at.
fn over_triangle<'a>(
    mesh: &'a Mesh,
    prim: u32,
    grid: &'a [(DVec3, DVec3)],
) -> impl Iterator<Item = (DVec3, f64)> + 'a {
    let c0 = mesh.corners(prim)[0];
    let n = mesh.area_normal(prim).normalize_or_zero();
    grid.iter().filter_map(move |&(g, _)| {
        let h = n.dot(g - c0);
        mesh.contains(prim, g - n * h).then_some((g, h))
    })
}

/// Warnings where a mesh vertex lies inside a CCFL tube, or a triangle crosses an LED's
/// emitting rectangle: light would be emitted inside a part.
pub(super) fn source_cuts(
    mesh: &Mesh,
    tags: &[String],
    sources: &[Source],
    eps: f64,
    offset: DVec3,
) -> Vec<String> {
    let mut out = Vec::new();
    for s in sources {
        let grid = s.emitter.surface_grid(24);
        let shape = s.emitter.shape();
        // A triangle that cuts the emitter meets the grid's bounding box (a vertex inside
        // the tube, or a point of the triangle between grid points on either side of it);
        // the pad covers the grid's shortfall from the true surface between its points.
        let reach = Aabb::of(grid.iter().map(|g| g.0));
        let span = reach.grown(0.1 * (reach.max - reach.min).max_element() + eps);
        let mut hit: BTreeMap<u32, DVec3> = BTreeMap::new();
        for (p, &tag) in mesh.tri_tag.iter().enumerate() {
            let c = mesh.corners(p as u32);
            if hit.contains_key(&tag) || !Aabb::of(c).overlaps(&span) {
                continue;
            }
            if cuts_emitter(&s.emitter, c, eps) || crosses_grid(mesh, p as u32, &shape, &grid, eps)
            {
                hit.insert(tag, c[0] + offset);
            }
        }
        out.extend(hit.into_iter().map(|(tag, at)| {
            format!(
                "source '{}': its emitting surface cuts tag '{}' (near {at:.3?} mm)",
                s.name, tags[tag as usize]
            )
        }));
    }
    out
}

/// True when points of the emitting surface's `grid` lie more than `eps` on both sides of
/// triangle `prim`, with their feet inside it: the triangle passes through the surface
/// (a sheet through a tube, whose vertices all lie outside it). Unless the whole emitting
/// surface reaches more than `eps` to both sides of the plane, no grid point can: the
/// common case (a reflector facet beside the lamp) is settled without the grid, which
/// on a finely meshed reflector would cost a point-in-triangle test per facet and point.
fn crosses_grid(
    mesh: &Mesh,
    prim: u32,
    surface: &BodyShape,
    grid: &[(DVec3, DVec3)],
    eps: f64,
) -> bool {
    let n = mesh.area_normal(prim).normalize_or_zero();
    let (lo, hi) = surface.support(n);
    let base = n.dot(mesh.corners(prim)[0]);
    // Rounding slack: the grid's heights are computed another way, n . (g - corner).
    let slack = 1e-9 * (lo.abs() + hi.abs() + base.abs());
    if !(lo - base - slack < -eps && hi - base + slack > eps) {
        return false;
    }
    let (mut above, mut below) = (false, false);
    over_triangle(mesh, prim, grid)
        .filter(|&(_, h)| h.abs() > eps)
        .any(|(_, h)| {
            above |= h > 0.0;
            below |= h < 0.0;
            above && below
        })
}

fn cuts_emitter(e: &Emitter, c: [DVec3; 3], eps: f64) -> bool {
    match e {
        Emitter::Ccfl(t) => c.iter().any(|x| {
            let rel = *x - t.center;
            let along = rel.dot(t.axis);
            along.abs() < t.length / 2.0 - eps && (rel - t.axis * along).length() < t.radius - eps
        }),
        Emitter::Led(_) | Emitter::RayFile(_) => {
            let Some(r) = e.rect() else {
                return false;
            };
            let plane = Plane {
                origin: r.center,
                u: r.u,
                v: r.normal.cross(r.u),
                n: r.normal,
            };
            let half = [r.half_width, r.half_height];
            plane.cut_meets(c, half.map(|h| -h), half, eps)
        }
    }
}

fn mm(p: DVec3) -> String {
    format!("({:.3}, {:.3}, {:.3}) mm", p.x, p.y, p.z)
}
