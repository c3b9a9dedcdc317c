//! Sharded runs as separate processes, merged, equal one process bit for bit.

mod support;

use std::path::Path;
use std::process::Command;

const SCENE: &str = "scenes/notebook14";
const PHOTONS: &str = "150000";

fn blutrace(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .args(args)
        .output()
        .expect("run blutrace")
}

fn ok(args: &[&str]) {
    let out = blutrace(args);
    assert!(
        out.status.success(),
        "blutrace {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A fresh temporary folder, removed on drop.
fn tmp(name: &str) -> tempfile::TempDir {
    support::temp_folder(&format!("shards-{name}"))
}

fn shard(dir: &Path, k: usize, m: usize, seed: &str) -> String {
    let out = dir.join(format!("s{k}"));
    ok(&[
        "trace",
        SCENE,
        "--photons",
        PHOTONS,
        "--seed",
        seed,
        "--shard",
        &format!("{k}/{m}"),
        "--threads",
        "1",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    out.to_string_lossy().into_owned()
}

fn summary_without_timing(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let o = v.as_object_mut().unwrap();
    // Shards record the scene by absolute path (so `merge` works from any folder): the
    // merged run names the same file.
    let file = o.remove("scene_file").unwrap();
    let file = std::fs::canonicalize(file.as_str().unwrap()).unwrap();
    let scene = std::fs::canonicalize(SCENE).unwrap().join("scene.toml");
    assert_eq!(file, scene);
    for k in [
        "runtime_s",
        "photons_per_s",
        "interactions_per_s",
        "threads",
        "figure_of_merit",
        "backend",
    ] {
        o.remove(k);
    }
    v
}

#[test]
fn four_shards_merge_to_the_single_run_bit_for_bit() {
    let tmp = tmp("equal");
    let dir = tmp.path();
    let single = dir.join("single");
    ok(&[
        "trace",
        SCENE,
        "--photons",
        PHOTONS,
        "--seed",
        "5",
        "--quiet",
        "--out",
        single.to_str().unwrap(),
    ]);
    let shards: Vec<String> = (0..4).map(|k| shard(dir, k, 4, "5")).collect();
    let merged = dir.join("merged");
    let mut args: Vec<&str> = vec!["merge"];
    args.extend(shards.iter().rev().map(String::as_str)); // order must not matter
    args.extend(["--out", merged.to_str().unwrap()]);
    ok(&args);
    // The images, byte for byte.
    for f in ["flux.exr", "angular.exr", "flux.png", "conoscope.png"] {
        let bytes = |d: &Path| std::fs::read(d.join(f)).unwrap();
        assert!(
            bytes(&single) == bytes(&merged),
            "{f} differs between the single run and the merged shards"
        );
    }
    assert_eq!(
        summary_without_timing(&single),
        summary_without_timing(&merged)
    );
}

#[test]
fn missing_duplicate_and_foreign_shards_are_errors() {
    let tmp_dir = tmp("bad");
    let dir = tmp_dir.path();
    let s0 = shard(dir, 0, 3, "9");
    let s1 = shard(dir, 1, 3, "9");
    let out = dir.join("m");
    let out = out.to_str().unwrap();
    let err = blutrace(&["merge", &s0, &s1, "--out", out]);
    assert!(!err.status.success());
    assert!(
        String::from_utf8_lossy(&err.stderr).contains("shards missing: 2/3"),
        "{}",
        String::from_utf8_lossy(&err.stderr)
    );
    assert!(
        !Path::new(out).exists(),
        "a failed merge must not write outputs"
    );
    let partial = blutrace(&["merge", &s0, &s1, "--partial", "--out", out]);
    assert!(partial.status.success());
    assert!(String::from_utf8_lossy(&partial.stderr).contains("missing 2/3"));
    let dup = blutrace(&["merge", &s0, &s0, "--out", out]);
    assert!(String::from_utf8_lossy(&dup.stderr).contains("given twice"));
    let other_dir = tmp("other");
    let foreign = shard(other_dir.path(), 2, 3, "10");
    let mixed = blutrace(&["merge", &s0, &s1, &foreign, "--out", out]);
    assert!(
        String::from_utf8_lossy(&mixed.stderr).contains("seed is 10"),
        "{}",
        String::from_utf8_lossy(&mixed.stderr)
    );
}

/// `merge` never writes into a folder that is or holds one of its shards (the set would
/// replace the folder and delete the shard); it merges from any folder (shards record
/// the scene by absolute path); an edited shard tally is refused.
#[test]
fn merge_keeps_its_inputs_and_checks_their_tallies() {
    let tmp = tmp("inputs");
    let dir = tmp.path();
    let shards: Vec<String> = (0..2).map(|k| shard(dir, k, 2, "3")).collect();
    for out in [shards[0].clone(), dir.to_string_lossy().into_owned()] {
        let run = Command::new(env!("CARGO_BIN_EXE_blutrace"))
            .args(["merge", &shards[0], &shards[1], "--out", &out])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "merged into {out}");
        assert!(err.contains("would delete"), "{err}");
        assert!(
            Path::new(&shards[0]).join("shard.json").is_file(),
            "shard 0 lost"
        );
    }
    let merged = dir.join("merged");
    let run = Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .args(["merge", &shards[0], &shards[1], "--quiet", "--out"])
        .arg(&merged)
        .current_dir(std::env::temp_dir())
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let file = Path::new(&shards[1]).join("shard.json");
    let text = std::fs::read_to_string(&file).unwrap();
    // Edited as text: the tallies are exact 128-bit integers a JSON round trip would
    // not keep. The first group's photon count becomes 5.
    let key = "\"ledger\":{\"photons\":";
    let at = text.find(key).expect("a group ledger") + key.len();
    let digits = text[at..].find(|c: char| !c.is_ascii_digit()).unwrap();
    let edited = format!("{}5{}", &text[..at], &text[at + digits..]);
    std::fs::write(&file, edited).unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .args(["merge", &shards[0], &shards[1], "--out"])
        .arg(dir.join("edited"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success(), "an edited shard merged");
    assert!(
        err.contains("groups[0]") && err.contains("5 photons"),
        "{err}"
    );
}

/// Shards kept in memory (`ShardFile::of`, no file written) check and merge into the
/// single run's tallies bit for bit, as the Python package's `merge` uses them.
#[test]
fn shards_held_in_memory_merge_to_the_single_run() {
    use blutrace::run::{RunOptions, Shard};
    use blutrace::shard::{self, ShardFile};
    let scene = support::load(&Path::new(SCENE).join("scene.toml"));
    let options = RunOptions {
        photons: 100_000,
        seed: 5,
        threads: Some(2),
        ..RunOptions::default()
    };
    let single = support::trace_opts(&scene, &options);
    let shards: Vec<_> = (0..3)
        .map(|index| {
            let run = support::trace_opts(
                &scene,
                &RunOptions {
                    shard: Some(Shard { index, count: 3 }),
                    ..options.clone()
                },
            );
            let file = ShardFile::of(&run).unwrap();
            assert_eq!(
                file.range,
                [run.options.photon_range().0, run.options.photon_range().1]
            );
            (format!("shard {index}/3").into(), file)
        })
        .collect();
    assert!(shard::check(&shards, &scene).unwrap().is_empty());
    let merged = shard::merge(&shards, &scene).unwrap();
    assert_eq!(merged.tally.ledger.photons, 100_000);
    let (a, b) = (single.flux_map(), merged.flux_map());
    assert_eq!(a.value, b.value);
    assert_eq!(a.stderr, b.stderr);
    assert_eq!(a.hits, b.hits);
    assert_eq!(single.angular_map().value, merged.angular_map().value);
    assert!(
        ShardFile::of(&single).is_err(),
        "a run of all photons is no shard"
    );
}
