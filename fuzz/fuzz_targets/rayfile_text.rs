//! The input is a text ray file `led.txt` (rows `x y z kx ky kz flux [nm]`), the source
//! of a fixed slab scene (fuzz/fixtures/rayfile-scene.toml) loaded by `Scene::load`; a
//! scene that loads emits a few photons.
#![no_main]

mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::rayfile_case("rayfile_text", "led.txt", data);
});
