//! A source's polarization: the state every photon it emits starts in.
//!
//! ```toml
//! [[sources]]
//! type = "led"
//! # ...
//! polarization = { linear_deg = 30.0 }            # linear, 30 degrees from u towards v
//! # polarization = { stokes = [1.0, 0.5, 0.0, 0.2] } # any state, S1 > 0 along u
//! ```
//!
//! The frame is the source's u axis (an LED's `u`, a CCFL's tube axis, a ray file's
//! placed x axis) made perpendicular to each photon's direction, `v = direction x u`, as
//! the detector's. Without the key the light is unpolarized (every CCFL, and LEDs, whose
//! phosphor and diffusing encapsulant depolarize them). A polarized source makes the scene
//! trace polarization unless `[trace] polarization = false`.

use crate::optics::polarization::Stokes;
use crate::spec_check::Ctx;
use anyhow::Result;
use serde::{Deserialize, Serialize};

/// `polarization = { ... }` of a `[[sources]]` entry.
#[derive(Clone, Copy, Debug, Deserialize, Serialize)]
#[serde(untagged, try_from = "Keys")]
pub enum SourcePolarizationSpec {
    /// Fully linearly polarized at `linear_deg` degrees from u towards v.
    Linear {
        /// The angle (degrees).
        linear_deg: f64,
    },
    /// A Stokes vector `[S0, S1, S2, S3]` (scaled to `S0 = 1`).
    Stokes {
        /// The vector.
        stokes: [f64; 4],
    },
}

/// The table as written, so that an unknown or missing key gets a message naming the keys.
#[derive(Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a table { linear_deg = D } or { stokes = [S0, S1, S2, S3] }"
)]
struct Keys {
    linear_deg: Option<f64>,
    stokes: Option<[f64; 4]>,
}

impl TryFrom<Keys> for SourcePolarizationSpec {
    type Error = String;

    fn try_from(k: Keys) -> Result<Self, String> {
        match (k.linear_deg, k.stokes) {
            (Some(linear_deg), None) => Ok(SourcePolarizationSpec::Linear { linear_deg }),
            (None, Some(stokes)) => Ok(SourcePolarizationSpec::Stokes { stokes }),
            _ => Err(
                "polarization: give one of { linear_deg = D } or { stokes = [S0, S1, S2, S3] }"
                    .into(),
            ),
        }
    }
}

impl schemars::JsonSchema for SourcePolarizationSpec {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "SourcePolarizationSpec".into()
    }

    /// One of the two closed tables `Keys` and its `try_from` accept.
    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({
            "description": "The state of the emitted light, relative to the source's u axis made perpendicular to each photon's direction; unpolarized without it.",
            "oneOf": [
                {
                    "type": "object",
                    "properties": { "linear_deg": {
                        "type": "number",
                        "description": "Fully linearly polarized at this angle (degrees) from u towards v = direction x u."
                    } },
                    "required": ["linear_deg"],
                    "additionalProperties": false
                },
                {
                    "type": "object",
                    "properties": { "stokes": {
                        "type": "array", "items": { "type": "number" }, "minItems": 4, "maxItems": 4,
                        "description": "A Stokes vector [S0, S1, S2, S3] (scaled to S0 = 1)."
                    } },
                    "required": ["stokes"],
                    "additionalProperties": false
                }
            ]
        })
    }
}

impl SourcePolarizationSpec {
    /// Check the entry at `field` and give its state, of unit power.
    pub fn build(&self, ctx: &Ctx, field: &str) -> Result<Stokes> {
        match *self {
            SourcePolarizationSpec::Linear { linear_deg } => {
                let deg = ctx.angle_deg(&format!("{field}.linear_deg"), linear_deg)?;
                Ok(Stokes::linear_deg(deg))
            }
            SourcePolarizationSpec::Stokes { stokes } => {
                let at = format!("{field}.stokes");
                for (k, s) in stokes.iter().enumerate() {
                    ctx.finite(&format!("{at}[{k}]"), *s)?;
                }
                if stokes[0] <= 0.0 {
                    return Err(ctx.err(&at, "S0 (the power) must be positive"));
                }
                let state = Stokes(stokes).normalized();
                if state.dop() > 1.0 + 1e-9 {
                    return Err(ctx.err(
                        &at,
                        format!(
                            "degree of polarization {} is more than 1: S1^2 + S2^2 + S3^2 may not exceed S0^2",
                            crate::spec_check::short(state.dop())
                        ),
                    ));
                }
                Ok(state)
            }
        }
    }
}
