//! The lamp bodies of each medium with their bounding boxes, built per run: a photon's
//! segment whose own box misses a body's box cannot meet that body, so its exact test is
//! skipped. In a scene with a lamp cavity at each end (notebook14) a photon in one cavity
//! is spared the exact tests of the other cavity's tubes.
//!
//! ```toml
//! [[sources]]          # every source whose body is not "transparent" is listed
//! type = "ccfl"
//! name = "left_upper"
//! medium = "air"       # the medium whose segments are tested against it
//! body = { model = "lambert", albedo = 0.5 }   # or "absorber" (the default)
//! ```

use crate::geometry::{Aabb, Ray};
use crate::optics::surface::MediumId;
use crate::scene::Scene;

/// Per medium: (source index, the body's box grown by the scene's spawn offset).
pub(super) struct BodyBoxes {
    per_medium: Vec<Vec<(u32, Aabb)>>,
}

impl BodyBoxes {
    /// The bodies of `scene`'s sources, by medium. Boxes are grown by the spawn offset so
    /// that rounding in a hit point can never put it outside.
    pub(super) fn new(scene: &Scene) -> Self {
        let mut per_medium = vec![Vec::new(); scene.media.len()];
        for (i, source, body) in scene.sources.bodies() {
            let grown = body.shape.bounds().grown(scene.spawn_eps);
            per_medium[source.medium as usize].push((i as u32, grown));
        }
        Self { per_medium }
    }

    /// True when a lamp body lies in `medium`.
    pub(super) fn any_in(&self, medium: MediumId) -> bool {
        !self.per_medium[medium as usize].is_empty()
    }

    /// The sources whose bodies in `medium` the segment of `ray` from its origin to
    /// distance `reach` may meet: every body of the medium when `reach` is not finite.
    pub(super) fn near<'a>(
        &'a self,
        medium: MediumId,
        ray: &Ray,
        reach: f64,
    ) -> impl Iterator<Item = u32> + 'a {
        let seg = reach
            .is_finite()
            .then(|| Aabb::of([ray.origin, ray.at(reach)]));
        self.per_medium[medium as usize]
            .iter()
            .filter(move |(_, b)| seg.is_none_or(|s| s.overlaps(b)))
            .map(|&(i, _)| i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::surface::Estimator;
    use crate::tracer::assert_same_chunks;
    use glam::DVec3;

    /// Chunks traced with the boxes and with every box the whole space (no body skipped)
    /// are the same bits: the boxes only skip bodies a segment cannot meet.
    #[test]
    fn boxes_skip_only_bodies_out_of_reach() {
        let everywhere = Aabb {
            min: DVec3::NEG_INFINITY,
            max: DVec3::INFINITY,
        };
        for name in ["notebook14", "phone-led", "direct-lit"] {
            let chunks = assert_same_chunks(
                name,
                Estimator::Analog,
                |_| {},
                |open| {
                    let boxes = &mut open.bodies.per_medium;
                    assert!(
                        boxes.iter().any(|m| !m.is_empty()),
                        "{name}: no lamp bodies"
                    );
                    boxes.iter_mut().flatten().for_each(|b| b.1 = everywhere);
                },
            );
            for c in &chunks {
                let lamps: i128 = c.ledger.absorbed_by_source.iter().map(|s| s.0).sum();
                assert!(lamps > 0, "{name}: no photon met a lamp body");
            }
        }
    }

    /// A segment in one lamp cavity of notebook14 is not offered the other cavity's tubes.
    #[test]
    fn a_segment_is_offered_only_the_bodies_near_it() {
        let root =
            std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes");
        let scene = Scene::load(&root.join("notebook14/scene.toml")).unwrap();
        let boxes = BodyBoxes::new(&scene);
        let left = scene
            .sources
            .list
            .iter()
            .position(|s| s.name == "left_upper")
            .unwrap();
        let body = scene.sources.list[left].body.as_ref().unwrap();
        let b = body.shape.bounds();
        // From 0.5 mm outside the tube's box, a 1 mm segment into it.
        let from = DVec3::new(
            b.min.x - 0.5,
            0.5 * (b.min.y + b.max.y),
            0.5 * (b.min.z + b.max.z),
        );
        let ray = Ray::new(from, DVec3::X);
        let air = scene.sources.list[left].medium;
        let near: Vec<u32> = boxes.near(air, &ray, 1.0).collect();
        assert!(near.contains(&(left as u32)), "{near:?}");
        let names: Vec<&str> = near
            .iter()
            .map(|&i| scene.sources.list[i as usize].name.as_str())
            .collect();
        assert!(names.iter().all(|n| n.starts_with("left")), "{names:?}");
        assert_eq!(boxes.near(air, &ray, f64::INFINITY).count(), 4);
    }
}
