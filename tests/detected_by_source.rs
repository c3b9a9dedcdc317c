//! Detected power per source (`ledger.detected_by_source`, `detected_by_source_w` in
//! summary.json): each detection is booked to the source that emitted its photon, exactly.
//!
//! - The per-source bins add up to the ledger's detections in fixed point: sums, sums of
//!   squares and photon counts, under both estimators (the weighted one scores fractional
//!   weights, so the sums of squares are not the counts).
//! - Two LEDs face the target; one sits in a closed absorbing box. Nothing it emits can
//!   reach the target, so its detected power is exactly 0, and the other's is not.
//! - The per-source tallies are the same bits at any thread count.

mod support;

use blutrace::estimator::Estimator;
use blutrace::run::{RunOptions, RunResult};
use blutrace::scene::Scene;
use blutrace::tally::BinStats;
use support::{assert_balanced, box_obj, load, trace_opts, write_scene};

/// Two 2 x 2 mm LEDs at z = 0 facing a 40 x 40 mm target at z = 10: `open` at x = -5 and
/// `blocked` at x = +5 inside a closed absorbing box; a grey Lambertian wall at x = -15
/// sends some light to the target at reduced weight (weighted estimator).
fn two_leds() -> Scene {
    let cap = box_obj(
        [3.0, -2.0, -0.5],
        [7.0, 2.0, 1.0],
        ["cap", "cap", "cap", "cap", "cap", "cap"],
    );
    let wall =
        "v -15 -20 -1\nv -15 20 -1\nv -15 20 9.9\nv -15 -20 9.9\nusemtl wall\nf 1 2 3\nf 1 3 4\n";
    let led = |name: &str, x: f64| {
        format!(
            "[[sources]]\ntype = \"led\"\nname = \"{name}\"\ncenter = [{x}, 0.0, 0.0]\n\
             normal = [0.0, 0.0, 1.0]\nu = [1.0, 0.0, 0.0]\nwidth_mm = 2.0\nheight_mm = 2.0\n\
             power_w = 1.0\n"
        )
    };
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"cap.obj\"\n[[geometry]]\nfile = \"wall.obj\"\n\
         [surfaces.cap]\nmodel = \"absorber\"\n\
         [surfaces.wall]\nmodel = \"lambert\"\nalbedo = 0.5\n{}{}\
         [detector]\norigin = [-20.0, -20.0, 10.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [40.0, 40.0]\nbins = [4, 4]\n",
        led("open", -5.0),
        led("blocked", 5.0)
    );
    load(&write_scene(
        "detected-by-source",
        &toml,
        &[("cap.obj", &cap), ("wall.obj", wall)],
    ))
}

fn run(scene: &Scene, estimator: Estimator, threads: usize) -> RunResult {
    let r = trace_opts(
        scene,
        &RunOptions {
            photons: 60_000,
            seed: 11,
            threads: Some(threads),
            estimator,
            ..RunOptions::default()
        },
    );
    assert_balanced(&r);
    r
}

#[test]
fn detections_per_source_add_up_exactly_and_a_blocked_source_detects_nothing() {
    let scene = two_leds();
    for estimator in [Estimator::Analog, Estimator::Weighted] {
        let r = run(&scene, estimator, 2);
        let l = &r.tally.ledger;
        assert_eq!(l.detected_by_source.len(), 2);
        let mut total = BinStats::default();
        l.detected_by_source.iter().for_each(|b| total.merge(b));
        assert_eq!(total, l.detected, "{estimator:?}: per source != detected");
        assert!(
            l.detected.hits > 1000,
            "{estimator:?}: the open LED lights the target"
        );
        let [open, blocked] = [&l.detected_by_source[0], &l.detected_by_source[1]];
        assert_eq!(
            blocked.hits, 0,
            "{estimator:?}: the boxed LED reaches the target"
        );
        assert_eq!(blocked.sum.0, 0);
        assert_eq!(open.hits, l.detected.hits);
        if estimator == Estimator::Weighted {
            assert_ne!(open.sum, open.sumsq, "the wall scores fractional weights");
        }

        let s = r.summary();
        let by = &s.ledger.detected_by_source_w;
        assert_eq!(
            by.iter().map(|d| d.source.as_str()).collect::<Vec<_>>(),
            ["open", "blocked"],
            "in source order"
        );
        assert_eq!(by[1].w, 0.0);
        assert_eq!(by[0].w, s.ledger.detected_w);
        assert!(by[0].stderr_w > 0.0 && by[0].stderr_w < 0.05 * by[0].w);
        // The efficiency's error is the same per-photon error, in watts of all sources.
        let watts = scene.sources.total_power();
        let want = s.extraction_efficiency_stderr * watts;
        assert!((by[0].stderr_w - want).abs() <= 1e-12 * want);
    }
}

#[test]
fn detections_per_source_are_the_same_bits_at_any_thread_count() {
    let scene = two_leds();
    let one = run(&scene, Estimator::Weighted, 1);
    let three = run(&scene, Estimator::Weighted, 3);
    assert_eq!(
        one.tally.ledger.detected_by_source,
        three.tally.ledger.detected_by_source
    );
    let groups: Vec<_> = one
        .groups
        .iter()
        .map(|g| &g.ledger.detected_by_source)
        .collect();
    let other: Vec<_> = three
        .groups
        .iter()
        .map(|g| &g.ledger.detected_by_source)
        .collect();
    assert_eq!(groups, other, "jackknife groups");
}
