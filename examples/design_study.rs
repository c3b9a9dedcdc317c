//! A design study with blutrace as a library: trace a bundled scene, read its flux map,
//! compare three ink albedos (each a copy of the scene with one value changed), and let
//! the feedback optimizer tune the dot density.
//!
//! ```sh
//! cargo run --release --example design_study            # scenes/phone-led, a few seconds
//! cargo run --release --example design_study -- scenes/notebook14
//! ```

use anyhow::Result;
use blutrace::optimize::{Method, OptimizeOptions, optimize};
use blutrace::run::{self, RunOptions};
use blutrace::scene::Scene;
use std::path::PathBuf;

fn main() -> Result<()> {
    let folder = std::env::args().nth(1).unwrap_or("scenes/phone-led".into());
    let scene = Scene::load(&PathBuf::from(folder).join("scene.toml"))?;
    let options = RunOptions {
        photons: 400_000,
        seed: 1,
        ..RunOptions::default()
    };

    // One trace: the summary's numbers and the flux map (W/mm^2 per bin, row-major from
    // the detector's origin, with a standard error per bin).
    let run = run::trace(&scene, &options, &|_| {})?;
    let s = run.summary();
    let map = run.flux_map();
    let peak = map.value.iter().cloned().fold(0.0, f64::max);
    println!(
        "{}: efficiency {:.4} +- {:.4}, debiased cv {:.3}, {} x {} bins, peak {peak:.3e} W/mm^2",
        scene.name,
        s.extraction_efficiency,
        s.extraction_efficiency_stderr,
        s.cv_debiased,
        map.nx,
        map.ny
    );

    // Scenes are values: each albedo is a copy of the scene with one number changed.
    let tag = dotted_tag(&scene)?;
    for albedo in [0.7, 0.8, 0.9] {
        let design = scene.with(&format!("surfaces.{tag}.ink_albedo"), albedo)?;
        let s = run::trace(design, &options, &|_| {})?.summary();
        println!(
            "ink_albedo {albedo}: efficiency {:.4} +- {:.4}",
            s.extraction_efficiency, s.extraction_efficiency_stderr
        );
    }

    // The feedback optimizer on the dot density, without the verification re-traces.
    let tuned = optimize(
        &scene,
        &OptimizeOptions {
            photons: 200_000,
            max_iter: 4,
            verify_photons: 0,
            ..OptimizeOptions::for_method(Method::Feedback)
        },
        &mut |report| println!("{report}"),
    )?;
    println!(
        "feedback: profile cv {:.3} -> {:.3} after {} rounds",
        tuned.initial.objective, tuned.best.objective, tuned.iterations
    );
    Ok(())
}

/// The scene's dotted surface (the one the optimizer tunes).
fn dotted_tag(scene: &Scene) -> Result<String> {
    scene
        .tags
        .iter()
        .zip(&scene.surfaces)
        .find(|(_, s)| s.kind() == "dots")
        .map(|(t, _)| t.clone())
        .ok_or_else(|| anyhow::anyhow!("{}: no dots surface", scene.path.display()))
}
