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
//! Read in one pass, line by line; an error names the file, the line and the column.

use super::{FileSpectrum, FluxUnit, RaySet, StoredRay, check_ray, checked_len};
use anyhow::{Result, bail};
use std::io::{BufRead, BufReader};
use std::path::Path;

/// Column names, for errors.
const COLUMNS: [&str; 8] = ["x", "y", "z", "kx", "ky", "kz", "flux", "nm"];

/// Read the text ray set at `path`.
pub fn read(path: &Path) -> Result<RaySet> {
    checked_len(path)?;
    let file = std::fs::File::open(path)
        .map_err(|e| anyhow::anyhow!("{}: cannot read ray file: {e}", path.display()))?;
    let shown = path.display();
    let (mut rays, mut nm): (Vec<StoredRay>, Vec<f32>) = (Vec::new(), Vec::new());
    let mut width = None;
    let mut line = String::new();
    let mut reader = BufReader::with_capacity(1 << 20, file);
    for number in 1.. {
        line.clear();
        match reader.read_line(&mut line) {
            Ok(0) => break,
            Ok(_) => {}
            Err(e) => bail!("{shown}: line {number}: {e}"),
        }
        let data = line.split('#').next().unwrap_or("").trim();
        if data.is_empty() {
            continue;
        }
        let cells: Vec<&str> = data
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|c| !c.is_empty())
            .collect();
        let n = *width.get_or_insert(cells.len());
        if !(7..=8).contains(&n) || cells.len() != n {
            bail!(
                "{shown}: line {number}: expected {} numbers 'x y z kx ky kz flux{}', got {}",
                n.clamp(7, 8),
                if n == 8 { " nm" } else { " [nm]" },
                cells.len()
            );
        }
        let mut v = [0f32; 8];
        for (k, c) in cells.iter().enumerate() {
            v[k] = c.parse().map_err(|_| {
                anyhow::anyhow!(
                    "{shown}: line {number}: {}: not a number: '{c}'",
                    COLUMNS[k]
                )
            })?;
        }
        let wl = (n == 8).then_some(v[7]);
        let ray =
            check_ray([v[0], v[1], v[2]], [v[3], v[4], v[5]], v[6], wl).map_err(|(col, why)| {
                anyhow::anyhow!("{shown}: line {number}: {}: {why}", COLUMNS[col])
            })?;
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
        unit: FluxUnit::Watt,
        header_flux: [f64::NAN; 2],
    })
}
