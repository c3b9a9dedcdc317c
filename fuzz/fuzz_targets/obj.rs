//! The input is an OBJ file, `mesh.obj`, the geometry of the fixed mesh scene
//! (fuzz/fixtures/mesh-scene.toml), loaded by `Scene::load`.
#![no_main]

mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::mesh_case("obj", "mesh.obj", false, data);
});
