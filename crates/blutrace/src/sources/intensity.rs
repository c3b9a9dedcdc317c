//! Measured LED intensity profiles: a relative intensity table `I(theta)` read from a CSV
//! or an IES LM-63 photometric file, sampled by inverse CDF.
//!
//! ```toml
//! [[sources]]
//! type = "led"
//! center = [-0.1, 4.25, 0.275]
//! normal = [1.0, 0.0, 0.0]
//! u = [0.0, 1.0, 0.0]
//! width_mm = 3.0
//! height_mm = 0.4
//! power_w = 0.05
//! intensity_file = "led.ies"   # or "led.csv"; relative to the scene file
//! ```
//!
//! `theta` is the angle from the emitter's normal. The profile is taken as rotationally
//! symmetric about the normal: the azimuth is uniform. `power_w` stays the radiant power;
//! the table only shapes the directions.
//!
//! **CSV** (`.csv`): one `theta_deg, relative_intensity` pair per line, comma separated;
//! blank lines and lines starting with `#` are ignored, and so is a first line whose first
//! field is not a number (a header such as `theta_deg,intensity`).
//!
//! **IES LM-63** (`.ies`, the 1995 and 2002 formats): keyword lines up to `TILT=`
//! (`NONE` or `INCLUDE`, whose tilt table is skipped), then the numbers. Only type C
//! photometry (photometric type 1) is read; vertical angles are `theta`. Candela values
//! are averaged over the horizontal angles with trapezoid weights over the range the file
//! covers: exact for a rotationally symmetric emitter (one horizontal angle) and for the
//! standard quadrant (0-90), bilateral (0-180) and full (0-360) layouts of an emitter whose
//! azimuthal variation we choose to ignore.
//!
//! Both formats: angles in degrees, strictly increasing, the first 0, all within [0, 180];
//! intensities non-negative, not all zero, and zero beyond 90 degrees (a flat emitter
//! lights one hemisphere; files may list the back hemisphere as zeros). Between table
//! angles the intensity is linear in `theta`; beyond the last angle it is zero.
//!
//! Sampling: the density of `theta` is `I(theta) sin(theta)`, tabulated on a fine grid
//! (every table interval split into equal cells, about [`FINE_CELLS`] in all) and taken as
//! linear within each cell, whose CDF is inverted exactly (a quadratic).

use anyhow::{Result, bail};
use std::f64::consts::FRAC_PI_2;
use std::path::Path;

/// About how many cells the sampling table has over `[0, 90]` degrees.
pub const FINE_CELLS: usize = 4096;

/// A rotationally symmetric relative intensity profile `I(theta)` with its sampling table.
#[derive(Clone)]
pub struct IntensityProfile {
    /// Table angles (degrees from the normal), strictly increasing from 0.
    angles_deg: Vec<f64>,
    /// Relative intensity at each angle (normalized so the largest is 1).
    intensity: Vec<f64>,
    /// Fine grid (radians) over `[0, min(last angle, 90 deg)]`.
    grid: Vec<f64>,
    /// `I(theta) sin(theta)` at each grid point.
    density: Vec<f64>,
    /// Integral of the linear-in-cell density from 0 to each grid point.
    cdf: Vec<f64>,
}

impl std::fmt::Debug for IntensityProfile {
    /// The table only: the sampling grid follows from it (and the content hash uses this).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("IntensityProfile")
            .field("angles_deg", &self.angles_deg)
            .field("intensity", &self.intensity)
            .finish()
    }
}

impl PartialEq for IntensityProfile {
    fn eq(&self, other: &Self) -> bool {
        self.angles_deg == other.angles_deg && self.intensity == other.intensity
    }
}

/// A value read from a file, with its 1-based line for error messages.
#[derive(Clone, Copy, Debug)]
struct Read {
    value: f64,
    line: usize,
}

impl IntensityProfile {
    /// Read a profile file by its extension (`.csv` or `.ies`, any case).
    pub fn read(path: &Path) -> Result<Self> {
        let text = crate::input_file::read_bytes(path, "intensity file")?;
        // IES files in the wild are often Latin-1: keep what is valid and replace the rest
        // (only keyword lines hold text).
        let text = String::from_utf8_lossy(&text);
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        match ext.as_str() {
            "csv" => Self::parse_csv(&text, path),
            "ies" => Self::parse_ies(&text, path),
            _ => bail!(
                "{}: unknown intensity file format (expected .csv or .ies)",
                path.display()
            ),
        }
    }

    /// Parse CSV text (`theta_deg, relative_intensity` per line); `path` names the file in
    /// errors.
    pub fn parse_csv(text: &str, path: &Path) -> Result<Self> {
        let file = path.display();
        let mut angles = Vec::new();
        let mut values = Vec::new();
        let mut first_row = true;
        for (i, raw) in text.lines().enumerate() {
            let line = i + 1;
            let l = raw.trim();
            if l.is_empty() || l.starts_with('#') {
                continue;
            }
            let fields: Vec<&str> = l.split(',').map(str::trim).collect();
            let is_header = first_row && fields[0].parse::<f64>().is_err();
            first_row = false;
            if is_header {
                continue;
            }
            if fields.len() != 2 {
                bail!(
                    "{file}: line {line}: expected 2 fields (theta_deg, intensity), found {}",
                    fields.len()
                );
            }
            for (name, s, out) in [
                ("theta_deg", fields[0], &mut angles),
                ("intensity", fields[1], &mut values),
            ] {
                let value = s.parse::<f64>().map_err(|_| {
                    anyhow::anyhow!("{file}: line {line}: {name}: '{s}' is not a number")
                })?;
                out.push(Read { value, line });
            }
        }
        Self::validated(&angles, &values, path, "theta_deg", "intensity")
    }

    /// Parse IES LM-63 text (type C photometry); `path` names the file in errors.
    fn parse_ies(text: &str, path: &Path) -> Result<Self> {
        let file = path.display();
        let lines: Vec<&str> = text.lines().collect();
        let Some(tilt_at) = lines
            .iter()
            .position(|l| l.trim_start().to_ascii_uppercase().starts_with("TILT"))
        else {
            bail!("{file}: no TILT= line: not an IES LM-63 file");
        };
        let tilt = lines[tilt_at].trim();
        let tilt_value = tilt
            .split_once('=')
            .map(|(_, v)| v.trim().to_ascii_uppercase())
            .unwrap_or_default();
        // The numbers after TILT, each with its line.
        let mut tokens = lines
            .iter()
            .enumerate()
            .skip(tilt_at + 1)
            .flat_map(|(i, l)| {
                l.split(|c: char| c.is_whitespace() || c == ',')
                    .filter(|t| !t.is_empty())
                    .map(move |t| (i + 1, t))
            });
        let mut last_line = tilt_at + 1;
        let mut next = |field: &str| -> Result<Read> {
            let Some((line, t)) = tokens.next() else {
                bail!("{file}: line {last_line}: {field}: the file ends before it");
            };
            last_line = line;
            let value = t.parse::<f64>().map_err(|_| {
                anyhow::anyhow!("{file}: line {line}: {field}: '{t}' is not a number")
            })?;
            if !value.is_finite() {
                bail!("{file}: line {line}: {field}: must be finite, got {t}");
            }
            Ok(Read { value, line })
        };
        let count = |r: Read, field: &str| -> Result<usize> {
            if r.value.fract() != 0.0 || r.value < 1.0 || r.value > 100_000.0 {
                bail!(
                    "{file}: line {}: {field}: must be a whole number within 1..=100000, got {}",
                    r.line,
                    r.value
                );
            }
            Ok(r.value as usize)
        };
        match tilt_value.as_str() {
            "NONE" => {}
            "INCLUDE" => {
                next("TILT lamp-to-luminaire geometry")?;
                let n = next("number of tilt angles")?;
                let n = count(n, "number of tilt angles")?;
                for k in 0..2 * n {
                    next(&format!("tilt table value {}", k + 1))?;
                }
            }
            _ => bail!(
                "{file}: line {}: TILT: only TILT=NONE and TILT=INCLUDE are supported, got '{tilt}'",
                tilt_at + 1
            ),
        }
        next("number of lamps")?;
        next("lumens per lamp")?;
        let multiplier = next("candela multiplier")?;
        let nv = next("number of vertical angles")?;
        let nv = count(nv, "number of vertical angles")?;
        let nh = next("number of horizontal angles")?;
        let nh = count(nh, "number of horizontal angles")?;
        let ptype = next("photometric type")?;
        if ptype.value != 1.0 {
            bail!(
                "{file}: line {}: photometric type: only type C (1) is supported, got {}",
                ptype.line,
                ptype.value
            );
        }
        for field in [
            "units type",
            "luminous opening width",
            "luminous opening length",
            "luminous opening height",
            "ballast factor",
            "ballast-lamp photometric factor",
            "input watts",
        ] {
            next(field)?;
        }
        let vertical: Vec<Read> = (0..nv)
            .map(|k| next(&format!("vertical angle {}", k + 1)))
            .collect::<Result<_>>()?;
        let horizontal: Vec<Read> = (0..nh)
            .map(|k| next(&format!("horizontal angle {}", k + 1)))
            .collect::<Result<_>>()?;
        for (k, h) in horizontal.iter().enumerate() {
            if !(0.0..=360.0).contains(&h.value) {
                bail!(
                    "{file}: line {}: horizontal angle {}: must be within [0, 360], got {}",
                    h.line,
                    k + 1,
                    h.value
                );
            }
            if k > 0 && h.value <= horizontal[k - 1].value {
                bail!(
                    "{file}: line {}: horizontal angle {}: angles must increase, got {} after {}",
                    h.line,
                    k + 1,
                    h.value,
                    horizontal[k - 1].value
                );
            }
        }
        // Trapezoid weights over the horizontal range (1 for a single angle).
        let weights: Vec<f64> = if nh == 1 {
            vec![1.0]
        } else {
            (0..nh)
                .map(|k| {
                    let lo = horizontal[k.saturating_sub(1)].value;
                    let hi = horizontal[(k + 1).min(nh - 1)].value;
                    0.5 * (hi - lo)
                })
                .collect()
        };
        let total_weight: f64 = weights.iter().sum();
        let mut mean = vec![0.0; nv];
        let mut lines_of = vec![0; nv];
        for (k, w) in weights.iter().enumerate() {
            for (j, m) in mean.iter_mut().enumerate() {
                let c = next(&format!(
                    "candela value (horizontal angle {}, vertical angle {})",
                    k + 1,
                    j + 1
                ))?;
                if c.value < 0.0 {
                    bail!(
                        "{file}: line {}: candela value (horizontal angle {}, vertical angle {}): must be >= 0, got {}",
                        c.line,
                        k + 1,
                        j + 1,
                        c.value
                    );
                }
                // The multiplier and the candela scale drop out in the normalisation to
                // the largest value; weights as fractions keep the mean within the
                // largest value (a product near 1e306 would overflow).
                *m += w / total_weight * c.value;
                lines_of[j] = c.line;
            }
        }
        if let Some((line, t)) = tokens.next() {
            bail!("{file}: line {line}: unexpected data '{t}' after the candela values");
        }
        if multiplier.value <= 0.0 {
            bail!(
                "{file}: line {}: candela multiplier: must be > 0, got {}",
                multiplier.line,
                multiplier.value
            );
        }
        let values: Vec<Read> = mean
            .iter()
            .zip(&lines_of)
            .map(|(&value, &line)| Read { value, line })
            .collect();
        Self::validated(
            &vertical,
            &values,
            path,
            "vertical angle",
            "candela value (averaged over horizontal angles)",
        )
    }

    /// Build a profile from a table given in code (angles in degrees).
    pub fn from_table(angles_deg: &[f64], intensity: &[f64]) -> Result<Self> {
        let wrap = |v: &[f64]| -> Vec<Read> {
            v.iter()
                .enumerate()
                .map(|(i, &value)| Read { value, line: i + 1 })
                .collect()
        };
        if angles_deg.len() != intensity.len() {
            bail!(
                "intensity table: {} angles but {} intensities",
                angles_deg.len(),
                intensity.len()
            );
        }
        Self::validated(
            &wrap(angles_deg),
            &wrap(intensity),
            Path::new("<table>"),
            "theta_deg",
            "intensity",
        )
    }

    fn validated(
        angles: &[Read],
        values: &[Read],
        path: &Path,
        angle_field: &str,
        value_field: &str,
    ) -> Result<Self> {
        let file = path.display();
        if angles.len() < 2 {
            bail!(
                "{file}: needs at least two angles (0 and more), found {}",
                angles.len()
            );
        }
        for (k, (a, v)) in angles.iter().zip(values).enumerate() {
            let at = |r: &Read, field: &str| format!("{file}: line {}: {field}", r.line);
            if !a.value.is_finite() || !(0.0..=180.0).contains(&a.value) {
                bail!(
                    "{}: must be within [0, 180] degrees, got {}",
                    at(a, angle_field),
                    a.value
                );
            }
            if k == 0 && a.value != 0.0 {
                bail!(
                    "{}: the first angle must be 0 (the emitter's normal), got {}",
                    at(a, angle_field),
                    a.value
                );
            }
            if k > 0 && a.value <= angles[k - 1].value {
                bail!(
                    "{}: angles must increase strictly, got {} after {}",
                    at(a, angle_field),
                    a.value,
                    angles[k - 1].value
                );
            }
            if !v.value.is_finite() || v.value < 0.0 {
                bail!("{}: must be >= 0, got {}", at(v, value_field), v.value);
            }
            if a.value > 90.0 && v.value != 0.0 {
                bail!(
                    "{}: must be 0 beyond 90 degrees (a flat emitter lights one hemisphere), got {} at {} degrees",
                    at(v, value_field),
                    v.value,
                    a.value
                );
            }
        }
        let max = values.iter().map(|v| v.value).fold(0.0, f64::max);
        if max <= 0.0 {
            bail!("{file}: {value_field}: all intensities are zero");
        }
        let angles_deg: Vec<f64> = angles.iter().map(|a| a.value).collect();
        let intensity: Vec<f64> = values.iter().map(|v| v.value / max).collect();
        let profile = Self::with_table(angles_deg, intensity);
        if profile.total() <= 0.0 {
            bail!("{file}: {value_field}: no intensity between 0 and 90 degrees");
        }
        Ok(profile)
    }

    fn with_table(angles_deg: Vec<f64>, intensity: Vec<f64>) -> Self {
        let mut p = Self {
            angles_deg,
            intensity,
            grid: Vec::new(),
            density: Vec::new(),
            cdf: Vec::new(),
        };
        let top = p.angles_deg.last().copied().unwrap_or(0.0).min(90.0);
        let mut grid = vec![0.0];
        for w in p.angles_deg.windows(2) {
            let (a, b) = (w[0], w[1].min(90.0));
            if b <= a {
                break;
            }
            let cells = ((FINE_CELLS as f64 * (b - a) / top).ceil() as usize).max(1);
            for k in 1..=cells {
                let t = if k == cells {
                    b
                } else {
                    a + (b - a) * k as f64 / cells as f64
                };
                grid.push(t.to_radians());
            }
        }
        let density: Vec<f64> = grid.iter().map(|&t| p.intensity(t) * t.sin()).collect();
        let mut cdf = vec![0.0];
        for k in 1..grid.len() {
            let h = grid[k] - grid[k - 1];
            cdf.push(cdf[k - 1] + 0.5 * h * (density[k - 1] + density[k]));
        }
        p.grid = grid;
        p.density = density;
        p.cdf = cdf;
        p
    }

    /// Relative intensity (largest table value 1) at `theta` radians from the normal:
    /// linear between table angles, zero beyond the last and beyond 90 degrees.
    pub fn intensity(&self, theta: f64) -> f64 {
        let d = theta.to_degrees();
        let a = &self.angles_deg;
        if !(0.0..=90.0).contains(&d) || d > a[a.len() - 1] {
            return 0.0;
        }
        let k = a.partition_point(|&x| x <= d).clamp(1, a.len() - 1);
        let (a0, a1) = (a[k - 1], a[k]);
        let t = ((d - a0) / (a1 - a0)).clamp(0.0, 1.0);
        self.intensity[k - 1] + t * (self.intensity[k] - self.intensity[k - 1])
    }

    /// The table: angles (degrees) and relative intensities (largest 1).
    pub fn table(&self) -> (&[f64], &[f64]) {
        (&self.angles_deg, &self.intensity)
    }

    /// Integral of the sampling density over `[0, 90]` degrees (unnormalized).
    fn total(&self) -> f64 {
        self.cdf.last().copied().unwrap_or(0.0)
    }

    /// Probability that a sampled `theta` falls within `[t0, t1]` radians, by the sampling
    /// table (for tests and reports).
    pub fn probability(&self, t0: f64, t1: f64) -> f64 {
        (self.cdf_at(t1) - self.cdf_at(t0)) / self.total()
    }

    fn cdf_at(&self, t: f64) -> f64 {
        let g = &self.grid;
        if t <= 0.0 {
            return 0.0;
        }
        if t >= g[g.len() - 1] {
            return self.total();
        }
        let k = g.partition_point(|&x| x <= t).clamp(1, g.len() - 1);
        let (h, s) = (g[k] - g[k - 1], t - g[k - 1]);
        let (f0, f1) = (self.density[k - 1], self.density[k]);
        self.cdf[k - 1] + f0 * s + (f1 - f0) * s * s / (2.0 * h)
    }

    /// The polar angle (radians from the normal) for a uniform number `u` in `[0, 1)`.
    pub fn sample_theta(&self, u: f64) -> f64 {
        let x = u.clamp(0.0, 1.0) * self.total();
        let g = &self.grid;
        let k = self.cdf.partition_point(|&c| c <= x).clamp(1, g.len() - 1);
        let h = g[k] - g[k - 1];
        let (f0, f1) = (self.density[k - 1], self.density[k]);
        let r = x - self.cdf[k - 1];
        // Solve f0 s + (f1 - f0) s^2 / (2 h) = r for s in [0, h], in the form that is
        // stable for every sign of f1 - f0 (and f0 = 0).
        let root = (f0 * f0 + 2.0 * (f1 - f0) * r / h).max(0.0).sqrt();
        let s = if f0 + root > 0.0 {
            2.0 * r / (f0 + root)
        } else {
            0.0
        };
        (g[k - 1] + s.clamp(0.0, h)).min(FRAC_PI_2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cos_table(step: f64) -> IntensityProfile {
        let n = (90.0 / step).round() as usize;
        let a: Vec<f64> = (0..=n).map(|k| k as f64 * step).collect();
        let i: Vec<f64> = a
            .iter()
            .map(|d: &f64| d.to_radians().cos().max(0.0))
            .collect();
        IntensityProfile::from_table(&a, &i).unwrap()
    }

    #[test]
    fn a_cosine_table_samples_like_a_lambertian_emitter() {
        // Stratified u: the sampled cos(theta) must match the Lambertian inverse CDF
        // cos = sqrt(1 - u) to the accuracy of the 1-degree linear table.
        let p = cos_table(1.0);
        for k in 0..1000 {
            let u = (k as f64 + 0.5) / 1000.0;
            let want = (1.0 - u).sqrt();
            let got = p.sample_theta(u).cos();
            assert!((got - want).abs() < 2e-4, "u {u}: {got} vs {want}");
        }
        // Bin probabilities of cos^2(t0) - cos^2(t1).
        for k in 0..18 {
            let (t0, t1) = (
                (5.0 * k as f64).to_radians(),
                (5.0 * (k + 1) as f64).to_radians(),
            );
            let want = t0.cos().powi(2) - t1.cos().powi(2);
            assert!((p.probability(t0, t1) - want).abs() < 1e-4);
        }
    }

    #[test]
    fn sampling_inverts_the_tabulated_cdf() {
        let p =
            IntensityProfile::from_table(&[0.0, 30.0, 60.0, 90.0], &[0.5, 1.0, 0.2, 0.0]).unwrap();
        for k in 0..=200 {
            let u = k as f64 / 200.0 * 0.999_999;
            let t = p.sample_theta(u);
            assert!((p.probability(0.0, t) - u).abs() < 1e-9, "u {u}");
        }
        assert_eq!(p.intensity(45f64.to_radians()), 0.6);
        assert_eq!(p.intensity(1.6), 0.0);
    }

    #[test]
    fn a_table_ending_early_emits_nothing_beyond_it() {
        let p = IntensityProfile::from_table(&[0.0, 40.0], &[1.0, 1.0]).unwrap();
        for k in 0..1000 {
            assert!(p.sample_theta(k as f64 / 1000.0) <= 40f64.to_radians() + 1e-12);
        }
    }

    fn csv_err(text: &str) -> String {
        IntensityProfile::parse_csv(text, Path::new("led.csv"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn csv_errors_name_file_line_and_field() {
        let e = csv_err("theta_deg,intensity\n0,1\n20,0.5\n10,0.2\n");
        assert!(
            e.contains("led.csv: line 4: theta_deg: angles must increase"),
            "{e}"
        );
        let e = csv_err("0,1\n45,-0.1\n90,0\n");
        assert!(
            e.contains("led.csv: line 2: intensity: must be >= 0"),
            "{e}"
        );
        let e = csv_err("0,1\n45,x\n");
        assert!(e.contains("line 2: intensity: 'x' is not a number"), "{e}");
        let e = csv_err("0,0\n90,0\n");
        assert!(e.contains("all intensities are zero"), "{e}");
        let e = csv_err("5,1\n90,0\n");
        assert!(
            e.contains("line 1: theta_deg: the first angle must be 0"),
            "{e}"
        );
        let e = csv_err("0,1\n90,0\n120,0.1\n");
        assert!(e.contains("line 3: intensity: must be 0 beyond 90"), "{e}");
        let e = csv_err("0,1\n190,0\n");
        assert!(
            e.contains("line 2: theta_deg: must be within [0, 180]"),
            "{e}"
        );
        let e = csv_err("0,1,2\n");
        assert!(e.contains("line 1: expected 2 fields"), "{e}");
        // A back hemisphere of zeros is fine.
        IntensityProfile::parse_csv("# c\n0,1\n90,0\n180,0\n", Path::new("x.csv")).unwrap();
    }

    const IES: &str = "IESNA:LM-63-2002\n[TEST] t\nTILT=NONE\n1 -1 1.0 4 3 1 2 0.003 0.0004 0\n\
        1.0 1.0 0.2\n0 30 60 90\n0 45 90\n1 2 1 0\n3 4 1 0\n1 2 1 0\n";

    #[test]
    fn ies_candela_values_are_averaged_over_horizontal_angles() {
        let p = IntensityProfile::parse_ies(IES, Path::new("a.ies")).unwrap();
        // Trapezoid weights 1/4, 1/2, 1/4: means 2, 3, 1, 0; normalized by 3.
        let (a, i) = p.table();
        assert_eq!(a, &[0.0, 30.0, 60.0, 90.0]);
        let want = [2.0 / 3.0, 1.0, 1.0 / 3.0, 0.0];
        for (g, w) in i.iter().zip(want) {
            assert!((g - w).abs() < 1e-12, "{i:?}");
        }
        let tilt = IES.replace("TILT=NONE\n", "TILT=INCLUDE\n1\n3\n0 45 90\n1 0.9 0.8\n");
        assert_eq!(
            IntensityProfile::parse_ies(&tilt, Path::new("b.ies")).unwrap(),
            p
        );
    }

    /// A profile is relative: candela values or a multiplier at 1e306 (whose products
    /// overflow) or 1e-300, or a CSV at 1e300 or a subnormal 1e-310, give the profile of
    /// the same table at 1.
    #[test]
    fn profiles_at_any_scale_are_the_same() {
        let ies = |t: &str| IntensityProfile::parse_ies(t, Path::new("a.ies")).unwrap();
        let want = ies(IES);
        let block = "1 2 1 0\n3 4 1 0\n1 2 1 0\n";
        let candela = |s: &str| {
            let scaled = format!("1{s} 2{s} 1{s} 0\n3{s} 4{s} 1{s} 0\n1{s} 2{s} 1{s} 0\n");
            IES.replace(block, &scaled)
        };
        let close = |p: &IntensityProfile, what: &str| {
            let (a, i) = p.table();
            assert_eq!(a, want.table().0, "{what}");
            for (g, w) in i.iter().zip(want.table().1) {
                assert!((g - w).abs() < 1e-12, "{what}: {i:?}");
            }
            for u in [0.1, 0.5, 0.9] {
                let (g, w) = (p.sample_theta(u), want.sample_theta(u));
                assert!((g - w).abs() < 1e-12, "{what}: {g} against {w}");
            }
        };
        close(&ies(&candela("e306")), "candela 1e306");
        close(&ies(&candela("e-300")), "candela 1e-300");
        close(
            &ies(&IES.replace(" 1.0 4 3 ", " 1e306 4 3 ")),
            "multiplier 1e306",
        );
        close(
            &ies(&IES.replace(" 1.0 4 3 ", " 1e-300 4 3 ")),
            "multiplier 1e-300",
        );
        let csv = |s: &str| {
            let text = format!("0,2{s}\n30,3{s}\n60,1{s}\n90,0\n");
            IntensityProfile::parse_csv(&text, Path::new("x.csv")).unwrap()
        };
        let one = csv("");
        for s in ["e300", "e-300", "e-310"] {
            let p = csv(s);
            for (g, w) in p.table().1.iter().zip(one.table().1) {
                assert!((g - w).abs() < 1e-12, "csv {s}: {:?}", p.table().1);
            }
        }
    }

    #[test]
    fn ies_errors_name_file_line_and_field() {
        let err = |t: &str| {
            IntensityProfile::parse_ies(t, Path::new("a.ies"))
                .unwrap_err()
                .to_string()
        };
        let e = err(&IES.replace("0 30 60 90", "0 30 20 90"));
        assert!(
            e.contains("a.ies: line 6: vertical angle: angles must increase"),
            "{e}"
        );
        let e = err(&IES.replace("3 4 1 0", "3 -4 1 0"));
        assert!(
            e.contains("line 9: candela value (horizontal angle 2, vertical angle 2)"),
            "{e}"
        );
        let e = err(&IES.replace("4 3 1 2", "4 3 2 2"));
        assert!(e.contains("line 4: photometric type: only type C"), "{e}");
        let e = err(&IES.replace("1 2 1 0\n", "1 2 1\n"));
        assert!(e.contains("the file ends before it"), "{e}");
        let e = err("IESNA:LM-63-2002\n1 2 3\n");
        assert!(e.contains("no TILT= line"), "{e}");
        let e = err(&IES.replace("TILT=NONE", "TILT=lamp.tlt"));
        assert!(e.contains("line 3: TILT"), "{e}");
        let e = err(&format!("{IES}7\n"));
        assert!(e.contains("line 11: unexpected data '7'"), "{e}");
    }
}
