//! Scene loading: the scene file, its geometry files, and validation into a traceable
//! [`Scene`]. Every error names the file and the field.
//!
//! See [`config`] for the file format. Loading also:
//! - drops zero-area triangles (with a warning);
//! - checks that every dielectric medium is bounded by a closed surface and orients its
//!   faces outward (re-winding inconsistent CAD exports, with a warning);
//! - moves the scene's centre to the origin, so f32 backends keep their precision far
//!   from the file's origin (outputs are in detector coordinates, so nothing changes).

mod array_lengths;
pub mod check_report;
pub mod config;
pub mod geometry_file;
pub mod geometry_report;
mod gltf_checks;
mod hash;
pub mod inputs;
pub mod key_path;
mod lamp_placement;
mod media_checks;
pub mod meshio;
pub mod procedural;
pub mod schema;
mod solids;

use crate::accel::convex::ConvexSolid;
use crate::detector::TargetPlane;
use crate::geometry::{Aabb, Mesh, spawn_epsilon};
use crate::optics::medium::{self, Medium, MediumId};
use crate::optics::surface::{Face, SurfaceModel};
use crate::sources::{SourceSpec, Sources};
use crate::spec_check::{Ctx, MAX_COORDINATE};
use anyhow::{Context, Result};
use config::SceneFile;
use geometry_report::GeometryReport;
use glam::DVec3;
use meshio::ReadCache;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A validated, traceable scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Scene name.
    pub name: String,
    /// The scene file.
    pub path: PathBuf,
    /// All triangles, each with a tag index.
    pub mesh: Arc<Mesh>,
    /// Tag names, indexed by the mesh's tag indices.
    pub tags: Vec<String>,
    /// Optical model per tag.
    pub surfaces: Vec<SurfaceModel>,
    /// The model of each tag's back, when it has one ([`crate::optics::two_sided`]).
    pub backs: Vec<Option<SurfaceModel>>,
    /// Media; index 0 is the ambient medium (air).
    pub media: Vec<Medium>,
    /// Light sources.
    pub sources: Sources,
    /// Target plane.
    pub detector: TargetPlane,
    /// Bounce cap per photon.
    pub max_bounces: u32,
    /// Default photon count.
    pub default_photons: u64,
    /// Default seed.
    pub default_seed: u64,
    /// Offset by which the file's coordinates were moved (file = scene + offset).
    pub offset: DVec3,
    /// Distance (mm) by which a scattered ray starts off its surface.
    pub spawn_eps: f64,
    /// Non-fatal findings of loading, for the user.
    pub warnings: Vec<String>,
    /// What each geometry file contributed, in the scene file's frame (for `check`).
    pub geometry: Vec<GeometryReport>,
    /// Per medium: its convex solid when the fast path applies (see [`ConvexSolid`]).
    pub convex: Vec<Option<ConvexSolid>>,
    /// Every file loading read ([`inputs`]): outputs never replace one of them.
    pub inputs: Vec<PathBuf>,
    /// Whether photons carry their polarization ([`crate::optics::polarization`]).
    pub polarized: bool,
    /// Hash of the scene file's physics sections and the tables they name.
    file_hash: u64,
    /// The scene file as written ([`Scene::source`]; [`key_path`] reads and edits it).
    source: toml::Value,
}

impl Scene {
    /// Load and validate the scene file at `path` and the geometry it names.
    pub fn load(path: &Path) -> Result<Scene> {
        let text = crate::input_file::read_text(path, "scene file")?;
        let parse_error = |e: toml::de::Error| anyhow::anyhow!("{}: {e}", path.display());
        // Typed from the text, so a parse error quotes its line.
        let file: SceneFile = toml::from_str(&text).map_err(parse_error)?;
        let source: toml::Value = toml::from_str(&text).map_err(parse_error)?;
        array_lengths::check(&Ctx(path), &source, &file)?;
        Self::build(&file, source, path, &ReadCache::default())
    }

    /// Build a scene from an already parsed scene file; geometry paths are relative to
    /// `path`'s folder.
    pub fn from_file(file: &SceneFile, path: &Path) -> Result<Scene> {
        Self::from_file_reading(file, path, &ReadCache::default())
    }

    /// [`Scene::from_file`], reading geometry files through `reads`: a file read for an
    /// earlier scene with the same placement is copied, not parsed again (the designs of
    /// a layout search).
    pub fn from_file_reading(file: &SceneFile, path: &Path, reads: &ReadCache) -> Result<Scene> {
        let source = toml::Value::try_from(file)
            .with_context(|| format!("{}: cannot write the scene file", path.display()))?;
        Self::build(file, source, path, reads)
    }

    /// Check `file` (whose document as written is `source`) and build the scene.
    fn build(
        file: &SceneFile,
        source: toml::Value,
        path: &Path,
        reads: &ReadCache,
    ) -> Result<Scene> {
        let ctx = Ctx(path);
        if file.version != config::SCENE_VERSION {
            return Err(ctx.err(
                "version",
                format!(
                    "this blutrace reads version {}, the file says {}",
                    config::SCENE_VERSION,
                    file.version
                ),
            ));
        }
        let mut warnings = Vec::new();
        // A spectral scene's particles scatter over wavelength (Mie tabulated at load).
        let keyed = file.sources.iter().any(SourceSpec::has_spectrum);
        let mut media = medium::build_media(&ctx, &file.media, keyed)?;
        // Sources first: procedural reflectors follow the lamps.
        let sources = Sources::build(&ctx, &file.sources, &media)?;
        // A ray file's wavelengths make a scene spectral without any `spectrum` key: the
        // media are built again, over wavelength (the same media, so the same ids).
        let spectral = sources.spectral();
        if spectral != keyed {
            media = medium::build_media(&ctx, &file.media, spectral)?;
        }
        if spectral {
            warnings.extend(medium::spectral_warnings(&file.media));
        }
        let (mut mesh, tags, geometry) =
            load_geometry(&ctx, file, path, &sources.list, &mut warnings, reads)?;
        let (mut surfaces, mut backs) = (Vec::new(), Vec::new());
        for tag in &tags {
            let entry = file
                .surfaces
                .get(tag)
                .expect("tags are checked against surfaces");
            let (front, back) = entry.build(&ctx, &format!("surfaces.{tag}"), &media)?;
            surfaces.push(front);
            backs.push(back);
        }
        for unused in file.surfaces.keys().filter(|k| !tags.contains(k)) {
            warnings.push(format!(
                "[surfaces.{unused}] is not used by any geometry file"
            ));
        }
        solids::orient_closed_solids(&ctx, &mut mesh, &tags, &surfaces, &media, &mut warnings)?;
        media_checks::check_media(
            &ctx,
            &mesh,
            &tags,
            &|p| surfaces[mesh.tri_tag[p] as usize].interface(),
            &media,
        )?;
        fit_models_to_faces(&ctx, &mesh, &tags, &mut surfaces)?;
        lamp_placement::check_source_media(
            &ctx,
            &mesh,
            &|p| surfaces[mesh.tri_tag[p] as usize].interface(),
            &media,
            &sources.list,
        )?;
        let polarized = traces_polarization(&ctx, file, (&surfaces, &backs), &sources)?;
        if !polarized {
            warnings.extend(unpolarized_sources(file));
        }
        let detector = file.detector.build(&ctx)?;
        warnings.extend(detector.coarse_warning());
        if file.trace.photons == 0 {
            return Err(ctx.err("trace.photons", "must be at least 1"));
        }
        if file.trace.max_bounces == 0 {
            return Err(ctx.err("trace.max_bounces", "must be at least 1"));
        }
        let name = match &file.name {
            Some(n) => ctx.name("name", n)?.to_owned(),
            None => default_name(path),
        };
        let mut scene = Scene {
            name,
            path: path.to_path_buf(),
            mesh: Arc::new(mesh),
            tags,
            surfaces,
            backs,
            media,
            sources,
            detector,
            max_bounces: file.trace.max_bounces,
            default_photons: file.trace.photons,
            default_seed: file.trace.seed,
            offset: DVec3::ZERO,
            spawn_eps: 0.0,
            warnings,
            geometry,
            convex: Vec::new(),
            inputs: inputs::input_files(file, path),
            file_hash: hash::file_hash(file, path, polarized)?,
            polarized,
            source,
        };
        scene.recenter();
        scene.warnings.extend(placement_warnings(&scene));
        scene.convex = convex_solids(&scene);
        Ok(scene)
    }

    /// Move the scene so its bounding box is centred on the origin and set the spawn
    /// offset for the new extent.
    fn recenter(&mut self) {
        let mut b = self.mesh.bounds();
        for s in &self.sources.list {
            b.grow(s.anchor());
        }
        b.grow(self.detector.origin);
        let c = if b.is_empty() {
            DVec3::ZERO
        } else {
            0.5 * (b.min + b.max)
        };
        let mesh = Arc::make_mut(&mut self.mesh);
        mesh.positions.iter_mut().for_each(|p| *p -= c);
        self.sources.translate(-c);
        self.detector.origin -= c;
        for s in self
            .surfaces
            .iter_mut()
            .chain(self.backs.iter_mut().flatten())
        {
            s.translate(-c);
        }
        self.offset += c;
        let extent = Aabb {
            min: b.min - c,
            max: b.max - c,
        }
        .max_abs_coordinate();
        self.spawn_eps = spawn_epsilon(extent);
    }

    /// The start of a ray leaving a surface at `point` (unit `normal`) along `dir`:
    /// nudged off the surface to the side `dir` goes. One rule for all backends.
    pub fn spawn_point(&self, point: DVec3, normal: DVec3, dir: DVec3) -> DVec3 {
        crate::geometry::spawn_origin(point, normal, dir, self.spawn_eps)
    }

    /// A 64-bit hash of everything that decides the physics, over canonical serialized
    /// data (see the `hash` module): not the name, path or defaults. Shards of one run
    /// must agree on it.
    pub fn content_hash(&self) -> u64 {
        hash::content_hash(self.file_hash, &self.mesh)
    }

    /// Edit the scene's mesh with `edit` (say, refine a tag's triangles for a benchmark),
    /// keeping what the scene derives from it (the convex solids of the fast path) in
    /// step. The edit must keep every solid closed and every tag on its faces.
    pub fn edit_mesh(&mut self, edit: impl FnOnce(&mut Mesh)) {
        edit(Arc::make_mut(&mut self.mesh));
        self.convex = convex_solids(self);
    }

    /// Whether the run has luminance maps (and colour maps): the sources give lumens or
    /// spectra.
    pub fn luminous(&self) -> bool {
        self.sources.spectral() || self.sources.luminous_efficacy().is_some()
    }

    /// The convex solid of `medium`, when the fast path applies to it.
    pub fn convex_solid(&self, medium: MediumId) -> Option<&ConvexSolid> {
        self.convex.get(medium as usize)?.as_ref()
    }

    /// Number of triangles per tag.
    pub fn triangles_per_tag(&self) -> Vec<usize> {
        let mut n = vec![0; self.tags.len()];
        self.mesh.tri_tag.iter().for_each(|&t| n[t as usize] += 1);
        n
    }
}

/// Parts cut by the detector plane or by a lamp's emitting surface (positions in the
/// scene file's frame).
fn placement_warnings(scene: &Scene) -> Vec<String> {
    let (mesh, tags, eps) = (&scene.mesh, &scene.tags, scene.spawn_eps);
    let mut w = geometry_report::detector_cuts(mesh, tags, &scene.detector, eps, scene.offset);
    w.extend(lamp_placement::source_cuts(
        mesh,
        tags,
        &scene.sources.list,
        eps,
        scene.offset,
    ));
    w.extend(lamp_placement::contact_warnings(
        mesh,
        tags,
        &scene.sources.list,
        2.0 * eps,
        scene.offset,
    ));
    w
}

/// For each medium, the convex solid enclosing it when the fast path is safe: exactly one
/// closed convex component, and no other triangle and no detector corner inside it.
fn convex_solids(scene: &Scene) -> Vec<Option<ConvexSolid>> {
    let mesh = &scene.mesh;
    let tol = 1e-9 * mesh.bounds().diagonal().max(1.0);
    (0..scene.media.len())
        .map(|m| {
            let encloses = |p: u32| {
                let tag = mesh.tri_tag[p as usize] as usize;
                scene.surfaces[tag]
                    .interface()
                    .is_some_and(|i| i.inside as usize == m)
            };
            let prims: Vec<u32> = (0..mesh.len() as u32).filter(|&p| encloses(p)).collect();
            if m == 0 || prims.is_empty() {
                return None;
            }
            let mut solid = ConvexSolid::from_triangles(mesh, &prims, tol)?;
            let others_inside = (0..mesh.len() as u32).filter(|&p| !encloses(p)).any(|p| {
                let c = mesh.corners(p);
                let centroid = (c[0] + c[1] + c[2]) / 3.0;
                c.iter().chain([&centroid]).any(|&v| solid.contains(v, tol))
            });
            let d = &scene.detector;
            let corners = [0.0, 1.0].map(|a| {
                [0.0, 1.0].map(|b| d.origin + d.u * (a * d.size[0]) + d.v * (b * d.size[1]))
            });
            let detector_inside = corners.iter().flatten().any(|&v| solid.contains(v, tol));
            let side = |v: DVec3| (v - d.origin).dot(d.normal());
            let vertices = || prims.iter().flat_map(|&p| mesh.corners(p));
            solid.clear_of_target =
                vertices().all(|v| side(v) < -tol) || vertices().all(|v| side(v) > tol);
            (!others_inside && !detector_inside).then_some(solid)
        })
        .collect()
}

/// A scene a result can hold: an `Arc<Scene>` is shared as it is; a `Scene` or `&Scene`
/// becomes one (a `&Scene` is copied once, cheap beside tracing: its mesh is shared).
pub trait SharedScene {
    /// The scene, shared.
    fn shared(self) -> Arc<Scene>;
}

impl SharedScene for Arc<Scene> {
    fn shared(self) -> Arc<Scene> {
        self
    }
}

impl SharedScene for &Arc<Scene> {
    fn shared(self) -> Arc<Scene> {
        self.clone()
    }
}

impl SharedScene for Scene {
    fn shared(self) -> Arc<Scene> {
        Arc::new(self)
    }
}

impl SharedScene for &Scene {
    fn shared(self) -> Arc<Scene> {
        Arc::new(self.clone())
    }
}

fn default_name(path: &Path) -> String {
    path.parent()
        .and_then(|p| p.file_name())
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into())
}

fn load_geometry(
    ctx: &Ctx,
    file: &SceneFile,
    path: &Path,
    lamps: &[crate::sources::Source],
    warnings: &mut Vec<String>,
    reads: &ReadCache,
) -> Result<(Mesh, Vec<String>, Vec<GeometryReport>)> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut tags: Vec<String> = Vec::new();
    let mut mesh = Mesh::default();
    let mut reports = Vec::new();
    let mut missing = MissingSurfaces::new();
    for (i, g) in file.geometry.iter().enumerate() {
        let gpath = dir.join(&g.file);
        if !gpath.exists() {
            return Err(ctx.err(
                &format!("geometry[{i}].file"),
                format!("{} does not exist", gpath.display()),
            ));
        }
        let tris = g.load(ctx, i, &gpath, warnings, reads)?;
        // NaN or infinite vertices would poison the bounds, the recentring and the f32
        // backends (a panic in the BVH build); beyond 1e12 mm f64 resolves no better than
        // 0.1 mm: a unit or export error either way.
        if let Some((k, p)) = tris
            .positions
            .iter()
            .enumerate()
            .find(|(_, p)| !p.is_finite() || p.abs().max_element() > MAX_COORDINATE)
        {
            return Err(ctx.err(
                &format!("geometry[{i}].file"),
                format!(
                    "{}: vertex {k} is at ({:?}, {:?}, {:?}) mm after units, scale, rotation and translate; coordinates must be finite and within {MAX_COORDINATE:e} mm",
                    gpath.display(),
                    p.x,
                    p.y,
                    p.z
                ),
            ));
        }
        let part = Part {
            label: gpath.display().to_string(),
            name: g.file.display().to_string(),
        };
        reports.push(add_part(
            file,
            (&mut mesh, &mut tags, &mut missing),
            &part,
            &tris,
            warnings,
        ));
    }
    for (i, p) in file.procedural.iter().enumerate() {
        let tris = p.build(ctx, i, lamps)?;
        let name = format!("procedural[{i}]");
        let part = Part {
            label: format!("{}: {name}", ctx.0.display()),
            name,
        };
        reports.push(add_part(
            file,
            (&mut mesh, &mut tags, &mut missing),
            &part,
            &tris,
            warnings,
        ));
    }
    if !missing.is_empty() {
        return Err(ctx.err("surfaces", missing_surfaces(&missing)));
    }
    let is_file: Vec<bool> = (0..reports.len())
        .map(|i| i < file.geometry.len())
        .collect();
    warnings.extend(geometry_report::unit_slip_warnings(
        &reports,
        &is_file,
        file.detector.size_mm,
    ));
    Ok((mesh, tags, reports))
}

/// Every tag the geometry uses without a `[surfaces.TAG]` table, with the parts using it.
type MissingSurfaces = std::collections::BTreeMap<String, Vec<String>>;

/// The message listing every missing surface table at once.
fn missing_surfaces(missing: &MissingSurfaces) -> String {
    let list: Vec<String> = missing
        .iter()
        .map(|(tag, parts)| format!("[surfaces.{tag}] (tag '{tag}' of {})", parts.join(", ")))
        .collect();
    format!(
        "the scene has no {}: add a table for each tag the geometry uses",
        list.join(", no ")
    )
}

/// A part's names: in messages (`label`) and in its report (`name`).
struct Part {
    label: String,
    name: String,
}

/// Add a part's triangles to `mesh` (their tags to `tags`), dropping zero-area ones with
/// a warning and noting in `missing` the tags without a surface table; returns the part's
/// report.
fn add_part(
    file: &SceneFile,
    (mesh, tags, missing): (&mut Mesh, &mut Vec<String>, &mut MissingSurfaces),
    part: &Part,
    tris: &meshio::TaggedTriangles,
    warnings: &mut Vec<String>,
) -> GeometryReport {
    let base = mesh.positions.len() as u32;
    let first = mesh.triangles.len();
    mesh.positions.extend(&tris.positions);
    let mut dropped = 0;
    for (t, tag) in tris.triangles.iter().zip(&tris.tags) {
        if !file.surfaces.contains_key(tag) {
            let parts = missing.entry(tag.clone()).or_default();
            if !parts.contains(&part.label) {
                parts.push(part.label.clone());
            }
            continue;
        }
        let tri = t.map(|v| v + base);
        let [a, b, c] = tri.map(|v| mesh.positions[v as usize]);
        if (b - a).cross(c - a).length_squared() == 0.0 {
            dropped += 1;
            continue;
        }
        let id = match tags.iter().position(|x| x == tag) {
            Some(p) => p,
            None => {
                tags.push(tag.clone());
                tags.len() - 1
            }
        };
        mesh.triangles.push(tri);
        mesh.tri_tag.push(id as u32);
    }
    if dropped > 0 {
        warnings.push(format!(
            "{}: dropped {dropped} zero-area triangle(s)",
            part.label
        ));
    }
    let kept: Vec<([u32; 3], &str)> = (first..mesh.triangles.len())
        .map(|k| (mesh.triangles[k], tags[mesh.tri_tag[k] as usize].as_str()))
        .collect();
    let report = GeometryReport::new(part.name.clone(), mesh, &kept);
    warnings.extend(report.extent_warning());
    report
}

/// Check a surface entry and build its model (each model checks its own fields).
/// Fit each tag's model to its face (a pattern's axes to the face plane, its sizes
/// against the face: [`SurfaceModel::fit_to_face`]); runs after the faces are oriented.
fn fit_models_to_faces(
    ctx: &Ctx,
    mesh: &Mesh,
    tags: &[String],
    surfaces: &mut [SurfaceModel],
) -> Result<()> {
    for (tag_id, s) in surfaces.iter_mut().enumerate() {
        let face = Face {
            mesh,
            tag: tag_id as u32,
        };
        s.fit_to_face(ctx, &format!("surfaces.{}", tags[tag_id]), &face)?;
    }
    Ok(())
}

/// The warnings of polarized sources in a scene that does not trace polarization
/// (`[trace] polarization = false`): their light starts unpolarized.
fn unpolarized_sources(file: &SceneFile) -> Vec<String> {
    let polarized = file
        .sources
        .iter()
        .enumerate()
        .filter(|(_, s)| s.is_polarized());
    polarized
        .map(|(i, _)| {
            format!(
                "sources[{i}].polarization is not traced: [trace] polarization = false averages every photon's state, so the source's light starts unpolarized"
            )
        })
        .collect()
}

/// Whether the scene traces polarization: `[trace] polarization`, else whether its result
/// depends on it: a surface with a partial Fresnel event (a dielectric-like model: an
/// interface), a polarizer or an analyzer (which need it: `false` with one is an error), or
/// a polarized source.
fn traces_polarization(
    ctx: &Ctx,
    file: &SceneFile,
    (surfaces, backs): (&[SurfaceModel], &[Option<SurfaceModel>]),
    sources: &Sources,
) -> Result<bool> {
    let all = || surfaces.iter().chain(backs.iter().flatten());
    let polarizer = all().any(|m| matches!(m, SurfaceModel::Polarizer(_)));
    let fresnel = all().any(|m| m.interface().is_some());
    let analyzer = file.detector.analyzer_deg.is_some();
    let polarized_source =
        (sources.list.iter()).any(|s| s.polarization.is_some() || s.emitter.polarized());
    match file.trace.polarization {
        Some(false) if polarizer => Err(ctx.err(
            "trace.polarization",
            "is false, but a surface is a polarizer, which needs polarization traced",
        )),
        Some(false) if analyzer => Err(ctx.err(
            "trace.polarization",
            "is false, but detector.analyzer_deg is set: an analyzer needs polarization traced",
        )),
        Some(on) => Ok(on),
        None => Ok(polarizer || analyzer || fresnel || polarized_source),
    }
}
