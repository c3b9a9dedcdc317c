//! blutrace against an independent implementation of the same physics: the hand-written
//! reference kernel of `blutrace bench` (`crates/bench/src/reference.rs`: analytic planes, f32,
//! its own random numbers, no tracing code shared) on `scenes/bench-box`.
//!
//! Both trace 262,144 photons (analog estimator; blutrace on its default backend with the
//! convex path). Compared, each within 4 standard errors of the difference:
//! - the fraction of photons with each fate (detected = the extraction efficiency,
//!   absorbed by the ink, by the sheet, in the PMMA, by the strip's body, escaped,
//!   killed): binomial, `SE = sqrt(p1 (1 - p1) / N1 + p2 (1 - p2) / N2)`;
//! - the fraction detected in each of 6 bands along the guide (20 mm each), and within
//!   30 degrees of the target's normal: the same;
//! - interactions per photon: `SE = s sqrt(1/N1 + 1/N2)`, `s^2` the per-photon variance
//!   of the interaction count measured by the reference (under the hypothesis tested,
//!   both have the same distribution; blutrace keeps no per-photon squares).
//!
//! The same comparison must fail when the reference's physics is wrong: ink albedo 5 %
//! low, sheet albedo 5 % low, or the guide's index 1.40 instead of 1.49 (Fresnel and the
//! critical angle): a check that the test can see an error of that size.

use blutrace::optics::surface::SurfaceModel;
use blutrace::run::{self, RunOptions};
use blutrace::scene::Scene;
use blutrace::tally::Ledger;
use blutrace_bench::reference::{Counts, Reference};
use std::path::Path;

/// Photons of the CI test; the `#[ignore]`d one traces 16 times more (errors 4 times
/// smaller: `cargo test --release --test bench_reference -- --ignored`).
const PHOTONS: u64 = 262_144;
const BANDS: usize = 6;

fn bench_box() -> Scene {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes/bench-box");
    Scene::load(&dir.join("scene.toml")).unwrap()
}

/// One compared quantity: its name, blutrace's and the reference's values, the standard
/// error of their difference.
struct Row(String, f64, f64, f64);

impl Row {
    fn z(&self) -> f64 {
        let d = self.1 - self.2;
        if d == 0.0 { 0.0 } else { d.abs() / self.3 }
    }
}

fn proportion(name: &str, k1: f64, n1: f64, k2: f64, n2: f64) -> Row {
    let (p1, p2) = (k1 / n1, k2 / n2);
    let se = (p1 * (1.0 - p1) / n1 + p2 * (1.0 - p2) / n2).sqrt();
    Row(name.to_string(), p1, p2, se)
}

/// blutrace's fates, bands and interactions, as counts (analog weights are 1).
struct Traced {
    photons: f64,
    fates: Vec<(&'static str, f64)>,
    bands: Vec<f64>,
    near_normal: f64,
    interactions: f64,
}

fn blutrace(scene: &Scene, photons: u64, dots_tag: usize, sheet_tag: usize) -> Traced {
    let o = RunOptions {
        photons,
        seed: 7,
        ..RunOptions::default()
    };
    let r = run::trace(scene, &o, &|_| {}).unwrap();
    let l: &Ledger = &r.tally.ledger;
    let other_surfaces: f64 = (0..scene.tags.len())
        .filter(|&t| t != dots_tag && t != sheet_tag)
        .map(|t| l.absorbed_by_surface[t].value())
        .sum();
    assert_eq!(other_surfaces, 0.0, "only ink and sheet absorb");
    // Angular bins: theta fastest, 90 / nt degrees each.
    let nt = scene.detector.angular_bins[0];
    assert_eq!(nt % 3, 0, "30 degrees is a bin edge");
    let near_normal = (r.tally.angular.bins.iter().enumerate())
        .filter(|(i, _)| i % nt < nt / 3)
        .map(|(_, b)| b.sum.value())
        .sum();
    let nx = scene.detector.bins[0];
    let mut bands = vec![0.0; BANDS];
    for (i, b) in r.tally.flux.bins.iter().enumerate() {
        bands[(i % nx) * BANDS / nx] += b.sum.value();
    }
    Traced {
        photons: l.photons as f64,
        fates: vec![
            ("detected (efficiency)", l.detected.sum.value()),
            ("absorbed by ink", l.absorbed_by_surface[dots_tag].value()),
            (
                "absorbed by sheet",
                l.absorbed_by_surface[sheet_tag].value(),
            ),
            (
                "absorbed in PMMA",
                l.absorbed_in_medium.iter().map(|a| a.value()).sum(),
            ),
            ("absorbed by strip body", l.absorbed_by_source[0].value()),
            ("escaped", l.escaped.value()),
            ("killed", l.killed.value()),
        ],
        bands,
        near_normal,
        interactions: l.interactions as f64,
    }
}

/// The reference's counts in the same form.
fn reference(scene: &Scene, photons: u64) -> (Traced, Counts) {
    let c = Reference::new(scene).unwrap().trace(11, photons);
    assert_eq!(c.fates(), c.photons, "one fate per photon");
    let nx = scene.detector.bins[0];
    let mut bands = vec![0.0; BANDS];
    for (i, &k) in c.flux.iter().enumerate() {
        bands[(i % nx) * BANDS / nx] += k as f64;
    }
    let t = Traced {
        photons: c.photons as f64,
        fates: vec![
            ("detected (efficiency)", c.detected as f64),
            ("absorbed by ink", c.absorbed_by_ink as f64),
            ("absorbed by sheet", c.absorbed_by_sheet as f64),
            ("absorbed in PMMA", c.absorbed_in_medium as f64),
            ("absorbed by strip body", c.absorbed_by_source as f64),
            ("escaped", c.escaped as f64),
            ("killed", c.killed as f64),
        ],
        bands,
        near_normal: c.detected_near_normal as f64,
        interactions: c.interactions as f64,
    };
    (t, c)
}

fn compare(b: &Traced, (r, c): &(Traced, Counts)) -> Vec<Row> {
    let mut rows: Vec<Row> = b
        .fates
        .iter()
        .zip(&r.fates)
        .map(|((name, kb), (_, kr))| proportion(name, *kb, b.photons, *kr, r.photons))
        .collect();
    for (k, (kb, kr)) in b.bands.iter().zip(&r.bands).enumerate() {
        let name = format!("detected in band {k} (x {}..{} mm)", 20 * k, 20 * (k + 1));
        rows.push(proportion(&name, *kb, b.photons, *kr, r.photons));
    }
    rows.push(proportion(
        "detected within 30 deg of the normal",
        b.near_normal,
        b.photons,
        r.near_normal,
        r.photons,
    ));
    let n = r.photons;
    let mean = r.interactions / n;
    let var = (c.interactions_sq as f64 / n - mean * mean) * n / (n - 1.0);
    rows.push(Row(
        "interactions per photon".into(),
        b.interactions / b.photons,
        mean,
        (var * (1.0 / b.photons + 1.0 / n)).sqrt(),
    ));
    rows
}

fn print(title: &str, rows: &[Row]) {
    println!("{title}\n| quantity | blutrace | reference | SE of difference | z |");
    for r in rows {
        println!(
            "| {} | {:.5} | {:.5} | {:.5} | {:.2} |",
            r.0,
            r.1,
            r.2,
            r.3,
            r.z()
        );
    }
}

/// The scene with its ink albedo, sheet albedo or guide index changed.
fn altered(scene: &Scene, what: &str) -> Scene {
    let mut s = scene.clone();
    for m in &mut s.surfaces {
        match (m, what) {
            (SurfaceModel::Dots(d), "ink albedo x 0.95") => {
                d.ink_albedo = d.ink_albedo.scaled(0.95)
            }
            (SurfaceModel::Lambert(l), "sheet albedo x 0.95") => l.albedo = l.albedo.scaled(0.95),
            _ => {}
        }
    }
    if what == "n = 1.40" {
        s.media[1].n = 1.40.into();
    }
    s
}

/// Trace `photons` with both; panic naming every quantity beyond 4 standard errors.
/// Returns blutrace's counts.
fn agree(scene: &Scene, photons: u64) -> Traced {
    let k = Reference::new(scene).unwrap();
    let (dots_tag, sheet_tag) = (k.scene().dots_tag, k.scene().sheet_tag);
    let b = blutrace(scene, photons, dots_tag, sheet_tag);
    let rows = compare(&b, &reference(scene, photons));
    print(&format!("bench-box, {photons} photons each"), &rows);
    let bad: Vec<&Row> = rows.iter().filter(|r| r.z() > 4.0).collect();
    assert!(
        bad.is_empty(),
        "beyond 4 SE: {:?}",
        bad.iter()
            .map(|r| (&r.0, r.1, r.2, r.z()))
            .collect::<Vec<_>>()
    );
    b
}

#[test]
fn blutrace_agrees_with_the_reference_kernel_and_the_test_sees_wrong_physics() {
    let scene = bench_box();
    let b = agree(&scene, PHOTONS);
    assert!(
        b.fates[0].1 / b.photons > 0.3,
        "a backlight: most light reaches the target"
    );
    for what in ["ink albedo x 0.95", "sheet albedo x 0.95", "n = 1.40"] {
        let rows = compare(&b, &reference(&altered(&scene, what), PHOTONS));
        print(&format!("reference with {what}"), &rows);
        let worst = rows.iter().map(Row::z).fold(0.0, f64::max);
        assert!(
            worst > 4.0,
            "{what}: the test does not see it (largest z {worst:.2})"
        );
    }
}

#[test]
#[ignore = "slow: 4 million photons each"]
fn blutrace_agrees_with_the_reference_kernel_at_16_times_the_photons() {
    agree(&bench_box(), 16 * PHOTONS);
}
