//! Encoding an RGB image as a PNG file, with text chunks saying what it shows.
//!
//! The figures of [`super::map`] and [`super::plot`] are drawn into a buffer and written
//! here (rather than by `plotters`' own encoder, which would pull in the `image` crate):
//! 8-bit RGB, the `png` crate's default compression, a `Software` and a `Comment` chunk
//! and nothing that depends on the time or the machine, so the same pixels give the same
//! bytes.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use anyhow::{Context, Result};

/// Encode `rgb` (8-bit RGB, `w × h`, rows from the top) as a PNG file at `path`
/// (overwriting it) with a `Comment` text chunk.
pub(crate) fn encode(path: &Path, w: u32, h: u32, rgb: &[u8], comment: &str) -> Result<()> {
    let file = File::create(path).context("cannot create file")?;
    let mut out = BufWriter::new(file);
    let mut encoder = ::png::Encoder::new(&mut out, w, h);
    encoder.set_color(::png::ColorType::Rgb);
    encoder.set_depth(::png::BitDepth::Eight);
    encoder.add_text_chunk("Software".to_string(), "blutrace".to_string())?;
    encoder.add_text_chunk("Comment".to_string(), comment.to_string())?;
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    out.flush().context("cannot flush file")?;
    Ok(())
}
