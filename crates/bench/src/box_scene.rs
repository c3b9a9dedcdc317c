//! The box-guide scene of the reference kernel ([`super::reference`]), read from a loaded
//! [`Scene`]: every number the kernel traces with, as axis-aligned rectangles in `f32`,
//! or an error saying why a scene is not of that shape.
//!
//! The shape (`scenes/bench-box`):
//!
//! ```toml
//! [media.pmma]                 # one clear medium besides air (air clear too)
//! n = 1.49
//! absorption_per_mm = 0.0003
//!
//! [surfaces.lgp_back]          # an axis-aligned box of dielectric faces (inside the
//! model = "dots"               # medium, outside air), one of them printed with dots:
//! lattice = "square"           # square lattice, dots at the cell centres, a polynomial
//! density = [0.05, 0.2, 0.4]   # density
//!
//! [surfaces.reflector_sheet]   # one flat axis-aligned Lambertian rectangle
//! model = "lambert"
//!
//! [[sources]]                  # one Lambertian LED rectangle, axis-aligned, in air; its
//! type = "led"                 # body absent, an absorber or Lambertian
//! cos_exponent = 1.0
//!
//! [detector]                   # axis-aligned u and v
//! ```
//!
//! Coordinates are the loaded scene's (recentred, so within a few hundred mm of the
//! origin): `f32` keeps positions to a few nanometres there, far below the dot sizes.

use anyhow::{Result, bail};
use blutrace::geometry::Aabb;
use blutrace::optics::density::Density;
use blutrace::optics::dots::{Lattice, Placement};
use blutrace::optics::lambert::Lambert;
use blutrace::optics::surface::SurfaceModel;
use blutrace::scene::Scene;
use blutrace::sources::Emitter;
use blutrace::sources::body_shape::BodyShape;
use blutrace::sources::led::LedProfile;
use glam::{DVec3, Vec3};
use std::f64::consts::PI;

/// An axis-aligned rectangle: the plane `x[axis] = at`, spanning `lo..hi` along the two
/// other axes, taken in the order `(axis + 1) % 3`, `(axis + 2) % 3`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AaRect {
    /// The axis of the normal.
    pub axis: usize,
    /// The plane's coordinate along it.
    pub at: f32,
    /// Lower bounds along the two other axes.
    pub lo: [f32; 2],
    /// Upper bounds along the two other axes.
    pub hi: [f32; 2],
}

impl AaRect {
    /// The two other axes.
    pub fn others(axis: usize) -> (usize, usize) {
        ((axis + 1) % 3, (axis + 2) % 3)
    }

    /// Distance along the ray `p + t d` to this rectangle, when ahead (`t > 0`) and
    /// within its edges. A ray starting on the plane never meets it.
    #[inline]
    pub fn hit(&self, p: Vec3, d: Vec3) -> Option<f32> {
        let (k1, k2) = Self::others(self.axis);
        let t = (self.at - p[self.axis]) / d[self.axis];
        if !(t > 0.0 && t.is_finite()) {
            return None;
        }
        let (a, b) = (p[k1] + d[k1] * t, p[k2] + d[k2] * t);
        (a >= self.lo[0] && a <= self.hi[0] && b >= self.lo[1] && b <= self.hi[1]).then_some(t)
    }

    /// The rectangle through the points `pts`, which must all lie on one axis-aligned
    /// plane (within `tol`).
    fn bounding(pts: &[DVec3], tol: f64) -> Option<AaRect> {
        let (lo, hi) = bounds(pts);
        let axis = (0..3).find(|&k| hi[k] - lo[k] <= tol)?;
        let (k1, k2) = Self::others(axis);
        Some(AaRect {
            axis,
            at: (0.5 * (lo[axis] + hi[axis])) as f32,
            lo: [lo[k1] as f32, lo[k2] as f32],
            hi: [hi[k1] as f32, hi[k2] as f32],
        })
    }

    /// Area (mm^2).
    fn area(&self) -> f64 {
        f64::from(self.hi[0] - self.lo[0]) * f64::from(self.hi[1] - self.lo[1])
    }
}

/// What the body of the strip does to light that comes back to its front.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Body {
    /// No body: the light passes.
    Transparent,
    /// Absorbed (front and back).
    Absorber,
    /// Lambertian front of this albedo; the back absorbs.
    Lambert(f32),
}

/// The Lambertian emitting rectangle and its body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Strip {
    /// The rectangle.
    pub rect: AaRect,
    /// +1 or -1: the emitting normal is this sign along `rect.axis`.
    pub facing: f32,
    /// Its body.
    pub body: Body,
}

/// The target plane: crossings along `+normal_sign` of `rect.axis` are detected.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    /// The plane and its extent.
    pub rect: AaRect,
    /// +1 or -1: detected photons travel this way along `rect.axis`.
    pub normal_sign: f32,
    /// The detector's corner.
    pub origin: Vec3,
    /// Axis and sign of grid x (`u`) and grid y (`v`).
    pub u: (usize, f32),
    /// See `u`.
    pub v: (usize, f32),
    /// Size along u and v (mm).
    pub size: [f32; 2],
    /// Flux bins along u and v.
    pub bins: [usize; 2],
}

/// A square lattice of dots at the cell centres on one face of the box.
#[derive(Clone, Debug, PartialEq)]
pub struct Dots {
    /// The box face (`2 axis + side`, side 1 the upper) printed with them.
    pub face: usize,
    /// Pattern origin.
    pub origin: Vec3,
    /// Propagation axis (the density varies along it).
    pub axis: Vec3,
    /// In-face direction across it.
    pub across: Vec3,
    /// Pitch (mm).
    pub pitch: f32,
    /// Column (cell index along `axis`) of `r2[0]`.
    pub col0: i32,
    /// Squared dot radius (mm^2) per column.
    pub r2: Vec<f32>,
    /// Ink albedo.
    pub ink_albedo: f32,
}

/// The whole box-guide scene, as the reference kernel traces it.
#[derive(Clone, Debug, PartialEq)]
pub struct BoxScene {
    /// The guide's lower corner.
    pub lo: Vec3,
    /// The guide's upper corner.
    pub hi: Vec3,
    /// Refractive index of the guide, and of the air around it.
    pub n_guide: f32,
    /// See `n_guide`.
    pub n_air: f32,
    /// Beer-Lambert absorption of the guide (1/mm).
    pub absorption: f32,
    /// The dotted face.
    pub dots: Dots,
    /// The Lambertian sheet and its albedo.
    pub sheet: AaRect,
    /// See `sheet`.
    pub sheet_albedo: f32,
    /// The emitter.
    pub strip: Strip,
    /// The target plane.
    pub target: Target,
    /// Interactions before a photon is killed.
    pub max_bounces: u32,
    /// Total source power (W).
    pub power_w: f64,
    /// Tags of the dotted face and of the sheet (to compare with blutrace's ledger).
    pub dots_tag: usize,
    /// See `dots_tag`.
    pub sheet_tag: usize,
}

/// Why a scene is not a box-guide scene.
fn refuse(scene: &Scene, why: impl std::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!(
        "{}: the reference kernel traces only box-guide scenes (like scenes/bench-box): {why}",
        scene.path.display()
    )
}

fn bounds(pts: &[DVec3]) -> (DVec3, DVec3) {
    let b = Aabb::of(pts.iter().copied());
    (b.min, b.max)
}

/// The axis and sign of a unit vector along a coordinate axis.
fn axis_of(v: DVec3) -> Option<(usize, f32)> {
    (0..3)
        .find(|&k| (v[k].abs() - 1.0).abs() < 1e-12)
        .map(|k| (k, v[k].signum() as f32))
}

impl BoxScene {
    /// Read the box-guide scene from `scene`, or say why it is not one.
    pub fn from_scene(scene: &Scene) -> Result<BoxScene> {
        if scene.polarized {
            bail!(refuse(
                scene,
                "it traces polarization: the kernel averages Fresnel over s and p ([trace] polarization = false)"
            ));
        }
        if scene.media.len() != 2 {
            bail!(refuse(scene, "it needs exactly one medium besides air"));
        }
        let (air, guide) = (&scene.media[0], &scene.media[1]);
        if air.absorption_per_mm.nominal() != 0.0 || air.scattering.scatters() {
            bail!(refuse(scene, "the air must be clear"));
        }
        if guide.scattering.scatters() {
            bail!(refuse(scene, format!("medium '{}' scatters", guide.name)));
        }
        let mesh = &scene.mesh;
        let tol = 1e-9 * mesh.bounds().diagonal().max(1.0);
        let (mut box_prims, mut other) = (Vec::new(), Vec::new());
        for p in 0..mesh.len() as u32 {
            let tag = mesh.tri_tag[p as usize] as usize;
            match scene.surfaces[tag].interface() {
                Some(i) if i.inside == 1 && i.outside == 0 => box_prims.push(p),
                Some(_) => bail!(refuse(
                    scene,
                    format!(
                        "tag '{}' is an interface but not guide to air",
                        scene.tags[tag]
                    )
                )),
                None => other.push(p),
            }
        }
        let pts: Vec<DVec3> = box_prims.iter().flat_map(|&p| mesh.corners(p)).collect();
        if pts.is_empty() || scene.convex_solid(1).is_none() {
            bail!(refuse(scene, "no convex guide"));
        }
        let (lo, hi) = bounds(&pts);
        // Each box triangle on one face; one tag, and full coverage, per face.
        let mut face_tag = [usize::MAX; 6];
        let mut face_area = [0.0; 6];
        for &p in &box_prims {
            let c = mesh.corners(p);
            let face = (0..6).find(|&f| {
                let (k, v) = (f / 2, if f % 2 == 0 { lo[f / 2] } else { hi[f / 2] });
                c.iter().all(|q| (q[k] - v).abs() <= tol)
            });
            let Some(f) = face else {
                bail!(refuse(scene, "the guide is not an axis-aligned box"));
            };
            let tag = mesh.tri_tag[p as usize] as usize;
            if face_tag[f] != usize::MAX && face_tag[f] != tag {
                bail!(refuse(scene, "a face of the guide carries two tags"));
            }
            face_tag[f] = tag;
            face_area[f] += 0.5 * (c[1] - c[0]).cross(c[2] - c[0]).length();
        }
        let ext = hi - lo;
        for (f, area) in face_area.iter().enumerate() {
            let (k1, k2) = AaRect::others(f / 2);
            let want = ext[k1] * ext[k2];
            if (area - want).abs() > 1e-9 * want.max(1.0) {
                bail!(refuse(
                    scene,
                    "the guide's faces do not close an axis-aligned box"
                ));
            }
        }
        let dots = dots_of(scene, &face_tag, lo, hi)?;
        let (sheet, sheet_albedo, sheet_tag) = sheet_of(scene, &other, tol)?;
        let strip = strip_of(scene)?;
        let target = target_of(scene)?;
        let (lo, hi) = (lo.as_vec3(), hi.as_vec3());
        for (what, r) in [
            ("the sheet", sheet),
            ("the source", strip.rect),
            ("the detector", target.rect),
        ] {
            if cuts_box(&r, lo, hi) {
                bail!(refuse(scene, format!("{what} reaches into the guide")));
            }
        }
        Ok(BoxScene {
            lo,
            hi,
            n_guide: guide.n.nominal() as f32,
            n_air: air.n.nominal() as f32,
            absorption: guide.absorption_per_mm.nominal() as f32,
            dots,
            sheet,
            sheet_albedo,
            strip,
            target,
            max_bounces: scene.max_bounces,
            power_w: scene.sources.total_power(),
            dots_tag: face_tag[0..6]
                .iter()
                .copied()
                .find(|&t| matches!(scene.surfaces[t], SurfaceModel::Dots { .. }))
                .expect("dots_of found one"),
            sheet_tag,
        })
    }
}

/// True when rectangle `r` has points strictly inside the box.
fn cuts_box(r: &AaRect, lo: Vec3, hi: Vec3) -> bool {
    let (k1, k2) = AaRect::others(r.axis);
    let open = |a0: f32, a1: f32, b0: f32, b1: f32| a0 < b1 && b0 < a1;
    r.at > lo[r.axis]
        && r.at < hi[r.axis]
        && open(r.lo[0], r.hi[0], lo[k1], hi[k1])
        && open(r.lo[1], r.hi[1], lo[k2], hi[k2])
}

/// The one dotted face: square lattice, dots at the cell centres, polynomial density.
fn dots_of(scene: &Scene, face_tag: &[usize; 6], lo: DVec3, hi: DVec3) -> Result<Dots> {
    let mut found = None;
    for (f, &tag) in face_tag.iter().enumerate() {
        match &scene.surfaces[tag] {
            SurfaceModel::Dielectric(_) => {}
            SurfaceModel::Dots(d) => {
                if found.is_some() {
                    bail!(refuse(scene, "dots on more than one face"));
                }
                found = Some((f, &d.pattern, d.ink_albedo.clone()));
            }
            other => bail!(refuse(
                scene,
                format!("guide face tag '{}' is {}", scene.tags[tag], other.kind())
            )),
        }
    }
    let Some((face, pattern, ink_albedo)) = found else {
        bail!(refuse(scene, "no dotted face"));
    };
    if pattern.lattice != Lattice::Square || pattern.placement != Placement::Lattice {
        bail!(refuse(
            scene,
            "dots must be on a square lattice at the cell centres (placement \"lattice\")"
        ));
    }
    let Density::Polynomial(coeffs) = &pattern.grade.density else {
        bail!(refuse(scene, "the dot density must be a polynomial"));
    };
    // The columns (cells along the axis) the face spans, one more each side.
    let (k, v) = (
        face / 2,
        if face % 2 == 0 {
            lo[face / 2]
        } else {
            hi[face / 2]
        },
    );
    let (k1, k2) = AaRect::others(k);
    let mut along = Vec::new();
    for (a, b) in [
        (lo[k1], lo[k2]),
        (hi[k1], lo[k2]),
        (lo[k1], hi[k2]),
        (hi[k1], hi[k2]),
    ] {
        let mut c = DVec3::ZERO;
        (c[k], c[k1], c[k2]) = (v, a, b);
        along.push((c - pattern.origin).dot(pattern.axis));
    }
    let p = pattern.pitch;
    let lo_col = (along.iter().copied().fold(f64::INFINITY, f64::min) / p).floor() as i32 - 1;
    let hi_col = (along.iter().copied().fold(f64::NEG_INFINITY, f64::max) / p).floor() as i32 + 1;
    let r2 = (lo_col..=hi_col)
        .map(|i| {
            let u = (f64::from(i) + 0.5) * p;
            let x = pattern.x_of(u);
            let d = coeffs.iter().rev().fold(0.0, |acc, c| acc * x + c);
            (d.max(0.0) * p * p / PI) as f32
        })
        .collect();
    Ok(Dots {
        face,
        origin: pattern.origin.as_vec3(),
        axis: pattern.axis.as_vec3(),
        across: pattern.across.as_vec3(),
        pitch: p as f32,
        col0: lo_col,
        r2,
        ink_albedo: ink_albedo.nominal() as f32,
    })
}

/// The one Lambertian sheet: every triangle outside the guide, one flat rectangle.
fn sheet_of(scene: &Scene, prims: &[u32], tol: f64) -> Result<(AaRect, f32, usize)> {
    let mesh = &scene.mesh;
    let Some(&first) = prims.first() else {
        bail!(refuse(scene, "no reflector sheet"));
    };
    let tag = mesh.tri_tag[first as usize] as usize;
    if prims
        .iter()
        .any(|&p| mesh.tri_tag[p as usize] as usize != tag)
    {
        bail!(refuse(scene, "more than one part besides the guide"));
    }
    let SurfaceModel::Lambert(Lambert { albedo }) = &scene.surfaces[tag] else {
        bail!(refuse(
            scene,
            format!("tag '{}' is not a Lambertian sheet", scene.tags[tag])
        ));
    };
    let pts: Vec<DVec3> = prims.iter().flat_map(|&p| mesh.corners(p)).collect();
    let area: f64 = prims
        .iter()
        .map(|&p| {
            let c = mesh.corners(p);
            0.5 * (c[1] - c[0]).cross(c[2] - c[0]).length()
        })
        .sum();
    match AaRect::bounding(&pts, tol) {
        Some(r) if (r.area() - area).abs() <= 1e-6 * area => Ok((r, albedo.nominal() as f32, tag)),
        _ => bail!(refuse(
            scene,
            format!(
                "tag '{}' is not one flat axis-aligned rectangle",
                scene.tags[tag]
            )
        )),
    }
}

/// The one source: a Lambertian LED rectangle in air, axis-aligned.
fn strip_of(scene: &Scene) -> Result<Strip> {
    let [s] = scene.sources.list.as_slice() else {
        bail!(refuse(scene, "it needs exactly one source"));
    };
    let lambertian =
        matches!(&s.emitter, Emitter::Led(led) if led.profile == LedProfile::CosPower(1.0));
    let rect = s.emitter.rect();
    let (Some(r), true, 0) = (rect, lambertian, s.medium) else {
        bail!(refuse(
            scene,
            "the source must be an LED with cos_exponent = 1, in air"
        ));
    };
    let v = r.normal.cross(r.u);
    let corners: Vec<DVec3> = [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)]
        .iter()
        .map(|(a, b)| r.center + r.u * (a * r.half_width) + v * (b * r.half_height))
        .collect();
    let (Some((axis, facing)), Some(_)) = (axis_of(r.normal), axis_of(r.u)) else {
        bail!(refuse(scene, "the LED must be axis-aligned"));
    };
    let rect = AaRect::bounding(&corners, 1e-9).expect("axis-aligned");
    debug_assert_eq!(rect.axis, axis);
    let body = match &s.body {
        None => Body::Transparent,
        Some(b) => match (&b.shape, &b.model) {
            (BodyShape::Rectangle(_), SurfaceModel::Absorber(_)) => Body::Absorber,
            (BodyShape::Rectangle(_), SurfaceModel::Lambert(l)) => {
                Body::Lambert(l.albedo.nominal() as f32)
            }
            _ => bail!(refuse(
                scene,
                "the LED's body must be its rectangle, absorbing or Lambertian"
            )),
        },
    };
    Ok(Strip { rect, facing, body })
}

/// The target plane, with axis-aligned `u` and `v`.
fn target_of(scene: &Scene) -> Result<Target> {
    let d = &scene.detector;
    let (Some(u), Some(v), Some((axis, normal_sign))) =
        (axis_of(d.u), axis_of(d.v), axis_of(d.normal()))
    else {
        bail!(refuse(
            scene,
            "the detector's u and v must be coordinate axes"
        ));
    };
    let far = d.origin + d.u * d.size[0] + d.v * d.size[1];
    let rect = AaRect::bounding(&[d.origin, far], 1e-9).expect("in its plane");
    debug_assert_eq!(rect.axis, axis);
    Ok(Target {
        rect,
        normal_sign,
        origin: d.origin.as_vec3(),
        u,
        v,
        size: [d.size[0] as f32, d.size[1] as f32],
        bins: d.bins,
    })
}
