//! Bakes the default folder of the run-time loaded Embree library into the library:
//! `<workspace>/third_party/embree/lib`, where `tools/fetch-embree.sh` puts it (this crate
//! is `<workspace>/crates/blutrace`). Nothing is linked at build time;
//! `src/accel/embree/` loads the library when asked for it.

fn main() {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let crate_dir = std::path::Path::new(&manifest);
    let workspace = crate_dir.ancestors().nth(2).unwrap_or(crate_dir);
    let dir = workspace.join("third_party/embree/lib");
    println!(
        "cargo:rustc-env=BLUTRACE_EMBREE_DEFAULT_DIR={}",
        dir.display()
    );
    println!("cargo:rerun-if-changed=build.rs");
}
