//! The input is an intensity table `led.csv` (CSV `theta_deg, intensity`), read by
//! `IntensityProfile::read`, sampled, then named by the LED of a fixed slab scene
//! (fuzz/fixtures/intensity-scene.toml) loaded by `Scene::load`.
#![no_main]

mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::intensity_case("csv", "led.csv", data);
});
