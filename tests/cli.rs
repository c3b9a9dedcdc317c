//! The command line as a user meets it: the report of a short run, and bad input.

mod support;

use std::process::{Command, Output};

fn blutrace(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .args(args)
        .output()
        .expect("run blutrace")
}

/// A fresh temporary folder, removed on drop.
fn tmp(name: &str) -> tempfile::TempDir {
    support::temp_folder(&format!("cli-{name}"))
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

/// The files of a complete trace output set.
const OUTPUTS: [&str; 7] = [
    "angular.exr",
    "conoscope.png",
    "convergence.csv",
    "convergence.png",
    "flux.exr",
    "flux.png",
    "summary.json",
];

fn assert_complete(dir: &std::path::Path, what: &str) {
    for f in OUTPUTS {
        assert!(dir.join(f).is_file(), "{what}: {f} missing");
    }
}

/// Runs in which no photon, or a single photon, reaches the target still write every
/// output: a chart with nothing to draw becomes a placeholder, never an error.
#[test]
fn runs_with_nothing_detected_write_the_whole_output_set() {
    let dir = tmp("empty");
    let cases: [&[&str]; 3] = [
        &["scenes/test/slab-edge-lit", "--photons", "20000"],
        &["scenes/test/slab", "--photons", "1"],
        &["scenes/test/slab", "--max-time", "1e-9"],
    ];
    for (k, case) in cases.iter().enumerate() {
        let out = dir.path().join(format!("run{k}"));
        let mut args = vec!["trace"];
        args.extend_from_slice(case);
        args.extend(["--quiet", "--out", out.to_str().unwrap()]);
        let run = blutrace(&args);
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(run.status.success(), "{case:?}: {err}");
        assert_complete(&out, &format!("{case:?}"));
    }
    let text = String::from_utf8_lossy(
        &blutrace(&[
            "trace",
            "scenes/test/slab-edge-lit",
            "--photons",
            "9000",
            "--quiet",
            "--out",
            dir.path().join("note").to_str().unwrap(),
        ])
        .stderr,
    )
    .to_string();
    assert!(
        text.contains("warning: no photon reached the target"),
        "{text}"
    );
    // A map without light has no uniformity: null, not the 0 of a uniform map.
    let summary = std::fs::read_to_string(dir.path().join("note/summary.json")).unwrap();
    let s: serde_json::Value = serde_json::from_str(&summary).unwrap();
    for key in ["cv_debiased", "cv_noise_floor"] {
        assert!(s[key].is_null(), "{key}: {}", s[key]);
    }
    assert!(s["uniformity"]["cv"].is_null(), "{}", s["uniformity"]);
    let warnings = s["warnings"].to_string();
    assert!(
        warnings.contains("no photon reached the target"),
        "{warnings}"
    );
    // Shards of such a run merge into a complete set too.
    let shards: Vec<String> = (0..2)
        .map(|k| {
            let s = dir.path().join(format!("shard{k}"));
            let run = blutrace(&[
                "trace",
                "scenes/test/slab-edge-lit",
                "--photons",
                "100",
                "--shard",
                &format!("{k}/2"),
                "--quiet",
                "--out",
                s.to_str().unwrap(),
            ]);
            assert!(run.status.success());
            s.to_str().unwrap().to_string()
        })
        .collect();
    let merged = dir.path().join("merged");
    let run = blutrace(&[
        "merge",
        &shards[0],
        &shards[1],
        "--out",
        merged.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert_complete(&merged, "merge");
}

#[test]
fn options_that_could_never_finish_are_refused() {
    let dir = tmp("opts");
    let out = dir.path().join("o");
    for (flag, value, says) in [
        ("--max-time", "NaN", "--max-time"),
        ("--max-time=-1", "", "--max-time"),
        ("--threads", "100000", "--threads"),
        ("--threads", "0", "--threads"),
        ("--target-error", "inf", "--target-error"),
    ] {
        let mut args = vec!["trace", "scenes/test/slab", flag];
        if !value.is_empty() {
            args.push(value);
        }
        args.extend(["--quiet", "--out", out.to_str().unwrap()]);
        let run = blutrace(&args);
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(
            !run.status.success() && err.contains(says),
            "{flag} {value}: {err}"
        );
        assert!(!out.exists(), "{flag} {value}: wrote outputs");
    }
}

/// summary.json says which layout and blutrace wrote it, names every row of the
/// luminance table, and reports the efficiency error the convergence history has.
#[test]
fn summary_is_versioned_labelled_and_agrees_with_the_history() {
    let dir = tmp("summary");
    let out = dir.path().join("o");
    let run = blutrace(&[
        "trace",
        "scenes/notebook14",
        "--photons",
        "200000",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["schema_version"], 2);
    assert_eq!(s["blutrace_version"], env!("CARGO_PKG_VERSION"));
    assert!(s["figure_of_merit"]["per_s"].as_f64().unwrap() > 0.0);
    let row = &s["luminance"]["by_theta"][0];
    assert!(
        row["theta_deg"].is_number() && row["cd_m2"].is_number(),
        "{row}"
    );
    let csv = std::fs::read_to_string(out.join("convergence.csv")).unwrap();
    let head: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let last: Vec<&str> = csv.lines().last().unwrap().split(',').collect();
    let col = head.iter().position(|h| *h == "efficiency_stderr").unwrap();
    let from_csv: f64 = last[col].parse().unwrap();
    let from_summary = s["extraction_efficiency_stderr"].as_f64().unwrap();
    assert!(
        (from_csv - from_summary).abs() <= 1e-9 * from_summary,
        "{from_csv} vs {from_summary}"
    );
}

/// A spectral run's report has a colour line: x, y, CCT and the debiased 13-point
/// Δu'v', each with its error, the numbers of summary.json's `color` as printed.
#[test]
fn a_spectral_run_reports_its_colour_as_the_summary_has_it() {
    let dir = tmp("colour");
    let out = dir.path().join("o");
    let run = blutrace(&[
        "trace",
        "scenes/notebook14-color",
        "--photons",
        "50000",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{stdout}");
    let line = stdout
        .lines()
        .find(|l| l.starts_with("colour     "))
        .unwrap_or_else(|| panic!("no colour line in {stdout}"));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    // The printed numbers in order: value and error of each quantity.
    let printed: Vec<&str> = line
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|w| w.parse::<f64>().is_ok())
        .collect();
    let keys = [
        ("x", 4),
        ("y", 4),
        ("cct_k", 0),
        ("delta_uv_13pt_debiased", 4),
    ];
    assert_eq!(printed.len(), 2 * keys.len(), "{line}");
    for (k, (key, digits)) in keys.iter().enumerate() {
        for (j, part) in ["value", "stderr"].iter().enumerate() {
            let want = s["color"][key][part].as_f64().unwrap();
            assert_eq!(
                printed[2 * k + j],
                format!("{want:.digits$}"),
                "{key}.{part}: {line}"
            );
        }
    }
    assert!(
        line.contains("CCT ") && line.contains("Δu'v' 13-point"),
        "{line}"
    );
}

/// A run that traces polarization prints its polarization line: the numbers of
/// summary.json's `polarization`, value and error of each.
#[test]
fn a_polarized_run_reports_its_polarization_as_the_summary_has_it() {
    let dir = tmp("polarized");
    let case = std::path::Path::new("tests/corpus/polarizer-without-polarization");
    for f in ["plate.obj", "film.obj"] {
        std::fs::copy(case.join(f), dir.path().join(f)).unwrap();
    }
    let toml = std::fs::read_to_string(case.join("scene.toml")).unwrap();
    let toml = toml.replace("polarization = false", "");
    std::fs::write(dir.path().join("scene.toml"), toml).unwrap();
    let out = dir.path().join("o");
    let args = [
        "trace",
        dir.path().to_str().unwrap(),
        "--photons",
        "20000",
        "--quiet",
    ];
    let run = blutrace(&[&args[..], &["--out", out.to_str().unwrap()]].concat());
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{stdout}");
    let line = stdout
        .lines()
        .find(|l| l.starts_with("polarized  "))
        .unwrap_or_else(|| panic!("no polarization line in {stdout}"));
    let numbers = line.split(" (detector frame").next().unwrap();
    let printed: Vec<&str> = numbers
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|w| w.parse::<f64>().is_ok())
        .collect();
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let keys = ["s1", "s2", "s3", "dop"];
    assert_eq!(printed.len(), 2 * keys.len(), "{line}");
    for (k, key) in keys.iter().enumerate() {
        for (j, part) in ["value", "stderr"].iter().enumerate() {
            let want = s["polarization"][key][part].as_f64().unwrap();
            assert_eq!(
                printed[2 * k + j],
                format!("{want:.4}"),
                "{key}.{part}: {line}"
            );
        }
    }
}
