//! Unit tests of output sets: staging, swap, refusal of foreign entries, recovery.

use super::*;

/// A fresh temporary parent folder.
fn parent(tag: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("blutrace-atomic-{tag}-"))
        .tempdir()
        .unwrap()
}

fn listing(dir: &Path) -> Vec<String> {
    entry_names(dir).unwrap()
}

const NAMES: &[&str] = &["a.json", "b.bin", "run"];
const NO_READS: &[&Path] = &[];

#[test]
fn drop_without_commit_leaves_nothing() {
    let t = parent("drop");
    let dest = t.path().join("out");
    {
        let s = OutputSet::new(&dest, NAMES, NO_READS).unwrap();
        s.write_bytes("a.json", b"{}").unwrap();
        assert_eq!(listing(t.path()).len(), 1, "the staging folder");
    }
    assert!(listing(t.path()).is_empty(), "{:?}", listing(t.path()));
}

#[test]
fn commit_replaces_the_whole_previous_set() {
    let t = parent("commit");
    let dest = t.path().join("out");
    let s = OutputSet::new(&dest, NAMES, NO_READS).unwrap();
    s.write_bytes("a.json", b"old").unwrap();
    s.write_bytes("b.bin", b"old").unwrap();
    s.commit().unwrap();
    assert_eq!(listing(&dest), vec![MANIFEST, "a.json", "b.bin"]);

    let s = OutputSet::new(&dest, NAMES, NO_READS).unwrap();
    s.write_bytes("a.json", b"new").unwrap();
    let run = s.subdir("run").unwrap();
    run.write_bytes("inner.txt", b"x").unwrap();
    let done = s.commit().unwrap();
    assert_eq!(done, vec![dest.join("a.json"), dest.join("run")]);
    // b.bin of the previous set is gone: the folder holds exactly the new set.
    assert_eq!(listing(&dest), vec![MANIFEST, "a.json", "run"]);
    assert_eq!(fs::read(dest.join("a.json")).unwrap(), b"new");
    assert_eq!(fs::read(dest.join("run/inner.txt")).unwrap(), b"x");
    assert_eq!(manifest_entries(&dest), vec!["a.json", "run"]);
    assert_eq!(
        listing(t.path()),
        vec!["out"],
        "no staging or old folder left"
    );
}

#[test]
fn the_two_rename_swap_gives_the_same_result() {
    let t = parent("two-step");
    let dest = t.path().join("out");
    fs::create_dir(&dest).unwrap();
    fs::write(dest.join("a.json"), b"old").unwrap();
    let staging = t.path().join(".out.tmp-1-1");
    fs::create_dir(&staging).unwrap();
    fs::write(staging.join("a.json"), b"new").unwrap();
    let old = swap_into_place(&staging, &dest, true).unwrap().unwrap();
    assert!(
        old.file_name()
            .unwrap()
            .to_string_lossy()
            .starts_with(".out.old-")
    );
    assert_eq!(fs::read(dest.join("a.json")).unwrap(), b"new");
    assert_eq!(fs::read(old.join("a.json")).unwrap(), b"old");
    assert!(!staging.exists());
}

#[test]
fn foreign_entries_are_refused_and_kept() {
    let t = parent("foreign");
    let dest = t.path().join("out");
    fs::create_dir(&dest).unwrap();
    fs::write(dest.join("a.json"), b"legacy").unwrap();
    fs::write(dest.join("notes.md"), b"mine").unwrap();
    let err = OutputSet::new(&dest, NAMES, NO_READS)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("notes.md") && err.contains(&*dest.to_string_lossy()),
        "{err}"
    );
    assert!(
        !err.contains("a.json"),
        "a name the command writes is not foreign: {err}"
    );
    assert_eq!(listing(&dest), vec!["a.json", "notes.md"]);
    assert_eq!(listing(t.path()), vec!["out"], "nothing staged");

    // Without the foreign file, the legacy folder (no manifest) is replaced.
    fs::remove_file(dest.join("notes.md")).unwrap();
    let s = OutputSet::new(&dest, NAMES, NO_READS).unwrap();
    s.write_bytes("b.bin", b"1").unwrap();
    // A file appearing while the run writes is refused at commit too, and survives.
    fs::write(dest.join("late.txt"), b"mine").unwrap();
    let err = s.commit().unwrap_err().to_string();
    assert!(err.contains("late.txt"), "{err}");
    assert_eq!(listing(&dest), vec!["a.json", "late.txt"]);
    assert_eq!(listing(t.path()), vec!["out"]);

    let file = t.path().join("file");
    fs::write(&file, b"").unwrap();
    let err = OutputSet::new(&file, NAMES, NO_READS)
        .unwrap_err()
        .to_string();
    assert!(err.contains("not a folder"), "{err}");
}

#[test]
fn errors_name_the_final_path() {
    let t = parent("errors");
    let dest = t.path().join("out");
    let s = OutputSet::new(&dest, NAMES, NO_READS).unwrap();
    let err = s
        .write_with("a.json", |p| {
            fs::write(p.join("no-such-folder/x"), b"")
                .with_context(|| format!("cannot create {}", p.display()))
        })
        .unwrap_err()
        .to_string();
    let want = format!("cannot create {}", dest.join("a.json").display());
    assert!(err.contains(&want), "{err}");
    assert!(!err.contains(".tmp-"), "{err}");
    let err = s.write_with("b.bin", |_| Ok(())).unwrap_err().to_string();
    assert!(
        err.contains(&*dest.join("b.bin").to_string_lossy()),
        "{err}"
    );
    for bad in ["", "..", ".", "x/y", "/abs", MANIFEST] {
        assert!(s.write_bytes(bad, b"1").is_err(), "{bad:?} accepted");
    }
}

#[test]
fn what_killed_runs_left_is_restored_or_removed() {
    // PID 2^31 - 1 is above Linux's pid_max: never a live process.
    let dead = 2_147_483_647;
    let t = parent("recover");
    let dest = t.path().join("out");
    // A kill between the two renames: the old set aside, no folder in place, a staging
    // folder with the complete new set.
    let aside = t.path().join(temp_name("out", "old", dead, 1));
    fs::create_dir(&aside).unwrap();
    fs::write(aside.join("a.json"), b"old").unwrap();
    let staged = t.path().join(temp_name("out", "tmp", dead, 0));
    fs::create_dir(&staged).unwrap();
    fs::write(staged.join("a.json"), b"new").unwrap();
    // Another folder's staging and a live run's staging are not ours to touch.
    let other = t.path().join(temp_name("other", "tmp", dead, 2));
    let live = t
        .path()
        .join(temp_name("out", "tmp", std::process::id(), 99));
    fs::create_dir(&other).unwrap();
    fs::create_dir(&live).unwrap();
    recover(t.path(), "out", &dest);
    assert_eq!(
        fs::read(dest.join("a.json")).unwrap(),
        b"old",
        "old set restored"
    );
    assert!(!aside.exists() && !staged.exists());
    assert!(other.exists() && live.exists());

    // With the folder in place, a dead aside folder is the previous set: removed.
    fs::create_dir(&aside).unwrap();
    recover(t.path(), "out", &dest);
    assert!(!aside.exists());
    assert_eq!(fs::read(dest.join("a.json")).unwrap(), b"old");
}

#[test]
fn temporary_names_parse() {
    assert_eq!(
        parse_temp(".flux.exr.tmp-12-0"),
        Some(("flux.exr", "tmp", 12))
    );
    assert_eq!(parse_temp(".run.v2.old-7-3"), Some(("run.v2", "old", 7)));
    assert_eq!(parse_temp("flux.exr"), None);
    assert_eq!(parse_temp(".notes.tmp-x-1"), None);
    assert_eq!(parse_temp(".a.new-1-1"), None);
}

/// A user's file named like a staging folder inside the output folder is refused, not
/// deleted with the old set (staging folders live beside the folder, never in it).
#[test]
fn a_staging_like_name_inside_the_folder_is_foreign() {
    let t = parent("staging-like");
    let dest = t.path().join("out");
    fs::create_dir(&dest).unwrap();
    fs::write(dest.join(".a.json.tmp-1-0"), b"mine").unwrap();
    let err = OutputSet::new(&dest, NAMES, NO_READS)
        .unwrap_err()
        .to_string();
    assert!(err.contains(".a.json.tmp-1-0"), "{err}");
    assert_eq!(listing(&dest), vec![".a.json.tmp-1-0"]);
}

/// Two runs into one new folder: the second to commit finds the folder the first created
/// after it looked, and replaces that complete set instead of failing.
#[test]
fn a_folder_created_meanwhile_is_replaced() {
    let t = parent("race");
    let dest = t.path().join("out");
    let first = OutputSet::new(&dest, NAMES, NO_READS).unwrap();
    let second = OutputSet::new(&dest, NAMES, NO_READS).unwrap();
    first.write_bytes("a.json", b"first").unwrap();
    second.write_bytes("a.json", b"second").unwrap();
    first.commit().unwrap();
    // The rename the second run tries when the folder was missing a moment ago.
    let staging = second.root.staging.clone();
    assert!(!rename_to_new(&staging, &dest).unwrap());
    assert!(
        staging.exists(),
        "the staging folder stays for the exchange"
    );
    second.commit().unwrap();
    assert_eq!(fs::read(dest.join("a.json")).unwrap(), b"second");
    assert_eq!(listing(t.path()), vec!["out"]);
}

#[test]
fn a_file_is_written_whole_or_left_as_it_was() {
    let t = parent("file");
    let path = t.path().join("t.bsdf");
    write_file(&path, b"old", NO_READS).unwrap();
    write_file(&path, b"new", NO_READS).unwrap();
    assert_eq!(fs::read(&path).unwrap(), b"new");
    assert_eq!(listing(t.path()), vec!["t.bsdf"], "no temporary left");
    // A folder in the way: an error naming the path, the folder untouched, no temporary.
    let blocked = t.path().join("dir.bsdf");
    fs::create_dir(&blocked).unwrap();
    let e = write_file(&blocked, b"x", NO_READS)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("dir.bsdf") && e.starts_with("cannot write"),
        "{e}"
    );
    assert!(blocked.is_dir());
    assert_eq!(listing(t.path()), vec!["dir.bsdf", "t.bsdf"]);
}

#[test]
fn a_set_never_replaces_a_folder_holding_what_the_run_read() {
    let t = parent("inputs");
    let dest = t.path().join("out");
    fs::create_dir_all(dest.join("sub")).unwrap();
    let scene = dest.join("sub/scene.toml");
    fs::write(&scene, "version = 1").unwrap();
    // A forged manifest that calls the scene file blutrace's does not make it so.
    let manifest = serde_json::json!({"entries": ["sub"]});
    fs::write(dest.join(MANIFEST), manifest.to_string()).unwrap();
    let err = OutputSet::new(&dest, NAMES, &[&scene])
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("out") && err.contains("scene.toml") && err.contains("input"),
        "{err}"
    );
    // Through a symbolic link and `..` too; a folder beside the input is fine.
    let link = t.path().join("link");
    std::os::unix::fs::symlink(&dest, &link).unwrap();
    assert!(OutputSet::new(&link.join("sub/.."), NAMES, &[&scene]).is_err());
    assert!(OutputSet::new(&t.path().join("other"), NAMES, &[&scene]).is_ok());
    assert_eq!(fs::read(&scene).unwrap(), b"version = 1");
}

#[test]
fn a_file_never_replaces_what_the_run_read() {
    let t = parent("file-inputs");
    let table = t.path().join("film.bsdf");
    fs::write(&table, "measured").unwrap();
    let err = write_file(&table, b"new", &[&table])
        .unwrap_err()
        .to_string();
    assert!(err.contains("film.bsdf") && err.contains("input"), "{err}");
    // A hard link to the input, or a path through `..`, is the input too.
    let hard = t.path().join("copy.bsdf");
    fs::hard_link(&table, &hard).unwrap();
    assert!(write_file(&hard, b"new", &[&table]).is_err());
    let dotted = t.path().join("x/../film.bsdf");
    assert!(write_file(&dotted, b"new", &[&table]).is_err());
    assert_eq!(fs::read(&table).unwrap(), b"measured");
    write_file(&t.path().join("out.bsdf"), b"new", &[&table]).unwrap();
}
