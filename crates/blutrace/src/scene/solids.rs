//! Closed dielectric solids: every medium other than air must be bounded by a closed,
//! consistently wound surface, or photons would leak through the gaps. Faces are
//! re-wound so normals point out of the medium they enclose.

use crate::geometry::{Aabb, Mesh};
use crate::optics::medium::Medium;
use crate::optics::surface::SurfaceModel;
use crate::spec_check::Ctx;
use anyhow::Result;
use std::collections::{HashMap, VecDeque};

/// Check closure and orient the faces of every enclosed medium outward.
pub(super) fn orient_closed_solids(
    ctx: &Ctx,
    mesh: &mut Mesh,
    tags: &[String],
    surfaces: &[SurfaceModel],
    media: &[Medium],
    warnings: &mut Vec<String>,
) -> Result<()> {
    for (m, medium) in media.iter().enumerate() {
        let solid_tags: Vec<usize> = (0..tags.len())
            .filter(|&t| {
                surfaces[t]
                    .interface()
                    .is_some_and(|i| i.inside as usize == m)
            })
            .collect();
        if solid_tags.is_empty() {
            continue;
        }
        let tris: Vec<usize> = (0..mesh.len())
            .filter(|&p| solid_tags.contains(&(mesh.tri_tag[p] as usize)))
            .collect();
        let names: Vec<&str> = solid_tags.iter().map(|&t| tags[t].as_str()).collect();
        let flipped = orient(ctx, mesh, &tris, &medium.name, &names)?;
        if flipped > 0 {
            warnings.push(format!(
                "medium '{}': re-wound {flipped} of {} triangles so normals point outward",
                medium.name,
                tris.len()
            ));
        }
    }
    Ok(())
}

/// Weld: each position within `q` = 1e-9 of the scene diagonal (in every coordinate) of an
/// earlier one is that vertex. Returns, per position, the index of its representative.
/// Points are binned in cells of 4q and also looked up in the neighbouring cells they lie
/// within q of, so two copies of a vertex that straddle a cell boundary still weld.
fn weld(mesh: &Mesh) -> Vec<u32> {
    let q = (mesh.bounds().diagonal() * 1e-9).max(1e-12);
    let cell = 4.0 * q;
    let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let mut rep = Vec::with_capacity(mesh.positions.len());
    for (i, p) in mesh.positions.iter().enumerate() {
        let f = *p / cell;
        let key = f.floor().to_array().map(|c| c as i64);
        let side = |r: f64| match r {
            r if r < 0.25 => -1,
            r if r > 0.75 => 1,
            _ => 0,
        };
        let steps = (f - f.floor()).to_array().map(|r| [0, side(r)]);
        let mut found = None;
        'search: for dx in steps[0] {
            for dy in steps[1] {
                for dz in steps[2] {
                    let k = [key[0] + dx, key[1] + dy, key[2] + dz];
                    let near = cells.get(&k).and_then(|c| {
                        c.iter()
                            .copied()
                            .find(|&j| (mesh.positions[j as usize] - *p).abs().max_element() <= q)
                    });
                    if near.is_some() {
                        found = near;
                        break 'search;
                    }
                }
            }
        }
        rep.push(found.unwrap_or_else(|| {
            cells.entry(key).or_default().push(i as u32);
            i as u32
        }));
    }
    rep
}

fn orient(
    ctx: &Ctx,
    mesh: &mut Mesh,
    tris: &[usize],
    medium: &str,
    names: &[&str],
) -> Result<usize> {
    let welded = weld(mesh);
    let corners = |p: usize| mesh.triangles[p].map(|v| welded[v as usize]);
    // Undirected edge -> triangles using it.
    let mut edges: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for &p in tris {
        let c = corners(p);
        for k in 0..3 {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            edges.entry((a.min(b), a.max(b))).or_default().push(p);
        }
    }
    // Bad edges by kind, sorted, so the message counts each kind and its example is the
    // same on every run (a HashMap's order is not).
    let kind = |pred: fn(usize) -> bool| {
        let mut e: Vec<(u32, u32)> = edges
            .iter()
            .filter(|(_, t)| pred(t.len()))
            .map(|(e, _)| *e)
            .collect();
        e.sort_unstable();
        e
    };
    let (open, crowded) = (kind(|n| n == 1), kind(|n| n > 2));
    if let Some(&(a, _)) = open.first().or(crowded.first()) {
        let at = mesh.positions[welded.iter().position(|&w| w == a).unwrap_or(0)];
        let what = [
            (open.len(), "open (a gap or T-junction)"),
            (crowded.len(), "shared by more than two faces"),
        ]
        .iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, w)| format!("{n} edge(s) {w}"))
        .collect::<Vec<_>>()
        .join(" and ");
        return Err(ctx.err(
            &format!("surfaces ({})", names.join(", ")),
            format!(
                "medium '{medium}' is not enclosed by a closed surface: {what}, e.g. at ({:.4}, {:.4}, {:.4}) mm",
                at.x, at.y, at.z
            ),
        ));
    }
    // Breadth-first: give each neighbour the winding opposite across the shared edge.
    let mut flip: HashMap<usize, bool> = HashMap::new();
    let mut components: Vec<Vec<usize>> = Vec::new();
    for &seed in tris {
        if flip.contains_key(&seed) {
            continue;
        }
        flip.insert(seed, false);
        let mut comp = vec![seed];
        let mut queue = VecDeque::from([seed]);
        while let Some(p) = queue.pop_front() {
            let cp = oriented(corners(p), flip[&p]);
            for k in 0..3 {
                let (a, b) = (cp[k], cp[(k + 1) % 3]);
                for &q in &edges[&(a.min(b), a.max(b))] {
                    if q == p || flip.contains_key(&q) {
                        continue;
                    }
                    // Consistent winding: q must traverse the shared edge as b -> a.
                    let cq = corners(q);
                    let same_dir = (0..3).any(|j| cq[j] == a && cq[(j + 1) % 3] == b);
                    flip.insert(q, same_dir);
                    comp.push(q);
                    queue.push_back(q);
                }
            }
        }
        components.push(comp);
    }
    let mut flipped = 0;
    for comp in components {
        let volume: f64 = comp
            .iter()
            .map(|&p| signed_volume(mesh, p) * if flip[&p] { -1.0 } else { 1.0 })
            .sum();
        let invert = volume < 0.0;
        for p in comp {
            // Welded copies become one vertex, so the traced surface is as closed as the
            // check above found it (no cracks between near-duplicate corners).
            mesh.triangles[p] = mesh.triangles[p].map(|v| welded[v as usize]);
            if flip[&p] != invert {
                let t = &mut mesh.triangles[p];
                t.swap(1, 2);
                flipped += 1;
            }
        }
    }
    Ok(flipped)
}

fn oriented(c: [u32; 3], flipped: bool) -> [u32; 3] {
    if flipped { [c[0], c[2], c[1]] } else { c }
}

/// Signed volume of the tetrahedron (origin, triangle): positive for outward winding.
fn signed_volume(mesh: &Mesh, p: usize) -> f64 {
    let [a, b, c] = mesh.corners(p as u32);
    a.dot(b.cross(c)) / 6.0
}

/// The closed solid of one medium: the faces that name it inside (oriented outward).
pub(super) struct Solid {
    /// The medium inside.
    pub medium: usize,
    /// Its triangles.
    pub tris: Vec<usize>,
    /// Its enclosed volume (mm^3).
    pub volume: f64,
    /// The box of its triangles: outside it the winding number is 0.
    pub bounds: Aabb,
}

/// The closed solid of every medium but air that some face names inside.
pub(super) fn closed_solids(
    mesh: &Mesh,
    interface_of: &dyn Fn(usize) -> Option<crate::optics::medium::Interface>,
    media: usize,
) -> Vec<Solid> {
    let mut tris = vec![Vec::new(); media];
    for p in 0..mesh.len() {
        if let Some(i) = interface_of(p) {
            tris[i.inside as usize].push(p);
        }
    }
    tris.into_iter()
        .enumerate()
        .skip(1)
        .filter(|(_, t)| !t.is_empty())
        .map(|(medium, tris)| Solid {
            medium,
            bounds: Aabb::of(tris.iter().flat_map(|&p| mesh.corners(p as u32))),
            volume: tris
                .iter()
                .map(|&p| signed_volume(mesh, p))
                .sum::<f64>()
                .abs(),
            tris,
        })
        .collect()
}

/// The medium at `p`: the smallest closed solid around it (winding number above 1/2),
/// air (0) outside them all.
pub(super) fn medium_at(mesh: &Mesh, solids: &[Solid], p: glam::DVec3) -> usize {
    solids
        .iter()
        .filter(|s| winding(mesh, s, p) > 0.5)
        .min_by(|a, b| a.volume.total_cmp(&b.volume))
        .map_or(0, |s| s.medium)
}

/// Vertices tested per solid for overlaps (`media_checks`).
pub const OVERLAP_SAMPLES: usize = 512;

/// Up to [`OVERLAP_SAMPLES`] vertices of the solid `tris`, each moved a hair into the
/// solid (against the sum of its faces' outward normals), so that a vertex lying on
/// another solid's surface (solids that touch) is judged by the side it really is on.
pub(super) fn sample_vertices(mesh: &Mesh, tris: &[usize]) -> Vec<glam::DVec3> {
    let mut normal: HashMap<u32, glam::DVec3> = HashMap::new();
    for &p in tris {
        let n = mesh.area_normal(p as u32).normalize_or_zero();
        for v in mesh.triangles[p] {
            *normal.entry(v).or_default() += n;
        }
    }
    let mut v: Vec<u32> = normal.keys().copied().collect();
    v.sort_unstable();
    let hair = 1e-7 * mesh.bounds().diagonal();
    let step = v.len().div_ceil(OVERLAP_SAMPLES).max(1);
    v.iter()
        .step_by(step)
        .map(|i| mesh.positions[*i as usize] - normal[i].normalize_or_zero() * hair)
        .collect()
}

/// Generalized winding number of the closed, outward-wound surface of `solid` about `p`:
/// 1 inside, 0 outside, 1/2 on the surface (van Oosterom and Strackee's solid angle).
/// A point beyond the solid's box is outside without a sum over its triangles (a lamp
/// beside a finely meshed guide would cost an `atan2` per triangle and grid point).
pub(super) fn winding(mesh: &Mesh, solid: &Solid, p: glam::DVec3) -> f64 {
    if !solid.bounds.contains_point(p) {
        return 0.0;
    }
    let total: f64 = solid
        .tris
        .iter()
        .map(|&t| {
            let [a, b, c] = mesh.corners(t as u32).map(|x| x - p);
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let num = a.dot(b.cross(c));
            let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
            2.0 * num.atan2(den)
        })
        .sum();
    total / (4.0 * std::f64::consts::PI)
}
