//! Reading tagged triangles from OBJ, glTF 2.0, STL and PLY files.
//!
//! Tags: in OBJ the `usemtl` name (whether or not the `.mtl` file exists), else the
//! `o`/`g` name; in glTF the material name of each primitive (without one, with a warning,
//! its mesh's name, else its node's); STL and PLY carry none. A
//! scene's `tag` replaces them all. glTF node transforms are applied, then the placement
//! the scene file gives ([`super::geometry_file`]).

use crate::input_file::{read_bytes, read_text};
use anyhow::{Context, Result, anyhow, bail};
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
    /// What the reader noticed that is legal but may not be meant (a glTF primitive
    /// tagged by its mesh's name for want of a material).
    pub warnings: Vec<String>,
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
        Format::Gltf => load_gltf(path, transform, tag.is_some())?,
        Format::Stl => load_stl(path, transform)?,
        Format::Ply => load_ply(path, transform)?,
    };
    if let Some(tag) = tag {
        let mut own: Vec<String> = tris
            .tags
            .iter()
            .filter(|t| *t != tag && !t.is_empty())
            .cloned()
            .collect();
        own.sort_unstable();
        own.dedup();
        tris.own_tags = (!own.is_empty() && !format.untagged()).then_some(own);
        tris.tags.iter_mut().for_each(|t| *t = tag.to_string());
    }
    Ok(tris)
}

/// Geometry file formats, by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// Wavefront OBJ (tags: `usemtl`, else `o`/`g` names).
    Obj,
    /// glTF 2.0, `.gltf` or `.glb` (tags: material names).
    Gltf,
    /// STL, ASCII or binary (no tags).
    Stl,
    /// PLY, ASCII or binary (no tags).
    Ply,
}

impl Format {
    /// The format of `path`, from its extension.
    pub fn of(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "obj" => Format::Obj,
            "gltf" | "glb" => Format::Gltf,
            "stl" => Format::Stl,
            "ply" => Format::Ply,
            _ => return None,
        })
    }

    /// True when the format carries no material names, so a file needs `tag`.
    pub fn untagged(self) -> bool {
        matches!(self, Format::Stl | Format::Ply)
    }
}

/// Untagged triangles read by a format without material names (tagged by the caller).
const UNTAGGED: &str = "";

fn load_obj(path: &Path, transform: DMat4, tag: Option<&str>) -> Result<TaggedTriangles> {
    let text = read_text(path, "geometry file")?;
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
        .map_err(|e| {
            let at = bad_obj_index(&text).unwrap_or_default();
            anyhow!("{}: not a valid OBJ file: {e}{at}", path.display())
        })?;
    let materials = materials.unwrap_or_default();
    let mut out = TaggedTriangles::default();
    for m in models.iter().filter(|m| !m.mesh.indices.is_empty()) {
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
    if models.iter().all(|m| m.mesh.indices.is_empty()) {
        bail!("{}: the OBJ file holds no triangles", path.display());
    }
    Ok(out)
}

/// Read a glTF file; `tagged`: the scene's `tag` replaces every primitive's own.
fn load_gltf(path: &Path, transform: DMat4, tagged: bool) -> Result<TaggedTriangles> {
    let bytes = read_bytes(path, "geometry file")?;
    let gltf::Gltf {
        document: doc,
        blob,
    } = super::gltf_checks::parse(path, &bytes)?;
    let base = path.parent().unwrap_or(Path::new("."));
    for b in doc.buffers() {
        if let gltf::buffer::Source::Uri(uri) = b.source() {
            check_buffer_uri(path, base, b.index(), uri)?;
        }
    }
    // Buffers only: images (textures) are no optics and are never read.
    let buffers = gltf::import_buffers(&doc, Some(base), blob)
        .map_err(|e| anyhow::anyhow!("{}: cannot read its buffers: {e}", path.display()))?;
    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .with_context(|| format!("{}: glTF file has no scene", path.display()))?;
    let mut out = TaggedTriangles::default();
    let mut walk = NodeWalk {
        ancestors: Vec::new(),
        visits: 0,
        buffers: &buffers,
        path,
        tagged,
    };
    for node in scene.nodes() {
        walk.node(&node, transform, &mut out)?;
    }
    Ok(out)
}

/// A glTF buffer's `uri` may embed its data (`data:`) or name a file beside the glTF
/// file, in its folder or below: never a path that leaves it (`../../etc/passwd`, an
/// absolute path, a link pointing out), nor another scheme.
fn check_buffer_uri(path: &Path, base: &Path, index: usize, uri: &str) -> Result<()> {
    if uri.starts_with("data:") {
        return Ok(());
    }
    let decoded = percent_decoded(uri);
    let file = base.join(&decoded);
    let leaves = decoded.starts_with('/') || uri.contains("://");
    if leaves || crate::input_file::inside(base, &file).is_none() {
        bail!(
            "{}: buffers[{index}].uri: must name a file inside the glTF file's folder{}",
            path.display(),
            if file.exists() {
                ""
            } else {
                " (and it does not exist)"
            }
        );
    }
    read_bytes(&file, &format!("buffers[{index}] of {}", path.display())).map(drop)
}

/// `%XX` escapes of a URI replaced by their bytes (as the glTF loader reads them).
pub(super) fn percent_decoded(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = (b[i] == b'%' && i + 2 < b.len())
            .then(|| u8::from_str_radix(std::str::from_utf8(&b[i + 1..i + 3]).ok()?, 16).ok())
            .flatten();
        match hex {
            Some(byte) => {
                out.push(byte);
                i += 3;
            }
            None => {
                out.push(b[i]);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Deepest node hierarchy a glTF file may have: CAD exports nest a few levels per
/// assembly; deeper is a damaged file, and unbounded depth would overflow the stack.
const MAX_NODE_DEPTH: usize = 256;

/// Most node instances one glTF scene may place (a node shared by several parents is
/// placed once per path to it): bounds the work a file of repeated sharing can ask for.
const MAX_NODE_VISITS: usize = 1 << 20;

/// The walk down a glTF scene's node tree, refusing cycles and unbounded files.
struct NodeWalk<'a> {
    /// Indices of the nodes above the current one.
    ancestors: Vec<usize>,
    visits: usize,
    buffers: &'a [gltf::buffer::Data],
    path: &'a Path,
    /// The scene's `tag` replaces the primitives' own: none is needed.
    tagged: bool,
}

impl NodeWalk<'_> {
    fn node(&mut self, node: &gltf::Node, parent: DMat4, out: &mut TaggedTriangles) -> Result<()> {
        let shown = self.path.display();
        if self.ancestors.contains(&node.index()) {
            bail!(
                "{shown}: nodes[{}]: is its own ancestor (a cycle through `children`)",
                node.index()
            );
        }
        if self.ancestors.len() >= MAX_NODE_DEPTH {
            bail!(
                "{shown}: nodes[{}]: nested deeper than {MAX_NODE_DEPTH} levels",
                node.index()
            );
        }
        self.visits += 1;
        if self.visits > MAX_NODE_VISITS {
            bail!("{shown}: the scene places more than {MAX_NODE_VISITS} node instances");
        }
        let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
        let world = parent * local;
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                let at = Primitive {
                    node,
                    mesh: &mesh,
                    prim: &prim,
                    tagged: self.tagged,
                };
                add_primitive(&at, world, self.buffers, self.path, out)?;
            }
        }
        self.ancestors.push(node.index());
        for child in node.children() {
            self.node(&child, world, out)?;
        }
        self.ancestors.pop();
        Ok(())
    }
}

/// A primitive and where it sits in the file, for its tag and its messages.
struct Primitive<'a> {
    node: &'a gltf::Node<'a>,
    mesh: &'a gltf::Mesh<'a>,
    prim: &'a gltf::Primitive<'a>,
    tagged: bool,
}

impl Primitive<'_> {
    /// `nodes[2] meshes[0] 'lgp' primitives[1]`: what a message names.
    fn place(&self) -> String {
        let name = self
            .mesh
            .name()
            .map_or(String::new(), |n| format!(" '{n}'"));
        format!(
            "nodes[{}] meshes[{}]{name} primitives[{}]",
            self.node.index(),
            self.mesh.index(),
            self.prim.index()
        )
    }

    /// The primitive's tag: its material's name, else (with a warning) its mesh's name,
    /// else its node's; CAD exporters leave parts without a material.
    fn tag(&self, path: &Path, warnings: &mut Vec<String>) -> Result<String> {
        if let Some(name) = self.prim.material().name() {
            return Ok(name.to_string());
        }
        if self.tagged {
            // Replaced by the scene's tag; not one of the file's own tags.
            return Ok(String::new());
        }
        let fallback = [("mesh", self.mesh.name()), ("node", self.node.name())]
            .into_iter()
            .find_map(|(what, name)| name.filter(|n| !n.trim().is_empty()).map(|n| (what, n)));
        let Some((what, name)) = fallback else {
            bail!(
                "{}: {}: the primitive has no material name and neither its mesh nor its node a name, so no tag: name its material, or give the geometry entry a tag",
                path.display(),
                self.place()
            );
        };
        warnings.push(format!(
            "{}: {}: no material name, tagged '{name}' by its {what}'s name",
            path.display(),
            self.place()
        ));
        Ok(name.to_string())
    }
}

fn add_primitive(
    at: &Primitive,
    world: DMat4,
    buffers: &[gltf::buffer::Data],
    path: &Path,
    out: &mut TaggedTriangles,
) -> Result<()> {
    let prim = at.prim;
    if prim.mode() != gltf::mesh::Mode::Triangles {
        bail!(
            "{}: {}: primitive mode {:?} is not supported (triangles only)",
            path.display(),
            at.place(),
            prim.mode()
        );
    }
    let tag = at.tag(path, &mut out.warnings)?;
    super::gltf_checks::check_mesh_accessors(prim, &at.place(), path)?;
    let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
    let Some(accessor) = prim.get(&gltf::Semantic::Positions) else {
        bail!("{}: {}: no POSITION attribute", path.display(), at.place());
    };
    let positions: Vec<DVec3> = reader
        .read_positions()
        .with_context(|| {
            format!(
                "{}: {}: the POSITION accessor ({} elements) does not fit its buffer view",
                path.display(),
                at.place(),
                accessor.count()
            )
        })?
        .map(|p| world.transform_point3(DVec3::new(p[0].into(), p[1].into(), p[2].into())))
        .collect();
    let indices: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..positions.len() as u32).collect(),
    };
    check_count(at, path, "POSITION", accessor.count(), positions.len())?;
    if let Some(a) = prim.indices() {
        check_count(at, path, "indices", a.count(), indices.len())?;
    }
    out.push_indexed(&positions, &indices, &tag, path)
}

/// An accessor must hold as many elements as its `count` says: the reader stops at the end
/// of the buffer view, so a larger `count` would load part of the mesh silently.
fn check_count(at: &Primitive, path: &Path, what: &str, count: usize, read: usize) -> Result<()> {
    if read != count {
        bail!(
            "{}: {}: the {what} accessor's count is {count}, but its buffer view holds {read}",
            path.display(),
            at.place()
        );
    }
    Ok(())
}

fn load_stl(path: &Path, transform: DMat4) -> Result<TaggedTriangles> {
    let bytes = read_bytes(path, "geometry file")?;
    check_binary_stl_count(path, &bytes)?;
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

/// Where an OBJ face names a vertex the file does not have (yet): `", line L: vertex
/// index I, but N vertices come before it"` (negative indices count back from the line).
fn bad_obj_index(text: &str) -> Option<String> {
    let mut vertices: i64 = 0;
    for (k, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => vertices += 1,
            Some("f") => {
                for w in words {
                    let i: i64 = w.split('/').next()?.parse().ok()?;
                    let at = if i < 0 { vertices + i + 1 } else { i };
                    if !(1..=vertices).contains(&at) {
                        return Some(format!(
                            ", line {}: vertex index {i}, but {vertices} vertices come before it",
                            k + 1
                        ));
                    }
                }
            }
            _ => {}
        }
    }
    None
}

/// A binary STL's triangle count (bytes 80..84) must match its length (84 + 50 per
/// triangle): a file cut short or with trailing triangles is damaged, not a smaller part.
/// A file starting `solid` whose length does not fit is read as ASCII STL.
fn check_binary_stl_count(path: &Path, bytes: &[u8]) -> Result<()> {
    let Some(count) = bytes.get(80..84) else {
        return Ok(());
    };
    let count = u64::from(u32::from_le_bytes(count.try_into().unwrap_or_default()));
    let fits = bytes.len() as u64 == 84 + 50 * count;
    if !fits && !bytes.starts_with(b"solid") {
        let body = bytes.len() as u64 - 84;
        let rest = match body % 50 {
            0 => String::new(),
            r => format!(" and {r} bytes more"),
        };
        bail!(
            "{}: binary STL header says {count} triangles, but the file's {} bytes hold {} \
             (an 84-byte header, then 50 bytes a triangle){rest}",
            path.display(),
            bytes.len(),
            body / 50
        );
    }
    Ok(())
}

fn load_ply(path: &Path, transform: DMat4) -> Result<TaggedTriangles> {
    use ply_rs_bw::{parser::Parser, ply::DefaultElement};
    let bytes = read_bytes(path, "geometry file")?;
    // The magic line first: the parser's messages quote the lines it fails on, and a file
    // that is no PLY (a mistyped path) must not have its contents echoed.
    if !(bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n")) {
        bail!(
            "{}: not a PLY file (its first line is not `ply`)",
            path.display()
        );
    }
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut BufReader::new(&bytes[..]))
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
            .with_context(|| format!("{}: face {k} has no vertex_indices list", path.display()))
            .and_then(|p| {
                ply_indices(p).map_err(|why| anyhow!("{}: face {k}: {why}", path.display()))
            })?;
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

/// A face's vertex indices; a negative one or a property that is no list of integers is
/// an error saying so.
fn ply_indices(p: &ply_rs_bw::ply::Property) -> std::result::Result<Vec<u32>, String> {
    use ply_rs_bw::ply::Property as P;
    fn signed<T: Copy + Into<i64>>(v: &[T]) -> std::result::Result<Vec<u32>, String> {
        v.iter()
            .enumerate()
            .map(|(j, &i)| {
                let i: i64 = i.into();
                u32::try_from(i)
                    .map_err(|_| format!("vertex index {i} (entry {j} of its list) is negative"))
            })
            .collect()
    }
    match p {
        P::ListInt(v) => signed(v),
        P::ListShort(v) => signed(v),
        P::ListChar(v) => signed(v),
        P::ListUInt(v) => Ok(v.clone()),
        P::ListUShort(v) => Ok(v.iter().map(|&i| u32::from(i)).collect()),
        P::ListUChar(v) => Ok(v.iter().map(|&i| u32::from(i)).collect()),
        _ => Err("vertex_indices is not a list of integers".into()),
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

    /// A face naming a vertex the file lacks is found with its line and index.
    #[test]
    fn a_bad_obj_index_is_named() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n";
        let at = bad_obj_index(text).unwrap();
        assert!(
            at.contains("line 4: vertex index 99, but 3 vertices"),
            "{at}"
        );
        assert_eq!(bad_obj_index(ONE), None);
        assert!(
            bad_obj_index("v 0 0 0\nf -1 -2 -3\n")
                .unwrap()
                .contains("index -2")
        );
    }
}
