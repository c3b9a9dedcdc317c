//! The reference kernel's own tests (its agreement with blutrace is
//! `crates/bench/tests/bench_reference.rs`).

use super::*;
use std::path::Path;

fn bench_box() -> Scene {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes/bench-box");
    Scene::load(&dir.join("scene.toml")).unwrap()
}

#[test]
fn every_photon_has_one_fate_for_any_thread_count() {
    let r = Reference::new(&bench_box()).unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let three = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap();
    let a = one.install(|| r.trace(5, 20_000));
    let b = three.install(|| r.trace(5, 20_000));
    assert_eq!(a, b);
    assert_eq!(a.fates(), 20_000);
    assert_eq!(a.flux.iter().sum::<u64>(), a.detected);
    assert!(a.detected > 0 && a.absorbed_by_ink > 0 && a.escaped > 0);
}

#[test]
fn reads_the_scene() {
    let r = Reference::new(&bench_box()).unwrap();
    let s = r.scene();
    let size = s.hi - s.lo - Vec3::new(120.0, 80.0, 3.0);
    assert!(size.abs().max_element() < 1e-4, "{size}");
    assert_eq!((s.n_guide, s.n_air, s.absorption), (1.49, 1.0, 0.0003));
    assert_eq!(
        (s.dots.face, s.dots.pitch, s.dots.ink_albedo),
        (4, 0.5, 0.9)
    );
    assert_eq!((s.sheet.axis, s.sheet_albedo), (2, 0.96));
    assert_eq!(s.strip.body, Body::Lambert(0.8));
    assert_eq!((s.target.bins, s.target.normal_sign), ([120, 80], 1.0));
    // Dot radius at the lit edge: d = 0.05 + 0.2 u + 0.4 u^2 at u = 0.25 / 120.
    let u = 0.25 / 120.0;
    let d = 0.05 + 0.2 * u + 0.4 * u * u;
    let r2 = s.dots.r2[(-s.dots.col0) as usize];
    assert!((f64::from(r2) - d * 0.25 / std::f64::consts::PI).abs() < 1e-8);
}

#[test]
fn refuses_other_scenes_saying_why() {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes");
    for (scene, why) in [
        ("notebook14", "square lattice"),
        ("edge-holder", "more than one part"),
        ("direct-lit", "scatters"),
        ("test/slab", "no dotted face"),
        ("bench-box", "traces polarization"),
    ] {
        let mut s = Scene::load(&dir.join(scene).join("scene.toml")).unwrap();
        // Each refused for its shape (polarization, on by default, is refused first),
        // and bench-box, whose kernel averages s and p, for polarization.
        s.polarized = scene == "bench-box";
        let e = Reference::new(&s).err().expect("refused").to_string();
        assert!(
            e.contains("box-guide scenes") && e.contains(why),
            "{scene}: {e}"
        );
    }
}

#[test]
fn fresnel_matches_the_closed_form_at_normal_incidence() {
    // R0 = ((n - 1)/(n + 1))^2: the share of reflections over many draws.
    let mut rng = Rng::new(1, 2);
    let n = 200_000;
    let reflected = (0..n)
        .filter(|_| Interface::new(1.0, 1.49).refract(1.0, &mut rng).is_none())
        .count();
    let r0 = (0.49f64 / 2.49).powi(2);
    let se = (r0 * (1.0 - r0) / n as f64).sqrt();
    assert!((reflected as f64 / n as f64 - r0).abs() < 4.0 * se);
    assert!(
        Interface::new(1.49, 1.0).refract(0.5, &mut rng).is_none(),
        "beyond critical"
    );
}
