//! The input is a scene file, `scene.toml`, in a folder holding the geometry and
//! intensity tables of the bundled scenes that fuzz/seeds/scene_toml copies
//! (fuzz/fixtures/scene): `Scene::load` parses it (`toml` into `SceneFile`), reads what it
//! names and validates the whole scene.
#![no_main]

mod common;

use blutrace::scene::Scene;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let dir = common::workdir("scene_toml", &["scene"], &[]);
    let path = common::put(dir, "scene.toml", data);
    let loaded = Scene::load(&path);
    common::report("scene", &loaded);
    if let Ok(scene) = loaded {
        let _ = scene.content_hash();
        let _ = scene.triangles_per_tag();
    }
});
