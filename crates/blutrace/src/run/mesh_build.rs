//! What a run builds from its scene's mesh before tracing, the intersection backend and
//! the triangle records, kept for the next run: a run of a scene with the same mesh (the
//! designs of a dot optimization, a layout search that moves only the lamps, the
//! verification traces after a search) reuses them instead of building them again. On a
//! CAD-sized mesh the build costs as much as tracing a few hundred thousand photons.
//!
//! ```text
//! blutrace optimize SCENE ...   # every design after the first reuses the build
//! ```
//!
//! Reuse cannot change a result: a backend's answers depend only on the mesh it was built
//! for, and the mesh is compared whole (the same shared mesh, or equal positions,
//! triangles and tags).

use crate::accel::{Accel, BackendChoice};
use crate::geometry::{Facet, Mesh};
use anyhow::Result;
use std::sync::Arc;

/// A backend and the triangle records, built for one mesh.
pub struct MeshBuild {
    mesh: Arc<Mesh>,
    choice: BackendChoice,
    /// The intersection backend (behind the mesh's box).
    pub accel: Box<dyn Accel>,
    /// One record per triangle, for refining and scoring hits.
    pub facets: Vec<Facet>,
}

/// The last mesh build, for the next run to reuse.
#[derive(Default)]
pub struct MeshBuildCache {
    last: Option<MeshBuild>,
    builds: usize,
}

impl MeshBuildCache {
    /// The build of `mesh` with `choice`: the last one when it was built for the same
    /// mesh and choice, else a new one (`build` runs the backend's construction, e.g. on
    /// the run's thread pool).
    pub fn get(
        &mut self,
        mesh: &Arc<Mesh>,
        choice: BackendChoice,
        build: impl FnOnce() -> Result<Box<dyn Accel>>,
    ) -> Result<&MeshBuild> {
        let reusable = self.last.as_ref().is_some_and(|b| {
            b.choice == choice && (Arc::ptr_eq(&b.mesh, mesh) || *b.mesh == **mesh)
        });
        if !reusable {
            // Drop the old build before making the new one: two large meshes' backends
            // need not fit in memory at once.
            self.last = None;
            let accel = build()?;
            self.builds += 1;
            self.last = Some(MeshBuild {
                mesh: Arc::clone(mesh),
                choice,
                accel,
                facets: mesh.facets(),
            });
        }
        Ok(self.last.as_ref().expect("just built or reused"))
    }

    /// Builds made so far (a run that reused one made none).
    pub fn builds(&self) -> usize {
        self.builds
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel;
    use glam::DVec3;

    fn plate(z: f64) -> Arc<Mesh> {
        Arc::new(Mesh {
            positions: vec![
                DVec3::new(0.0, 0.0, z),
                DVec3::new(1.0, 0.0, z),
                DVec3::new(0.0, 1.0, z),
            ],
            triangles: vec![[0, 1, 2]],
            tri_tag: vec![0],
        })
    }

    #[test]
    fn an_equal_mesh_reuses_the_build_and_another_mesh_does_not() {
        let mut cache = MeshBuildCache::default();
        let (a, b) = (plate(1.0), plate(1.0));
        for (mesh, choice, builds) in [
            (&a, BackendChoice::Brute, 1),
            (&a, BackendChoice::Brute, 1),
            (&b, BackendChoice::Brute, 1), // another Arc, equal content
            (&b, BackendChoice::Bvh, 2),   // another backend
            (&plate(2.0), BackendChoice::Bvh, 3),
            (&b, BackendChoice::Bvh, 4), // only the last build is kept
        ] {
            let built = cache
                .get(mesh, choice, || accel::build(choice, Arc::clone(mesh)))
                .unwrap();
            assert_eq!(built.facets[0].corners[0].z, mesh.positions[0].z);
            assert_eq!(
                cache.builds(),
                builds,
                "{choice:?} at z = {}",
                mesh.positions[0].z
            );
        }
    }
}
