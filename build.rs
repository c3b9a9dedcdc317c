//! Bakes the default folder of the run-time loaded Embree library into the binary:
//! `<crate>/third_party/embree/lib`, where `tools/fetch-embree.sh` puts it. Nothing is
//! linked at build time; `src/accel/embree/` loads the library when asked for it.

fn main() {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let dir = std::path::Path::new(&manifest).join("third_party/embree/lib");
    println!(
        "cargo:rustc-env=BLUTRACE_EMBREE_DEFAULT_DIR={}",
        dir.display()
    );
    println!("cargo:rerun-if-changed=build.rs");
}
