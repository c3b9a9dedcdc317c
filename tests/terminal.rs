//! The terminal as people use it: Ctrl-C, photon counts as written in the README, the
//! stopping rules' ends, one vocabulary, and commands that must refuse before they trace.
//! Every case runs the binary, as a user does.

mod support;

use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn blutrace(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .args(args)
        .output()
        .expect("run blutrace")
}

fn summary(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).expect("summary.json");
    serde_json::from_str(&text).unwrap()
}

/// scenes/test/slab with `from` replaced by `to` in its scene file.
fn slab_with(name: &str, from: &str, to: &str) -> support::SceneDir {
    let text = std::fs::read_to_string("scenes/test/slab/scene.toml").unwrap();
    assert!(text.contains(from), "{from}");
    let file = |f: &str| std::fs::read_to_string(Path::new("scenes/test/slab").join(f)).unwrap();
    let (obj, mtl) = (file("slab.obj"), file("slab.mtl"));
    support::write_scene(
        name,
        &text.replace(from, to),
        &[("slab.obj", &obj), ("slab.mtl", &mtl)],
    )
}

fn spawn_trace(out: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .args([
            "trace",
            "scenes/direct-lit",
            "--photons",
            "1e9",
            "--quiet",
            "--out",
        ])
        .arg(out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start blutrace")
}

fn signal(child: &Child, name: &str) {
    let ok = Command::new("kill")
        .args([&format!("-{name}"), &child.id().to_string()])
        .status()
        .expect("run kill")
        .success();
    assert!(ok, "kill -{name} failed");
}

/// Wait for `child` at most `limit`; kills it and fails the test past that.
fn wait_bounded(mut child: Child, limit: Duration) -> Output {
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("blutrace did not end within {limit:?} of the signal");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// Ctrl-C (a real SIGINT to the process) ends a trace after the chunk it is on, with the
/// whole output set of the photons traced, `stopped_by = "interrupted"` and exit 130.
#[test]
fn ctrl_c_writes_what_was_traced_and_exits_130() {
    let dir = support::temp_folder("ctrl-c");
    let out = dir.path().join("out");
    let child = spawn_trace(&out);
    std::thread::sleep(Duration::from_secs(3));
    signal(&child, "INT");
    let run = wait_bounded(child, Duration::from_secs(60));
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert_eq!(run.status.code(), Some(130), "{stdout}");
    let s = summary(&out);
    assert_eq!(s["stopped_by"], "interrupted");
    let photons = s["photons"].as_u64().unwrap();
    assert!(photons > 0 && photons < 1_000_000_000, "{photons}");
    assert_eq!(s["ledger"]["balance_rel_error"].as_f64(), Some(0.0));
    assert!(stdout.contains("stopped by interrupted"), "{stdout}");
    assert!(stdout.contains("note       interrupted"), "{stdout}");
    for f in [
        "flux.exr",
        "angular.exr",
        "flux.png",
        "conoscope.png",
        "convergence.csv",
        "convergence.png",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
}

/// A second Ctrl-C ends the program at once and leaves the previous output set as it was.
#[test]
fn a_second_ctrl_c_quits_at_once_and_keeps_the_previous_set() {
    let dir = support::temp_folder("ctrl-c-twice");
    let out = dir.path().join("out");
    let first = blutrace(&[
        "trace",
        "scenes/direct-lit",
        "--photons",
        "2e4",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(first.status.success());
    let before = std::fs::read(out.join("summary.json")).unwrap();
    let child = spawn_trace(&out);
    std::thread::sleep(Duration::from_secs(3));
    signal(&child, "INT");
    signal(&child, "INT");
    let run = wait_bounded(child, Duration::from_secs(60));
    assert_eq!(run.status.code(), Some(130));
    assert_eq!(std::fs::read(out.join("summary.json")).unwrap(), before);
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.contains(&"out".to_string()), "{names:?}");
}

/// SIGTERM (a batch system's stop) is an interrupt too.
#[test]
fn sigterm_is_an_interrupt_too() {
    let dir = support::temp_folder("sigterm");
    let out = dir.path().join("out");
    let child = spawn_trace(&out);
    std::thread::sleep(Duration::from_secs(3));
    signal(&child, "TERM");
    let run = wait_bounded(child, Duration::from_secs(60));
    assert_eq!(run.status.code(), Some(130));
    assert_eq!(summary(&out)["stopped_by"], "interrupted");
}

/// Start `blutrace args...` with its output piped; returns once a stdout line starts with
/// `ready` (a search's first iteration line), with the child and the lines so far.
fn spawn_until(args: &[&str], ready: &str) -> (Child, std::sync::mpsc::Receiver<String>) {
    use std::io::BufRead;
    let mut child = Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start blutrace");
    let stdout = child.stdout.take().unwrap();
    let (send, lines) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in std::io::BufReader::new(stdout)
            .lines()
            .map_while(Result::ok)
        {
            if send.send(line).is_err() {
                break;
            }
        }
    });
    let start = Instant::now();
    loop {
        match lines.recv_timeout(Duration::from_secs(300)) {
            Ok(line) if line.starts_with(ready) => return (child, lines),
            Ok(_) => {}
            Err(e) => {
                let _ = child.kill();
                panic!(
                    "no line starting with {ready:?} after {:?}: {e}",
                    start.elapsed()
                );
            }
        }
    }
}

/// Ctrl-C during `optimize` ends the search after the design it is tracing, writes the
/// whole output set of the designs traced before (optimize.json says `interrupted`) and
/// exits 130. The verification's billion photons make sure the run is still going when the
/// signal comes.
#[test]
fn ctrl_c_ends_an_optimization_with_its_best_design_so_far() {
    let dir = support::temp_folder("ctrl-c-optimize");
    let out = dir.path().join("out");
    let (child, lines) = spawn_until(
        &[
            "optimize",
            "scenes/bench-box",
            "--photons",
            "2e4",
            "--verify-photons",
            "1e9",
            "--threads",
            "2",
            "--out",
            out.to_str().unwrap(),
        ],
        "iter",
    );
    signal(&child, "INT");
    let run = wait_bounded(child, Duration::from_secs(120));
    let stdout: Vec<String> = lines.iter().collect();
    assert_eq!(run.status.code(), Some(130), "{stdout:?}");
    assert!(
        stdout
            .iter()
            .any(|l| l.starts_with("note       interrupted")),
        "{stdout:?}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("optimize.json")).unwrap()).unwrap();
    assert_eq!(json["interrupted"], true);
    assert!(json["verification"].is_null());
    for f in [
        "optimized.toml",
        "final/summary.json",
        "initial/summary.json",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
}

/// Photon counts are read as the README writes them; fractions and zero are refused.
#[test]
fn photon_counts_read_as_written() {
    let dir = support::temp_folder("counts");
    for (text, want) in [("1e4", 10_000), ("1_500", 1_500), ("2.5e3", 2_500)] {
        let out = dir.path().join(text);
        let run = blutrace(&[
            "trace",
            "scenes/test/slab",
            "--photons",
            text,
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(
            run.status.success(),
            "{text}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        assert_eq!(summary(&out)["photons"].as_u64(), Some(want), "{text}");
    }
    for (text, why) in [
        ("1.5", "whole number"),
        ("0", "at least 1 photon"),
        ("-3", ""),
    ] {
        let run = blutrace(&["trace", "scenes/test/slab", "--photons", text]);
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{text}: {err}");
        assert!(err.contains(why), "{text}: {err}");
    }
}

/// Runs of no photons are refused before anything is traced or written, by every command.
#[test]
fn zero_photon_runs_are_refused() {
    let dir = support::temp_folder("zero");
    let scene = slab_with("zero-photons", "photons = 100000", "photons = 0");
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    let cases: [&[&str]; 4] = [
        &["trace", "scenes/test/slab", "--max-time", "0", "--out", o],
        &["optimize", "scenes/phone-led", "--photons", "0", "--out", o],
        &["bench", "--photons", "0"],
        &["trace", "scenes/test/slab", "--photons", "0", "--out", o],
    ];
    for case in cases {
        let run = blutrace(case);
        assert!(!run.status.success(), "{case:?} was accepted");
        assert!(!out.exists(), "{case:?} wrote outputs");
    }
    let run = blutrace(&["trace", scene.to_str().unwrap(), "--out", o]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(err.contains("trace.photons: must be at least 1"), "{err}");
}

/// `--max-time` is honoured within a few chunks, not a whole first round (131,072
/// photons): the photons traced past the limit, at the run's own rate, are few.
#[test]
fn max_time_is_honoured_within_a_few_chunks() {
    let dir = support::temp_folder("max-time");
    let out = dir.path().join("out");
    let run = blutrace(&[
        "trace",
        "scenes/direct-lit",
        "--max-time",
        "0.3",
        "--threads",
        "2",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success());
    let s = summary(&out);
    assert_eq!(s["stopped_by"], "time");
    let (photons, seconds) = (
        s["photons"].as_f64().unwrap(),
        s["runtime_s"].as_f64().unwrap(),
    );
    let over = (seconds - 0.3).max(0.0) * photons / seconds;
    let chunk = blutrace::tracer::CHUNK as f64;
    assert!(
        over <= 6.0 * chunk,
        "{over} photons past the limit ({photons} in {seconds} s)"
    );
}

/// A target no run can reach stops and says why: a cv on a one-bin detector (which has none) is refused
/// before tracing; a detector that catches nothing stops after about 1e6 photons.
#[test]
fn unreachable_targets_stop_and_say_so() {
    let dir = support::temp_folder("unreachable");
    let one_bin = slab_with("one-bin", "bins = [20, 20]", "bins = [1, 1]");
    let run = blutrace(&[
        "trace",
        one_bin.to_str().unwrap(),
        "--target-error",
        "0.01",
        "--target-metric",
        "cv",
    ]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(err.contains("a map this coarse has no cv"), "{err}");

    let out = dir.path().join("dark");
    let run = blutrace(&[
        "trace",
        "scenes/test/slab-edge-lit",
        "--target-error",
        "0.1",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let s = summary(&out);
    assert_eq!(s["stopped_by"], "unreachable");
    let photons = s["photons"].as_u64().unwrap();
    assert!(
        (blutrace::run::UNREACHABLE_AFTER..4 << 20).contains(&photons),
        "{photons}"
    );
    assert!(stdout.contains("cannot be reached"), "{stdout}");
}

/// The terminal says what summary.json says, in the same words.
#[test]
fn the_terminal_uses_the_summary_vocabulary() {
    let dir = support::temp_folder("words");
    let out = dir.path().join("out");
    let run = blutrace(&[
        "trace",
        "scenes/test/slab",
        "--photons",
        "1e4",
        "--estimator",
        "weighted",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    let s = summary(&out);
    assert_eq!(
        (&s["estimator"], &s["stopped_by"]),
        (&"weighted".into(), &"photons".into())
    );
    assert!(stdout.contains("estimator weighted"), "{stdout}");
    assert!(stdout.contains("stopped by photons"), "{stdout}");
    assert!(stdout.contains("(mean)"), "{stdout}");
    for rust_name in ["Weighted", "Photons", "TargetError", "(Mean)"] {
        assert!(!stdout.contains(rust_name), "{rust_name} in {stdout}");
    }
}

/// `optimize --help` states the iteration cap per method, not one default for both.
#[test]
fn help_states_the_defaults_that_apply() {
    let run = blutrace(&["optimize", "--help"]);
    let help = String::from_utf8_lossy(&run.stdout);
    let line = help
        .split("--max-iter")
        .nth(1)
        .and_then(|rest| rest.split("\n  -").next())
        .unwrap_or("");
    assert!(
        line.contains("60 for Nelder-Mead, 15 for feedback"),
        "{line}"
    );
    assert!(!line.contains("[default: 60]"), "{line}");
}

/// `--quiet` is a flag of every command, before or after the command's name (clap checks
/// the flags before it acts on `--help`, so an unknown one would fail here).
#[test]
fn every_command_takes_the_common_flags() {
    for command in ["trace", "merge", "optimize", "bench", "check"] {
        for args in [
            [command, "--quiet", "--help"],
            ["--quiet", command, "--help"],
        ] {
            let run = blutrace(&args);
            assert!(
                run.status.success(),
                "{args:?}: {}",
                String::from_utf8_lossy(&run.stderr)
            );
            let help = String::from_utf8_lossy(&run.stdout);
            assert!(help.contains("--quiet"), "{args:?}: {help}");
        }
    }
    let run = blutrace(&["check", "scenes/test/slab", "--quiet"]);
    assert!(run.status.success());
}

/// Bad option values get blutrace's own message before anything runs: a negative number
/// is read as the option's value (not clap's advice to write `-- -5`), NaN is no number,
/// a benchmark needs a round, a missing scene is named as given, and `--vary` refuses the
/// run's own settings.
#[test]
fn bad_option_values_are_refused_with_our_own_message() {
    let dir = support::temp_folder("bad-values");
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    let cases: [(&[&str], &str); 6] = [
        (
            &["trace", "scenes/test/slab", "--photons", "-5", "--out", o],
            "\"-5\" is not a count",
        ),
        (
            &[
                "optimize",
                "scenes/phone-led",
                "--target-cv",
                "NaN",
                "--out",
                o,
            ],
            "\"NaN\" is not a finite number",
        ),
        (
            &["trace", "scenes/test/slab", "--max-time", "inf", "--out", o],
            "\"inf\" is not a finite number",
        ),
        (&["bench", "--repeat", "0"], "0 rounds: give 1 to 1000"),
        (
            &["bench", "--scene", "x/missing", "--photons", "1000"],
            "--scene x/missing: no scene file x/missing",
        ),
        (
            &[
                "optimize",
                "scenes/phone-led",
                "--vary",
                "trace.photons=1..2",
                "--out",
                o,
            ],
            "the search sets itself",
        ),
    ];
    for (args, says) in cases {
        let run = blutrace(args);
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{args:?} was accepted");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(!err.contains("-- -"), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} wrote outputs");
    }
}

/// A reader that closes stdout early (`| head -1`) ends the printing, not the work: an
/// optimization still writes its whole output set and says so on stderr.
#[test]
fn a_closed_stdout_does_not_cost_an_optimization_its_outputs() {
    let dir = support::temp_folder("closed-stdout");
    let out = dir.path().join("out");
    let mut child = Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .args([
            "optimize",
            "scenes/bench-box",
            "--method",
            "feedback",
            "--max-iter",
            "2",
            "--photons",
            "2e4",
            "--verify-photons",
            "0",
            "--quiet",
            "--out",
        ])
        .arg(&out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start blutrace");
    drop(child.stdout.take());
    let run = wait_bounded(child, Duration::from_secs(300));
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{:?}: {err}", run.status);
    assert!(err.contains("stdout was closed"), "{err}");
    assert!(out.join("optimize.json").is_file(), "{err}");
    assert!(out.join("final/summary.json").is_file(), "{err}");
}
