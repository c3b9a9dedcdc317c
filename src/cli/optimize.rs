//! The `optimize` subcommand.
//!
//! ```text
//! blutrace optimize scenes/notebook14 --method feedback --photons 1000000 --target-cv 0.03
//! blutrace optimize scenes/notebook14 --method nelder-mead --max-iter 60 --out out/nm
//! blutrace optimize scenes/direct-lit --vary 'sources.*.center.2=4..20' --objective cv
//! ```
//!
//! Prints one line per iteration (best objective with its noise, whole-map cv and 13-point
//! ratio of the best design, photons and time so far), then the verification of the
//! first and final design with error bars, and the files written.

use super::optimize_flags::OptimizeFlags;
use super::{default_out, scene_path};
use anyhow::Result;
use blutrace::optimize::layout::EvaluationRecord;
use blutrace::optimize::{
    LayoutResult, OptimizeOptions, OptimizeResult, VerifiedDesign, optimize, optimize_layout,
};
use blutrace::scene::Scene;
use blutrace::spec_check::short;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `blutrace optimize`.
#[derive(Debug, clap::Args)]
pub struct OptimizeArgs {
    /// Scene file (or a folder holding scene.toml).
    pub scene: PathBuf,
    /// Seed shared by every evaluation (default: the scene's trace.seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Output folder (default: out/NAME-optimize-METHOD, NAME being the scene's name).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// How to optimize.
    #[command(flatten)]
    pub flags: OptimizeFlags,
}

impl OptimizeArgs {
    /// The options these arguments ask for, with the scene's defaults.
    pub fn options(&self, scene: &Scene) -> OptimizeOptions {
        self.flags.options(self.seed.unwrap_or(scene.default_seed))
    }
}

/// Run `blutrace optimize`: exit 130 after an interrupt (Ctrl-C), with the outputs of
/// the designs traced before it when there are any.
/// `quiet`: no per-iteration lines.
pub fn run(args: OptimizeArgs, quiet: bool) -> Result<ExitCode> {
    let interrupt = super::stop_on_signals();
    let scene = Scene::load(&scene_path(&args.scene))?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    let options = OptimizeOptions {
        interrupt,
        ..args.options(&scene)
    };
    let done = if options.vary.is_empty() {
        run_density(&scene, &options, &args.out, quiet)
    } else {
        run_layout(&scene, &options, &args.out, quiet)
    };
    match done {
        Ok(false) => Ok(ExitCode::SUCCESS),
        Ok(true) => {
            say!(
                "note       interrupted: the outputs hold the designs traced before it (the one being traced, and the verification, were dropped)"
            );
            Ok(ExitCode::from(130))
        }
        Err(e) if blutrace::run::is_interrupted(&e) => {
            eprintln!("interrupted before the first design was traced: nothing written");
            Ok(ExitCode::from(130))
        }
        Err(e) => Err(e),
    }
}

/// `blutrace optimize` of the dot density; returns whether an interrupt stopped it.
fn run_density(
    scene: &Scene,
    options: &OptimizeOptions,
    out: &Option<PathBuf>,
    quiet: bool,
) -> Result<bool> {
    let out = out.clone().unwrap_or_else(|| {
        let suffix = if options.tunes_grid() { "-2d" } else { "" };
        default_out(&format!(
            "{}-optimize-{}{suffix}",
            scene.name, options.method
        ))
    });
    blutrace::output::atomic::check_dest(&out, blutrace::optimize::OUTPUT_NAMES, &scene.inputs)?;
    let objective = if options.tunes_grid() {
        "area cv of the flux map (2-D density grid)".to_string()
    } else if options.objective.reads_color() {
        format!(
            "{} (cv of the flux profile along the axis, Δu'v' 13-point of the colour)",
            options.objective
        )
    } else {
        "cv of the flux profile along the axis".to_string()
    };
    say!(
        "optimize   {} ({}) by {}: {} photons per design, seed {}, objective = {objective}",
        scene.name,
        scene.path.display(),
        options.method,
        options.photons,
        options.seed
    );
    let result = optimize(scene, options, &mut |r| {
        if !quiet {
            say!("{r}");
        }
    })?;
    print_report(&result);
    for f in result.write(&out)? {
        say!("wrote      {}", f.display());
    }
    Ok(result.interrupted)
}

/// `blutrace optimize --vary`; returns whether an interrupt stopped it.
fn run_layout(
    scene: &Scene,
    options: &OptimizeOptions,
    out: &Option<PathBuf>,
    quiet: bool,
) -> Result<bool> {
    let out = out.clone().unwrap_or_else(|| {
        default_out(&format!(
            "{}-optimize-layout-{}",
            scene.name, options.method
        ))
    });
    blutrace::output::atomic::check_dest(
        &out,
        blutrace::optimize::LAYOUT_OUTPUT_NAMES,
        &scene.inputs,
    )?;
    say!(
        "optimize   {} ({}) by {} over {} variable(s): {} photons per design, seed {}, objective = {}",
        scene.name,
        scene.path.display(),
        options.method,
        options.vary.len(),
        options.photons,
        options.seed,
        options.objective
    );
    let result = optimize_layout(scene, options, &mut |r, names| {
        if !quiet {
            print_evaluation(r, names);
        }
    })?;
    print_layout_report(&result);
    for f in result.write(&out)? {
        say!("wrote      {}", f.display());
    }
    Ok(result.interrupted)
}

/// One line per evaluated design.
fn print_evaluation(r: &EvaluationRecord, names: &[String]) {
    let head = format!(
        "eval {:>4}  photons {:>8.2}M  {:>6.1} s  {}",
        r.evaluation,
        r.photons as f64 * 1e-6,
        r.seconds,
        r.assignment(names)
    );
    match (&r.result, &r.rejected) {
        (Some(e), _) => say!("{head}  {e}"),
        (None, Some(why)) => say!("{head}  not traced: {why}"),
        (None, None) => say!("{head}"),
    }
}

/// The search's totals, each integer case, the variables and the verification.
pub fn print_layout_report(r: &LayoutResult) {
    say!(
        "search     {} designs, {} photons ({:.2}M), {:.1} s",
        r.history.len(),
        r.photons,
        r.photons as f64 * 1e-6,
        r.seconds
    );
    if r.cases.len() > 1 {
        for c in &r.cases {
            say!(
                "case       {:?}: objective {:.4} ± {:.4} ({} designs; {})",
                c.integers,
                c.objective,
                c.noise,
                c.evaluations,
                c.termination
            );
        }
    } else if let Some(c) = r.cases.first() {
        say!("stopped    {}", c.termination);
    }
    say!(
        "objective  {:.4} ± {:.4} -> {:.4} ± {:.4} (seed {}, {} photons; cv noise floor {:.4})",
        r.initial.objective,
        r.initial.noise,
        r.best.objective,
        r.best.noise,
        r.options.seed,
        r.options.photons,
        r.best.noise_floor
    );
    if r.best.below_noise_floor() || r.initial.below_noise_floor() {
        say!(
            "warning    a design's cv is below its noise floor at {} photons: the cv term compares noise, not designs; use more --photons",
            r.options.photons
        );
    }
    for v in &r.variables {
        say!(
            "variable   {} = {} -> {} (range {}..{})",
            v.name,
            short(v.initial),
            short4(v.final_value),
            short(v.min),
            short(v.max)
        );
        if let Some(end) = v.at_range_end() {
            say!(
                "warning    {} ends within 1 % of its range's {end} end: the best design may lie beyond it (widen the range?)",
                v.name
            );
        }
    }
    if let Some(v) = &r.verification {
        say!(
            "verify     re-traced with seed {} and {} photons:",
            v.seed,
            v.photons
        );
        say!("  initial  {}", v.initial.evaluation);
        say!("  final    {}", v.final_design.evaluation);
    }
}

fn print_verified(label: &str, v: &VerifiedDesign, margin: f64) {
    let (u, e) = (&v.summary.uniformity, &v.summary.uniformity_stderr);
    let ev = &v.evaluation;
    let debiased = blutrace::run::metrics::debiased(ev.area_cv, ev.area_noise_floor);
    say!(
        "{label:<10} area cv {:.4} ± {:.4} (noise floor {:.4}, debiased {debiased:.4}) over the map without {margin} mm at the ends",
        ev.area_cv,
        ev.area_cv_noise,
        ev.area_noise_floor
    );
    say!(
        "{label:<10} profile cv {:.4} ± {:.4}; map cv {:.4} ± {:.4} (noise floor {:.4}, debiased {:.4} ± {:.4}), 13-pt {:.3} ± {:.3}, 9-pt {:.3} ± {:.3}, efficiency {:.4} ± {:.4}",
        ev.cv,
        ev.cv_noise,
        u.cv,
        e.cv,
        v.summary.cv_noise_floor,
        v.summary.cv_debiased,
        v.summary.cv_debiased_stderr,
        u.thirteen_point_min_over_max,
        e.thirteen_point_min_over_max,
        u.nine_point_min_over_max,
        e.nine_point_min_over_max,
        v.summary.extraction_efficiency,
        v.summary.extraction_efficiency_stderr,
    );
    if let Some(c) = &v.summary.color {
        say!(
            "{label:<10} colour Δu'v' 13-pt {:.4} ± {:.4} (noise floor {:.4}, debiased {:.4} ± {:.4}), CCT {:.0} ± {:.0} K",
            c.delta_uv_13pt.value,
            c.delta_uv_13pt.stderr,
            c.delta_uv_13pt_noise_floor,
            c.delta_uv_13pt_debiased.value,
            c.delta_uv_13pt_debiased.stderr,
            c.cct_k.value,
            c.cct_k.stderr
        );
    }
}

/// Print the search's totals and the verification.
pub fn print_report(r: &OptimizeResult) {
    say!(
        "search     {}: {} iterations, {} designs, {} photons ({:.2}M), {:.1} s",
        r.termination,
        r.iterations,
        r.evaluations,
        r.photons,
        r.photons as f64 * 1e-6,
        r.seconds
    );
    say!(
        "objective  {:.4} ± {:.4} -> {:.4} ± {:.4} (seed {}; noise floor {:.4}: the cv of noise alone at {} photons)",
        r.initial.objective,
        r.initial.noise,
        r.best.objective,
        r.best.noise,
        r.options.seed,
        r.best.noise_floor,
        r.options.photons
    );
    if let (Some(a), Some(b)) = (
        r.initial.delta_uv_13pt_debiased,
        r.best.delta_uv_13pt_debiased,
    ) {
        say!(
            "colour     Δu'v' 13-point {:.4} ± {:.4} -> {:.4} ± {:.4}; profile cv {:.4} -> {:.4}",
            a.value,
            a.stderr,
            b.value,
            b.stderr,
            r.initial.cv,
            r.best.cv
        );
    }
    match &r.final_density {
        blutrace::optics::dots::Density::Polynomial(c) => {
            let c: Vec<String> = c.iter().map(|v| format!("{v:.6}")).collect();
            say!("density    polynomial [{}]", c.join(", "));
        }
        blutrace::optics::dots::Density::Table(k) => {
            say!("density    table of {} knots", k.len());
        }
        blutrace::optics::dots::Density::Grid(g) => {
            let (nx, ny) = g.shape();
            say!("density    grid of {nx} x {ny} knots (along x across)");
        }
    }
    match (&r.dots, r.dots_placement) {
        (Some(dots), Some(p)) if p == r.pattern.placement => {
            say!(
                "dots       {} on {} ({} placement)",
                dots.len(),
                r.tag,
                p.name()
            )
        }
        (Some(dots), Some(p)) => say!(
            "dots       {} on {}: the traced placement \"virtual\" is not printable; the dot files hold a {} placement of the same density",
            dots.len(),
            r.tag,
            p.name()
        ),
        _ => say!(
            "dots       none written: surfaces.{} has placement \"virtual\", which is not printable; --export-placement stochastic (or jittered, lattice) writes a printable sheet of the same density",
            r.tag
        ),
    }
    if let Some(v) = &r.verification {
        say!(
            "verify     re-traced with seed {} and {} photons:",
            v.seed,
            v.photons
        );
        let m = r.options.edge_margin_mm;
        print_verified("  initial", &v.initial, m);
        print_verified("  final", &v.final_design, m);
    }
}

/// `x` with 4 decimals, or short (`1e300`) when that is long: a varied number's result.
fn short4(x: f64) -> String {
    let fixed = format!("{x:.4}");
    if fixed.len() <= 16 { fixed } else { short(x) }
}
