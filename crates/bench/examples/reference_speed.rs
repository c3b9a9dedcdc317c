//! Time one reference kernel alone, single-threaded, for A/B rounds under `/usr/bin/time`:
//!
//! ```text
//! cargo run --release -p blutrace-bench --example reference_speed -- new|before|blutrace|diff PHOTONS [SEED]
//! ```
//!
//! `new` is the reference kernel, `before` the kernel before issue 35, `blutrace` a
//! single-threaded `run::trace` of the same scene and photons (auto backend, convex path,
//! as `blutrace bench`), so all three can be timed the same way; `diff` finds the first
//! photon whose counts differ between the two kernels. Prints the fates and a checksum of
//! the flux bins, so two builds can be compared for identical results as well as for
//! speed.

use blutrace::run::{self, RunOptions};
use blutrace::scene::Scene;
use blutrace_bench::{reference, reference_before};
use std::path::Path;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let which = args.get(1).map_or("new", String::as_str);
    let photons: u64 = args.get(2).map_or(Ok(1_000_000), |s| s.parse())?;
    let seed: u64 = args.get(3).map_or(Ok(1), |s| s.parse())?;
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes/bench-box");
    let scene = Scene::load(&dir.join("scene.toml"))?;
    if which == "diff" {
        first_diff(&scene);
        return Ok(());
    }
    if which == "dbg" {
        reference_before::Reference::new(&scene)?.trace(1, 3000);
        reference::Reference::new(&scene)?.trace(1, 3000);
        return Ok(());
    }
    if which == "blutrace" {
        let o = RunOptions {
            photons,
            seed,
            threads: Some(1),
            ..RunOptions::default()
        };
        let r = run::trace(&scene, &o, &|_| {})?;
        println!(
            "blutrace: detected {:.4}",
            r.tally.ledger.detected.sum.value()
        );
        return Ok(());
    }
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let c = match which {
        "before" => {
            let k = reference_before::Reference::new(&scene)?;
            pool.install(|| k.trace(seed, photons))
        }
        _ => {
            let k = reference::Reference::new(&scene)?;
            pool.install(|| k.trace(seed, photons))
        }
    };
    let sum: u64 = c
        .flux
        .iter()
        .enumerate()
        .map(|(i, &k)| (i as u64 + 1) * k)
        .sum();
    println!(
        "{which}: detected {} ink {} sheet {} medium {} source {} escaped {} killed {} interactions {} flux checksum {sum}",
        c.detected,
        c.absorbed_by_ink,
        c.absorbed_by_sheet,
        c.absorbed_in_medium,
        c.absorbed_by_source,
        c.escaped,
        c.killed,
        c.interactions
    );
    Ok(())
}
/// The first photon index at which the two kernels' counts differ (up to 200,000).
fn first_diff(scene: &Scene) {
    let a = reference_before::Reference::new(scene).unwrap();
    let b = reference::Reference::new(scene).unwrap();
    let (mut lo, mut hi) = (0u64, 200_000u64);
    if a.trace(1, hi) == b.trace(1, hi) {
        println!("identical counts for {hi} photons");
        return;
    }
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if a.trace(1, mid) == b.trace(1, mid) {
            lo = mid
        } else {
            hi = mid
        }
    }
    println!("first differing photon: {lo}");
}
