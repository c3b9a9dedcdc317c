//! `cargo run -p scenegen --release -- [OUT_DIR]`: regenerate every bundled scene (default
//! folder `scenes`, relative to the current directory). Existing files are overwritten;
//! nothing is deleted.

use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let mut args = std::env::args_os().skip(1);
    let out = args
        .next()
        .map(PathBuf::from)
        .unwrap_or_else(|| "scenes".into());
    if args.next().is_some() || out.to_str().is_some_and(|s| s.starts_with('-')) {
        eprintln!("usage: scenegen [OUT_DIR]   (default: scenes)");
        return ExitCode::FAILURE;
    }
    match scenegen::write_all(&out) {
        Ok(files) => {
            for f in &files {
                println!("{} ({} bytes)", out.join(&f.path).display(), f.bytes.len());
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("scenegen: cannot write to {}: {e}", out.display());
            ExitCode::FAILURE
        }
    }
}
