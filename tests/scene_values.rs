//! Scenes are values: a scene keeps the file it was loaded from, reads any number of it by
//! key path and makes a copy with another value (loaded again with every check), as a
//! design study from a script does; the original is left as it was.

use blutrace::run::{self, RunOptions};
use blutrace::scene::Scene;
use std::path::Path;

fn slab() -> Scene {
    Scene::load(Path::new("scenes/test/slab/scene.toml")).unwrap()
}

fn options() -> RunOptions {
    RunOptions {
        photons: 20_000,
        seed: 3,
        threads: Some(2),
        ..RunOptions::default()
    }
}

/// Twice the lamp's power, traced with the same photons and seed, detects exactly twice
/// the power in every bin (each photon carries the power over the count); the copy
/// keeps the original's geometry, found relative to the original scene file.
#[test]
fn a_changed_value_traces_as_that_design() {
    let scene = slab();
    assert_eq!(scene.get("sources.0.power_w").unwrap(), 1.0.into());
    let brighter = scene.with("sources.0.power_w", 2.0).unwrap();
    assert_eq!(brighter.get("sources.0.power_w").unwrap(), 2.0.into());
    assert_eq!(
        scene.get("sources.0.power_w").unwrap(),
        1.0.into(),
        "the original changed"
    );
    let (a, b) = (
        run::trace(&scene, &options(), &|_| {}).unwrap(),
        run::trace(brighter, &options(), &|_| {}).unwrap(),
    );
    let (fa, fb) = (a.flux_map(), b.flux_map());
    assert!(fa.value.iter().sum::<f64>() > 0.0);
    for (x, y) in fa.value.iter().zip(&fb.value) {
        assert!((2.0 * x - y).abs() <= 1e-12 * y.abs(), "{x} {y}");
    }
}

/// A whole number for an integer field is that integer; the new bins shape the map.
#[test]
fn integer_fields_take_whole_numbers() {
    let coarse = slab().with("detector.bins.0", 10.0).unwrap();
    assert_eq!(coarse.get("detector.bins.0").unwrap(), 10.into());
    assert_eq!(coarse.detector.bins, [10, 20]);
    let r = run::trace(coarse, &options(), &|_| {}).unwrap();
    assert_eq!((r.flux_map().nx, r.flux_map().ny), (10, 20));
}

/// Bad keys and bad values are errors naming the scene file, the key and what is wrong.
#[test]
fn bad_keys_and_values_name_the_key() {
    let scene = slab();
    let cases: [(&str, toml::Value, &[&str]); 4] = [
        (
            "sources.0.nope",
            1.0.into(),
            &["scene.toml", "sources.0.nope", "no key 'nope'"],
        ),
        (
            "sources.3.power_w",
            1.0.into(),
            &["sources.3.power_w", "no index 3"],
        ),
        (
            "media.pmma.absorption_per_mm",
            (-1.0).into(),
            &["with media.pmma.absorption_per_mm = -1", "absorption"],
        ),
        ("detector.bins.0", 0.5.into(), &["detector.bins.0", "0.5"]),
    ];
    for (key, value, says) in cases {
        let e = format!("{:#}", scene.with(key, value).map(|_| ()).unwrap_err());
        for s in says {
            assert!(e.contains(s), "{key}: {e}");
        }
    }
}
