//! The input is an STL file (ASCII or binary), `mesh.stl`, the geometry of the fixed mesh scene
//! (fuzz/fixtures/mesh-scene.toml, with `tag = "lgp"`), loaded by `Scene::load`.
#![no_main]

mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::mesh_case("stl", "mesh.stl", true, data);
});
