//! `blutrace check` on every bundled scene (found by walking `scenes/`): each one loads,
//! validates and reports without a warning, and lists each source's medium and body.

mod support;

use std::process::Command;

#[test]
fn check_passes_on_every_bundled_scene() {
    let scenes = support::bundled_scene_files();
    assert!(!scenes.is_empty(), "no scene.toml under scenes/");
    for path in scenes {
        let out = Command::new(env!("CARGO_BIN_EXE_blutrace"))
            .arg("check")
            .arg(&path)
            .output()
            .expect("run blutrace");
        let (stdout, stderr) = (
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr),
        );
        let p = path.display();
        assert!(out.status.success(), "check {p} failed: {stderr}");
        assert_eq!(stdout.lines().last(), Some("ok"), "check {p}: {stdout}");
        for part in [
            "scene ",
            "geometry ",
            "tag ",
            "medium ",
            "source ",
            "detector ",
        ] {
            assert!(
                stdout.contains(part),
                "check {p} does not report '{part}': {stdout}"
            );
        }
        assert!(!stdout.contains("warning"), "check {p} warns: {stdout}");
        // Every source reports its medium and its body.
        for line in stdout.lines().filter(|l| l.starts_with("source ")) {
            assert!(
                line.contains(" in ") && line.contains("; body: "),
                "check {p}: {line}"
            );
        }
    }
}

#[test]
fn a_reader_that_stops_early_ends_check_quietly() {
    use std::process::Stdio;
    let scene = &support::bundled_scene_files()[0];
    let mut child = Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .arg("check")
        .arg(scene)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run blutrace");
    // Close the reading end before check has printed anything (it loads the scene first).
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("wait");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        out.status.success() || out.status.code() == Some(141),
        "{:?}: {stderr}",
        out.status
    );
}
