//! Closed dielectric solids: every medium other than air must be bounded by a closed,
//! consistently wound surface, or photons would leak through the gaps. Faces are
//! re-wound so normals point out of the medium they enclose.

use super::Ctx;
use crate::geometry::Mesh;
use crate::optics::surface::{Medium, SurfaceModel};
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

/// Weld key: positions equal to a relative 1e-9 of the scene size are one vertex.
fn weld(mesh: &Mesh) -> Vec<u32> {
    let q = (mesh.bounds().diagonal() * 1e-9).max(1e-12);
    let mut ids: HashMap<[i64; 3], u32> = HashMap::new();
    mesh.positions
        .iter()
        .map(|p| {
            let key = (*p / q).round().to_array().map(|c| c as i64);
            let next = ids.len() as u32;
            *ids.entry(key).or_insert(next)
        })
        .collect()
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
    let bad: Vec<(&(u32, u32), usize)> = edges
        .iter()
        .filter(|(_, t)| t.len() != 2)
        .map(|(e, t)| (e, t.len()))
        .collect();
    if let Some(&(&(a, _), n)) = bad.first() {
        let at = mesh.positions[welded.iter().position(|&w| w == a).unwrap_or(0)];
        let what = if n == 1 {
            "open (a gap or T-junction)"
        } else {
            "shared by more than two faces"
        };
        return Err(ctx.err(
            &format!("surfaces ({})", names.join(", ")),
            format!(
                "medium '{medium}' is not enclosed by a closed surface: {} edge(s) {what}, e.g. at ({:.4}, {:.4}, {:.4}) mm",
                bad.len(), at.x, at.y, at.z
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
