//! Where media meet: the checks that every point of the scene has one medium and that each
//! face names the medium really in front of it.
//!
//! ```toml
//! [surfaces.lgp_face]
//! model = "dielectric"
//! inside = "pmma"          # the closed solid behind the face
//! outside = "air"          # must be the medium in front of it: air, or the solid around it
//! ```
//!
//! - Two closed solids (of different media, or two shells of one medium) whose surfaces
//!   cross, or a shell wholly inside another shell of its own medium, are an error: the
//!   photons in the shared volume would be traced in the wrong medium. A solid wholly
//!   inside another medium's solid is the one nesting allowed (a bead in a guide), its
//!   faces then naming that medium outside.
//! - Each face's `outside` must be the medium around the face: the smallest other-medium
//!   solid enclosing it, or air. Faces that touch another solid's face (a film lying on a
//!   guide) may name either, the thin gap between parts in contact being air in practice.
//!   A black backing (a medium absorbing at least [`BACKING_PER_MM`], clear) may be named
//!   outside with no solid around it: an index-matched black coating of no thickness.
//!
//! Tested with the generalized winding number (`solids::winding`) of sampled points.

use super::solids::{self, Solid};
use crate::geometry::{Aabb, Mesh};
use crate::optics::medium::{BACKING_PER_MM, Interface, Medium};
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use std::collections::HashMap;

/// Face centres tested per tag for the medium in front of them.
const FACE_SAMPLES: usize = 64;

/// Refuse overlapping solids and faces that name the wrong medium outside.
pub(super) fn check_media(
    ctx: &Ctx,
    mesh: &Mesh,
    tags: &[String],
    interface_of: &dyn Fn(usize) -> Option<Interface>,
    media: &[Medium],
) -> Result<()> {
    let solids = solids::closed_solids(mesh, interface_of, media.len());
    check_crossings(ctx, mesh, &solids, media)?;
    for s in &solids {
        check_shells(ctx, mesh, s, media)?;
    }
    check_outside(ctx, mesh, tags, interface_of, &solids, media)
}

/// Solids of different media whose surfaces cross.
fn check_crossings(ctx: &Ctx, mesh: &Mesh, solids: &[Solid], media: &[Medium]) -> Result<()> {
    for (i, a) in solids.iter().enumerate() {
        let verts = solids::sample_vertices(mesh, &a.tris);
        for b in &solids[i + 1..] {
            if !boxes_meet(&a.bounds, &b.bounds) {
                continue;
            }
            let w: Vec<f64> = verts.iter().map(|&p| solids::winding(mesh, b, p)).collect();
            if let (Some(k), true) = (
                w.iter().position(|&w| w > 0.75),
                w.iter().any(|&w| w < 0.25),
            ) {
                return Err(ctx.err(
                    "geometry",
                    format!(
                        "the closed solids of media '{}' and '{}' overlap: their surfaces cross (near {})",
                        media[a.medium].name,
                        media[b.medium].name,
                        mm(verts[k])
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Shells (connected closed surfaces) of one medium that overlap or nest.
fn check_shells(ctx: &Ctx, mesh: &Mesh, solid: &Solid, media: &[Medium]) -> Result<()> {
    let shells = shells(mesh, &solid.tris);
    if shells.len() < 2 {
        return Ok(());
    }
    let boxes: Vec<Aabb> = shells
        .iter()
        .map(|s| Aabb::of(s.iter().flat_map(|&p| mesh.corners(p as u32))))
        .collect();
    for (i, a) in shells.iter().enumerate() {
        let verts = solids::sample_vertices(mesh, a);
        for (j, b) in shells.iter().enumerate() {
            if i == j || !boxes_meet(&boxes[i], &boxes[j]) {
                continue;
            }
            let other = Solid {
                medium: solid.medium,
                tris: b.clone(),
                volume: 0.0,
                bounds: boxes[j],
            };
            if let Some(&p) = verts
                .iter()
                .find(|&&p| solids::winding(mesh, &other, p) > 0.75)
            {
                return Err(ctx.err(
                    "geometry",
                    format!(
                        "two closed solids of medium '{}' overlap (near {}): a point inside both would be traced as leaving one; join them into one solid or move them apart",
                        media[solid.medium].name,
                        mm(p)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Each interface face's `outside` against the medium around it.
fn check_outside(
    ctx: &Ctx,
    mesh: &Mesh,
    tags: &[String],
    interface_of: &dyn Fn(usize) -> Option<Interface>,
    solids: &[Solid],
    media: &[Medium],
) -> Result<()> {
    let mut by_tag: HashMap<u32, Vec<usize>> = HashMap::new();
    for p in 0..mesh.len() {
        by_tag.entry(mesh.tri_tag[p]).or_default().push(p);
    }
    let enclosed = |m: usize| solids.iter().any(|s| s.medium == m);
    let mut order: Vec<u32> = by_tag.keys().copied().collect();
    order.sort_unstable();
    for t in order {
        let tris = &by_tag[&t];
        let Some(face) = interface_of(tris[0]) else {
            continue;
        };
        if face.inside == 0 {
            continue;
        }
        let step = tris.len().div_ceil(FACE_SAMPLES).max(1);
        let hair = 1e-7 * mesh.bounds().diagonal();
        for &p in tris.iter().step_by(step) {
            let [a, b, c] = mesh.corners(p as u32);
            let centre = (a + b + c) / 3.0;
            let n = mesh.area_normal(p as u32).normalize_or_zero() * hair;
            let (around, touching) = medium_around(mesh, solids, face.inside as usize, centre, n);
            let named = face.outside as usize;
            let backing = media[named].is_backing() && !enclosed(named);
            if around != named && touching != Some(named) && !backing {
                let tag = &tags[t as usize];
                let named = &media[named].name;
                let why = if face.outside != 0 && !enclosed(face.outside as usize) {
                    format!(
                        " (no closed solid encloses '{named}': no face names it inside; only a black backing, absorption_per_mm >= {BACKING_PER_MM:e} and no scattering, needs none)"
                    )
                } else {
                    String::new()
                };
                return Err(ctx.err(
                    &format!("surfaces.{tag}.outside"),
                    format!(
                        "is '{named}', but the faces of '{tag}' have '{}' in front of them (near {}){why}",
                        media[around].name,
                        mm(centre)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The media around the point `p` on a face of medium `inside` whose outward normal is
/// `n` (a hair long): the smallest solid of another medium enclosing both `p + n` and
/// `p - n` (air when none does), and the medium of a solid holding only `p + n`, whose
/// surface touches the face (parts in contact: either may be named outside). The winding
/// number on a surface itself is ill-defined (+-1/2 by the sign of a zero), hence the two
/// points.
fn medium_around(
    mesh: &Mesh,
    solids: &[Solid],
    inside: usize,
    p: DVec3,
    n: DVec3,
) -> (usize, Option<usize>) {
    let mut around: Option<&Solid> = None;
    let mut touching = None;
    for s in solids.iter().filter(|s| s.medium != inside) {
        let front = solids::winding(mesh, s, p + n) > 0.5;
        let behind = solids::winding(mesh, s, p - n) > 0.5;
        match (front, behind) {
            (true, false) => touching = Some(s.medium),
            (true, true) if around.is_none_or(|a| s.volume < a.volume) => around = Some(s),
            _ => {}
        }
    }
    (around.map_or(0, |s| s.medium), touching)
}

/// The connected pieces of `tris` (sharing a vertex: faces are welded by then).
fn shells(mesh: &Mesh, tris: &[usize]) -> Vec<Vec<usize>> {
    let mut parent: HashMap<u32, u32> = HashMap::new();
    fn root(parent: &mut HashMap<u32, u32>, v: u32) -> u32 {
        let mut r = v;
        while let Some(&p) = parent.get(&r).filter(|&&p| p != r) {
            r = p;
        }
        parent.insert(v, r);
        r
    }
    for &p in tris {
        let [a, b, c] = mesh.triangles[p];
        for v in [a, b, c] {
            parent.entry(v).or_insert(v);
        }
        let ra = root(&mut parent, a);
        for v in [b, c] {
            let rv = root(&mut parent, v);
            parent.insert(rv, ra);
        }
    }
    let mut pieces: HashMap<u32, Vec<usize>> = HashMap::new();
    for &p in tris {
        let r = root(&mut parent, mesh.triangles[p][0]);
        pieces.entry(r).or_default().push(p);
    }
    let mut out: Vec<Vec<usize>> = pieces.into_values().collect();
    out.sort_by_key(|s| s[0]);
    out
}

fn boxes_meet(a: &Aabb, b: &Aabb) -> bool {
    (0..3).all(|k| a.min[k] <= b.max[k] && b.min[k] <= a.max[k])
}

fn mm(p: DVec3) -> String {
    format!("({:.4}, {:.4}, {:.4}) mm", p.x, p.y, p.z)
}
