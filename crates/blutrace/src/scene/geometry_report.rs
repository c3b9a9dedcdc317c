//! What each geometry file put into the scene, for `blutrace check`: triangles and
//! bounding boxes in millimetres after all transforms, per file and per tag, and the
//! placement warnings that catch unit and axis mistakes (a part 1000x too large or small,
//! the detector plane cutting through a part; lamps cutting parts: `scene::lamp_placement`).

use crate::detector::TargetPlane;
use crate::geometry::{Aabb, Mesh};
use glam::DVec3;
use serde::Serialize;
use std::collections::BTreeMap;

/// Smallest and largest plausible extent of a backlight part (mm): outside, "check units".
pub const PLAUSIBLE_EXTENT_MM: (f64, f64) = (0.01, 5000.0);

/// An axis-aligned box in scene millimetres (the scene file's frame).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BoxMm {
    /// Smallest corner.
    pub min: [f64; 3],
    /// Largest corner.
    pub max: [f64; 3],
}

impl BoxMm {
    fn of(points: impl Iterator<Item = DVec3>) -> Option<BoxMm> {
        let b = Aabb::of(points);
        (!b.is_empty()).then(|| BoxMm {
            min: b.min.to_array(),
            max: b.max.to_array(),
        })
    }

    /// The three sides (mm).
    pub fn sides(&self) -> [f64; 3] {
        std::array::from_fn(|i| self.max[i] - self.min[i])
    }

    /// The largest side (mm).
    pub fn extent(&self) -> f64 {
        (0..3)
            .map(|i| self.max[i] - self.min[i])
            .fold(0.0, f64::max)
    }
}

/// One tag's share of a file.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TagReport {
    /// Triangles kept (zero-area ones dropped).
    pub triangles: usize,
    /// Their bounding box.
    pub bounds_mm: BoxMm,
}

/// One geometry file as loaded.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GeometryReport {
    /// The file, as the scene names it.
    pub file: String,
    /// Triangles kept.
    pub triangles: usize,
    /// Bounding box of its triangles (None when every triangle was dropped).
    pub bounds_mm: Option<BoxMm>,
    /// Per tag.
    pub tags: BTreeMap<String, TagReport>,
}

impl GeometryReport {
    /// The report of `file`'s triangles `tris` (indices into `mesh`) with their tag names.
    pub fn new(file: String, mesh: &Mesh, tris: &[([u32; 3], &str)]) -> Self {
        let corners = |sel: &dyn Fn(&str) -> bool| {
            let pts: Vec<DVec3> = tris
                .iter()
                .filter(|(_, tag)| sel(tag))
                .flat_map(|(t, _)| t.map(|v| mesh.positions[v as usize]))
                .collect();
            pts
        };
        let mut tags = BTreeMap::new();
        for (_, tag) in tris {
            if tags.contains_key(*tag) {
                continue;
            }
            let pts = corners(&|t| t == *tag);
            let bounds_mm = BoxMm::of(pts.iter().copied()).expect("a tag has triangles");
            let triangles = pts.len() / 3;
            tags.insert(
                tag.to_string(),
                TagReport {
                    triangles,
                    bounds_mm,
                },
            );
        }
        GeometryReport {
            file,
            triangles: tris.len(),
            bounds_mm: BoxMm::of(corners(&|_| true).into_iter()),
            tags,
        }
    }

    /// A warning when the file's extent is implausible for a backlight part.
    pub fn extent_warning(&self) -> Option<String> {
        let e = self.bounds_mm?.extent();
        let (lo, hi) = PLAUSIBLE_EXTENT_MM;
        (e < lo || e > hi).then(|| {
            format!(
                "{}: the part is {e:.4e} mm across, outside {lo}..{hi} mm for a backlight \
                 part: check units (and scale)",
                self.file
            )
        })
    }
}

/// Unit mistakes a file's size can give away: the factor its part is off by, and the
/// `units` that would undo it. Inches read as millimetres make a part 25.4x small, metres
/// (a glTF's own unit) declared `units = "mm"` 1000x small, and the reverse mistakes
/// 25.4x or 1000x large.
const UNIT_SLIPS: [(f64, &str, &str); 4] = [
    (25.4, "1/25.4", "units = \"in\"?"),
    (1000.0, "1/1000", "units = \"m\"?"),
    (1.0 / 25.4, "25.4x", "units = \"mm\" (it reads as inches)?"),
    (
        1.0 / 1000.0,
        "1000x",
        "units = \"mm\" (it reads as metres)?",
    ),
];

/// How close (as a ratio) a rescaled part's two largest sides must come to the
/// reference's to count as the same size.
const SAME_SIZE: f64 = 1.3;

/// Warnings for geometry files (`reports[i]` with `is_file[i]`) whose part, scaled by a
/// unit factor, takes the footprint of the rest of the scene (the other parts' bounding
/// box) or of the detector (`detector_mm`, its two sides): about 25.4x or 1000x off, as a
/// file exported in other units than read is. Both of the two largest sides must match
/// within `SAME_SIZE`, which a small part that is only proportioned like the scene (an
/// LED package, a screw) does not.
pub fn unit_slip_warnings(
    reports: &[GeometryReport],
    is_file: &[bool],
    detector_mm: [f64; 2],
) -> Vec<String> {
    let mut out = Vec::new();
    for (i, r) in reports.iter().enumerate() {
        let Some(own) = r.bounds_mm.filter(|_| is_file[i]) else {
            continue;
        };
        let rest = reports
            .iter()
            .enumerate()
            .filter(|&(k, _)| k != i)
            .filter_map(|(_, o)| o.bounds_mm)
            .reduce(|a, b| BoxMm {
                min: std::array::from_fn(|k| a.min[k].min(b.min[k])),
                max: std::array::from_fn(|k| a.max[k].max(b.max[k])),
            });
        let mut references = vec![("the detector", sides([detector_mm[0], detector_mm[1], 0.0]))];
        if let Some(rest) = rest {
            references.push(("the rest of the scene", sides(rest.sides())));
        }
        let part = sides(own.sides());
        let slip = references.iter().find_map(|&(what, reference)| {
            UNIT_SLIPS
                .iter()
                .find(|&&(k, _, _)| {
                    same_size([part[0] * k, part[1] * k], reference) && !same_size(part, reference)
                })
                .map(|&(_, off, hint)| (what, reference, off, hint))
        });
        if let Some((what, reference, off, hint)) = slip {
            out.push(format!(
                "{}: the part is {:.4} x {:.4} mm, about {off} the size of {what} ({:.4} x {:.4} mm): {hint}",
                r.file, part[0], part[1], reference[0], reference[1]
            ));
        }
    }
    out
}

/// The two largest of three sides, largest first.
fn sides(mut s: [f64; 3]) -> [f64; 2] {
    s.sort_by(|a, b| b.total_cmp(a));
    [s[0], s[1]]
}

/// Whether both sides agree within [`SAME_SIZE`] (none of them zero).
fn same_size(a: [f64; 2], b: [f64; 2]) -> bool {
    a.iter()
        .zip(&b)
        .all(|(&x, &y)| x > 0.0 && y > 0.0 && (x / y).max(y / x) <= SAME_SIZE)
}

/// Warnings where the detector plane passes through a triangle inside its rectangle (the
/// target should lie in air in front of the guide, not cut a part).
pub fn detector_cuts(
    mesh: &Mesh,
    tags: &[String],
    d: &TargetPlane,
    eps: f64,
    offset: DVec3,
) -> Vec<String> {
    let n = d.u.cross(d.v);
    let mut hit = BTreeMap::new();
    for (p, &tag) in mesh.tri_tag.iter().enumerate() {
        let c = mesh.corners(p as u32);
        let plane = Plane {
            origin: d.origin,
            u: d.u,
            v: d.v,
            n,
        };
        if plane.cut_meets(c, [0.0, 0.0], d.size, eps) {
            hit.entry(tag).or_insert(c[0] + offset);
        }
    }
    hit.into_iter()
        .map(|(tag, at)| {
            format!(
                "the detector plane cuts tag '{}' (near {at:.3?} mm): the target should lie \
                 in front of the parts",
                tags[tag as usize]
            )
        })
        .collect()
}

/// A plane with an in-plane frame: points `origin + a u + b v`, normal `n`.
pub(super) struct Plane {
    pub(super) origin: DVec3,
    pub(super) u: DVec3,
    pub(super) v: DVec3,
    pub(super) n: DVec3,
}

impl Plane {
    /// True when triangle `c` passes through the plane (vertices more than `eps` on both
    /// sides) along a segment that meets the rectangle `lo..hi` of frame coordinates.
    pub(super) fn cut_meets(&self, c: [DVec3; 3], lo: [f64; 2], hi: [f64; 2], eps: f64) -> bool {
        let s = c.map(|x| self.n.dot(x - self.origin));
        if s.iter().all(|&h| h > -eps) || s.iter().all(|&h| h < eps) {
            return false;
        }
        let ends: Vec<[f64; 2]> = (0..3)
            .filter_map(|i| {
                let (a, b) = (i, (i + 1) % 3);
                ((s[a] > 0.0) != (s[b] > 0.0)).then(|| {
                    let x = c[a] + (c[b] - c[a]) * (s[a] / (s[a] - s[b])) - self.origin;
                    [x.dot(self.u), x.dot(self.v)]
                })
            })
            .collect();
        match ends.as_slice() {
            [p] => segment_meets_box(*p, *p, lo, hi),
            [p, q, ..] => segment_meets_box(*p, *q, lo, hi),
            [] => false,
        }
    }
}

/// Liang-Barsky: does the segment `p..q` meet the box `lo..hi`?
fn segment_meets_box(p: [f64; 2], q: [f64; 2], lo: [f64; 2], hi: [f64; 2]) -> bool {
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    for k in 0..2 {
        let d = q[k] - p[k];
        for (num, den) in [(p[k] - lo[k], -d), (hi[k] - p[k], d)] {
            if den == 0.0 {
                if num < 0.0 {
                    return false;
                }
            } else {
                let t = num / den;
                if den < 0.0 {
                    t0 = t0.max(t);
                } else {
                    t1 = t1.min(t);
                }
            }
        }
    }
    t0 <= t1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_and_boxes() {
        let (lo, hi) = ([0.0, 0.0], [1.0, 1.0]);
        assert!(segment_meets_box([-1.0, 0.5], [2.0, 0.5], lo, hi));
        assert!(segment_meets_box([0.5, 0.5], [0.5, 0.5], lo, hi));
        assert!(!segment_meets_box([-1.0, 2.0], [2.0, 1.5], lo, hi));
        assert!(!segment_meets_box([1.5, -1.0], [1.5, 2.0], lo, hi));
        assert!(segment_meets_box([-0.5, 0.0], [0.5, 2.0], lo, hi));
        assert!(!segment_meets_box([-1.0, 0.5], [-0.1, 0.9], lo, hi));
    }
}
