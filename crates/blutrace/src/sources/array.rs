//! Source rows: one `[[sources]]` entry standing for `count` identical sources, `pitch_mm`
//! apart along `direction` and centred on the entry's `center`.
//!
//! ```toml
//! [[sources]]
//! type = "ccfl"
//! name = "lamp"                  # the copies are lamp.0, lamp.1, ...
//! center = [200.0, 125.0, 8.0]   # the middle of the row
//! axis = [0.0, 1.0, 0.0]
//! radius_mm = 1.5
//! length_mm = 240.0
//! power_w = 1.0                  # per lamp
//! array = { count = 6, pitch_mm = 66.67, direction = [1.0, 0.0, 0.0] }
//! ```
//!
//! A layout becomes two numbers (`sources.0.array.count`, `sources.0.array.pitch_mm`) for
//! `blutrace optimize --vary`. Every copy is the entry as written, `power_w` included: a
//! row of `count` lamps emits `count` times the entry's power. CCFL tubes of one row must
//! not overlap (their axes at least a diameter apart across the tube).

use super::Source;
use crate::spec_check::Ctx;
use anyhow::Result;
use serde::{Deserialize, Serialize};

/// Most sources one row may hold.
pub const MAX_COUNT: usize = 100_000;

/// `array = { ... }` of a `[[sources]]` entry.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ArraySpec {
    /// Number of sources in the row (at least 1).
    pub count: usize,
    /// Distance between neighbours (mm).
    pub pitch_mm: f64,
    /// Direction of the row.
    pub direction: [f64; 3],
}

/// The sources of entry `i`: `source` itself, or its row when the entry has an `array`.
pub fn replicate(
    ctx: &Ctx,
    i: usize,
    source: Source,
    array: Option<&ArraySpec>,
) -> Result<Vec<Source>> {
    let Some(a) = array else {
        return Ok(vec![source]);
    };
    let f = |k: &str| format!("sources[{i}].array.{k}");
    if !(1..=MAX_COUNT).contains(&a.count) {
        return Err(ctx.err(
            &f("count"),
            format!("must be within 1..={MAX_COUNT}, got {}", a.count),
        ));
    }
    let pitch = ctx.non_negative(&f("pitch_mm"), a.pitch_mm)?;
    if a.count > 1 {
        ctx.length(&f("pitch_mm"), pitch)?;
    }
    let d = ctx.direction(&f("direction"), a.direction)?;
    if a.count > 1
        && let Some(why) = source.emitter.copies_overlap(d, pitch)
    {
        return Err(ctx.err(&f("pitch_mm"), why));
    }
    let span = pitch * (a.count - 1) as f64;
    let half = 0.5 * span;
    ctx.point(&f("pitch_mm"), (source.anchor() + d * half).to_array())?;
    Ok((0..a.count)
        .map(|k| {
            let mut s = source.clone();
            s.name = format!("{}.{k}", source.name);
            s.translate(d * (k as f64 * pitch - half));
            s
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sources::Emitter;
    use crate::sources::ccfl::Tube;
    use glam::DVec3;
    use std::path::Path;

    fn tube() -> Source {
        Source {
            name: "lamp".into(),
            power_w: 2.0,
            lumens: None,
            spectrum: None,
            polarization: None,
            emitter: Emitter::Ccfl(Tube {
                center: DVec3::new(10.0, 0.0, 5.0),
                axis: DVec3::Y,
                radius: 1.5,
                length: 100.0,
            }),
            medium: 0,
            body: None,
        }
    }

    fn row(count: usize, pitch_mm: f64, direction: [f64; 3]) -> Result<Vec<Source>> {
        let a = ArraySpec {
            count,
            pitch_mm,
            direction,
        };
        replicate(&Ctx(Path::new("s.toml")), 0, tube(), Some(&a))
    }

    #[test]
    fn a_row_is_centred_on_the_entry() {
        let r = row(4, 20.0, [2.0, 0.0, 0.0]).unwrap();
        let x: Vec<f64> = r.iter().map(|s| s.anchor().x).collect();
        assert_eq!(x, vec![-20.0, 0.0, 20.0, 40.0]);
        assert!(r.iter().all(|s| s.anchor().z == 5.0 && s.power_w == 2.0));
        let names: Vec<&str> = r.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, vec!["lamp.0", "lamp.1", "lamp.2", "lamp.3"]);
        assert_eq!(
            row(1, 0.0, [1.0, 0.0, 0.0]).unwrap(),
            vec![Source {
                name: "lamp.0".into(),
                ..tube()
            }]
        );
    }

    #[test]
    fn bad_rows_name_the_field() {
        for (r, says) in [
            (
                row(0, 20.0, [1.0, 0.0, 0.0]),
                "sources[0].array.count: must be within 1",
            ),
            (
                row(3, -1.0, [1.0, 0.0, 0.0]),
                "sources[0].array.pitch_mm: must be >= 0",
            ),
            (
                row(3, 0.0, [1.0, 0.0, 0.0]),
                "sources[0].array.pitch_mm: must be > 0",
            ),
            (row(3, 2.0, [1.0, 0.0, 0.0]), "the tubes overlap"),
            (
                row(3, 20.0, [0.0, 0.0, 0.0]),
                "sources[0].array.direction: must be a non-zero",
            ),
        ] {
            let e = format!("{:#}", r.unwrap_err());
            assert!(e.contains(says), "{e}");
        }
        // End to end along the axis, tubes do not overlap.
        assert_eq!(row(2, 100.0, [0.0, 1.0, 0.0]).unwrap().len(), 2);
    }
}
