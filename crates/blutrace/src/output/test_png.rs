//! Test helpers shared by the PNG writers' tests: a temporary file path and a decoder.

use std::fs::File;
use std::path::{Path, PathBuf};

/// A path (not yet a file) in a fresh temporary folder, removed on drop.
pub(crate) struct TempFile(pub(crate) PathBuf, #[allow(dead_code)] tempfile::TempDir);

impl TempFile {
    pub(crate) fn new(tag: &str) -> Self {
        let dir = tempfile::Builder::new()
            .prefix(&format!("blutrace-png-{tag}-"))
            .tempdir()
            .unwrap();
        Self(dir.path().join("file.png"), dir)
    }
}

/// Decode an 8-bit RGB PNG: `(width, height, pixels)`.
pub(crate) fn decode(path: &Path) -> (u32, u32, Vec<u8>) {
    let file = std::io::BufReader::new(File::open(path).unwrap());
    let mut reader = ::png::Decoder::new(file).read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, ::png::ColorType::Rgb);
    assert_eq!(info.bit_depth, ::png::BitDepth::Eight);
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

/// Where a visual-check test (`#[ignore]`, run by hand) writes a picture to look at:
/// `$BLUTRACE_PREVIEW_DIR/name`, or the temporary folder when that is not set.
pub(crate) fn preview_path(name: &str) -> PathBuf {
    std::env::var_os("BLUTRACE_PREVIEW_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(std::env::temp_dir)
        .join(name)
}
