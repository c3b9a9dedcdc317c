//! The brute-force backend: tests every triangle. Slow, obviously right: the oracle.

use super::{Accel, Hit};
use crate::geometry::{Mesh, Ray};
use std::sync::Arc;

/// Tests every triangle of the mesh against every ray.
pub struct BruteForce {
    mesh: Arc<Mesh>,
}

impl BruteForce {
    /// A brute-force backend over `mesh`.
    pub fn new(mesh: Arc<Mesh>) -> Self {
        Self { mesh }
    }
}

impl Accel for BruteForce {
    fn name(&self) -> &'static str {
        "brute"
    }

    fn intersect(&self, ray: &Ray, tmax: f64) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        for prim in 0..self.mesh.len() as u32 {
            let limit = best.map_or(tmax, |h| h.t);
            if let Some(t) = self.mesh.intersect_triangle(ray, prim, limit) {
                best = Some(Hit { t, prim });
            }
        }
        best
    }
}
