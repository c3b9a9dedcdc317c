//! Procedural reflectors: parametric parts generated at load and tagged like any mesh, so a
//! reflector's shape is a few numbers of the scene file (and `optimize --vary` can search
//! them).
//!
//! ```toml
//! [[procedural]]
//! type = "direct_lit_box"          # a direct-lit box: back reflector and four walls
//! tag = "box_reflector"            # the tag of every face ([surfaces.box_reflector])
//! origin = [0.0, 0.0, 0.0]         # inner corner: x across the lamps, y along them, z up
//! size_mm = [400.0, 250.0, 25.0]   # inner x, y and depth (valleys to the open top)
//! ridge_height_mm = 6.0            # 0: a flat back
//! profile = "triangle"             # or "parabola": parabolic troughs under the lamps
//! segments = 8                     # straight pieces per half trough of a parabola
//!
//! [[procedural]]
//! type = "lamp_holder"             # an edge-lit lamp holder: a reflector sheet around a CCFL
//! tag = "lamp_reflector"
//! center = [-3.0, 107.5, 1.5]      # the lamp's axis centre
//! axis = [0.0, 1.0, 0.0]           # the lamp's axis
//! opening = [1.0, 0.0, 0.0]        # towards the guide's edge
//! length_mm = 215.0
//! aperture_mm = 3.0                # height of the opening (across the axis)
//! section = { shape = "circle", radius_mm = 2.5 }
//! # section = { shape = "ellipse", depth_mm = 4.0, height_mm = 2.5 }  # semi-axes along and across the opening
//! # section = { shape = "parabola", focal_mm = 1.5 }                   # focus on the lamp axis
//! segments = 32                    # straight pieces of the section
//! end_caps = true                  # flat caps closing both ends (default)
//! ```
//!
//! The direct-lit box has its valleys (z = 0) under every lamp whose axis lies over the
//! box, ridges of `ridge_height_mm` midway between neighbouring lamps and at the x walls
//! (the shape `tools/scenegen` meshes for `direct-lit`), straight slopes (`triangle`) or
//! parabolas with their vertex under the lamp (`parabola`); its side and end walls rise to
//! the open top. It is open only along that top rim. A CCFL over the box that comes
//! beside the box (within its y and z range) that is outside it or closer to its back, walls
//! or top than its radius is an error. The lamp holder is a sheet extruded
//! along the lamp, open only at its aperture. Faces are wound towards the lamps (into the
//! box, towards the holder's axis).

use super::meshio::TaggedTriangles;
use crate::sources::{Emitter, Source};
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Most straight pieces of a curved profile or section.
pub const MAX_SEGMENTS: usize = 4096;

/// `[[procedural]]`: one generated part.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ProceduralSpec {
    /// A direct-lit box: ridged or flat back reflector and four walls, open at the top.
    DirectLitBox {
        /// Tag of every face.
        tag: String,
        /// Inner corner at the valleys' level (mm).
        origin: [f64; 3],
        /// Inner size (mm): x (across the lamps), y (along them), depth.
        size_mm: [f64; 3],
        /// Ridge height above the valleys (mm; 0: flat).
        #[serde(default)]
        ridge_height_mm: f64,
        /// Profile of the troughs.
        #[serde(default)]
        profile: Profile,
        /// Straight pieces per half trough of a parabola.
        #[serde(default = "default_trough_segments")]
        segments: usize,
    },
    /// An edge-lit lamp holder: a reflector sheet around a lamp, open towards the guide.
    LampHolder {
        /// Tag of every face.
        tag: String,
        /// Centre of the lamp axis (mm).
        center: [f64; 3],
        /// Lamp axis.
        axis: [f64; 3],
        /// Direction of the opening (perpendicular to the axis).
        opening: [f64; 3],
        /// Length along the axis (mm).
        length_mm: f64,
        /// Height of the opening across the axis (mm).
        aperture_mm: f64,
        /// The section's shape.
        section: Section,
        /// Straight pieces of the section.
        #[serde(default = "default_section_segments")]
        segments: usize,
        /// Flat caps closing both ends.
        #[serde(default = "yes")]
        end_caps: bool,
    },
}

fn default_trough_segments() -> usize {
    8
}

fn default_section_segments() -> usize {
    32
}

fn yes() -> bool {
    true
}

/// The troughs' profile.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum Profile {
    /// Straight slopes from the valley to the ridges.
    #[default]
    Triangle,
    /// A parabola with its vertex in the valley.
    Parabola,
}

/// A lamp holder's section, in the plane across the lamp axis.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum Section {
    /// A circle centred on the lamp axis.
    Circle {
        /// Radius (mm).
        radius_mm: f64,
    },
    /// An ellipse centred on the lamp axis.
    Ellipse {
        /// Semi-axis along the opening direction (mm).
        depth_mm: f64,
        /// Semi-axis across it (mm).
        height_mm: f64,
    },
    /// A parabola whose focus is the lamp axis, its vertex behind the lamp.
    Parabola {
        /// Focal length (mm).
        focal_mm: f64,
    },
}

impl ProceduralSpec {
    /// Check entry `i` and generate its triangles; `lamps` are the scene's sources.
    pub fn build(&self, ctx: &Ctx, i: usize, lamps: &[Source]) -> Result<TaggedTriangles> {
        let f = |k: &str| format!("procedural[{i}].{k}");
        match self {
            ProceduralSpec::DirectLitBox {
                tag,
                origin,
                size_mm,
                ridge_height_mm,
                profile,
                segments,
            } => {
                let origin = ctx.point(&f("origin"), *origin)?;
                let size = size_mm
                    .iter()
                    .map(|s| ctx.length(&f("size_mm"), *s))
                    .collect::<Result<Vec<f64>>>()?;
                let height = ctx.non_negative(&f("ridge_height_mm"), *ridge_height_mm)?;
                if height >= size[2] {
                    return Err(ctx.err(
                        &f("ridge_height_mm"),
                        format!("must be below the depth {} mm, got {height}", size[2]),
                    ));
                }
                let segments = check_segments(ctx, &f("segments"), *segments)?;
                let xs = valleys(origin, [size[0], size[1], size[2]], lamps);
                let prof = back_profile(&xs, size[0], height, *profile, segments);
                check_clearance(
                    ctx,
                    &f("ridge_height_mm"),
                    origin,
                    [size[0], size[1], size[2]],
                    &prof,
                    lamps,
                )?;
                Ok(direct_lit_box(
                    tag,
                    origin,
                    [size[0], size[1], size[2]],
                    &prof,
                ))
            }
            ProceduralSpec::LampHolder {
                tag,
                center,
                axis,
                opening,
                length_mm,
                aperture_mm,
                section,
                segments,
                end_caps,
            } => {
                let center = ctx.point(&f("center"), *center)?;
                let axis = ctx.direction(&f("axis"), *axis)?;
                let opening = ctx.direction(&f("opening"), *opening)?;
                if axis.dot(opening).abs() > 1e-6 {
                    return Err(ctx.err(&f("opening"), "must be perpendicular to axis"));
                }
                let length = ctx.length(&f("length_mm"), *length_mm)?;
                let half = 0.5 * ctx.length(&f("aperture_mm"), *aperture_mm)?;
                let segments = check_segments(ctx, &f("segments"), *segments)?;
                let curve = section_curve(ctx, &f("section"), *section, half, segments)?;
                let frame = Frame {
                    center,
                    axis,
                    opening,
                    across: axis.cross(opening),
                };
                Ok(lamp_holder(tag, &frame, &curve, length, *end_caps))
            }
        }
    }
}

fn check_segments(ctx: &Ctx, field: &str, n: usize) -> Result<usize> {
    if (1..=MAX_SEGMENTS).contains(&n) {
        Ok(n)
    } else {
        Err(ctx.err(field, format!("must be within 1..={MAX_SEGMENTS}, got {n}")))
    }
}

/// x (from the box's origin) of every lamp over the box, sorted.
fn valleys(origin: DVec3, size: [f64; 3], lamps: &[Source]) -> Vec<f64> {
    let mut xs: Vec<f64> = lamps
        .iter()
        .map(|s| s.anchor() - origin)
        .filter(|p| p.x > 0.0 && p.x < size[0] && p.y >= 0.0 && p.y <= size[1])
        .map(|p| p.x)
        .collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    xs
}

/// Every CCFL over the box must lie inside it, clear of the back and the x walls and
/// below the top (light emitted inside a part would be wrong).
fn check_clearance(
    ctx: &Ctx,
    field: &str,
    origin: DVec3,
    size: [f64; 3],
    prof: &[[f64; 2]],
    lamps: &[Source],
) -> Result<()> {
    for s in lamps {
        let Emitter::Ccfl(crate::sources::ccfl::Tube { center, radius, .. }) = &s.emitter else {
            continue;
        };
        // Lamps in the box's slab (its y and z range) must be inside it; lamps above or
        // beyond its ends belong to other parts.
        let p = *center - origin;
        if !(p.y >= 0.0 && p.y <= size[1] && p.z >= 0.0 && p.z <= size[2]) {
            continue;
        }
        let clear = prof
            .windows(2)
            .map(|w| point_segment([p.x, p.z], w[0], w[1]))
            .chain([p.x, size[0] - p.x, size[2] - p.z])
            .fold(f64::INFINITY, f64::min);
        if clear < 0.0 {
            return Err(ctx.err(
                field,
                format!(
                    "source '{}' lies beside the box, outside it ({:.3} mm beyond a wall)",
                    s.name, -clear
                ),
            ));
        }
        if clear < *radius {
            return Err(ctx.err(
                field,
                format!(
                    "source '{}' has its axis {clear:.3} mm from the box's back, walls or top, less than its radius {radius} mm: the tube would cut the box",
                    s.name
                ),
            ));
        }
    }
    Ok(())
}

/// Distance from `p` to the segment `a b` (x, z).
fn point_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dz) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dz * dz;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dz) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dz)
}

/// The back's profile (x, z) from x = 0 to `width`: valleys at `xs`, ridges of `height`
/// midway and at the walls (flat when there is no ridge or no lamp).
fn back_profile(
    xs: &[f64],
    width: f64,
    height: f64,
    profile: Profile,
    segments: usize,
) -> Vec<[f64; 2]> {
    if height == 0.0 || xs.is_empty() {
        return vec![[0.0, 0.0], [width, 0.0]];
    }
    let mut ridges = vec![0.0];
    ridges.extend(xs.windows(2).map(|w| 0.5 * (w[0] + w[1])));
    ridges.push(width);
    let n = match profile {
        Profile::Triangle => 1,
        Profile::Parabola => segments,
    };
    let mut p = vec![[0.0, height]];
    for (k, &v) in xs.iter().enumerate() {
        // Down from the ridge before the valley, then up to the one after it.
        for (from, to) in [(ridges[k], v), (v, ridges[k + 1])] {
            let half_width = if to > v { to - v } else { v - from };
            for j in 1..=n {
                let x = if j == n {
                    to
                } else {
                    from + (to - from) * j as f64 / n as f64
                };
                let r = ((x - v) / half_width).abs();
                let z = match profile {
                    Profile::Triangle => height * r,
                    Profile::Parabola => height * r * r,
                };
                p.push([x, z]);
            }
        }
    }
    p
}

/// Triangles under construction, one tag.
struct Builder {
    tag: String,
    out: TaggedTriangles,
}

impl Builder {
    fn new(tag: &str) -> Self {
        Builder {
            tag: tag.to_string(),
            out: TaggedTriangles::default(),
        }
    }

    /// A triangle wound a, b, c (normal (b - a) x (c - a)).
    fn tri(&mut self, a: DVec3, b: DVec3, c: DVec3) {
        let base = self.out.positions.len() as u32;
        self.out.positions.extend([a, b, c]);
        self.out.triangles.push([base, base + 1, base + 2]);
        self.out.tags.push(self.tag.clone());
    }

    /// Two triangles a, b, c and a, c, d (as `tools/scenegen` splits a quad).
    fn quad(&mut self, a: DVec3, b: DVec3, c: DVec3, d: DVec3) {
        self.tri(a, b, c);
        self.tri(a, c, d);
    }
}

/// The box: one strip of the back per profile segment, the two x walls and a trapezoid of
/// each end wall over each segment, in `tools/scenegen`'s order and winding (into the box).
fn direct_lit_box(
    tag: &str,
    origin: DVec3,
    [w, l, top]: [f64; 3],
    prof: &[[f64; 2]],
) -> TaggedTriangles {
    let p = |x: f64, y: f64, z: f64| origin + DVec3::new(x, y, z);
    let mut b = Builder::new(tag);
    for s in prof.windows(2) {
        let ([xa, za], [xb, zb]) = (s[0], s[1]);
        b.quad(p(xa, 0.0, za), p(xb, 0.0, zb), p(xb, l, zb), p(xa, l, za));
    }
    let (z0, z1) = (prof[0][1], prof[prof.len() - 1][1]);
    b.quad(
        p(0.0, 0.0, z0),
        p(0.0, l, z0),
        p(0.0, l, top),
        p(0.0, 0.0, top),
    );
    b.quad(p(w, 0.0, z1), p(w, 0.0, top), p(w, l, top), p(w, l, z1));
    for s in prof.windows(2) {
        let ([xa, za], [xb, zb]) = (s[0], s[1]);
        b.quad(
            p(xa, 0.0, za),
            p(xa, 0.0, top),
            p(xb, 0.0, top),
            p(xb, 0.0, zb),
        );
        b.quad(p(xa, l, za), p(xb, l, zb), p(xb, l, top), p(xa, l, top));
    }
    b.out
}

/// A lamp holder's frame: the lamp axis centre, the axis, the opening direction and
/// `axis x opening`.
struct Frame {
    center: DVec3,
    axis: DVec3,
    opening: DVec3,
    across: DVec3,
}

impl Frame {
    /// The point `s` along the opening, `t` across it, `a` along the axis.
    fn at(&self, [s, t]: [f64; 2], a: f64) -> DVec3 {
        self.center + self.opening * s + self.across * t + self.axis * a
    }
}

/// The section curve (s along the opening, t across it) from one edge of the aperture
/// (t = -half) round the back to the other (t = +half), in `segments` pieces.
fn section_curve(
    ctx: &Ctx,
    field: &str,
    section: Section,
    half: f64,
    segments: usize,
) -> Result<Vec<[f64; 2]>> {
    let n = segments;
    let arc = |a: f64, b: f64, field: &str| -> Result<Vec<[f64; 2]>> {
        if half >= b {
            return Err(ctx.err(
                field,
                format!(
                    "the aperture ({} mm) must be narrower than the section ({} mm across)",
                    2.0 * half,
                    2.0 * b
                ),
            ));
        }
        // Angle from the opening direction; the aperture edges at +-phi0, the curve
        // round the back from -phi0 down to -(2 pi - phi0).
        let phi0 = (half / b).asin();
        Ok((0..=n)
            .map(|j| {
                let phi = -phi0 - (std::f64::consts::TAU - 2.0 * phi0) * j as f64 / n as f64;
                [a * phi.cos(), b * phi.sin()]
            })
            .collect())
    };
    match section {
        Section::Circle { radius_mm } => {
            let r = ctx.length(&format!("{field}.radius_mm"), radius_mm)?;
            arc(r, r, &format!("{field}.radius_mm"))
        }
        Section::Ellipse {
            depth_mm,
            height_mm,
        } => {
            let a = ctx.length(&format!("{field}.depth_mm"), depth_mm)?;
            let b = ctx.length(&format!("{field}.height_mm"), height_mm)?;
            arc(a, b, &format!("{field}.height_mm"))
        }
        Section::Parabola { focal_mm } => {
            let f = ctx.length(&format!("{field}.focal_mm"), focal_mm)?;
            // Focus at the origin, vertex at s = -f: s = t^2 / (4 f) - f.
            Ok((0..=n)
                .map(|j| {
                    let t = -half + 2.0 * half * j as f64 / n as f64;
                    [t * t / (4.0 * f) - f, t]
                })
                .collect())
        }
    }
}

/// The holder: the section extruded over `length`, wound towards the lamp axis, and a
/// fan-triangulated cap at each end (the section and its aperture chord bound a convex
/// region).
fn lamp_holder(
    tag: &str,
    frame: &Frame,
    curve: &[[f64; 2]],
    length: f64,
    caps: bool,
) -> TaggedTriangles {
    let (a0, a1) = (-0.5 * length, 0.5 * length);
    let mut b = Builder::new(tag);
    for s in curve.windows(2) {
        let (p, q) = (s[0], s[1]);
        let quad = [
            frame.at(p, a0),
            frame.at(q, a0),
            frame.at(q, a1),
            frame.at(p, a1),
        ];
        // Wind towards the axis: the normal must point at the lamp.
        let normal = (quad[1] - quad[0]).cross(quad[2] - quad[0]);
        let mid = 0.5 * (frame.at(p, 0.0) + frame.at(q, 0.0));
        if normal.dot(frame.center - mid) >= 0.0 {
            b.quad(quad[0], quad[1], quad[2], quad[3]);
        } else {
            b.quad(quad[0], quad[3], quad[2], quad[1]);
        }
    }
    if caps {
        let n = curve.len() as f64;
        let c = curve
            .iter()
            .fold([0.0, 0.0], |acc, p| [acc[0] + p[0] / n, acc[1] + p[1] / n]);
        // The fan's last triangle reaches from the aperture chord to the centre.
        let mut edges: Vec<([f64; 2], [f64; 2])> = curve.windows(2).map(|s| (s[0], s[1])).collect();
        edges.push((curve[curve.len() - 1], curve[0]));
        for (a, inward) in [(a0, frame.axis), (a1, -frame.axis)] {
            for &(p, q) in &edges {
                let (p, q, m) = (frame.at(p, a), frame.at(q, a), frame.at(c, a));
                if (q - p).cross(m - p).dot(inward) >= 0.0 {
                    b.tri(p, q, m);
                } else {
                    b.tri(p, m, q);
                }
            }
        }
    }
    b.out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;
    use std::collections::HashMap;
    use std::path::Path;

    /// Directed edges of `t` keyed by their corner positions (bits), with counts.
    fn edges(t: &TaggedTriangles) -> HashMap<([u64; 3], [u64; 3]), usize> {
        let key = |p: DVec3| p.to_array().map(f64::to_bits);
        let mut e = HashMap::new();
        for tri in &t.triangles {
            let c = tri.map(|v| t.positions[v as usize]);
            for k in 0..3 {
                *e.entry((key(c[k]), key(c[(k + 1) % 3]))).or_insert(0) += 1;
            }
        }
        e
    }

    /// The open edges (used once, not by a neighbour the other way round); panics when an
    /// edge is used twice the same way (inconsistent winding) or by more than two faces.
    fn open_edges(t: &TaggedTriangles) -> Vec<[DVec3; 2]> {
        let e = edges(t);
        let p = |k: [u64; 3]| DVec3::from_array(k.map(f64::from_bits));
        let mut open = Vec::new();
        for (&(a, b), &n) in &e {
            assert_eq!(
                n,
                1,
                "edge {:?}-{:?} used {n} times the same way",
                p(a),
                p(b)
            );
            if !e.contains_key(&(b, a)) {
                open.push([p(a), p(b)]);
            }
        }
        open
    }

    fn normals_and_centroids(t: &TaggedTriangles) -> Vec<(DVec3, DVec3)> {
        t.triangles
            .iter()
            .map(|tri| {
                let [a, b, c] = tri.map(|v| t.positions[v as usize]);
                ((b - a).cross(c - a).normalize(), (a + b + c) / 3.0)
            })
            .collect()
    }

    fn ctx() -> Ctx<'static> {
        Ctx(Path::new("scene.toml"))
    }

    fn dl_box(height: f64, profile: Profile, lamps: &[Source]) -> Result<TaggedTriangles> {
        let spec = ProceduralSpec::DirectLitBox {
            tag: "box_reflector".into(),
            origin: [0.0, 0.0, 0.0],
            size_mm: [400.0, 250.0, 25.0],
            ridge_height_mm: height,
            profile,
            segments: 8,
        };
        spec.build(&ctx(), 0, lamps)
    }

    /// The bundled direct-lit scene's lamps, in its file's frame.
    fn direct_lit() -> (Scene, Vec<Source>) {
        let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("scenes/direct-lit/scene.toml");
        let scene = Scene::load(&path).unwrap();
        let mut lamps = scene.sources.clone();
        lamps.translate(scene.offset);
        (scene, lamps.list)
    }

    #[test]
    fn the_direct_lit_box_matches_scenegens_mesh() {
        let (scene, lamps) = direct_lit();
        let ours = dl_box(6.0, Profile::Triangle, &lamps).unwrap();
        let tag = scene
            .tags
            .iter()
            .position(|t| t == "box_reflector")
            .unwrap();
        let theirs: Vec<[DVec3; 3]> = (0..scene.mesh.len() as u32)
            .filter(|&p| scene.mesh.tri_tag[p as usize] as usize == tag)
            .map(|p| scene.mesh.corners(p).map(|c| c + scene.offset))
            .collect();
        assert_eq!(ours.triangles.len(), theirs.len());
        for (t, want) in ours.triangles.iter().zip(&theirs) {
            let got = t.map(|v| ours.positions[v as usize]);
            for (g, w) in got.iter().zip(want) {
                // The OBJ holds 6 decimals.
                assert!((*g - *w).abs().max_element() < 1e-6, "{got:?} vs {want:?}");
            }
        }
    }

    #[test]
    fn the_box_is_open_only_at_its_top_and_faces_inwards() {
        let (_, lamps) = direct_lit();
        for (h, profile) in [
            (6.0, Profile::Triangle),
            (10.0, Profile::Parabola),
            (0.0, Profile::Triangle),
        ] {
            let b = dl_box(h, profile, &lamps).unwrap();
            let open = open_edges(&b);
            assert!(!open.is_empty());
            assert!(
                open.iter().flatten().all(|p| p.z == 25.0),
                "{h} {profile:?}: {open:?}"
            );
            let rim: f64 = open.iter().map(|[a, b]| (*b - *a).length()).sum();
            assert!((rim - 2.0 * (400.0 + 250.0)).abs() < 1e-9, "rim {rim}");
            // The back faces up; each wall faces the middle of the box.
            for (n, c) in normals_and_centroids(&b) {
                let inwards = if n.z.abs() > 1e-9 {
                    n.z > 0.0
                } else if n.x.abs() > 0.999 {
                    n.x * (200.0 - c.x) > 0.0
                } else {
                    n.y.abs() > 0.999 && n.y * (125.0 - c.y) > 0.0
                };
                assert!(inwards, "{h} {profile:?}: normal {n} at {c}");
            }
        }
    }

    #[test]
    fn parabolic_troughs_have_their_vertex_under_each_lamp() {
        let (_, lamps) = direct_lit();
        let xs = valleys(DVec3::ZERO, [400.0, 250.0, 25.0], &lamps);
        assert_eq!(xs.len(), 6);
        let p = back_profile(&xs, 400.0, 6.0, Profile::Parabola, 4);
        assert_eq!(p.len(), 1 + 6 * 2 * 4);
        // Valleys at the lamps, ridges midway and at the walls, z = h (dx / half width)^2.
        let half = 400.0 / 12.0;
        for [x, z] in &p {
            let v = xs
                .iter()
                .map(|v| (x - v).abs())
                .fold(f64::INFINITY, f64::min);
            assert!((z - 6.0 * (v / half).powi(2)).abs() < 1e-6, "({x}, {z})");
        }
    }

    fn holder(section: Section, caps: bool) -> Result<TaggedTriangles> {
        ProceduralSpec::LampHolder {
            tag: "holder".into(),
            center: [1.0, 2.0, 3.0],
            axis: [0.0, 1.0, 0.0],
            opening: [1.0, 0.0, 0.0],
            length_mm: 50.0,
            aperture_mm: 3.0,
            section,
            segments: 24,
            end_caps: caps,
        }
        .build(&ctx(), 0, &[])
    }

    #[test]
    fn lamp_holders_are_open_only_at_their_aperture_and_face_the_lamp() {
        let centre = DVec3::new(1.0, 2.0, 3.0);
        for (section, edge_s) in [
            (
                Section::Circle { radius_mm: 2.5 },
                (2.5f64.powi(2) - 1.5f64.powi(2)).sqrt(),
            ),
            (
                Section::Ellipse {
                    depth_mm: 4.0,
                    height_mm: 2.5,
                },
                4.0 * (1.0 - (1.5f64 / 2.5).powi(2)).sqrt(),
            ),
            (Section::Parabola { focal_mm: 1.0 }, 1.5 * 1.5 / 4.0 - 1.0),
        ] {
            let h = holder(section, true).unwrap();
            let open = open_edges(&h);
            // The two long aperture edges and the two cap chords, all in the aperture plane.
            let len: f64 = open.iter().map(|[a, b]| (*b - *a).length()).sum();
            assert!(
                (len - 2.0 * (50.0 + 3.0)).abs() < 1e-9,
                "{section:?}: {len}"
            );
            for p in open.iter().flatten() {
                assert!((p.x - centre.x - edge_s).abs() < 1e-9, "{section:?}: {p}");
            }
            for (n, c) in normals_and_centroids(&h) {
                let to_axis = DVec3::new(centre.x - c.x, 0.0, centre.z - c.z);
                let is_cap = n.y.abs() > 0.5;
                let inward = if is_cap {
                    DVec3::new(0.0, centre.y - c.y, 0.0)
                } else {
                    to_axis
                };
                assert!(n.dot(inward) > 0.0, "{section:?}: normal {n} at {c}");
            }
            let sheet = holder(section, false).unwrap();
            assert_eq!(sheet.triangles.len(), 2 * 24);
        }
    }

    #[test]
    fn sections_follow_their_curves() {
        let c = |s| section_curve(&ctx(), "s", s, 1.5, 64).unwrap();
        for [s, t] in c(Section::Circle { radius_mm: 2.5 }) {
            assert!((s.hypot(t) - 2.5).abs() < 1e-12);
        }
        for [s, t] in c(Section::Ellipse {
            depth_mm: 4.0,
            height_mm: 2.5,
        }) {
            assert!(((s / 4.0).powi(2) + (t / 2.5).powi(2) - 1.0).abs() < 1e-12);
        }
        // A parabola's points are as far from the focus as from the directrix s = -2f.
        for [s, t] in c(Section::Parabola { focal_mm: 1.0 }) {
            assert!((s.hypot(t) - (s + 2.0)).abs() < 1e-12);
        }
        let ends = c(Section::Circle { radius_mm: 2.5 });
        assert!((ends[0][1] + 1.5).abs() < 1e-12 && (ends[64][1] - 1.5).abs() < 1e-12);
    }

    #[test]
    fn bad_parameters_name_the_field() {
        let e = |r: Result<TaggedTriangles>| format!("{:#}", r.unwrap_err());
        assert!(
            e(dl_box(25.0, Profile::Triangle, &[]))
                .contains("procedural[0].ridge_height_mm: must be below the depth")
        );
        assert!(
            e(dl_box(-1.0, Profile::Triangle, &[]))
                .contains("procedural[0].ridge_height_mm: must be >= 0")
        );
        assert!(
            e(holder(Section::Circle { radius_mm: 1.0 }, true))
                .contains("procedural[0].section.radius_mm: the aperture")
        );
        assert!(
            e(holder(Section::Parabola { focal_mm: 0.0 }, true))
                .contains("procedural[0].section.focal_mm: must be > 0")
        );
        // Lamps 1 mm above the valleys: the tubes (radius 1.5) would cut the back.
        let (_, mut lamps) = direct_lit();
        lamps
            .iter_mut()
            .for_each(|l| l.translate(DVec3::new(0.0, 0.0, -7.0)));
        let m = e(dl_box(6.0, Profile::Triangle, &lamps));
        assert!(
            m.contains("procedural[0].ridge_height_mm: source 'lamp1' has its axis 0.984 mm from"),
            "{m}"
        );
        // A lamp beside the box, beyond its x wall.
        let (_, mut lamps) = direct_lit();
        lamps[5].translate(DVec3::new(50.0, 0.0, 0.0));
        let m = e(dl_box(6.0, Profile::Triangle, &lamps));
        assert!(
            m.contains("source 'lamp6' lies beside the box, outside it (16.667 mm beyond a wall)"),
            "{m}"
        );
    }
}
