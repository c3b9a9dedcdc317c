//! Copies the repository's bundled scenes (`../scenes`) into the Python package
//! (`blutrace/_scenes`, not in git) before maturin packs the wheel, so
//! `blutrace.scenes.path(name)` finds them in an installed package. Maturin collects the
//! package's files after this crate is built.

use std::fs;
use std::io;
use std::path::Path;

fn copy_tree(from: &Path, to: &Path) -> io::Result<()> {
    fs::create_dir_all(to)?;
    for entry in fs::read_dir(from)? {
        let entry = entry?;
        let (src, dst) = (entry.path(), to.join(entry.file_name()));
        if entry.file_type()?.is_dir() {
            copy_tree(&src, &dst)?;
        } else {
            fs::copy(&src, &dst)?;
        }
    }
    Ok(())
}

/// Marks a finished copy. Dated in the past, so it never looks newer than this script's
/// last run (which would rerun it every build); a copy removed reruns it (it is missing).
const STAMP: &str = "blutrace/_scenes/.copied";

fn main() {
    let (scenes, packaged) = (Path::new("../scenes"), Path::new("blutrace/_scenes"));
    println!("cargo::rerun-if-changed=../scenes");
    println!("cargo::rerun-if-changed={STAMP}");
    if !scenes.is_dir() {
        // An sdist unpacked elsewhere: it carries blutrace/_scenes itself.
        return;
    }
    let _ = fs::remove_dir_all(packaged);
    copy_tree(scenes, packaged).expect("copying ../scenes into blutrace/_scenes");
    let stamp = fs::File::create(STAMP).expect("writing blutrace/_scenes/.copied");
    stamp
        .set_modified(std::time::UNIX_EPOCH + std::time::Duration::from_secs(86_400))
        .expect("dating blutrace/_scenes/.copied");
}
