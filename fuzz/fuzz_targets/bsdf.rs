//! The input is an IS BSDF table `t.bsdf` (Monochrome or XYZ), the model of the back face
//! of a fixed slab scene (fuzz/fixtures/bsdf-scene.toml) loaded by `Scene::load`; a table
//! that loads is sampled at a few angles of incidence.
#![no_main]

mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::bsdf_case("bsdf", data);
});
