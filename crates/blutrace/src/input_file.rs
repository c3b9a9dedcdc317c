//! Reading an input file (scene, geometry, intensity table, shard) safely: only regular
//! files, at most [`MAX_INPUT_BYTES`], so a path that is a FIFO, a device (`/dev/zero`) or
//! a symbolic link to one fails at once with an error naming it, instead of blocking or
//! filling memory.
//!
//! ```toml
//! [[geometry]]
//! file = "guide.obj"   # read through `read_bytes`: a regular file of at most 2 GiB
//! ```

use anyhow::{Context, Result, bail};
use std::io::Read;
use std::path::{Path, PathBuf};

/// Largest input file read (bytes): far above any scene's (a 2.2M-triangle OBJ is about
/// 150 MB), far below this machine class's memory.
pub const MAX_INPUT_BYTES: u64 = 2 << 30;

/// The whole file at `path`, if it is a regular file (symbolic links followed) of at
/// most [`MAX_INPUT_BYTES`]; `what` names it in errors ("cannot read scene file").
pub fn read_bytes(path: &Path, what: &str) -> Result<Vec<u8>> {
    let shown = path.display();
    let meta = std::fs::metadata(path).with_context(|| format!("{shown}: cannot read {what}"))?;
    if !meta.is_file() {
        bail!("{shown}: cannot read {what}: not a regular file");
    }
    if meta.len() > MAX_INPUT_BYTES {
        bail!(
            "{shown}: cannot read {what}: {:.1} GiB, more than the {} GiB an input may hold",
            meta.len() as f64 / (1u64 << 30) as f64,
            MAX_INPUT_BYTES >> 30
        );
    }
    let file = std::fs::File::open(path).with_context(|| format!("{shown}: cannot read {what}"))?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // Bounded again: a file that grows while being read stops at the limit.
    file.take(MAX_INPUT_BYTES + 1)
        .read_to_end(&mut bytes)
        .with_context(|| format!("{shown}: cannot read {what}"))?;
    if bytes.len() as u64 > MAX_INPUT_BYTES {
        bail!(
            "{shown}: cannot read {what}: it grew past {} GiB while read",
            MAX_INPUT_BYTES >> 30
        );
    }
    Ok(bytes)
}

/// [`read_bytes`] as UTF-8 text.
pub fn read_text(path: &Path, what: &str) -> Result<String> {
    String::from_utf8(read_bytes(path, what)?).map_err(|e| {
        anyhow::anyhow!(
            "{}: {what} is not UTF-8 text (byte {})",
            path.display(),
            e.utf8_error().valid_up_to()
        )
    })
}

/// `path` resolved (symbolic links, `..`), if it lies inside `folder` (resolved too):
/// a file a file refers to (a glTF buffer) must not reach outside the folder it sits in.
pub fn inside(folder: &Path, path: &Path) -> Option<PathBuf> {
    let real = std::fs::canonicalize(path).ok()?;
    let root = std::fs::canonicalize(folder).ok()?;
    real.starts_with(&root).then_some(real)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_regular_files_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("a.obj");
        std::fs::write(&file, "v 0 0 0\n").unwrap();
        assert_eq!(read_text(&file, "geometry file").unwrap(), "v 0 0 0\n");
        let err = format!("{:#}", read_bytes(dir.path(), "geometry file").unwrap_err());
        assert!(err.contains("not a regular file"), "{err}");
        let link = dir.path().join("zero.obj");
        std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
        let err = format!("{:#}", read_bytes(&link, "geometry file").unwrap_err());
        assert!(
            err.contains("zero.obj") && err.contains("not a regular file"),
            "{err}"
        );
        let fifo = dir.path().join("fifo.obj");
        assert!(
            std::process::Command::new("mkfifo")
                .arg(&fifo)
                .status()
                .unwrap()
                .success()
        );
        let err = format!("{:#}", read_bytes(&fifo, "geometry file").unwrap_err());
        assert!(err.contains("not a regular file"), "{err}");
    }

    #[test]
    fn inside_refuses_paths_that_leave_the_folder() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("scene")).unwrap();
        std::fs::write(dir.path().join("secret"), "x").unwrap();
        std::fs::write(dir.path().join("scene/part.bin"), "x").unwrap();
        let scene = dir.path().join("scene");
        assert!(inside(&scene, &scene.join("part.bin")).is_some());
        assert!(inside(&scene, &scene.join("../secret")).is_none());
        std::os::unix::fs::symlink("../secret", scene.join("link.bin")).unwrap();
        assert!(inside(&scene, &scene.join("link.bin")).is_none());
    }
}
