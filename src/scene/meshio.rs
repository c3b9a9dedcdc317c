//! Reading tagged triangles from OBJ, glTF 2.0, STL and PLY files.
//!
//! Tags: in OBJ the `usemtl` name (whether or not the `.mtl` file exists), else the
//! `o`/`g` name; in glTF the material name of each primitive; STL and PLY carry none. A
//! scene's `tag` replaces them all. glTF node transforms are applied, then the placement
//! the scene file gives ([`super::geometry_file`]).

use super::geometry_file::Format;
use anyhow::{Context, Result, bail};
use glam::{DMat4, DVec3};
use std::cell::{Cell, RefCell};
use std::collections::HashMap;
use std::io::BufReader;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

/// Triangles read from one file, each with its tag.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TaggedTriangles {
    /// Vertex positions (mm).
    pub positions: Vec<DVec3>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Tag per triangle.
    pub tags: Vec<String>,
    /// The file's own tags, where a scene's `tag` replaced them.
    pub own_tags: Option<Vec<String>>,
}

impl TaggedTriangles {
    fn push_indexed(
        &mut self,
        positions: &[DVec3],
        indices: &[u32],
        tag: &str,
        file: &Path,
    ) -> Result<()> {
        if !indices.len().is_multiple_of(3) {
            bail!(
                "{}: tag '{tag}': index count {} is not a multiple of 3",
                file.display(),
                indices.len()
            );
        }
        let base = self.positions.len() as u32;
        if let Some(bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
            bail!(
                "{}: tag '{tag}': vertex index {bad} out of range ({} vertices)",
                file.display(),
                positions.len()
            );
        }
        self.positions.extend_from_slice(positions);
        for t in indices.chunks_exact(3) {
            self.triangles.push([t[0] + base, t[1] + base, t[2] + base]);
            self.tags.push(tag.to_string());
        }
        Ok(())
    }
}

/// Files read so far, by everything a read depends on: the file (path, size and
/// modification time, so an edited file is read again), its format, the transform and the
/// tag. A layout search loads every design from the same files: each is parsed once (a
/// third of the load time of a 540k-triangle OBJ).
#[derive(Default)]
pub struct ReadCache {
    files: RefCell<HashMap<ReadKey, TaggedTriangles>>,
    reads: Cell<usize>,
}

#[derive(PartialEq, Eq, Hash)]
struct ReadKey {
    path: PathBuf,
    len: u64,
    modified: Option<SystemTime>,
    format: Format,
    transform: [u64; 16],
    tag: Option<String>,
}

impl ReadCache {
    /// [`load`], or a copy of what it returned for the same file and arguments.
    pub fn load(
        &self,
        path: &Path,
        format: Format,
        transform: DMat4,
        tag: Option<&str>,
    ) -> Result<TaggedTriangles> {
        let meta =
            std::fs::metadata(path).with_context(|| format!("{}: cannot read", path.display()))?;
        let key = ReadKey {
            path: path.to_path_buf(),
            len: meta.len(),
            modified: meta.modified().ok(),
            format,
            transform: transform.to_cols_array().map(f64::to_bits),
            tag: tag.map(str::to_string),
        };
        if let Some(t) = self.files.borrow().get(&key) {
            return Ok(t.clone());
        }
        let tris = load(path, format, transform, tag)?;
        self.reads.set(self.reads.get() + 1);
        self.files.borrow_mut().insert(key, tris.clone());
        Ok(tris)
    }

    /// Files read from disk so far (a copy from the cache is not a read).
    pub fn reads(&self) -> usize {
        self.reads.get()
    }
}

/// Read a geometry file of `format`, applying `transform` to every position; `tag`, when
/// given, tags every triangle.
pub fn load(
    path: &Path,
    format: Format,
    transform: DMat4,
    tag: Option<&str>,
) -> Result<TaggedTriangles> {
    let mut tris = match format {
        Format::Obj => load_obj(path, transform, tag)?,
        Format::Gltf => load_gltf(path, transform)?,
        Format::Stl => load_stl(path, transform)?,
        Format::Ply => load_ply(path, transform)?,
    };
    if let Some(tag) = tag {
        let mut own: Vec<String> = tris.tags.iter().filter(|t| *t != tag).cloned().collect();
        own.sort_unstable();
        own.dedup();
        tris.own_tags = (!own.is_empty() && !format.untagged()).then_some(own);
        tris.tags.iter_mut().for_each(|t| *t = tag.to_string());
    }
    Ok(tris)
}

/// Untagged triangles read by a format without material names (tagged by the caller).
const UNTAGGED: &str = "";

fn load_obj(path: &Path, transform: DMat4, tag: Option<&str>) -> Result<TaggedTriangles> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    // Material names become tags even when the .mtl file is missing: hand tobj a
    // synthetic material library holding every name used by `usemtl`.
    let mut names: Vec<&str> = text
        .lines()
        .filter_map(|l| l.trim().strip_prefix("usemtl "))
        .map(str::trim)
        .collect();
    names.sort_unstable();
    names.dedup();
    let mtl: String = names.iter().map(|n| format!("newmtl {n}\n")).collect();
    let source = format!("mtllib blutrace-tags.mtl\n{text}");
    let opts = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, materials) =
        tobj::load_obj_buf(&mut BufReader::new(source.as_bytes()), &opts, |_| {
            tobj::load_mtl_buf(&mut BufReader::new(mtl.as_bytes()))
        })
        .map_err(|e| anyhow::anyhow!("{}: not a valid OBJ file: {e}", path.display()))?;
    let materials = materials.unwrap_or_default();
    let mut out = TaggedTriangles::default();
    for m in &models {
        let tag = match m.mesh.material_id {
            Some(i) => materials[i].name.clone(),
            None if m.name == "unnamed_object" => tag.unwrap_or_default().to_string(),
            None => m.name.clone(),
        };
        if tag.is_empty() {
            bail!(
                "{}: faces with neither `usemtl` nor an `o`/`g` name: cannot tag them (give the \
                 geometry a `tag`)",
                path.display()
            );
        }
        let pos: Vec<DVec3> = m
            .mesh
            .positions
            .chunks_exact(3)
            .map(|p| transform.transform_point3(DVec3::new(p[0], p[1], p[2])))
            .collect();
        out.push_indexed(&pos, &m.mesh.indices, &tag, path)?;
    }
    Ok(out)
}

fn load_gltf(path: &Path, transform: DMat4) -> Result<TaggedTriangles> {
    let (doc, buffers, _) = gltf::import(path)
        .map_err(|e| anyhow::anyhow!("{}: not a valid glTF file: {e}", path.display()))?;
    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .with_context(|| format!("{}: glTF file has no scene", path.display()))?;
    let mut out = TaggedTriangles::default();
    for node in scene.nodes() {
        walk_node(&node, transform, &buffers, path, &mut out)?;
    }
    Ok(out)
}

fn walk_node(
    node: &gltf::Node,
    parent: DMat4,
    buffers: &[gltf::buffer::Data],
    path: &Path,
    out: &mut TaggedTriangles,
) -> Result<()> {
    let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
    let world = parent * local;
    if let Some(mesh) = node.mesh() {
        for prim in mesh.primitives() {
            add_primitive(&prim, &mesh, world, buffers, path, out)?;
        }
    }
    for child in node.children() {
        walk_node(&child, world, buffers, path, out)?;
    }
    Ok(())
}

fn add_primitive(
    prim: &gltf::Primitive,
    mesh: &gltf::Mesh,
    world: DMat4,
    buffers: &[gltf::buffer::Data],
    path: &Path,
    out: &mut TaggedTriangles,
) -> Result<()> {
    let mesh_name = mesh.name().unwrap_or("<unnamed>");
    if prim.mode() != gltf::mesh::Mode::Triangles {
        bail!(
            "{}: mesh '{mesh_name}': primitive mode {:?} is not supported (triangles only)",
            path.display(),
            prim.mode()
        );
    }
    let Some(tag) = prim.material().name() else {
        bail!(
            "{}: mesh '{mesh_name}': primitive has no material name, so no tag",
            path.display()
        );
    };
    let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
    let positions: Vec<DVec3> = reader
        .read_positions()
        .with_context(|| {
            format!(
                "{}: mesh '{mesh_name}': no POSITION attribute",
                path.display()
            )
        })?
        .map(|p| world.transform_point3(DVec3::new(p[0].into(), p[1].into(), p[2].into())))
        .collect();
    let indices: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..positions.len() as u32).collect(),
    };
    out.push_indexed(&positions, &indices, tag, path)
}

fn load_stl(path: &Path, transform: DMat4) -> Result<TaggedTriangles> {
    let bytes = std::fs::read(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let mesh = stl_io::read_stl(&mut std::io::Cursor::new(&bytes))
        .map_err(|e| anyhow::anyhow!("{}: not a valid STL file: {e}", path.display()))?;
    if mesh.faces.is_empty() {
        bail!("{}: the STL file holds no triangles", path.display());
    }
    let positions: Vec<DVec3> = mesh
        .vertices
        .iter()
        .map(|v| transform.transform_point3(DVec3::from_array(v.0.map(f64::from))))
        .collect();
    let indices: Vec<u32> = mesh
        .faces
        .iter()
        .flat_map(|f| f.vertices.map(|i| i as u32))
        .collect();
    let mut out = TaggedTriangles::default();
    out.push_indexed(&positions, &indices, UNTAGGED, path)?;
    Ok(out)
}

fn load_ply(path: &Path, transform: DMat4) -> Result<TaggedTriangles> {
    use ply_rs_bw::{parser::Parser, ply::DefaultElement};
    let file =
        std::fs::File::open(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut BufReader::new(file))
        .map_err(|e| anyhow::anyhow!("{}: not a valid PLY file: {e}", path.display()))?;
    let element = |name: &str| ply.payload.get(name).map(Vec::as_slice).unwrap_or_default();
    let positions = element("vertex")
        .iter()
        .enumerate()
        .map(|(k, v)| {
            let c = |axis: &str| {
                ply_number(v.get(axis)).with_context(|| {
                    format!("{}: vertex {k} has no number `{axis}`", path.display())
                })
            };
            Ok(transform.transform_point3(DVec3::new(c("x")?, c("y")?, c("z")?)))
        })
        .collect::<Result<Vec<DVec3>>>()?;
    let mut indices = Vec::new();
    for (k, f) in element("face").iter().enumerate() {
        let list = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .and_then(ply_indices)
            .with_context(|| format!("{}: face {k} has no vertex_indices list", path.display()))?;
        if list.len() < 3 {
            bail!("{}: face {k} has {} vertices", path.display(), list.len());
        }
        // A fan triangulates the convex polygons exporters write.
        for j in 1..list.len() - 1 {
            indices.extend([list[0], list[j], list[j + 1]]);
        }
    }
    if indices.is_empty() {
        bail!("{}: the PLY file holds no faces", path.display());
    }
    let mut out = TaggedTriangles::default();
    out.push_indexed(&positions, &indices, UNTAGGED, path)?;
    Ok(out)
}

fn ply_number(p: Option<&ply_rs_bw::ply::Property>) -> Option<f64> {
    use ply_rs_bw::ply::Property as P;
    Some(match p? {
        P::Float(x) => f64::from(*x),
        P::Double(x) => *x,
        P::Char(x) => f64::from(*x),
        P::UChar(x) => f64::from(*x),
        P::Short(x) => f64::from(*x),
        P::UShort(x) => f64::from(*x),
        P::Int(x) => f64::from(*x),
        P::UInt(x) => f64::from(*x),
        _ => return None,
    })
}

fn ply_indices(p: &ply_rs_bw::ply::Property) -> Option<Vec<u32>> {
    use ply_rs_bw::ply::Property as P;
    let signed = |v: Vec<i64>| v.into_iter().map(|i| u32::try_from(i).ok()).collect();
    match p {
        P::ListInt(v) => signed(v.iter().map(|&i| i64::from(i)).collect()),
        P::ListShort(v) => signed(v.iter().map(|&i| i64::from(i)).collect()),
        P::ListChar(v) => signed(v.iter().map(|&i| i64::from(i)).collect()),
        P::ListUInt(v) => Some(v.clone()),
        P::ListUShort(v) => Some(v.iter().map(|&i| u32::from(i)).collect()),
        P::ListUChar(v) => Some(v.iter().map(|&i| u32::from(i)).collect()),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ONE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n";
    const TWO: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nusemtl a\nf 1 2 3\nf 2 4 3\n";

    /// A file is parsed once per placement and tag, and again once it changes on disk.
    #[test]
    fn the_read_cache_reads_a_file_once_until_it_changes() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("part.obj");
        std::fs::write(&path, ONE).unwrap();
        let cache = ReadCache::default();
        let read = |m: DMat4, tag: Option<&str>| cache.load(&path, Format::Obj, m, tag).unwrap();
        let first = read(DMat4::IDENTITY, None);
        assert_eq!(read(DMat4::IDENTITY, None), first);
        assert_eq!(cache.reads(), 1);
        let moved = DMat4::from_translation(DVec3::Z);
        assert_eq!(read(moved, None).positions[0], DVec3::Z);
        assert_eq!(read(DMat4::IDENTITY, Some("b")).tags, vec!["b".to_string()]);
        assert_eq!(cache.reads(), 3);
        std::fs::write(&path, TWO).unwrap();
        assert_eq!(read(DMat4::IDENTITY, None).triangles.len(), 2);
        assert_eq!(cache.reads(), 4);
        assert_eq!(
            read(DMat4::IDENTITY, None),
            load(&path, Format::Obj, DMat4::IDENTITY, None).unwrap()
        );
    }
}
