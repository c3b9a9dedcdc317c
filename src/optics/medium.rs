//! Optical media and the interface between two of them.
//!
//! ```toml
//! [media.pmma]
//! n = 1.49
//! absorption_per_mm = 0.0002   # Beer-Lambert coefficient (natural log), 0 = lossless
//! ```
//!
//! The medium `air` (n = 1, lossless) exists unless the file redefines it; surfaces and
//! sources name media, the scene numbers them ([`MediumId`]).

use crate::spec_check::Ctx;
use anyhow::Result;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Index of a medium in the scene's medium table (0 is the ambient medium, air).
pub type MediumId = u16;

/// A homogeneous optical medium.
#[derive(Clone, Debug, PartialEq)]
pub struct Medium {
    /// Name from the scene file.
    pub name: String,
    /// Refractive index.
    pub n: f64,
    /// Beer-Lambert absorption coefficient (1/mm).
    pub absorption_per_mm: f64,
}

/// The two media either side of a dielectric face.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interface {
    /// The medium behind the face (the normal points away from it).
    pub inside: MediumId,
    /// The medium in front of the face.
    pub outside: MediumId,
}

/// `[media.NAME]`: a homogeneous medium in the scene file.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MediumSpec {
    /// Refractive index.
    pub n: f64,
    /// Beer-Lambert absorption coefficient (1/mm).
    #[serde(default)]
    pub absorption_per_mm: f64,
}

/// The default of a face's or source's `outside`/`medium`: the ambient medium.
pub fn air() -> String {
    "air".into()
}

/// The scene's medium table from its `[media.*]` sections: air first (index 0, redefined
/// if the file names it), then the others in name order.
pub fn build_media(ctx: &Ctx, specs: &BTreeMap<String, MediumSpec>) -> Result<Vec<Medium>> {
    let mut media = vec![Medium {
        name: "air".into(),
        n: 1.0,
        absorption_per_mm: 0.0,
    }];
    for (name, spec) in specs {
        let n = ctx.positive(&format!("media.{name}.n"), spec.n)?;
        let a = ctx.finite(
            &format!("media.{name}.absorption_per_mm"),
            spec.absorption_per_mm,
        )?;
        if a < 0.0 {
            return Err(ctx.err(
                &format!("media.{name}.absorption_per_mm"),
                format!("must be >= 0, got {a}"),
            ));
        }
        let m = Medium {
            name: name.clone(),
            n,
            absorption_per_mm: a,
        };
        if name == "air" {
            media[0] = m;
        } else {
            media.push(m);
        }
    }
    if media.len() > MediumId::MAX as usize {
        return Err(ctx.err("media", "too many media"));
    }
    Ok(media)
}

/// The id of the medium named `name` (given at `field`).
pub fn medium_id(ctx: &Ctx, field: &str, name: &str, media: &[Medium]) -> Result<MediumId> {
    media
        .iter()
        .position(|m| m.name == name)
        .map(|i| i as MediumId)
        .ok_or_else(|| {
            let known: Vec<&str> = media.iter().map(|m| m.name.as_str()).collect();
            ctx.err(
                field,
                format!("unknown medium '{name}' (known: {})", known.join(", ")),
            )
        })
}

impl Interface {
    /// The interface of `[surfaces.TAG]` from its `inside` and `outside` medium names.
    pub fn build(
        ctx: &Ctx,
        tag: &str,
        inside: &str,
        outside: &str,
        media: &[Medium],
    ) -> Result<Interface> {
        Ok(Interface {
            inside: medium_id(ctx, &format!("surfaces.{tag}.inside"), inside, media)?,
            outside: medium_id(ctx, &format!("surfaces.{tag}.outside"), outside, media)?,
        })
    }
}
