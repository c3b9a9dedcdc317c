//! The input is a glTF 2.0 file, JSON (`.gltf`) or binary (`.glb`: the reader tells them
//! apart by the `glTF` magic, not by the name), written as `mesh.gltf`, the geometry of
//! the fixed mesh scene (fuzz/fixtures/mesh-scene.toml), loaded by `Scene::load`. The
//! external buffers the seeds name (reflector.bin, wedge-ccfl.bin) lie beside it.
#![no_main]

mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::mesh_case("gltf", "mesh.gltf", false, data);
});
