//! The `placement` of a dots pattern: which of the ways to place its dots (see
//! [`super::dot_placement`] for where each way puts them).
//!
//! ```toml
//! [surfaces.lgp_back]
//! model = "dots"
//! placement = "stochastic"   # "lattice" (default), "jittered", "stochastic" or "virtual"
//! placement_seed = 7         # jittered, stochastic: which random screen (default 0)
//! ```

use crate::spec_check::Ctx;
use anyhow::Result;

/// How the dots of a pattern are placed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Placement {
    /// At the lattice's cell centres.
    #[default]
    Lattice,
    /// Each moved within its cell by a pseudo-random offset, without overlap.
    Jittered,
    /// A coverage-corrected Poisson screen (overlap allowed).
    Stochastic,
    /// No printed dots: ink with probability `d` per hit.
    Virtual,
}

impl serde::Serialize for Placement {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// Largest `placement_seed`: TOML integers are signed 64-bit.
pub const MAX_PLACEMENT_SEED: i64 = i64::MAX;

impl Placement {
    /// Every placement, by its scene-file name.
    pub const ALL: [(&'static str, Placement); 4] = [
        ("lattice", Placement::Lattice),
        ("jittered", Placement::Jittered),
        ("stochastic", Placement::Stochastic),
        ("virtual", Placement::Virtual),
    ];

    /// The scene-file name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, p)| *p == self)
            .map_or("lattice", |(n, _)| n)
    }

    /// The placement named `name` (`None`: the default), else an error at `field`.
    pub fn parse(ctx: &Ctx, field: &str, name: Option<&str>) -> Result<Placement> {
        let Some(name) = name else {
            return Ok(Placement::default());
        };
        Self::ALL
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, p)| *p)
            .ok_or_else(|| {
                ctx.err(
                    field,
                    format!(
                        "unknown placement \"{name}\": use \"lattice\", \"jittered\", \"stochastic\" or \"virtual\""
                    ),
                )
            })
    }

    /// False for `virtual`, which prints nothing.
    pub fn printable(self) -> bool {
        self != Placement::Virtual
    }

    /// Whether `placement_seed` means anything (the random screens, and `virtual`, whose
    /// printable stand-in an export may draw).
    fn uses_seed(self) -> bool {
        self != Placement::Lattice
    }

    /// Check `placement_seed` (at `field`) for this placement; `None` gives 0.
    pub fn seed(self, ctx: &Ctx, field: &str, seed: Option<i64>) -> Result<u64> {
        match seed {
            None => Ok(0),
            Some(_) if !self.uses_seed() => Err(ctx.err(
                field,
                "only the jittered and stochastic placements (and virtual, for exports) take a seed; the lattice has no randomness",
            )),
            Some(s) if s < 0 => Err(ctx.err(
                field,
                format!("{s} is out of range: give a whole number from 0 to {MAX_PLACEMENT_SEED}"),
            )),
            Some(s) => Ok(s as u64),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn placements_parse_by_name() {
        let ctx = Ctx(std::path::Path::new("scene.toml"));
        for (name, p) in Placement::ALL {
            assert_eq!(Placement::parse(&ctx, "f", Some(name)).unwrap(), p);
            assert_eq!(p.name(), name);
        }
        assert_eq!(
            Placement::parse(&ctx, "f", None).unwrap(),
            Placement::Lattice
        );
        assert!(Placement::parse(&ctx, "f", Some("Lattice")).is_err());
        assert_eq!(
            Placement::Stochastic
                .seed(&ctx, "f", Some(i64::MAX))
                .unwrap(),
            i64::MAX as u64
        );
        assert!(Placement::Virtual.printable() != Placement::Jittered.printable());
    }
}
