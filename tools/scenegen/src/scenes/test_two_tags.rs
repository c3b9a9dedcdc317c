//! `test/two-tags`: a Lambertian floor and a mirror wall lit by an LED, with tags taken
//! from OBJ `o`/`g` names (no materials). For loader tests.

use super::GENERATED;
use crate::shapes::sheet_up;
use crate::templates::{
    Detector, Led, geometry, lambert, mirror, preamble, scene_file, trace_table,
};
use crate::{GenFile, ObjTags, P3, Part, dims, triangle_count, write_obj};

/// Floor side (mm): the floor spans x, y 0..FLOOR at z = 0.
pub const FLOOR: f64 = 10.0;
/// Mirror wall height (mm): the wall stands at x = FLOOR.
pub const WALL: f64 = 5.0;
/// LED centre.
pub const LED: P3 = [5.0, 5.0, 4.0];
/// Detector height (mm).
pub const DETECTOR_Z: f64 = 6.0;

/// The floor (`o diffuser`) and the mirror wall (`g mirror`).
pub fn parts() -> Vec<Part> {
    let f = FLOOR;
    let floor = sheet_up("diffuser", "diffuser", [0.0, 0.0], [f, f], 0.0);
    let mut wall = Part::new("mirror");
    wall.quad(
        "mirror",
        [f, 0.0, 0.0],
        [f, f, 0.0],
        [f, f, WALL],
        [f, 0.0, WALL],
    );
    vec![floor, wall]
}

fn scene_toml(triangles: usize) -> String {
    let header = format!(
        "test/two-tags: a Lambertian floor and a mirror wall under an LED. A loader test scene.
{GENERATED}

- Tags come from OBJ object/group names, not materials: `o diffuser` is a {FLOOR} x {FLOOR} mm
  floor at z = 0 (x, y 0..{FLOOR}), lambert albedo 0.8; `g mirror` a {FLOOR} x {WALL} mm wall at
  x = {FLOOR} (y 0..{FLOOR}, z 0..{WALL}), mirror reflectance 0.9. No media besides air.
- LED: 1 x 1 mm at {led}, facing down (-z), Lambertian.
- Detector: z = {DETECTOR_Z}, over the floor (x, y 0..{FLOOR}), counting light going up.

Geometry: two-tags.obj, {triangles} triangles.
",
        led = dims(&LED),
    );
    let led = Led {
        body: false,
        ..Led::new("led", LED, [0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [1.0, 1.0])
    };
    let detector = Detector {
        angular_bins: [9, 12],
        ..Detector::new([0.0, 0.0, DETECTOR_Z], [FLOOR, FLOOR], [10, 10])
    };
    scene_file(
        &header,
        &[
            preamble(
                "test-two-tags",
                "A Lambertian floor and a mirror wall lit by an LED; tags from OBJ o/g names",
            ),
            geometry("two-tags.obj"),
            lambert("diffuser", 0.8),
            mirror("mirror", 0.9),
            led.toml(),
            detector.toml(),
            trace_table(10_000, 1000),
        ],
    )
}

/// `test/two-tags/scene.toml` and `.obj`.
pub fn files() -> Vec<GenFile> {
    let parts = parts();
    let triangles = triangle_count(&parts);
    let header = format!(
        "test/two-tags: floor and mirror (see scene.toml). Units mm. Tags are o/g names.\n{GENERATED}"
    );
    vec![
        GenFile::text("test/two-tags/scene.toml", scene_toml(triangles)),
        GenFile::text(
            "test/two-tags/two-tags.obj",
            write_obj(&header, &parts, ObjTags::ObjectNames),
        ),
    ]
}
