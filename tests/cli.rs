//! The command line as a user meets it: the report of a short run, and bad input.

use std::process::{Command, Output};

fn blutrace(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .args(args)
        .output()
        .expect("run blutrace")
}

/// A fresh temporary folder, removed on drop.
fn tmp(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("blutrace-cli-{name}-"))
        .tempdir()
        .unwrap()
}

#[test]
fn a_run_too_short_for_jackknife_errors_says_so() {
    let dir = tmp("short");
    let out = dir.path().join("out");
    let run = blutrace(&[
        "trace",
        "scenes/phone-led",
        "--photons",
        "1000",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success());
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(!text.contains("NaN"), "{text}");
    assert!(text.contains("cv ") && text.contains("± n/a"), "{text}");
    assert!(text.contains("need at least 8192 photons"), "{text}");
}

#[test]
fn a_bad_scene_names_file_and_field_and_writes_nothing() {
    let tmp = tmp("bad");
    let dir = tmp.path();
    let scene = std::fs::read_to_string("scenes/phone-led/scene.toml").unwrap();
    let bad = scene.replacen("pitch_mm = 0.3", "pitch_mm = -0.3", 1);
    assert_ne!(bad, scene);
    // Geometry and intensity files (`file = "..."`, `intensity_file = "..."`) by absolute path.
    let folder = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/phone-led/");
    let bad = bad.replace("file = \"", &format!("file = \"{folder}"));
    let path = dir.join("scene.toml");
    std::fs::write(&path, bad).unwrap();
    let out = dir.join("out");
    let run = blutrace(&[
        "trace",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!run.status.success());
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        err.contains("scene.toml") && err.contains("pitch_mm"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists(), "no output for a scene that does not load");
}
