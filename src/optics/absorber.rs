//! Black absorbers: every photon that meets the surface ends there.
//!
//! ```toml
//! [surfaces.housing]
//! model = "absorber"
//! ```

use serde::{Deserialize, Serialize};

/// `[surfaces.TAG]` with `model = "absorber"`: no parameters, nothing to check.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct AbsorberSpec {}
