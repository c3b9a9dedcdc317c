//! Checks of scene-file values that name their place: the file and the field
//! (`scene.toml: sources[0].radius_mm: must be > 0, got -1`).
//!
//! A low layer: the scene loader and the models that own their part of the file format
//! (surface models, media, sources) all check their values with a [`Ctx`].

use anyhow::Result;

/// Largest coordinate or length (mm) a scene may use: beyond it f64 resolves no better
/// than 0.1 mm, a unit or export error either way.
pub const MAX_COORDINATE: f64 = 1e12;
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
            Err(self.err(field, format!("must be a finite number, got {x}")))
        }
    }

    /// `x`, if finite and > 0.
    pub fn positive(&self, field: &str, x: f64) -> Result<f64> {
        if self.finite(field, x)? > 0.0 {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be > 0, got {x}")))
        }
    }

    /// `x`, if finite and >= 0.
    pub fn non_negative(&self, field: &str, x: f64) -> Result<f64> {
        if self.finite(field, x)? >= 0.0 {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be >= 0, got {x}")))
        }
    }

    /// `x`, if within `[0, 1]`.
    pub fn fraction(&self, field: &str, x: f64) -> Result<f64> {
        if (0.0..=1.0).contains(&self.finite(field, x)?) {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be within [0, 1], got {x}")))
        }
    }

    /// `x`, if given, finite and > 0.
    pub fn optional_positive(&self, field: &str, x: Option<f64>) -> Result<Option<f64>> {
        x.map(|v| self.positive(field, v)).transpose()
    }

    /// A point with finite coordinates within [`MAX_COORDINATE`] mm (`field[i]` names a
    /// bad one).
    pub fn point(&self, field: &str, p: [f64; 3]) -> Result<DVec3> {
        for (i, c) in p.iter().enumerate() {
            let f = format!("{field}[{i}]");
            if self.finite(&f, *c)?.abs() > MAX_COORDINATE {
                return Err(self.err(
                    &f,
                    format!("must be within ±{MAX_COORDINATE:e} mm, got {c}"),
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
                format!("must be at most {MAX_COORDINATE:e} mm, got {x}"),
            ));
        }
        Ok(x)
    }

    /// A non-zero direction, normalized.
    pub fn direction(&self, field: &str, p: [f64; 3]) -> Result<DVec3> {
        let v = self.point(field, p)?;
        if v.length() < 1e-12 {
            return Err(self.err(field, "must be a non-zero direction"));
        }
        Ok(v.normalize())
    }
}
