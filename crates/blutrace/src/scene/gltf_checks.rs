//! What the `gltf` crate trusts in a file and blutrace checks first, so a damaged or
//! hostile glTF is an error naming its place, never a panic or a silent misreading:
//! a GLB header's length, every accessor index a primitive names (the crate's own
//! validation indexes with them), and the types of the accessors the mesh is read from
//! (the crate's reader assumes them).

use anyhow::{Result, bail};
use gltf::accessor::{DataType, Dimensions};
use std::path::Path;

/// Parse `bytes` (glTF JSON or GLB) and validate it, checking first what the crate's
/// validation would index or subtract with.
pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<gltf::Gltf> {
    check_glb_header(path, bytes)?;
    let not_valid =
        |e: gltf::Error| anyhow::anyhow!("{}: not a valid glTF file: {e}", path.display());
    let raw = gltf::Gltf::from_slice_without_validation(bytes).map_err(not_valid)?;
    let json = raw.document.into_json();
    check_accessor_indices(path, &json)?;
    let document = gltf::Document::from_json(json).map_err(not_valid)?;
    Ok(gltf::Gltf {
        document,
        blob: raw.blob,
    })
}

/// A GLB's 12-byte header must be whole and declare a length of at least itself.
fn check_glb_header(path: &Path, bytes: &[u8]) -> Result<()> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    let declared = bytes
        .get(8..12)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    match declared {
        Some(n) if n >= 12 => Ok(()),
        Some(n) => bail!(
            "{}: a GLB file's header declares {n} bytes, less than the header's own 12",
            path.display()
        ),
        None => bail!(
            "{}: a GLB file shorter than its 12-byte header",
            path.display()
        ),
    }
}

/// Every accessor a mesh primitive names (attributes, indices, morph targets) exists.
fn check_accessor_indices(path: &Path, json: &gltf::json::Root) -> Result<()> {
    let count = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let at = format!("meshes[{m}].primitives[{p}]");
            let targets = prim.targets.iter().flatten().flat_map(|t| {
                [&t.positions, &t.normals, &t.tangents]
                    .into_iter()
                    .flatten()
                    .map(|i| ("targets", i.value()))
            });
            let named = prim
                .attributes
                .values()
                .map(|i| ("attributes", i.value()))
                .chain(prim.indices.iter().map(|i| ("indices", i.value())))
                .chain(targets);
            for (field, i) in named {
                if i >= count {
                    bail!(
                        "{}: {at}.{field}: accessor {i} does not exist (the file has {count})",
                        path.display()
                    );
                }
            }
        }
    }
    Ok(())
}

/// The POSITION accessor holds three 32-bit floats per vertex, and an indices accessor
/// unsigned integers one per element, as glTF 2.0 requires (the reader assumes both).
pub(super) fn check_mesh_accessors(prim: &gltf::Primitive, place: &str, path: &Path) -> Result<()> {
    if let Some(a) = prim.get(&gltf::Semantic::Positions)
        && (a.dimensions() != Dimensions::Vec3 || a.data_type() != DataType::F32)
    {
        bail!(
            "{}: {place}: the POSITION accessor is {:?} of {:?}; glTF requires VEC3 of FLOAT",
            path.display(),
            a.dimensions(),
            a.data_type()
        );
    }
    if let Some(a) = prim.indices() {
        let integer = matches!(a.data_type(), DataType::U8 | DataType::U16 | DataType::U32);
        if a.dimensions() != Dimensions::Scalar || !integer {
            bail!(
                "{}: {place}: the indices accessor is {:?} of {:?}; glTF requires SCALAR of an unsigned integer type",
                path.display(),
                a.dimensions(),
                a.data_type()
            );
        }
    }
    Ok(())
}
