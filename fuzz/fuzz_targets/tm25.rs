//! The input is a TM-25-13 binary ray file `led.TM25RAY`, the source of a fixed slab
//! scene (fuzz/fixtures/rayfile-scene.toml) loaded by `Scene::load`; a scene that loads
//! emits a few photons.
#![no_main]

mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::rayfile_case("tm25", "led.TM25RAY", data);
});
