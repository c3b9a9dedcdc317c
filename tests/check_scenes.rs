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
