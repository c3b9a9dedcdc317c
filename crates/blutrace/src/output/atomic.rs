//! All-or-nothing output sets: every file of a run is written into a hidden staging folder
//! next to the output folder, which then replaces the previous folder in one step.
//!
//! [`OutputSet::new`]`(dest)` creates `PARENT/.NAME.tmp-PID-N` beside `dest = PARENT/NAME`;
//! writers write plain names inside it ([`SetDir::write_with`], [`SetDir::write_bytes`],
//! subfolders through [`SetDir::subdir`]). [`OutputSet::commit`] syncs every file to disk,
//! writes the manifest [`MANIFEST`] (the set's entries) last, and swaps the staging folder
//! with `dest`:
//! - on Linux, `renameat2(RENAME_EXCHANGE)` exchanges the two folders in one system call,
//!   so at every instant `dest` holds the complete old set or the complete new set; the
//!   old set, now under the staging name, is then removed;
//! - where the exchange is not supported (NFS, other systems), `dest` is renamed aside to
//!   `PARENT/.NAME.old-PID-N` and the staging folder renamed into its place. A kill
//!   between these two renames leaves no `dest`: the next `OutputSet::new` for that
//!   folder renames the aside folder back, so the old set returns.
//!
//! Staging and aside folders of killed runs (whose PID is no longer alive) are removed by
//! the next run into the same folder; dropping an uncommitted set (an error, a panic)
//! removes its staging folder at once. Errors name the final path (`out/x/flux.exr`), never
//! the staging path.
//!
//! The set replaces the whole folder, so `dest` must not be or hold a file the run read
//! (its scene, meshes, tables: [`check_apart`]), and must be new, empty, or hold only what
//! blutrace wrote there: the entries its manifest names, or (folders written before
//! manifests existed) names the command itself writes. Anything else is refused with an
//! error naming it, before tracing when the command calls [`check_dest`] first, and never
//! deleted.
//!
//! Test hooks, for `tests/output_sets.rs` and not meant for users: with
//! `BLUTRACE_TEST_OUTPUT_PAUSE=STEP` set, a set prints `blutrace-test-hook: STEP` on stderr
//! at every step (`wrote NAME` after each file, `swap`, `aside` between the two renames,
//! `swapped`) and stops for a minute at the step named, so that a test can kill the process
//! exactly there; `BLUTRACE_TEST_OUTPUT_SWAP=two-step` forces the two-rename swap.
//!
//! ```no_run
//! # fn main() -> anyhow::Result<()> {
//! use blutrace::output::atomic::OutputSet;
//! let reads: [&std::path::Path; 0] = []; // the files the run read
//! let out = OutputSet::new(std::path::Path::new("results"), &["summary.json", "map.png"], &reads)?;
//! out.write_bytes("summary.json", b"{}")?;
//! out.write_with("map.png", |path| Ok(std::fs::write(path, b"")?))?;
//! let written = out.commit()?; // results/map.png, results/summary.json
//! # let _ = written;
//! # Ok(())
//! # }
//! ```

use std::fs;
use std::io;
use std::ops::Deref;
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use anyhow::{Context, Result, bail};

/// The manifest every output folder gets, written last: `{"software", "entries"}`.
pub const MANIFEST: &str = ".blutrace-outputs.json";

/// Distinguishes the staging folders of several sets alive in the same process.
static STAGE_COUNTER: AtomicU64 = AtomicU64::new(0);

/// A folder of an output set being written: files go to the staging folder, errors and
/// returned paths name where they end up.
#[derive(Debug, Clone)]
pub struct SetDir {
    /// Where writers write.
    staging: PathBuf,
    /// Where the files end up (as the user gave it), for messages and returned paths.
    shown: PathBuf,
}

impl SetDir {
    /// Write the file `name` (a plain file name) with `write`, which is handed the path to
    /// write to; returns the file's final path. Errors of `write` name the final path.
    pub fn write_with(
        &self,
        name: &str,
        write: impl FnOnce(&Path) -> Result<()>,
    ) -> Result<PathBuf> {
        let shown = self.shown.join(name);
        check_name(name, &shown)?;
        let temp = self.staging.join(name);
        write(&temp).map_err(|e| self.final_names(&e))?;
        if !temp.exists() {
            bail!("{}: the writer wrote nothing", shown.display());
        }
        test_hook(&format!("wrote {name}"));
        Ok(shown)
    }

    /// Write `bytes` as the file `name`.
    pub fn write_bytes(&self, name: &str, bytes: &[u8]) -> Result<PathBuf> {
        self.write_with(name, |p| {
            fs::write(p, bytes).with_context(|| format!("cannot write {}", p.display()))
        })
    }

    /// Create the subfolder `name` and return it, to be written like this one.
    pub fn subdir(&self, name: &str) -> Result<SetDir> {
        let shown = self.shown.join(name);
        check_name(name, &shown)?;
        let staging = self.staging.join(name);
        fs::create_dir(&staging)
            .with_context(|| format!("cannot create output folder {}", shown.display()))?;
        Ok(SetDir { staging, shown })
    }

    /// `e`'s message with the staging folder replaced by the final one.
    fn final_names(&self, e: &anyhow::Error) -> anyhow::Error {
        let staging = self.staging.display().to_string();
        let shown = self.shown.display().to_string();
        anyhow::anyhow!("{}", format!("{e:#}").replace(&staging, &shown))
    }
}

/// The output set of one run: a [`SetDir`] staged beside its destination folder, moved into
/// place by [`commit`](Self::commit).
#[derive(Debug)]
pub struct OutputSet {
    root: SetDir,
    /// The destination folder, absolute (a symbolic link resolved).
    dest: PathBuf,
    /// Names the command may write, accepted in a folder without a manifest.
    may_write: Vec<String>,
    /// The files the run read, which the set must not replace.
    reads: Vec<PathBuf>,
    /// Moved into place (so `Drop` must not remove the staging folder).
    committed: bool,
}

impl Deref for OutputSet {
    type Target = SetDir;
    fn deref(&self) -> &SetDir {
        &self.root
    }
}

impl OutputSet {
    /// Start a set that will replace the folder `dest`. `may_write` lists the names the
    /// command can write (for [`check_dest`]); `reads` the files the run read, which
    /// `dest` must not be or hold ([`check_apart`]). Restores or removes what killed runs
    /// left (see the module documentation), checks `dest` and creates the staging folder.
    pub fn new<P: AsRef<Path>>(dest: &Path, may_write: &[&str], reads: &[P]) -> Result<Self> {
        let reads: Vec<PathBuf> = reads.iter().map(|p| p.as_ref().to_path_buf()).collect();
        check_apart(dest, &reads)?;
        let (parent, name) = split_dest(dest)?;
        recover(&parent, &name, dest);
        check_dest(dest, may_write, &reads)?;
        let abs = parent.join(&name);
        let n = STAGE_COUNTER.fetch_add(1, Ordering::Relaxed);
        let staging = parent.join(temp_name(&name, "tmp", std::process::id(), n));
        fs::create_dir(&staging)
            .with_context(|| format!("cannot create output folder {}", dest.display()))?;
        Ok(Self {
            root: SetDir {
                staging,
                shown: dest.to_path_buf(),
            },
            dest: abs,
            may_write: may_write.iter().map(|s| s.to_string()).collect(),
            reads,
            committed: false,
        })
    }

    /// Sync every file, write the manifest and replace the destination folder with the set;
    /// returns the final paths of the set's entries (files and subfolders), sorted.
    pub fn commit(mut self) -> Result<Vec<PathBuf>> {
        let shown = self.root.shown.clone();
        let entries = entry_names(&self.root.staging)?;
        // A folder changed by someone else since the run began is refused too.
        let names: Vec<&str> = self.may_write.iter().map(String::as_str).collect();
        check_dest(&shown, &names, &self.reads)?;
        let manifest = serde_json::json!({
            "software": format!("blutrace {}", env!("CARGO_PKG_VERSION")),
            "entries": entries,
        });
        let staging = self.root.staging.clone();
        fs::write(
            staging.join(MANIFEST),
            serde_json::to_vec_pretty(&manifest)?,
        )
        .with_context(|| format!("cannot write {}", shown.join(MANIFEST).display()))?;
        sync_tree(&staging)
            .map_err(|e| anyhow::anyhow!("cannot sync the outputs in {}: {e}", shown.display()))?;
        test_hook("swap");
        let two_step = std::env::var("BLUTRACE_TEST_OUTPUT_SWAP").as_deref() == Ok("two-step");
        let old = swap_into_place(&staging, &self.dest, two_step)
            .with_context(|| format!("cannot move the new outputs into {}", shown.display()))?;
        self.committed = true;
        if let Some(parent) = self.dest.parent() {
            sync_dir(parent);
        }
        test_hook("swapped");
        if let Some(old) = old {
            // The previous set: blutrace's own files only (check_dest refused anything else).
            let _ = fs::remove_dir_all(old);
        }
        Ok(entries.iter().map(|e| shown.join(e)).collect())
    }
}

impl Drop for OutputSet {
    /// Remove the staging folder of a set never committed.
    fn drop(&mut self) {
        if !self.committed {
            let _ = fs::remove_dir_all(&self.root.staging);
        }
    }
}

/// Write one file whole or not at all: `bytes` go to a hidden temporary file beside `path`
/// (`.NAME.tmp-PID`), synced, then renamed over `path` in one step; on an error the
/// temporary is removed and `path` is as it was. `path` must not be one of `reads`, the
/// files the run read ([`check_apart`]). Errors name `path`.
pub fn write_file<P: AsRef<Path>>(path: &Path, bytes: &[u8], reads: &[P]) -> Result<()> {
    check_apart(path, reads)?;
    let name = path
        .file_name()
        .with_context(|| format!("{}: not a file name", path.display()))?;
    let temp = path.with_file_name(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let written = (|| -> io::Result<()> {
        let mut f = fs::File::create(&temp)?;
        io::Write::write_all(&mut f, bytes)?;
        f.sync_all()?;
        fs::rename(&temp, path)
    })();
    if let Err(e) = written {
        let _ = fs::remove_file(&temp);
        bail!("cannot write {}: {e}", path.display());
    }
    Ok(())
}

/// Refuse an output folder the set could not replace without losing something: one that
/// is or holds a file the run read (`reads`, see [`check_apart`]), a file that is not a
/// folder, a folder holding entries blutrace did not write (neither named by its manifest
/// nor in `may_write` nor a blutrace temporary), the current directory, or a mount point.
/// A folder that does not exist yet is fine.
pub fn check_dest<P: AsRef<Path>>(dest: &Path, may_write: &[&str], reads: &[P]) -> Result<()> {
    check_apart(dest, reads)?;
    let shown = dest.display();
    let meta = match fs::metadata(dest) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => bail!("{shown}: cannot read the output folder: {e}"),
        Ok(m) => m,
    };
    if !meta.is_dir() {
        bail!("{shown}: exists and is not a folder; choose a folder for the outputs");
    }
    let real = fs::canonicalize(dest).with_context(|| format!("{shown}: cannot resolve"))?;
    if std::env::current_dir().and_then(fs::canonicalize).ok() == Some(real.clone()) {
        bail!(
            "{shown}: is the current directory, which the new output set would replace; choose a folder inside it"
        );
    }
    if is_mount_point(&real) {
        bail!("{shown}: is a mount point, which cannot be replaced; choose a folder inside it");
    }
    let mut ours: Vec<String> = may_write.iter().map(|s| s.to_string()).collect();
    ours.extend(manifest_entries(&real));
    let mut foreign: Vec<String> = Vec::new();
    for e in fs::read_dir(&real).with_context(|| format!("{shown}: cannot list"))? {
        let n = e?.file_name().to_string_lossy().into_owned();
        // A name like a staging folder's is foreign too: staging folders live beside the
        // output folder, never in it, so such an entry is someone's file.
        if n != MANIFEST && !ours.contains(&n) {
            foreign.push(n);
        }
    }
    if !foreign.is_empty() {
        foreign.sort();
        let more = if foreign.len() > 5 { ", ..." } else { "" };
        foreign.truncate(5);
        bail!(
            "{shown}: holds {} that blutrace did not write; a run replaces the whole output folder, so move them or choose a new output folder",
            foreign.join(", ") + more
        );
    }
    Ok(())
}

/// Refuse an output (a folder, or a file) that is, or holds, one of a command's `inputs`
/// (the files a scene reads, the shards of a merge): writing the outputs would replace
/// the output and so delete the input. Paths are compared resolved (symbolic links,
/// `..`), a path that does not exist yet by its nearest existing ancestor; a hard link
/// to an input is the input too.
pub fn check_apart<P: AsRef<Path>>(dest: &Path, inputs: &[P]) -> Result<()> {
    let out = resolved(dest);
    let out_id = file_id(&out);
    for input in inputs.iter().map(AsRef::as_ref) {
        let real = resolved(input);
        if real.starts_with(&out) || (out_id.is_some() && file_id(&real) == out_id) {
            bail!(
                "{}: is or holds {}, an input of this run, which writing the outputs there would delete or replace; choose another output path",
                dest.display(),
                input.display()
            );
        }
    }
    Ok(())
}

/// The device and inode of the file at `p`, if it exists (a hard link shares them).
fn file_id(p: &Path) -> Option<(u64, u64)> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        fs::metadata(p).ok().map(|m| (m.dev(), m.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = p;
        None
    }
}

/// `p` made absolute with every existing part resolved (the rest appended as written).
fn resolved(p: &Path) -> PathBuf {
    let abs = std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let mut missing = Vec::new();
    let mut at = abs.as_path();
    loop {
        if let Ok(real) = fs::canonicalize(at) {
            return missing.iter().rev().fold(real, |acc, part| acc.join(part));
        }
        match (at.parent(), at.file_name()) {
            (Some(parent), Some(name)) => {
                missing.push(name.to_owned());
                at = parent;
            }
            _ => return abs,
        }
    }
}

/// The entries named by `dir`'s manifest (none without one).
fn manifest_entries(dir: &Path) -> Vec<String> {
    let Ok(text) = fs::read_to_string(dir.join(MANIFEST)) else {
        return Vec::new();
    };
    let v: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
    v["entries"]
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(|e| e.as_str().map(str::to_owned))
                .collect()
        })
        .unwrap_or_default()
}

/// `dest`'s parent folder (absolute, created if needed, symbolic links resolved) and name.
fn split_dest(dest: &Path) -> Result<(PathBuf, String)> {
    let resolved = match fs::canonicalize(dest) {
        Ok(p) => p,
        Err(_) => {
            let name = dest
                .file_name()
                .with_context(|| format!("{}: not a folder name", dest.display()))?;
            let parent = match dest.parent() {
                Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
                _ => PathBuf::from("."),
            };
            fs::create_dir_all(&parent)
                .with_context(|| format!("cannot create output folder {}", parent.display()))?;
            fs::canonicalize(&parent)
                .with_context(|| format!("cannot resolve {}", parent.display()))?
                .join(name)
        }
    };
    match (resolved.parent(), resolved.file_name()) {
        (Some(p), Some(n)) => Ok((p.to_path_buf(), n.to_string_lossy().into_owned())),
        _ => bail!("{}: cannot be an output folder", dest.display()),
    }
}

/// Undo or clean up what killed runs into `PARENT/NAME` left: an aside folder (the old set
/// of a two-rename swap) goes back into place when `NAME` is missing, and is removed
/// otherwise; staging folders are removed. Only temporaries of dead processes are touched.
/// Best effort: a failure here shows up as an error when the set is written.
fn recover(parent: &Path, name: &str, shown: &Path) {
    let Ok(list) = fs::read_dir(parent) else {
        return;
    };
    let dest = parent.join(name);
    let mut stale: Vec<(String, PathBuf)> = Vec::new();
    for e in list.flatten() {
        let entry = e.file_name().to_string_lossy().into_owned();
        if let Some((of, kind, pid)) = parse_temp(&entry)
            && of == name
            && !is_alive(pid)
        {
            stale.push((kind.to_owned(), e.path()));
        }
    }
    // Restore first, so that the old set is back before anything is removed.
    stale.sort_by_key(|(kind, _)| kind != "old");
    for (kind, path) in stale {
        if kind == "old" && !dest.exists() {
            if fs::rename(&path, &dest).is_ok() {
                eprintln!(
                    "note: restored the previous outputs of {} that a killed run had moved aside",
                    shown.display()
                );
            }
            continue;
        }
        let _ = fs::remove_dir_all(&path).or_else(|_| fs::remove_file(&path));
    }
}

/// Move `staging` to `dest`, replacing what is there, by an exchange or (`two_step`, or
/// when the exchange is not supported) two renames; returns where the previous folder went
/// (to be removed), if there was one.
fn swap_into_place(staging: &Path, dest: &Path, two_step: bool) -> io::Result<Option<PathBuf>> {
    if fs::symlink_metadata(dest).is_err() && rename_to_new(staging, dest)? {
        return Ok(None);
    }
    if !two_step && exchange(staging, dest)? {
        return Ok(Some(staging.to_path_buf()));
    }
    let name = dest
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let n = STAGE_COUNTER.fetch_add(1, Ordering::Relaxed);
    let aside = dest.with_file_name(temp_name(&name, "old", std::process::id(), n));
    fs::rename(dest, &aside)?;
    test_hook("aside");
    if let Err(e) = fs::rename(staging, dest) {
        let _ = fs::rename(&aside, dest);
        return Err(e);
    }
    Ok(Some(aside))
}

/// Rename `staging` to `dest`, which did not exist a moment ago; `Ok(false)` when another
/// run has created `dest` since (two runs into one new folder): the caller then replaces
/// that set like any previous one, so the last run's complete set is what remains.
fn rename_to_new(staging: &Path, dest: &Path) -> io::Result<bool> {
    match fs::rename(staging, dest) {
        Ok(()) => Ok(true),
        Err(_) if fs::symlink_metadata(dest).is_ok() => Ok(false),
        Err(e) => Err(e),
    }
}

/// Exchange the folders `a` and `b` atomically; `Ok(false)` when the file system or system
/// cannot.
#[cfg(any(target_os = "linux", target_os = "android"))]
fn exchange(a: &Path, b: &Path) -> io::Result<bool> {
    use rustix::fs::{CWD, RenameFlags, renameat_with};
    use rustix::io::Errno;
    match renameat_with(CWD, a, CWD, b, RenameFlags::EXCHANGE) {
        Ok(()) => Ok(true),
        Err(Errno::INVAL | Errno::NOSYS | Errno::OPNOTSUPP | Errno::PERM) => Ok(false),
        Err(e) => Err(e.into()),
    }
}

/// Exchange the folders `a` and `b` atomically; `Ok(false)` when the file system or system
/// cannot.
#[cfg(not(any(target_os = "linux", target_os = "android")))]
fn exchange(_a: &Path, _b: &Path) -> io::Result<bool> {
    Ok(false)
}

/// `.NAME.KIND-PID-N`: the staging (`tmp`) or aside (`old`) folder of `NAME`.
fn temp_name(name: &str, kind: &str, pid: u32, n: u64) -> String {
    format!(".{name}.{kind}-{pid}-{n}")
}

/// The parts `(NAME, KIND, PID)` of a temporary name `.NAME.KIND-PID-N` (also the
/// per-file temporaries of earlier versions, `.FILE.tmp-PID-N`).
fn parse_temp(entry: &str) -> Option<(&str, &str, u32)> {
    let rest = entry.strip_prefix('.')?;
    let (name, tail) = rest.rsplit_once('.')?;
    let (kind, ids) = tail.split_once('-')?;
    if kind != "tmp" && kind != "old" {
        return None;
    }
    let (pid, n) = ids.split_once('-')?;
    n.parse::<u64>().ok()?;
    Some((name, kind, pid.parse().ok()?))
}

/// Linux: `/proc/PID` exists. Elsewhere only this process is known to be alive, so other
/// runs writing into the same folder at the same time are not seen; nor are runs on other
/// machines sharing the folder: give every run (every shard) its own output folder.
fn is_alive(pid: u32) -> bool {
    pid == std::process::id() || Path::new(&format!("/proc/{pid}")).exists()
}

/// The sorted entry names of `dir`.
fn entry_names(dir: &Path) -> Result<Vec<String>> {
    let mut v: Vec<String> = fs::read_dir(dir)?
        .map(|e| Ok(e?.file_name().to_string_lossy().into_owned()))
        .collect::<io::Result<_>>()?;
    v.sort();
    Ok(v)
}

/// Flush every file and folder under `dir` to disk.
fn sync_tree(dir: &Path) -> io::Result<()> {
    for e in fs::read_dir(dir)? {
        let e = e?;
        if e.file_type()?.is_dir() {
            sync_tree(&e.path())?;
        } else {
            fs::File::open(e.path())?.sync_all()?;
        }
    }
    sync_dir(dir);
    Ok(())
}

/// A plain file name: one normal path component.
fn check_name(name: &str, shown: &Path) -> Result<()> {
    let mut c = Path::new(name).components();
    match (c.next(), c.next()) {
        (Some(Component::Normal(n)), None) if n == name && name != MANIFEST => Ok(()),
        _ => bail!(
            "{}: invalid output name {name:?}: must be a plain file name",
            shown.display()
        ),
    }
}

/// `dir` is on another device than its parent.
fn is_mount_point(dir: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let dev = |p: &Path| fs::metadata(p).map(|m| m.dev()).ok();
        match dir.parent() {
            Some(parent) => dev(dir) != dev(parent),
            None => true,
        }
    }
    #[cfg(not(unix))]
    {
        dir.parent().is_none()
    }
}

/// Make renames in `dir` durable. Best effort: not every platform can sync a directory.
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = fs::File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

/// The test hook of the module documentation.
fn test_hook(step: &str) {
    let Ok(pause_at) = std::env::var("BLUTRACE_TEST_OUTPUT_PAUSE") else {
        return;
    };
    eprintln!("blutrace-test-hook: {step}");
    if pause_at == step {
        std::thread::sleep(std::time::Duration::from_secs(60));
    }
}

#[cfg(test)]
#[path = "atomic_tests.rs"]
mod tests;
