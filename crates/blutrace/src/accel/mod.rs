//! Ray acceleration backends behind one trait.
//!
//! A backend answers one question: which triangle does this ray reach first, and how far
//! away. Everything physical (the exact hit point, the normal, the surface model) is looked
//! up afterwards in shared code ([`crate::geometry::Facet::refine_hit`]), so backends cannot
//! disagree on physics. [`brute::BruteForce`] is the test oracle.
//!
//! ```toml
//! # chosen on the command line, not in the scene file:
//! # blutrace trace SCENE --backend auto|embree|bvh|brute
//! ```
//!
//! `auto` takes Embree when its library loads (see [`embree`] for where it is looked
//! for), else the BVH; [`Accel::name`] tells which one was built.

pub mod brute;
pub mod bvh;
pub mod convex;
pub mod culled;
pub mod embree;

use crate::geometry::{Mesh, Ray};
use std::sync::Arc;

/// The minimal answer of a backend: distance and primitive index.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the ray (mm), as the backend measured it.
    pub t: f64,
    /// Index of the triangle in the scene mesh.
    pub prim: u32,
}

/// Nearest-hit queries against one scene mesh.
pub trait Accel: Send + Sync {
    /// Short name for reports ("bvh", "brute", "embree").
    fn name(&self) -> &'static str;
    /// The nearest triangle hit in `(0, tmax)`, if any.
    fn intersect(&self, ray: &Ray, tmax: f64) -> Option<Hit>;
}

/// Which backend the user asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BackendChoice {
    /// The fastest backend available on this machine: Embree if its library loads, else
    /// the BVH.
    Auto,
    /// Intel Embree 4.4, loaded at run time (an error when it cannot be loaded).
    Embree,
    /// Pure-Rust BVH (obvhs).
    Bvh,
    /// Every triangle for every ray: the test oracle.
    Brute,
}

/// Build the backend `choice` over `mesh`, behind the mesh's box ([`culled::Culled`]).
/// Call it inside the rayon pool that will trace: Embree sizes its thread pool from it.
pub fn build(choice: BackendChoice, mesh: Arc<Mesh>) -> anyhow::Result<Box<dyn Accel>> {
    let inner: Box<dyn Accel> = match choice {
        // Only a library that cannot be loaded (or has the wrong version) means "no
        // Embree"; a failing build over a loaded library is an error worth reporting.
        BackendChoice::Auto if embree::info().is_ok() => {
            Box::new(embree::EmbreeAccel::new(mesh.clone())?)
        }
        BackendChoice::Embree => Box::new(embree::EmbreeAccel::new(mesh.clone())?),
        BackendChoice::Auto | BackendChoice::Bvh => Box::new(bvh::ObvhsBvh::new(mesh.clone())),
        BackendChoice::Brute => Box::new(brute::BruteForce::new(mesh.clone())),
    };
    Ok(Box::new(culled::Culled::new(inner, &mesh)))
}
