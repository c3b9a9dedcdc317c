//! Pieces of geometry several scenes share: axis-aligned solid boxes (light guides,
//! plates, films), flat horizontal sheets and the five-walled lamp box behind a guide's
//! x = 0 edge.

use crate::{P3, Part, box_corners, hexahedron};

/// The tags of a light guide's faces: front (+z), back (-z), the four edges.
pub const LGP_TAGS: [&str; 3] = ["lgp_front", "lgp_back", "lgp_edge"];

/// A part holding the closed box `lo..hi`, wound outward; `tags` name its front (+z),
/// back (-z) and edge faces.
pub fn solid_box(name: &str, lo: P3, hi: P3, tags: [&str; 3]) -> Part {
    let mut p = Part::new(name);
    let [front, back, edge] = tags;
    hexahedron(&mut p, &box_corners(lo, hi), front, back, edge);
    p
}

/// A light guide `0..size`, its faces tagged [`LGP_TAGS`].
pub fn guide_box(name: &str, size: P3) -> Part {
    solid_box(name, [0.0; 3], size, LGP_TAGS)
}

/// A part holding one rectangle `lo..hi` (x, y) at height `z`, facing +z, tagged `tag`:
/// a reflector sheet or a floor.
pub fn sheet_up(name: &str, tag: &str, lo: [f64; 2], hi: [f64; 2], z: f64) -> Part {
    let mut p = Part::new(name);
    let ([x0, y0], [x1, y1]) = (lo, hi);
    p.quad(tag, [x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]);
    p
}

/// Which way a lamp box's walls face.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Facing {
    /// Away from the lamp.
    Out,
    /// Towards the lamp.
    In,
}

/// A part of five walls closing the box x `-depth..0`, y `0..size[0]`, z `0..size[1]`
/// round a lamp, tagged `tag`; its sixth side, x = 0, is open onto a guide's edge face.
pub fn lamp_box(name: &str, tag: &str, depth: f64, size: [f64; 2], facing: Facing) -> Part {
    let (d, [sy, sz]) = (-depth, size);
    let walls = [
        [[d, 0.0, 0.0], [d, 0.0, sz], [d, sy, sz], [d, sy, 0.0]],
        [[d, 0.0, 0.0], [d, sy, 0.0], [0.0, sy, 0.0], [0.0, 0.0, 0.0]],
        [[d, 0.0, sz], [0.0, 0.0, sz], [0.0, sy, sz], [d, sy, sz]],
        [[d, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, sz], [d, 0.0, sz]],
        [[d, sy, 0.0], [d, sy, sz], [0.0, sy, sz], [0.0, sy, 0.0]],
    ];
    let mut p = Part::new(name);
    for [a, b, c, e] in walls {
        match facing {
            Facing::Out => p.quad(tag, a, b, c, e),
            Facing::In => p.quad(tag, a, e, c, b),
        }
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sum over the triangles of (centroid - lamp) . normal: positive when the walls face
    /// away from a lamp inside the box.
    fn outwardness(p: &Part, lamp: P3) -> f64 {
        p.triangles_of("t")
            .iter()
            .map(|[a, b, c]| {
                let e1 = [0, 1, 2].map(|k| b[k] - a[k]);
                let e2 = [0, 1, 2].map(|k| c[k] - a[k]);
                let n = [
                    e1[1] * e2[2] - e1[2] * e2[1],
                    e1[2] * e2[0] - e1[0] * e2[2],
                    e1[0] * e2[1] - e1[1] * e2[0],
                ];
                (0..3)
                    .map(|k| ((a[k] + b[k] + c[k]) / 3.0 - lamp[k]) * n[k])
                    .sum::<f64>()
            })
            .sum()
    }

    #[test]
    fn lamp_box_walls_face_the_way_asked() {
        let lamp = [-1.0, 5.0, 1.0];
        for facing in [Facing::Out, Facing::In] {
            let p = lamp_box("walls", "t", 2.0, [10.0, 2.0], facing);
            assert_eq!(p.triangle_count(), 10);
            let o = outwardness(&p, lamp);
            assert_eq!(o > 0.0, facing == Facing::Out, "{facing:?}: {o}");
        }
    }

    #[test]
    fn sheet_faces_up() {
        let p = sheet_up("sheet", "t", [0.0, 0.0], [2.0, 3.0], -0.1);
        assert!(outwardness(&p, [1.0, 1.5, -1.0]) > 0.0);
    }
}
