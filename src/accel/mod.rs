//! Ray acceleration backends behind one trait.
//!
//! A backend answers one question: which triangle does this ray reach first, and how far
//! away. Everything physical (the exact hit point, the normal, the surface model) is looked
//! up afterwards in shared code ([`crate::geometry::Mesh::refine_hit`]), so backends cannot
//! disagree on physics. [`brute::BruteForce`] is the test oracle.
//!
//! ```toml
//! # chosen on the command line, not in the scene file:
//! # blutrace trace SCENE --backend auto|bvh|brute
//! ```

pub mod brute;
pub mod bvh;

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
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BackendChoice {
    /// The fastest backend available on this machine.
    Auto,
    /// Pure-Rust BVH (obvhs).
    Bvh,
    /// Every triangle for every ray: the test oracle.
    Brute,
}

/// Build the backend `choice` over `mesh`.
pub fn build(choice: BackendChoice, mesh: Arc<Mesh>) -> anyhow::Result<Box<dyn Accel>> {
    Ok(match choice {
        BackendChoice::Auto | BackendChoice::Bvh => Box::new(bvh::ObvhsBvh::new(mesh)),
        BackendChoice::Brute => Box::new(brute::BruteForce::new(mesh)),
    })
}
