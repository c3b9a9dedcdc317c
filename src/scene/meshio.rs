//! Reading tagged triangles from OBJ and glTF 2.0 files.
//!
//! Tags: in OBJ the `usemtl` name (whether or not the `.mtl` file exists), else the
//! `o`/`g` name; in glTF the material name of each primitive. glTF node transforms are
//! applied. Positions are scaled and translated as the scene file says.

use anyhow::{Context, Result, bail};
use glam::{DMat4, DVec3};
use std::io::BufReader;
use std::path::Path;

/// Triangles read from one file, each with its tag.
#[derive(Debug, Default)]
pub struct TaggedTriangles {
    /// Vertex positions (mm).
    pub positions: Vec<DVec3>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Tag per triangle.
    pub tags: Vec<String>,
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

/// Read a geometry file (by extension), applying `transform` to every position.
pub fn load(path: &Path, transform: DMat4) -> Result<TaggedTriangles> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    match ext.as_str() {
        "obj" => load_obj(path, transform),
        "gltf" | "glb" => load_gltf(path, transform),
        _ => bail!(
            "{}: unknown geometry format (expected .obj, .gltf or .glb)",
            path.display()
        ),
    }
}

fn load_obj(path: &Path, transform: DMat4) -> Result<TaggedTriangles> {
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
            None => m.name.clone(),
        };
        if tag.is_empty() || tag == "unnamed_object" {
            bail!(
                "{}: faces with neither `usemtl` nor an `o`/`g` name: cannot tag them",
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
