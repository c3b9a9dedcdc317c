//! The `blutrace` command line: one subcommand per file (`trace` and `merge`, `check`,
//! `bench`, `optimize`; `schema` prints the library's scene-file schema), each a thin layer that parses options, calls the library and
//! prints. `src/main.rs` only calls [`main`].

/// `println!` for the command line's reports, which never stops the work: a reader that
/// closes stdout early (`blutrace optimize ... | head`) ends the printing, while the
/// command goes on and writes its outputs ([`stdout_closed`] tells it so).
macro_rules! say {
    () => {
        $crate::cli::say_line(format_args!(""))
    };
    ($($arg:tt)*) => {
        $crate::cli::say_line(format_args!($($arg)*))
    };
}

mod bench;
mod bsdf;
mod check;
mod enums;
pub mod optimize;
mod optimize_flags;
mod trace;

use anyhow::Result;
use blutrace::run::Interrupt;
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

/// Monte Carlo photon tracer for LCD backlight units.
#[derive(Parser)]
#[command(version, about)]
struct Cli {
    /// No progress output (progress bars, per-iteration lines); results, warnings and errors
    /// still print. Taken by every command, before or after its name.
    #[arg(long, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Trace photons through a scene and write flux/angular maps and a summary.
    Trace(trace::TraceArgs),
    /// Merge shard runs (`trace --shard K/M`) into the outputs of one run.
    Merge(trace::MergeArgs),
    /// Optimize the ink-dot density for uniformity (Nelder-Mead or feedback), or any
    /// numbers of the scene file (`--vary`).
    Optimize(Box<optimize::OptimizeArgs>),
    /// Measure photons/s per backend (ratios in one run; see the book's Performance and backends page).
    Bench {
        /// Photons per configuration.
        #[arg(long, default_value_t = 200_000, value_parser = blutrace::count::parse_photons)]
        photons: u64,
        /// Worker threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// The notebook scene folder.
        #[arg(long, default_value = "scenes/notebook14")]
        scene: PathBuf,
        /// The box-guide scene folder of the speed-of-light table (default: `bench-box`
        /// beside the notebook scene's folder).
        #[arg(long)]
        box_scene: Option<PathBuf>,
        /// Rounds per timing (each round measures every configuration once; medians).
        #[arg(long, default_value_t = 3, value_parser = blutrace::count::parse_rounds)]
        repeat: usize,
    },
    /// Characterise a part of a scene (a film, a plate, a face) into an IS BSDF table.
    Bsdf(bsdf::BsdfArgs),
    /// Validate a scene and print what it uses.
    Check {
        /// Scene file (or a folder holding scene.toml).
        scene: PathBuf,
        /// Write the geometry report (files and tags with triangle counts and bounding
        /// boxes in mm, after all transforms) and the warnings as JSON on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Print the JSON Schema (draft 2020-12) of the scene file, for editors and validators
    /// (`.taplo.toml` associates scene files with it).
    Schema,
}

/// Parse the command line, run it, and report an error on stderr.
pub fn main() -> ExitCode {
    let matches = command().get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    match cli.command.execute(cli.quiet) {
        Ok(code) if stdout_closed() => {
            eprintln!(
                "note: stdout was closed before the report ended; the output files are complete"
            );
            code
        }
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", as_flags(&format!("{e:#}")));
            ExitCode::FAILURE
        }
    }
}

/// The command line's grammar: every option's value may start with `-`, so `--photons -5`
/// reaches blutrace's own check of the value ("not a count") instead of clap's advice to
/// write `-- -5`, which does not apply to an option's value.
fn command() -> clap::Command {
    fn negatives(c: clap::Command) -> clap::Command {
        c.mut_args(|a| {
            let takes = a.get_action().takes_values();
            a.allow_negative_numbers(takes)
        })
        .mut_subcommands(negatives)
    }
    negatives(Cli::command())
}

/// A library message with its options named as flags: the library writes "option
/// `max_time`" (the field of its options), the command line reads `--max-time`.
fn as_flags(msg: &str) -> String {
    const MARK: &str = "option `";
    let mut out = String::with_capacity(msg.len());
    let mut rest = msg;
    while let Some(i) = rest.find(MARK) {
        let after = &rest[i + MARK.len()..];
        match after.find('`') {
            Some(j)
                if after[..j]
                    .bytes()
                    .all(|b| b.is_ascii_lowercase() || b == b'_') =>
            {
                out.push_str(&rest[..i]);
                out.push_str("--");
                out.push_str(&after[..j].replace('_', "-"));
                rest = &after[j + 1..];
            }
            _ => {
                out.push_str(&rest[..i + MARK.len()]);
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

/// Set once a line could not be written to stdout (its reader is gone).
static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);

/// Write one line of a report to stdout (see `say!`); a failed write marks stdout closed
/// and later lines are dropped.
pub(crate) fn say_line(args: std::fmt::Arguments) {
    if stdout_closed() {
        return;
    }
    let mut out = std::io::stdout().lock();
    if writeln!(out, "{args}").and_then(|()| out.flush()).is_err() {
        STDOUT_CLOSED.store(true, Ordering::Relaxed);
    }
}

/// Whether stdout's reader has gone (a write failed).
pub(crate) fn stdout_closed() -> bool {
    STDOUT_CLOSED.load(Ordering::Relaxed)
}

impl Command {
    fn execute(self, quiet: bool) -> Result<ExitCode> {
        let done = match self {
            Command::Trace(args) => return trace::trace(args, quiet),
            Command::Merge(args) => return trace::merge(args),
            Command::Optimize(args) => return optimize::run(*args, quiet),
            Command::Bench {
                photons,
                threads,
                scene,
                box_scene,
                repeat,
            } => {
                let box_scene = box_scene
                    .unwrap_or_else(|| scene.parent().unwrap_or(Path::new(".")).join("bench-box"));
                bench::check_threads(threads)?;
                bench::check_scenes(&scene, &box_scene)?;
                bench::bench(&scene, &box_scene, photons, threads, repeat)
            }
            Command::Check { scene, json } => check::check(&scene_path(&scene), json),
            Command::Bsdf(args) => bsdf::bsdf(args),
            Command::Schema => {
                let schema = blutrace::scene::schema::scene_schema();
                say!("{}", serde_json::to_string_pretty(&schema)?);
                Ok(())
            }
        };
        done.map(|()| ExitCode::SUCCESS)
    }
}

/// SIGINT, SIGTERM and SIGHUP ask a run to stop after the chunk it is absorbing: its
/// outputs then hold what was traced and the command exits 130. A second signal ends the
/// program at once, leaving the previous output set as it was (sets are all-or-nothing).
pub(crate) fn stop_on_signals() -> Interrupt {
    let interrupt = Interrupt::default();
    let seen = interrupt.clone();
    let installed = ctrlc::set_handler(move || {
        if seen.requested() {
            std::process::exit(130);
        }
        seen.request();
        eprintln!(
            "\ninterrupted: writing what was traced after the current chunk (again to quit at once)"
        );
    });
    if let Err(e) = installed {
        eprintln!("warning: cannot catch Ctrl-C ({e}): an interrupt ends the run without outputs");
    }
    interrupt
}

/// The name summary.json gives a value (`analog`, `target_error`): the one vocabulary of
/// the files and the terminal.
pub(crate) fn word<T: serde::Serialize>(value: &T) -> String {
    match serde_json::to_value(value) {
        Ok(serde_json::Value::String(s)) => s,
        Ok(other) => other.to_string(),
        Err(_) => "?".into(),
    }
}

/// Accept a scene folder as well as the file itself.
pub(crate) fn scene_path(p: &Path) -> PathBuf {
    if p.is_dir() {
        p.join("scene.toml")
    } else {
        p.to_path_buf()
    }
}

/// The default output folder for a run named `name`: `out/<name>`, the name made a plain
/// file name (letters, digits, `.`, `-`, `_`; anything else becomes `_`; no leading dot),
/// so a scene's `name` can never point outside `out/` or at `out/` itself.
pub(crate) fn default_out(name: &str) -> PathBuf {
    let clean: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '_') {
                c
            } else {
                '_'
            }
        })
        .collect();
    let clean = clean.trim_start_matches('.');
    let clean = if clean.is_empty() { "scene" } else { clean };
    PathBuf::from("out").join(clean)
}

#[cfg(test)]
mod tests {
    use super::{as_flags, default_out};
    use std::path::PathBuf;

    #[test]
    fn default_output_folders_stay_inside_out() {
        for (name, want) in [
            ("notebook14", "notebook14"),
            ("../../x", "_.._x"),
            ("", "scene"),
            ("..", "scene"),
            ("a/b c", "a_b_c"),
            ("/etc", "_etc"),
            (".hidden", "hidden"),
        ] {
            assert_eq!(
                default_out(name),
                PathBuf::from("out").join(want),
                "{name:?}"
            );
        }
    }

    #[test]
    fn library_options_read_as_flags() {
        assert_eq!(
            as_flags("option `max_time` must be > 0; option `vary` a.b: no key"),
            "--max-time must be > 0; --vary a.b: no key"
        );
        // Anything else in backticks is left alone.
        assert_eq!(
            as_flags("a `usemtl` name, option `Bad`"),
            "a `usemtl` name, option `Bad`"
        );
    }
}
