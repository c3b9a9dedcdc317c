//! Output sets are all or nothing: a run killed (SIGKILL) at any step of writing its outputs
//! leaves the folder holding the complete previous set or the complete new one, never a
//! mix, and the next run into the folder cleans up after it.
//!
//! The real binary runs as a child with the test hook of `output::atomic`
//! (`BLUTRACE_TEST_OUTPUT_PAUSE=STEP`: print every step, stop at STEP), so every kill lands
//! exactly at the step named, on the `renameat2` exchange and on the two-rename swap.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};

const SCENE: &str = "scenes/test/slab";
/// The outputs whose bytes depend only on scene, seed and photons (not on timings).
const DETERMINISTIC: [&str; 4] = ["flux.exr", "angular.exr", "flux.png", "conoscope.png"];
/// The steps of writing a run's output set, in order, as the test hook names them.
const STEPS: [&str; 9] = [
    "wrote flux.exr",
    "wrote angular.exr",
    "wrote flux.png",
    "wrote conoscope.png",
    "wrote convergence.csv",
    "wrote convergence.png",
    "wrote summary.json",
    "swap",
    "swapped",
];

fn trace(seed: u64, out: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_blutrace"));
    c.args(["trace", SCENE, "--photons", "3000", "--quiet", "--seed"])
        .arg(seed.to_string())
        .arg("--out")
        .arg(out)
        .stdout(Stdio::null());
    c
}

/// The listing of `dir` and the bytes of its deterministic files and summary seed.
fn set_of(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut m = BTreeMap::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        let bytes = if DETERMINISTIC.contains(&name.as_str()) {
            std::fs::read(dir.join(&name)).unwrap()
        } else if name == "summary.json" {
            let s: serde_json::Value =
                serde_json::from_slice(&std::fs::read(dir.join(&name)).unwrap()).unwrap();
            s["seed"].to_string().into_bytes()
        } else {
            Vec::new()
        };
        m.insert(name, bytes);
    }
    m
}

/// Run with the hook stopping at `step`, wait for it to get there, and kill it.
fn kill_at(seed: u64, out: &Path, step: &str, two_step: bool) {
    let mut cmd = trace(seed, out);
    cmd.env("BLUTRACE_TEST_OUTPUT_PAUSE", step)
        .stderr(Stdio::piped());
    if two_step {
        cmd.env("BLUTRACE_TEST_OUTPUT_SWAP", "two-step");
    }
    let mut child = cmd.spawn().unwrap();
    let want = format!("blutrace-test-hook: {step}");
    let mut seen = Vec::new();
    let mut reached = false;
    for line in BufReader::new(child.stderr.take().unwrap()).lines() {
        let line = line.unwrap();
        if line == want {
            reached = true;
            child.kill().unwrap(); // SIGKILL: no destructor runs
            break;
        }
        seen.push(line);
    }
    child.wait().unwrap();
    assert!(
        reached,
        "the run never reached step {step:?}; stderr: {seen:#?}"
    );
}

/// The entries of `parent` other than the output folder: temporaries of killed runs.
fn leftovers(parent: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(parent)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "out" && !n.starts_with("ref"))
        .collect();
    v.sort();
    v
}

#[test]
fn a_killed_run_leaves_the_old_set_or_the_new_one() {
    let tmp = tempfile::tempdir().unwrap();
    let parent = tmp.path();
    let dest = parent.join("out");
    // The two complete sets, written by runs nobody kills.
    let mut sets = Vec::new();
    for seed in [1, 2] {
        let r = parent.join(format!("ref{seed}"));
        assert!(trace(seed, &r).status().unwrap().success());
        sets.push(set_of(&r));
    }
    assert_ne!(sets[0], sets[1]);
    assert!(trace(1, &dest).status().unwrap().success());
    let mut current = 0; // index of the set in `dest`
    for two_step in [false, true] {
        let steps = STEPS
            .iter()
            .copied()
            .chain(two_step.then_some("aside"))
            .collect::<Vec<_>>();
        for step in steps {
            let other = 1 - current;
            kill_at(other as u64 + 1, &dest, step, two_step);
            if step == "aside" {
                // Between the two renames the old set is aside, whole; the next run puts
                // it back before it writes anything.
                assert!(!dest.exists());
                let aside = leftovers(parent)
                    .into_iter()
                    .find(|n| n.starts_with(".out.old-"))
                    .expect("an aside folder");
                assert_eq!(set_of(&parent.join(aside)), sets[current], "{step}");
                kill_at(other as u64 + 1, &dest, "wrote flux.exr", two_step);
            } else if step == "swapped" {
                current = other;
            }
            assert_eq!(
                set_of(&dest),
                sets[current],
                "killed at {step:?} (two-step {two_step}): the folder must hold set {current}"
            );
        }
    }
    // The next complete run removes every temporary the killed runs left.
    assert!(!leftovers(parent).is_empty());
    assert!(trace(2, &dest).status().unwrap().success());
    assert_eq!(set_of(&dest), sets[1]);
    assert_eq!(leftovers(parent), Vec::<String>::new());
}

#[test]
fn a_folder_holding_other_files_is_refused_before_tracing() {
    let tmp = tempfile::tempdir().unwrap();
    let dest = tmp.path().join("out");
    std::fs::create_dir(&dest).unwrap();
    std::fs::write(dest.join("notes.md"), b"mine").unwrap();
    let run = trace(1, &dest).stderr(Stdio::piped()).output().unwrap();
    assert!(!run.status.success());
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        err.contains("notes.md") && err.contains(&*dest.to_string_lossy()),
        "{err}"
    );
    let left: Vec<_> = std::fs::read_dir(&dest).unwrap().collect();
    assert_eq!(left.len(), 1, "the folder is untouched");
    assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 1);
}
