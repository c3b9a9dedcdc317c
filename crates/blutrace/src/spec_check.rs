//! Checks of scene-file values that name their place: the file and the field
//! (`scene.toml: sources[0].radius_mm: must be > 0, got -1`).
//!
//! A low layer: the scene loader and the models that own their part of the file format
//! (surface models, media, sources) all check their values with a [`Ctx`].

use anyhow::Result;

/// Largest coordinate or length (mm) a scene may use: beyond it f64 resolves no better
/// than 0.1 mm, a unit or export error either way.
pub const MAX_COORDINATE: f64 = 1e12;

/// Longest name (bytes) of a scene or a lamp: a folder name may have 255 bytes, and the
/// name is part of longer ones.
pub const MAX_NAME_BYTES: usize = 100;

/// Largest rotation angle (degrees): a thousand turns and more is a typing mistake.
pub const MAX_ANGLE_DEG: f64 = 3.6e5;

use glam::DVec3;
use std::path::Path;

/// Names an error's place: the scene file (and, per call, the field).
#[derive(Clone, Copy, Debug)]
pub struct Ctx<'a>(pub &'a Path);

impl Ctx<'_> {
    /// An error at `field` of the file.
    pub fn err(&self, field: &str, msg: impl std::fmt::Display) -> anyhow::Error {
        anyhow::anyhow!("{}: {field}: {msg}", self.0.display())
    }

    /// `x`, if finite.
    pub fn finite(&self, field: &str, x: f64) -> Result<f64> {
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be a finite number, got {}", short(x))))
        }
    }

    /// `x`, if finite and > 0.
    pub fn positive(&self, field: &str, x: f64) -> Result<f64> {
        if self.finite(field, x)? > 0.0 {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be > 0, got {}", short(x))))
        }
    }

    /// `x`, if finite and >= 0.
    pub fn non_negative(&self, field: &str, x: f64) -> Result<f64> {
        if self.finite(field, x)? >= 0.0 {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be >= 0, got {}", short(x))))
        }
    }

    /// `x`, if within `[0, 1]`.
    pub fn fraction(&self, field: &str, x: f64) -> Result<f64> {
        if (0.0..=1.0).contains(&self.finite(field, x)?) {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be within [0, 1], got {}", short(x))))
        }
    }

    /// `x`, if given, finite and > 0.
    pub fn optional_positive(&self, field: &str, x: Option<f64>) -> Result<Option<f64>> {
        x.map(|v| self.positive(field, v)).transpose()
    }

    /// A point with finite coordinates within [`MAX_COORDINATE`] mm (`field[i]` names a
    /// bad one).
    pub fn point(&self, field: &str, p: [f64; 3]) -> Result<DVec3> {
        self.bounded(field, p, MAX_COORDINATE, " mm")
    }

    /// Rotation angles (degrees) within [`MAX_ANGLE_DEG`].
    pub fn angles_deg(&self, field: &str, p: [f64; 3]) -> Result<DVec3> {
        self.bounded(field, p, MAX_ANGLE_DEG, " degrees")
    }

    /// One angle (degrees): finite and within ±[`MAX_ANGLE_DEG`].
    pub fn angle_deg(&self, field: &str, deg: f64) -> Result<f64> {
        if self.finite(field, deg)?.abs() > MAX_ANGLE_DEG {
            return Err(self.err(
                field,
                format!(
                    "must be within ±{MAX_ANGLE_DEG:e} degrees (a thousand turns and more is a typing mistake), got {}",
                    short(deg)
                ),
            ));
        }
        Ok(deg)
    }

    /// Three finite numbers within `±max` (`unit` after the bound in the message).
    fn bounded(&self, field: &str, p: [f64; 3], max: f64, unit: &str) -> Result<DVec3> {
        for (i, c) in p.iter().enumerate() {
            let f = format!("{field}[{i}]");
            if self.finite(&f, *c)?.abs() > max {
                return Err(self.err(
                    &f,
                    format!("must be within ±{max:e}{unit}, got {}", short(*c)),
                ));
            }
        }
        Ok(DVec3::from_array(p))
    }

    /// A length (mm): finite, > 0 and at most [`MAX_COORDINATE`].
    pub fn length(&self, field: &str, x: f64) -> Result<f64> {
        if self.positive(field, x)? > MAX_COORDINATE {
            return Err(self.err(
                field,
                format!("must be at most {MAX_COORDINATE:e} mm, got {}", short(x)),
            ));
        }
        Ok(x)
    }

    /// A name shown in outputs (a scene's or a lamp's): 1 to [`MAX_NAME_BYTES`] bytes,
    /// no control characters (a NUL cannot be written into an EXR attribute or a file
    /// name), no path separator and not `.` or `..` (a scene's name names its default
    /// output folder).
    pub fn name<'n>(&self, field: &str, name: &'n str) -> Result<&'n str> {
        let why = if name.is_empty() {
            Some("must not be empty".to_string())
        } else if name.len() > MAX_NAME_BYTES {
            Some(format!(
                "is {} bytes long; at most {MAX_NAME_BYTES} (it names files and folders)",
                name.len()
            ))
        } else if let Some(c) = name.chars().find(|c| c.is_control()) {
            Some(format!(
                "holds the control character {:?}; names are printable text",
                c
            ))
        } else if name.contains(['/', '\\']) || name == "." || name == ".." {
            Some(format!(
                "is {name:?}: a name is not a path (no '/' or '\\')"
            ))
        } else {
            None
        };
        match why {
            Some(w) => Err(self.err(field, w)),
            None => Ok(name),
        }
    }

    /// A non-zero direction, normalized.
    pub fn direction(&self, field: &str, p: [f64; 3]) -> Result<DVec3> {
        let v = self.bounded(field, p, MAX_COORDINATE, "")?;
        if v.length() < 1e-12 {
            return Err(self.err(field, "must be a non-zero direction"));
        }
        Ok(v.normalize())
    }
}

/// A number for a message: at most 6 significant digits (`1e300`, `0.333333`, `125`), so a
/// bound error never prints 301 digits.
pub fn short(x: f64) -> String {
    let plain = format!("{x}");
    if plain.len() <= 12 {
        return plain;
    }
    let sci = format!("{x:.5e}");
    match sci.split_once('e') {
        Some((m, e)) => {
            let m = m.trim_end_matches('0').trim_end_matches('.');
            let e: i32 = e.parse().unwrap_or(0);
            if (-4..=6).contains(&e) {
                format!("{}", m.parse::<f64>().unwrap_or(x) * 10f64.powi(e))
            } else {
                format!("{m}e{e}")
            }
        }
        None => plain,
    }
}

/// `T` read from `table`, an error prefixed by the key it is about (`albedo: invalid
/// type: ...`): the table is read again from its own TOML text, whose error has the
/// place of the key or value it is about. For the tables serde's tagged enums read
/// (`[surfaces.TAG]` by `model`, `[[sources]]` by `type`), whose errors lose the key.
pub fn keyed<T: serde::de::DeserializeOwned>(table: &toml::Table) -> Result<T, String> {
    let text = toml::to_string(table).map_err(|e| e.to_string())?;
    toml::from_str::<T>(&text).map_err(|e| {
        let missing = e.message().starts_with("missing field");
        match e.span().filter(|_| !missing).and_then(|s| key_at(&text, s)) {
            Some(key) => format!("{key}: {}", e.message()),
            None => e.message().to_string(),
        }
    })
}

/// The dotted key of the `key = value` line that holds all of `span` in the TOML `text`
/// (`None` for an empty span or one over several lines).
fn key_at(text: &str, span: std::ops::Range<usize>) -> Option<String> {
    if span.is_empty() {
        return None;
    }
    let start = text.get(..span.start)?.rfind('\n').map_or(0, |i| i + 1);
    let line = text[start..].lines().next()?;
    if span.end > start + line.len() || line.starts_with('[') {
        return None;
    }
    let key = line.split_once('=')?.0.trim().trim_matches('"');
    let section = text[..start]
        .lines()
        .rev()
        .find(|l| l.starts_with('['))
        .map(|l| l.trim_matches(|c| c == '[' || c == ']').trim().to_string());
    Some(match section {
        Some(s) => format!("{s}.{key}"),
        None => key.to_string(),
    })
}
