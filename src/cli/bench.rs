//! `blutrace bench`: photons/s per backend as Markdown tables (ratios measured in one run).

use anyhow::{Result, bail};
use std::path::{Path, PathBuf};

/// Both scenes are there before anything is timed: errors name the option and the path
/// given (the box scene's default is derived from `--scene`, so a wrong `--scene` is named
/// as such).
pub(super) fn check_scenes(scene: &Path, box_scene: &Path) -> Result<()> {
    let file = super::scene_path(scene);
    if !file.is_file() {
        bail!(
            "--scene {}: no scene file {}",
            scene.display(),
            file.display()
        );
    }
    let boxed = super::scene_path(box_scene);
    if !boxed.is_file() {
        bail!(
            "--box-scene {}: no scene file {} (by default the folder bench-box beside --scene's folder)",
            box_scene.display(),
            boxed.display()
        );
    }
    Ok(())
}

/// `--threads` is within the bounds a run takes before any pool is built: the tables build
/// their own thread pools first, and 100000 threads hung the machine instead of an error.
pub(super) fn check_threads(threads: Option<usize>) -> Result<()> {
    use blutrace::run::MAX_THREADS;
    if let Some(n) = threads
        && !(1..=MAX_THREADS).contains(&n)
    {
        bail!("--threads must be within 1..={MAX_THREADS}, got {n}");
    }
    Ok(())
}

/// Stop a benchmark whose stdout's reader has gone: its tables are all it makes.
fn reader_still_there() -> Result<()> {
    if super::stdout_closed() {
        bail!("stdout was closed: the benchmark stopped (its tables are its only output)");
    }
    Ok(())
}

pub(super) fn bench(
    scene: &Path,
    box_scene: &Path,
    photons: u64,
    threads: Option<usize>,
    repeat: usize,
) -> Result<()> {
    let rows = blutrace_bench::reference_table(box_scene, photons, threads, repeat)?;
    say!(
        "| {}, {photons} photons | photons/s | interactions/s | ratio to the reference | ratio to the old reference |",
        box_scene.display()
    );
    say!("|---|---:|---:|---:|---:|");
    for r in rows {
        say!(
            "| {} | {:.0} | {:.0} | {:.3} | {:.3} |",
            r.tracer,
            r.photons_per_s,
            r.interactions_per_s,
            r.ratio_to_reference,
            r.ratio_to_old_reference
        );
    }
    say!();
    reader_still_there()?;
    say!(
        "| scene | triangles | backend | convex path | photons/s | interactions/s | ratio to obvhs |"
    );
    say!("|---|---:|---|---|---:|---:|---:|");
    let traced = blutrace_bench::trace_table(scene, photons, threads, repeat)?;
    for r in &traced {
        say!(
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
    say!();
    reader_still_there()?;
    print_load(scene, &traced, repeat)?;
    let table = blutrace_bench::in_guide_table(scene, 1_000_000, repeat)?;
    let convex = table.last().map_or(f64::NAN, |(_, q)| *q);
    say!("| in-guide nearest-hit queries (1 thread) | queries/s | convex path speed-up |");
    say!("|---|---:|---:|");
    for (name, q) in &table {
        say!("| {name} | {q:.0} | {:.2} |", convex / q);
    }
    say!();
    reader_still_there()?;
    let large = blutrace_bench::large_mesh_table(scene, 1_000_000, repeat)?;
    if let Some(native) = large.native_packets {
        say!(
            "Embree packet widths on this machine: {native} (RTC_DEVICE_PROPERTY_NATIVE_RAY*_SUPPORTED)"
        );
        say!();
        reader_still_there()?;
    }
    say!(
        "| lamp-cavity nearest-hit queries, {}-triangle mesh (1 thread) | rays | queries/s | ratio to obvhs |",
        large.triangles
    );
    say!("|---|---|---:|---:|");
    for r in &large.rows {
        say!(
            "| {} | {} | {:.0} | {:.2} |",
            r.method,
            r.rays,
            r.queries_per_s,
            r.ratio_to_obvhs
        );
    }
    say!();
    reader_still_there()?;
    let rows = blutrace_bench::error_table(scene, 4.0, threads)?;
    say!(
        "| backend | estimator | photons in ~4 s | mean-flux error | per-bin error | FOM mean | FOM bins |"
    );
    say!("|---|---|---:|---:|---:|---:|---:|");
    for r in rows {
        say!(
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
    say!();
    reader_still_there()?;
    polarization_table(&[box_scene, scene], photons, threads, repeat)?;
    say!();
    reader_still_there()?;
    print_luminance_estimators(scene, photons, threads, repeat)
}

/// The luminance map's estimators on every bundled scene beside `scene` that has one.
fn print_luminance_estimators(
    scene: &Path,
    photons: u64,
    threads: Option<usize>,
    repeat: usize,
) -> Result<()> {
    let root = scene.parent().unwrap_or(Path::new("."));
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(root)?
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| p.join("scene.toml").is_file())
        .collect();
    dirs.sort();
    let dirs: Vec<&Path> = dirs.iter().map(PathBuf::as_path).collect();
    let rows = blutrace_bench::luminance::luminance_table(&dirs, photons, threads, repeat)?;
    say!(
        "| luminance map, 2° cone | estimator | photons | seconds | noise floor | mean error | cone-counted | FOM 1/(floor²·s) | FOM ratio |"
    );
    say!("|---|---|---:|---:|---:|---:|---:|---:|---:|");
    for pair in rows.chunks(2) {
        for r in pair {
            say!(
                "| {} | {} | {} | {:.2} | {:.3} | {:.2e} | {:.3} | {:.3e} | {:.1} |",
                r.scene,
                r.estimator.name(),
                r.photons,
                r.seconds,
                r.noise_floor,
                r.mean_rel_error,
                r.cone_counted,
                r.fom_map,
                r.fom_map / pair[0].fom_map
            );
        }
    }
    Ok(())
}

/// The cost of polarized transport on `dirs` (see `blutrace_bench::polarization`).
fn polarization_table(
    dirs: &[&Path],
    photons: u64,
    threads: Option<usize>,
    repeat: usize,
) -> Result<()> {
    let rows = blutrace_bench::polarization_table(dirs, photons, threads, repeat)?;
    say!("| {photons} photons | averaged Fresnel photons/s | polarized photons/s | ratio |");
    say!("|---|---:|---:|---:|");
    for r in rows {
        say!(
            "| {} | {:.0} | {:.0} | {:.3} |",
            r.scene,
            r.averaged_per_s,
            r.polarized_per_s,
            r.ratio
        );
    }
    Ok(())
}

/// The large mesh's load time, and the photons the fastest configuration of the trace
/// table traces on that mesh in the same time.
fn print_load(scene: &Path, traced: &[blutrace_bench::BenchRow], repeat: usize) -> Result<()> {
    let load = blutrace_bench::large_load_row(scene, repeat)?;
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
    say!(
        "| loading with every check | triangles | OBJ (MB) | seconds | photons traced in that time ({}, convex path {path}) |",
        fastest.backend
    );
    say!("|---|---:|---:|---:|---:|");
    say!(
        "| {} | {} | {:.0} | {:.2} | {:.0} |",
        fastest.scene,
        load.triangles,
        load.obj_bytes as f64 / 1e6,
        load.seconds,
        load.seconds * fastest.photons_per_s
    );
    say!();
    reader_still_there()?;
    Ok(())
}
