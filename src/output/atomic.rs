//! All-or-nothing output: stage files under temporary names, then rename them into place.
//!
//! A [`StagedDir`] hands out temporary paths inside the target directory (hidden names of
//! the form `.NAME.tmp-PID-N`), so the final rename is within one file system and therefore
//! atomic per file. [`StagedDir::commit`] fsyncs every staged file before renaming any of
//! them; dropping a `StagedDir` without committing (an error, a panic, Ctrl-C unwinding)
//! deletes the temporary files, so a failed run leaves neither half-written nor partial
//! output files behind. A whole folder (written by its own `StagedDir`, say) can be staged
//! the same way with [`StagedDir::stage_dir`].

use std::fs::{self, OpenOptions};
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use anyhow::{Context, Result, bail};

/// Distinguishes temporary names of several `StagedDir`s alive in the same process.
static STAGE_COUNTER: AtomicU64 = AtomicU64::new(0);

/// One file staged for commit.
#[derive(Debug)]
struct Staged {
    /// The name the caller asked for.
    name: String,
    /// Where the writer writes.
    temp: PathBuf,
    /// Where the file ends up after [`StagedDir::commit`].
    dest: PathBuf,
    /// Already renamed to `dest` (so `Drop` must not touch it).
    renamed: bool,
    /// A folder (from [`StagedDir::stage_dir`]) rather than a file.
    is_dir: bool,
}

/// A set of output files written under temporary names inside one directory and moved to
/// their final names together by [`commit`](StagedDir::commit).
///
/// ```no_run
/// # fn main() -> anyhow::Result<()> {
/// use blutrace::output::atomic::StagedDir;
/// let mut out = StagedDir::new(std::path::Path::new("results"))?;
/// out.write_bytes("summary.json", b"{}")?;
/// let image = out.stage_path("map.png"); // hand this path to a writer
/// # std::fs::write(&image, b"")?;
/// let written = out.commit()?; // results/summary.json, results/map.png
/// # let _ = written;
/// # Ok(())
/// # }
/// ```
#[derive(Debug)]
pub struct StagedDir {
    dir: PathBuf,
    staged: Vec<Staged>,
    /// Problems found by [`stage_path`](Self::stage_path) (which cannot fail), reported by
    /// [`commit`](Self::commit).
    errors: Vec<String>,
}

impl StagedDir {
    /// Prepare to write files into `dir`, creating it (and its parents) if needed, and
    /// remove the temporaries that killed runs left there (see [`remove_stale`]).
    pub fn new(dir: &Path) -> Result<Self> {
        fs::create_dir_all(dir)
            .with_context(|| format!("cannot create output directory {}", dir.display()))?;
        remove_stale(dir);
        Ok(Self {
            dir: dir.to_path_buf(),
            staged: Vec::new(),
            errors: Vec::new(),
        })
    }

    /// The target directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Reserve the output file `name` (a plain file name, no directory part) and return the
    /// temporary path inside the target directory that a writer should write it to.
    ///
    /// Staging the same name twice returns the same temporary path. An invalid name (empty,
    /// `.`/`..`, or containing a path separator) still yields a usable temporary path, but
    /// [`commit`](Self::commit) then fails and nothing is renamed.
    pub fn stage_path(&mut self, name: &str) -> PathBuf {
        self.stage(name, false)
    }

    /// Reserve the output folder `name` (a plain name, like [`stage_path`](Self::stage_path)'s)
    /// and return the temporary path a writer should create it at; [`commit`](Self::commit)
    /// replaces an existing folder of that name with it.
    pub fn stage_dir(&mut self, name: &str) -> PathBuf {
        let temp = self.stage(name, true);
        // A stale folder of the same temporary name must not leak into the output.
        let _ = fs::remove_dir_all(&temp);
        temp
    }

    /// Reserve `name` as a file or a folder.
    fn stage(&mut self, name: &str, is_dir: bool) -> PathBuf {
        if let Some(existing) = self.staged.iter().find(|s| s.name == name) {
            return existing.temp.clone();
        }
        let valid = is_plain_file_name(name);
        if !valid {
            self.errors.push(format!(
                "invalid output file name {name:?}: must be a plain file name without directories"
            ));
        }
        let stem = if valid { name } else { "invalid-name" };
        let n = STAGE_COUNTER.fetch_add(1, Ordering::Relaxed);
        let temp = self
            .dir
            .join(format!(".{stem}.tmp-{}-{n}", std::process::id()));
        let dest = self.dir.join(if valid { name } else { stem });
        self.staged.push(Staged {
            name: name.to_owned(),
            temp: temp.clone(),
            dest,
            renamed: false,
            is_dir,
        });
        temp
    }

    /// Stage `name` and write `bytes` to its temporary path.
    pub fn write_bytes(&mut self, name: &str, bytes: &[u8]) -> Result<()> {
        let temp = self.stage_path(name);
        fs::write(&temp, bytes)
            .with_context(|| format!("cannot write {} (staged as {})", name, temp.display()))
    }

    /// Move every staged file to its final name and return the final paths, in staging
    /// order.
    ///
    /// First every staged file is flushed to disk (`fsync`); if any is missing or cannot be
    /// synced, nothing is renamed and all temporary files are removed. Then the files are
    /// renamed one by one (replacing existing files of the same name) and the directory
    /// itself is synced. Should a rename fail midway, the files renamed so far stay and the
    /// remaining temporary files are removed.
    pub fn commit(mut self) -> Result<Vec<PathBuf>> {
        if !self.errors.is_empty() {
            bail!("{}", self.errors.join("; "));
        }
        for s in &self.staged {
            if s.is_dir {
                if !s.temp.is_dir() {
                    bail!(
                        "staged output folder {} was never written ({})",
                        s.name,
                        s.temp.display()
                    );
                }
                continue;
            }
            let file = OpenOptions::new()
                .write(true)
                .open(&s.temp)
                .with_context(|| {
                    format!(
                        "staged output {} was never written ({})",
                        s.name,
                        s.temp.display()
                    )
                })?;
            file.sync_all()
                .with_context(|| format!("cannot sync {}", s.temp.display()))?;
        }
        for s in &mut self.staged {
            if s.is_dir && s.dest.is_dir() {
                fs::remove_dir_all(&s.dest)
                    .with_context(|| format!("cannot replace {}", s.dest.display()))?;
            }
            fs::rename(&s.temp, &s.dest).with_context(|| {
                format!("cannot rename {} to {}", s.temp.display(), s.dest.display())
            })?;
            s.renamed = true;
        }
        sync_dir(&self.dir);
        Ok(self.staged.iter().map(|s| s.dest.clone()).collect())
    }
}

impl Drop for StagedDir {
    /// Remove the temporary files of everything not committed.
    fn drop(&mut self) {
        for s in self.staged.iter().filter(|s| !s.renamed) {
            // The file may never have been created: ignore errors.
            if s.is_dir {
                let _ = fs::remove_dir_all(&s.temp);
            } else {
                let _ = fs::remove_file(&s.temp);
            }
        }
    }
}

/// `name` is a single normal path component.
/// Remove the temporaries (`.NAME.tmp-PID-N`) in `dir` whose process is gone: what a run
/// killed while writing (SIGKILL, power loss) left behind, which no `Drop` could delete.
/// A live process's temporaries are left alone (Linux: `/proc/PID` exists; elsewhere only
/// this process's own are known to be alive, so nothing of another PID is kept). Runs on
/// other machines writing into the same shared folder at the same time cannot be seen:
/// give every run (every shard) its own output folder, as `trace --shard` usage does.
pub fn remove_stale(dir: &Path) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    let me = std::process::id();
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(pid) = stale_pid(&name) else {
            continue;
        };
        let alive = pid == me || Path::new(&format!("/proc/{pid}")).exists();
        if !alive {
            let p = e.path();
            let _ = fs::remove_dir_all(&p).or_else(|_| fs::remove_file(&p));
        }
    }
}

/// The PID in a temporary name `.NAME.tmp-PID-N`, if `name` is one.
fn stale_pid(name: &str) -> Option<u32> {
    let rest = name.strip_prefix('.')?;
    let (_, tail) = rest.rsplit_once(".tmp-")?;
    let (pid, n) = tail.split_once('-')?;
    n.parse::<u64>().ok()?;
    pid.parse().ok()
}

fn is_plain_file_name(name: &str) -> bool {
    let mut components = Path::new(name).components();
    matches!((components.next(), components.next()), (Some(Component::Normal(c)), None) if c == name)
}

/// Make the renames durable. Best effort: not every platform can open a directory for sync.
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = fs::File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh empty directory under the system temp dir, removed on drop.
    struct TestDir(PathBuf);

    impl TestDir {
        fn new(tag: &str) -> Self {
            let n = STAGE_COUNTER.fetch_add(1, Ordering::Relaxed);
            let p = std::env::temp_dir()
                .join(format!("blutrace-atomic-{tag}-{}-{n}", std::process::id()));
            let _ = fs::remove_dir_all(&p);
            Self(p)
        }

        fn listing(&self) -> Vec<String> {
            let mut v: Vec<String> = fs::read_dir(&self.0)
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            v.sort();
            v
        }
    }

    impl Drop for TestDir {
        fn drop(&mut self) {
            let _ = fs::remove_dir_all(&self.0);
        }
    }

    #[test]
    fn drop_without_commit_leaves_nothing() {
        let t = TestDir::new("drop");
        {
            let mut s = StagedDir::new(&t.0.join("sub")).unwrap();
            s.write_bytes("a.json", b"{}").unwrap();
            let p = s.stage_path("b.png");
            assert_eq!(p.parent(), Some(t.0.join("sub").as_path()));
            fs::write(&p, b"partial").unwrap();
            let _never_written = s.stage_path("c.exr");
            assert_eq!(fs::read_dir(t.0.join("sub")).unwrap().count(), 2);
        }
        assert_eq!(fs::read_dir(t.0.join("sub")).unwrap().count(), 0);
    }

    #[test]
    fn commit_leaves_exactly_the_final_files() {
        let t = TestDir::new("commit");
        fs::create_dir_all(&t.0).unwrap();
        fs::write(t.0.join("a.json"), b"old").unwrap();
        let mut s = StagedDir::new(&t.0).unwrap();
        s.write_bytes("a.json", b"new").unwrap();
        let p = s.stage_path("b.bin");
        assert!(
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with(".b.bin.tmp-")
        );
        fs::write(&p, [1u8, 2, 3]).unwrap();
        assert_eq!(s.stage_path("b.bin"), p, "restaging returns the same path");
        let done = s.commit().unwrap();
        assert_eq!(done, vec![t.0.join("a.json"), t.0.join("b.bin")]);
        assert_eq!(t.listing(), vec!["a.json", "b.bin"]);
        assert_eq!(fs::read(t.0.join("a.json")).unwrap(), b"new");
        assert_eq!(fs::read(t.0.join("b.bin")).unwrap(), [1, 2, 3]);
    }

    #[test]
    fn commit_fails_cleanly_when_a_file_was_never_written() {
        let t = TestDir::new("missing");
        let mut s = StagedDir::new(&t.0).unwrap();
        s.write_bytes("a.json", b"{}").unwrap();
        let _ = s.stage_path("never.png");
        let err = s.commit().unwrap_err();
        assert!(format!("{err:#}").contains("never.png"), "{err:#}");
        assert!(t.listing().is_empty(), "{:?}", t.listing());
    }

    #[test]
    fn staged_folders_replace_old_ones_or_vanish() {
        let t = TestDir::new("dirs");
        fs::create_dir_all(t.0.join("run")).unwrap();
        fs::write(t.0.join("run").join("old.txt"), b"old").unwrap();
        let mut s = StagedDir::new(&t.0).unwrap();
        s.write_bytes("a.json", b"{}").unwrap();
        let run = s.stage_dir("run");
        let mut inner = StagedDir::new(&run).unwrap();
        inner.write_bytes("new.txt", b"new").unwrap();
        inner.commit().unwrap();
        let done = s.commit().unwrap();
        assert_eq!(done, vec![t.0.join("a.json"), t.0.join("run")]);
        assert_eq!(t.listing(), vec!["a.json", "run"]);
        let run_listing: Vec<_> = fs::read_dir(t.0.join("run")).unwrap().collect();
        assert_eq!(run_listing.len(), 1);
        assert_eq!(fs::read(t.0.join("run").join("new.txt")).unwrap(), b"new");

        let mut s = StagedDir::new(&t.0).unwrap();
        let never = s.stage_dir("never");
        assert!(s.commit().is_err(), "a folder never written is an error");
        assert!(!never.exists());
        {
            let mut s = StagedDir::new(&t.0).unwrap();
            let dropped = s.stage_dir("dropped");
            fs::create_dir_all(dropped.join("sub")).unwrap();
        }
        assert_eq!(t.listing(), vec!["a.json", "run"]);
    }

    #[test]
    fn invalid_names_are_rejected_at_commit() {
        let t = TestDir::new("invalid");
        for bad in ["", "..", ".", "x/y", "/abs"] {
            let mut s = StagedDir::new(&t.0).unwrap();
            s.write_bytes("ok.txt", b"1").unwrap();
            let p = s.stage_path(bad);
            assert_eq!(p.parent(), Some(t.0.as_path()));
            fs::write(&p, b"2").unwrap();
            assert!(s.commit().is_err(), "{bad:?} accepted");
            assert!(t.listing().is_empty(), "{bad:?}: {:?}", t.listing());
        }
    }

    #[test]
    fn temporaries_of_dead_runs_are_removed_and_live_ones_kept() {
        let t = TestDir::new("stale");
        fs::create_dir_all(&t.0).unwrap();
        // PID 2^31 - 1 is above Linux's pid_max: never a live process.
        let dead = t.0.join(".flux.exr.tmp-2147483647-3");
        let dead_dir = t.0.join(".final.tmp-2147483647-4");
        let mine =
            t.0.join(format!(".summary.json.tmp-{}-9", std::process::id()));
        let other = t.0.join(".notes.tmp-x-1");
        fs::write(&dead, b"half").unwrap();
        fs::create_dir(&dead_dir).unwrap();
        fs::write(dead_dir.join("a"), b"x").unwrap();
        fs::write(&mine, b"in progress").unwrap();
        fs::write(&other, b"not ours").unwrap();
        let _s = StagedDir::new(&t.0).unwrap();
        assert!(!dead.exists() && !dead_dir.exists());
        assert!(mine.exists() && other.exists());
        assert_eq!(stale_pid(".flux.exr.tmp-12-0"), Some(12));
        assert_eq!(stale_pid("flux.exr"), None);
    }
}
