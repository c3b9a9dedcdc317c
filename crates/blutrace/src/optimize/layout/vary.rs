//! `--vary KEY=MIN..MAX`: any number of the scene file as a variable of the search.
//!
//! ```text
//! blutrace optimize scenes/direct-lit --vary 'sources.*.center.2=4..20' --vary sources.0.array.pitch_mm=40..80
//! ```
//!
//! `KEY` is a dotted path into the scene file as written (not its defaults): table keys,
//! array indices from 0, and `*` for every element of an array, all set to the one value
//! of the variable ("moved together"; they must agree in the file). The path must end at
//! a number. A key whose field is an integer (a source row's `count`) is an integer
//! variable: the search enumerates every integer of its range and optimizes the others for
//! each. Unknown paths, non-numbers and empty, inverted or non-finite ranges are errors
//! naming the key.

use crate::scene::config::SceneFile;
use crate::scene::key_path::{self, Place, get, get_mut, kind, show};
use anyhow::{Context, Result, bail};
use serde::Serialize;
use toml::Value;

/// A `--vary` argument as given: the key and its range.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VarySpec {
    /// The dotted path.
    pub key: String,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

impl std::str::FromStr for VarySpec {
    type Err = String;

    /// `KEY=MIN..MAX`.
    fn from_str(s: &str) -> Result<Self, String> {
        let (key, range) = s
            .split_once('=')
            .ok_or_else(|| format!("expected KEY=MIN..MAX, got '{s}'"))?;
        let key = key.trim();
        if key.is_empty() || key.split('.').any(str::is_empty) {
            return Err(format!(
                "'{s}': the key must be a dotted path such as sources.0.center.2"
            ));
        }
        let (lo, hi) = range
            .split_once("..")
            .ok_or_else(|| format!("{key}: expected a range MIN..MAX, got '{range}'"))?;
        let number = |t: &str| {
            t.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("{key}: '{}' is not a finite number", t.trim()))
        };
        let (min, max) = (number(lo)?, number(hi)?);
        if min >= max {
            return Err(format!(
                "{key}: the range {}..{} is empty or inverted",
                crate::spec_check::short(min),
                crate::spec_check::short(max)
            ));
        }
        Ok(VarySpec {
            key: key.to_string(),
            min,
            max,
        })
    }
}

/// A variable resolved against a scene file: the places it sets and its value there.
#[derive(Clone, Debug, Serialize)]
pub struct Variable {
    /// The key as given.
    pub name: String,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// The scene file's value.
    pub initial: f64,
    /// Whether the field is an integer (enumerated, not searched).
    pub integer: bool,
    /// Every place the variable sets (one, or every element of a `*`).
    #[serde(skip)]
    places: Vec<Place>,
}

impl Variable {
    /// Resolve `spec` in the scene file `doc`; errors name the key.
    pub fn resolve(doc: &Value, spec: &VarySpec) -> Result<Variable> {
        let key = &spec.key;
        if key.split('.').next() == Some("trace") {
            bail!(
                "option `vary` {key}: [trace] holds how a run is traced (photons, seed, max_bounces), \
                 which the search sets itself (option `photons`, option `seed`); vary a number of the design"
            );
        }
        let places = key_path::resolve(doc, key).with_context(|| format!("option `vary` {key}"))?;
        let values: Vec<&Value> = places.iter().map(|p| get(doc, p)).collect();
        let numbers: Vec<f64> = values
            .iter()
            .zip(&places)
            .map(|(v, p)| match v {
                Value::Integer(i) => Ok(*i as f64),
                Value::Float(x) => Ok(*x),
                other => bail!(
                    "option `vary` {key}: {} is {}, not a number",
                    show(p),
                    kind(other)
                ),
            })
            .collect::<Result<_>>()?;
        let initial = numbers[0];
        if let Some(i) = numbers.iter().position(|x| *x != initial) {
            bail!(
                "option `vary` {key}: the elements differ ({} = {initial}, {} = {}); a `*` variable \
                 sets them all to one value",
                show(&places[0]),
                show(&places[i]),
                numbers[i]
            );
        }
        let integer = values.iter().all(|v| v.is_integer()) && !accepts_float(doc, &places);
        if integer && spec.min.ceil() > spec.max.floor() {
            bail!(
                "option `vary` {key}: an integer field, and {}..{} holds no integer",
                crate::spec_check::short(spec.min),
                crate::spec_check::short(spec.max)
            );
        }
        Ok(Variable {
            name: key.clone(),
            min: spec.min,
            max: spec.max,
            initial,
            integer,
            places,
        })
    }

    /// Set the variable to `x` in `doc` (rounded for an integer field).
    pub fn set(&self, doc: &mut Value, x: f64) {
        for p in &self.places {
            *get_mut(doc, p) = if self.integer {
                Value::Integer(x.round() as i64)
            } else {
                Value::Float(x)
            };
        }
    }

    /// Whether the two variables set a number in common.
    pub fn overlaps(&self, other: &Variable) -> bool {
        self.places.iter().any(|p| other.places.contains(p))
    }

    /// Whether `x` lies within the range.
    pub fn contains(&self, x: f64) -> bool {
        (self.min..=self.max).contains(&x)
    }

    /// The integers of an integer variable's range.
    pub fn integers(&self) -> Vec<f64> {
        let (lo, hi) = (self.min.ceil() as i64, self.max.floor() as i64);
        (lo..=hi).map(|i| i as f64).collect()
    }
}

/// Whether the scene file still parses with a fractional number at `places`.
fn accepts_float(doc: &Value, places: &[Place]) -> bool {
    let mut probe = doc.clone();
    for p in places {
        let v = get_mut(&mut probe, p);
        *v = Value::Float(v.as_integer().unwrap_or(0) as f64 + 0.5);
    }
    probe.try_into::<SceneFile>().is_ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"
version = 1
[[geometry]]
file = "box.obj"
[surfaces.wall]
model = "lambert"
albedo = 0.9
[[sources]]
type = "ccfl"
name = "a"
center = [-10.0, 0.0, 5.0]
axis = [0.0, 1.0, 0.0]
radius_mm = 1.0
length_mm = 50.0
power_w = 1.0
[[sources]]
type = "ccfl"
name = "b"
center = [10.0, 0.0, 5.0]
axis = [0.0, 1.0, 0.0]
radius_mm = 1.0
length_mm = 50.0
power_w = 1.0
[detector]
origin = [0.0, 0.0, 10.0]
u = [1.0, 0.0, 0.0]
v = [0.0, 1.0, 0.0]
size_mm = [40.0, 40.0]
bins = [10, 10]
"#;

    fn doc() -> Value {
        toml::from_str(SCENE).unwrap()
    }

    fn spec(s: &str) -> VarySpec {
        s.parse().unwrap()
    }

    #[test]
    fn ranges_parse_and_bad_ones_name_the_key() {
        assert_eq!(
            spec("sources.0.center.2=-1.5..2e1"),
            VarySpec {
                key: "sources.0.center.2".into(),
                min: -1.5,
                max: 20.0
            }
        );
        for (bad, says) in [
            ("a.b=3..3", "a.b: the range 3..3 is empty"),
            ("a.b=4..3", "a.b: the range 4..3 is empty or inverted"),
            ("a.b=x..3", "a.b: 'x' is not a finite number"),
            ("a.b=1..inf", "a.b: 'inf' is not a finite number"),
            ("a.b=1", "a.b: expected a range"),
            ("a..b=1..2", "dotted path"),
            ("a.b", "expected KEY=MIN..MAX"),
        ] {
            let e = bad.parse::<VarySpec>().unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }

    #[test]
    fn a_path_is_set_and_read_back() {
        let mut d = doc();
        let v = Variable::resolve(&d, &spec("sources.1.center.2=2..9")).unwrap();
        assert_eq!((v.initial, v.integer), (5.0, false));
        v.set(&mut d, 7.25);
        assert_eq!(d["sources"][1]["center"][2].as_float(), Some(7.25));
        assert_eq!(d["sources"][0]["center"][2].as_float(), Some(5.0));
        let file: SceneFile = d.try_into().unwrap();
        let crate::sources::SourceSpec::Ccfl(tube) = &file.sources[1] else {
            panic!()
        };
        assert_eq!(tube.center[2], 7.25);
    }

    #[test]
    fn a_star_moves_every_element_together() {
        let mut d = doc();
        let v = Variable::resolve(&d, &spec("sources.*.center.2=2..9")).unwrap();
        v.set(&mut d, 3.5);
        for s in d["sources"].as_array().unwrap() {
            assert_eq!(s["center"][2].as_float(), Some(3.5));
        }
        let e = Variable::resolve(&d, &spec("sources.*.center.0=-20..20")).unwrap_err();
        assert!(format!("{e:#}").contains("the elements differ"), "{e:#}");
    }

    #[test]
    fn integer_fields_are_integer_variables() {
        let d = doc();
        let v = Variable::resolve(&d, &spec("detector.bins.0=4.5..8")).unwrap();
        assert!(v.integer);
        assert_eq!(v.integers(), vec![5.0, 6.0, 7.0, 8.0]);
        assert!(Variable::resolve(&d, &spec("detector.bins.0=4.2..4.8")).is_err());
    }

    #[test]
    fn unknown_paths_and_non_numbers_are_errors_naming_the_key() {
        let d = doc();
        for (key, says) in [
            (
                "sources.2.center.0=0..1",
                "sources has 2 elements, no index 2",
            ),
            ("sources.x.center.0=0..1", "expected an index or *"),
            ("detector.nope=0..1", "no key 'nope' in detector"),
            ("trace.seed=0..1", "the search sets itself"),
            ("trace.photons=1..2", "the search sets itself"),
            (
                "sources.0.name=0..1",
                "sources.0.name is a string, not a number",
            ),
            (
                "detector.bins.0.x=0..1",
                "detector.bins.0 is an integer: nothing below it",
            ),
        ] {
            let e = format!("{:#}", Variable::resolve(&d, &spec(key)).unwrap_err());
            let k = key.split('=').next().unwrap();
            assert!(
                e.contains(&format!("option `vary` {k}")) && e.contains(says),
                "{key}: {e}"
            );
        }
    }
}
