//! Plain-text ray sets: one ray per line, `x y z kx ky kz flux` or `x y z kx ky kz flux
//! nm` (blanks or commas between numbers; every line the same number of columns), `#`
//! starts a comment. Positions in the entry's `units` (mm by default), flux in W.
//!
//! ```toml
//! [[sources]]
//! type = "rayfile"
//! file = "two_colours.rays"   # e.g. "0 0 0  0 0 1  0.25  450" and "0 0 0  0 0 1  0.75  650"
//! ```
//!
//! Read in one pass, line by line; an error names the file, the line and the column. At
//! most [`MAX_RAYS`] rays (76,694,548) and lines of at most [`MAX_LINE_BYTES`].

use super::{FileSpectrum, FluxUnit, RaySet, StoredRay, check_ray, checked_len};
use anyhow::{Result, bail};
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

/// Column names, for errors.
const COLUMNS: [&str; 8] = ["x", "y", "z", "kx", "ky", "kz", "flux", "nm"];

/// Most rays a text ray file may hold: as many as the largest TM-25 file read
/// ([`super::tm25::MAX_RAYS`], 2 GiB of 28-byte rays), far above the largest vendor files
/// (20M rays). A text ray takes as little as 14 bytes, so without it a 2 GiB text file
/// could ask for twice the memory of any TM-25 file.
pub const MAX_RAYS: usize = super::tm25::MAX_RAYS;

/// Longest line read (bytes, comment included): a ray's eight numbers need under 200.
pub const MAX_LINE_BYTES: usize = 1 << 16;

/// Read the text ray set at `path`.
pub fn read(path: &Path) -> Result<RaySet> {
    checked_len(path)?;
    let file = std::fs::File::open(path)
        .map_err(|e| anyhow::anyhow!("{}: cannot read ray file: {e}", path.display()))?;
    let reader = BufReader::with_capacity(1 << 20, file);
    read_rows(reader, &path.display().to_string(), MAX_RAYS)
}

/// Read the rows of `reader` (`shown` names it in errors), at most `max_rays` rays.
pub fn read_rows(mut reader: impl BufRead, shown: &str, max_rays: usize) -> Result<RaySet> {
    let (mut rays, mut nm): (Vec<StoredRay>, Vec<f32>) = (Vec::new(), Vec::new());
    let mut width = None;
    let mut bytes = Vec::new();
    for number in 1.. {
        let at = |e: &dyn std::fmt::Display| anyhow::anyhow!("{shown}: line {number}: {e}");
        bytes.clear();
        let got = (&mut reader)
            .take(MAX_LINE_BYTES as u64 + 1)
            .read_until(b'\n', &mut bytes)
            .map_err(|e| at(&e))?;
        if got == 0 {
            break;
        }
        if got > MAX_LINE_BYTES {
            return Err(at(&format!("longer than {MAX_LINE_BYTES} bytes")));
        }
        let line = std::str::from_utf8(&bytes).map_err(|_| at(&"not UTF-8 text"))?;
        let Some((ray, wl)) = row(line, &mut width).map_err(|e| at(&e))? else {
            continue;
        };
        if rays.len() == max_rays {
            bail!(
                "{shown}: line {number}: more than {max_rays} rays, the most a ray file may hold"
            );
        }
        rays.push(ray);
        nm.extend(wl);
    }
    if rays.is_empty() {
        bail!("{shown}: no rays (expected lines 'x y z kx ky kz flux [nm]')");
    }
    Ok(RaySet {
        text: Default::default(),
        spectrum: if nm.is_empty() {
            FileSpectrum::None
        } else {
            FileSpectrum::PerRay
        },
        rays,
        nm,
        table: Vec::new(),
        unit: FluxUnit::Watt,
        stokes: Vec::new(),
        header_flux: [f64::NAN; 2],
    })
}

/// The ray of one line and its wavelength (`None`: a blank or comment line); `width` is
/// the number of columns, set by the first data line.
fn row(line: &str, width: &mut Option<usize>) -> Result<Option<(StoredRay, Option<f32>)>> {
    let data = line.split('#').next().unwrap_or("").trim();
    if data.is_empty() {
        return Ok(None);
    }
    let cells = || {
        data.split(|c: char| c == ',' || c.is_whitespace())
            .filter(|c| !c.is_empty())
    };
    let count = cells().count();
    let n = *width.get_or_insert(count);
    if !(7..=8).contains(&n) || count != n {
        bail!(
            "expected {} numbers 'x y z kx ky kz flux{}', got {count}",
            n.clamp(7, 8),
            if n == 8 { " nm" } else { " [nm]" },
        );
    }
    let mut v = [0f32; 8];
    for (k, c) in cells().enumerate() {
        v[k] = c
            .parse()
            .map_err(|_| anyhow::anyhow!("{}: not a number: '{c}'", COLUMNS[k]))?;
    }
    let wl = (n == 8).then_some(v[7]);
    let ray = check_ray([v[0], v[1], v[2]], [v[3], v[4], v[5]], v[6], wl)
        .map_err(|(col, why)| anyhow::anyhow!("{}: {why}", COLUMNS[col]))?;
    Ok(Some((ray, wl)))
}
