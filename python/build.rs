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

fn main() {
    let (scenes, packaged) = (Path::new("../scenes"), Path::new("blutrace/_scenes"));
    println!("cargo::rerun-if-changed=../scenes");
    if !scenes.is_dir() {
        // An sdist unpacked elsewhere: it carries blutrace/_scenes itself.
        return;
    }
    let _ = fs::remove_dir_all(packaged);
    copy_tree(scenes, packaged).expect("copying ../scenes into blutrace/_scenes");
}
