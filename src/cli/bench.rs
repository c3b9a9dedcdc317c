//! `blutrace bench`: photons/s per backend as Markdown tables (ratios measured in one run).

use anyhow::Result;
use std::path::Path;

pub(super) fn bench(
    scene: &Path,
    box_scene: &Path,
    photons: u64,
    threads: Option<usize>,
    repeat: usize,
) -> Result<()> {
    let rows = crate::bench::reference_table(box_scene, photons, threads, repeat)?;
    println!(
        "| {}, {photons} photons | photons/s | interactions/s | ratio to the reference |",
        box_scene.display()
    );
    println!("|---|---:|---:|---:|");
    for r in rows {
        println!(
            "| {} | {:.0} | {:.0} | {:.3} |",
            r.tracer, r.photons_per_s, r.interactions_per_s, r.ratio_to_reference
        );
    }
    println!();
    println!(
        "| scene | triangles | backend | convex path | photons/s | interactions/s | ratio to obvhs |"
    );
    println!("|---|---:|---|---|---:|---:|---:|");
    let traced = crate::bench::trace_table(scene, photons, threads, repeat)?;
    for r in &traced {
        println!(
            "| {} | {} | {} | {} | {:.0} | {:.0} | {:.2} |",
            r.scene,
            r.triangles,
            r.backend,
            if r.convex { "on" } else { "off" },
            r.photons_per_s,
            r.interactions_per_s,
            r.ratio_to_obvhs
        );
    }
    println!();
    print_load(scene, &traced, repeat)?;
    let table = crate::bench::in_guide_table(scene, 1_000_000, repeat)?;
    let convex = table.last().map_or(f64::NAN, |(_, q)| *q);
    println!("| in-guide nearest-hit queries (1 thread) | queries/s | convex path speed-up |");
    println!("|---|---:|---:|");
    for (name, q) in &table {
        println!("| {name} | {q:.0} | {:.2} |", convex / q);
    }
    println!();
    let large = crate::bench::large_mesh_table(scene, 1_000_000, repeat)?;
    if let Some(native) = large.native_packets {
        println!(
            "Embree packet widths on this machine: {native} (RTC_DEVICE_PROPERTY_NATIVE_RAY*_SUPPORTED)"
        );
        println!();
    }
    println!(
        "| lamp-cavity nearest-hit queries, {}-triangle mesh (1 thread) | rays | queries/s | ratio to obvhs |",
        large.triangles
    );
    println!("|---|---|---:|---:|");
    for r in &large.rows {
        println!(
            "| {} | {} | {:.0} | {:.2} |",
            r.method, r.rays, r.queries_per_s, r.ratio_to_obvhs
        );
    }
    println!();
    let rows = crate::bench::error_table(scene, 4.0, threads)?;
    println!(
        "| backend | estimator | photons in ~4 s | mean-flux error | per-bin error | FOM mean | FOM bins |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|");
    for r in rows {
        println!(
            "| {} | {} | {} | {:.2e} | {:.3} | {:.3e} | {:.3e} |",
            r.backend,
            super::word(&r.estimator),
            r.photons,
            r.mean_rel_error,
            r.bin_rel_error,
            r.fom_mean,
            r.fom_bins
        );
    }
    Ok(())
}

/// The large mesh's load time, and the photons the fastest configuration of the trace
/// table traces on that mesh in the same time.
fn print_load(scene: &Path, traced: &[crate::bench::BenchRow], repeat: usize) -> Result<()> {
    let load = crate::bench::large_load_row(scene, repeat)?;
    let Some(fastest) = traced
        .iter()
        .filter(|r| r.triangles == load.triangles)
        .max_by(|a, b| a.photons_per_s.total_cmp(&b.photons_per_s))
    else {
        anyhow::bail!(
            "the trace table has no row for the {}-triangle mesh",
            load.triangles
        );
    };
    let path = if fastest.convex { "on" } else { "off" };
    println!(
        "| loading with every check | triangles | OBJ (MB) | seconds | photons traced in that time ({}, convex path {path}) |",
        fastest.backend
    );
    println!("|---|---:|---:|---:|---:|");
    println!(
        "| {} | {} | {:.0} | {:.2} | {:.0} |",
        fastest.scene,
        load.triangles,
        load.obj_bytes as f64 / 1e6,
        load.seconds,
        load.seconds * fastest.photons_per_s
    );
    println!();
    Ok(())
}
