//! Key paths into a scene file as written: a dotted path of table keys and array indices
//! from 0, with `*` for every element of an array. `blutrace optimize --vary` varies the
//! number a path names; [`Scene::get`] reads it and [`Scene::with`] makes the scene with
//! another value (a design study from a script):
//!
//! ```toml
//! [[sources]]             # sources.0
//! center = [0.0, 10.0, 0.3]   # sources.0.center.2 is 0.3; sources.*.center.2 names every source's
//! [surfaces.lgp_back]
//! ink_albedo = 0.9        # surfaces.lgp_back.ink_albedo
//! ```
//!
//! A path names what the file holds, not its defaults: a key left at its default must be
//! written into the file to be named.

use super::Scene;
use super::config::SceneFile;
use anyhow::{Context, Result, anyhow, bail};
use std::path::Path;
use toml::Value;

/// One step of a resolved path.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// A table key.
    Key(String),
    /// An array index.
    Index(usize),
}

/// A resolved path: the steps to one value.
pub type Place = Vec<Step>;

/// Every place `key` names in `doc` (one, or every element a `*` stands for); errors say
/// what is missing or not a table or array.
pub fn resolve(doc: &Value, key: &str) -> Result<Vec<Place>> {
    if key.is_empty() || key.split('.').any(str::is_empty) {
        bail!("'{key}' is not a dotted path such as sources.0.center.2");
    }
    let mut places = Vec::new();
    expand(
        doc,
        &key.split('.').collect::<Vec<_>>(),
        &mut Vec::new(),
        &mut places,
    )?;
    Ok(places)
}

impl Scene {
    /// The scene file as written (its TOML document).
    pub fn source(&self) -> &Value {
        &self.source
    }

    /// The scene file, parsed.
    pub fn file(&self) -> SceneFile {
        self.source
            .clone()
            .try_into()
            .expect("a scene's source parsed when it was loaded")
    }

    /// The value at `key` (for a `*`, the one value all its places hold).
    pub fn get(&self, key: &str) -> Result<Value> {
        let places = resolve(&self.source, key).with_context(|| self.at(key))?;
        let first = get(&self.source, &places[0]).clone();
        if let Some(p) = places.iter().find(|p| *get(&self.source, p) != first) {
            bail!(
                "{}: the elements differ ({} and {})",
                self.at(key),
                show(&places[0]),
                show(p)
            );
        }
        Ok(first)
    }

    /// This scene with `key` set to `value` at every place it names: loaded again from
    /// the edited file (every check runs; geometry paths stay relative to this scene's
    /// file). A whole number given for an integer field is that integer.
    pub fn with(&self, key: &str, value: impl Into<Value>) -> Result<Scene> {
        let value = value.into();
        let mut doc = self.source.clone();
        let places = resolve(&doc, key).with_context(|| self.at(key))?;
        for p in &places {
            let slot = get_mut(&mut doc, p);
            *slot = match (&*slot, &value) {
                (Value::Integer(_), Value::Float(x)) if x.fract() == 0.0 && x.abs() < 9e15 => {
                    Value::Integer(*x as i64)
                }
                _ => value.clone(),
            };
        }
        Scene::from_source(doc, &self.path)
            .with_context(|| format!("with {key} = {}", shown(&value)))
    }

    /// `key` in this scene's file, for messages.
    fn at(&self, key: &str) -> String {
        format!("{}: {key}", self.path.display())
    }

    /// Load the scene whose file, as written, is `doc` (geometry relative to `path`).
    pub fn from_source(doc: Value, path: &Path) -> Result<Scene> {
        let file: SceneFile = doc
            .clone()
            .try_into()
            .map_err(|e| anyhow!("{}: {e}", path.display()))?;
        super::array_lengths::check(&crate::spec_check::Ctx(path), &doc, &file)?;
        Scene::build(&file, doc, path, &super::meshio::ReadCache::default())
    }
}

/// Every concrete path `segments` names under `v` (`*` expanded), appended to `out`.
fn expand(v: &Value, segments: &[&str], at: &mut Vec<Step>, out: &mut Vec<Place>) -> Result<()> {
    let Some((first, rest)) = segments.split_first() else {
        out.push(at.clone());
        return Ok(());
    };
    match v {
        Value::Table(t) => {
            let Some(child) = t.get(*first) else {
                let keys: Vec<&str> = t.keys().map(String::as_str).collect();
                bail!(
                    "no key '{first}' in {} (the file has: {}; a key left at its default \
                     must be written into the scene file to be varied)",
                    show_or_root(at),
                    keys.join(", ")
                );
            };
            at.push(Step::Key(first.to_string()));
            expand(child, rest, at, out)?;
            at.pop();
        }
        Value::Array(a) => {
            let indices: Vec<usize> = if *first == "*" {
                if a.is_empty() {
                    bail!("{} is an empty array", show_or_root(at));
                }
                (0..a.len()).collect()
            } else {
                let i: usize = first.parse().map_err(|_| {
                    anyhow::anyhow!(
                        "{} is an array: expected an index or *, got '{first}'",
                        show_or_root(at)
                    )
                })?;
                if i >= a.len() {
                    bail!(
                        "{} has {} elements, no index {i}",
                        show_or_root(at),
                        a.len()
                    );
                }
                vec![i]
            };
            for i in indices {
                at.push(Step::Index(i));
                expand(&a[i], rest, at, out)?;
                at.pop();
            }
        }
        other => bail!(
            "{} is {}: nothing below it (left: {})",
            show_or_root(at),
            kind(other),
            segments.join(".")
        ),
    }
    Ok(())
}

pub fn get<'v>(mut v: &'v Value, path: &[Step]) -> &'v Value {
    for s in path {
        v = match s {
            Step::Key(k) => &v[k.as_str()],
            Step::Index(i) => &v[*i],
        };
    }
    v
}

pub fn get_mut<'v>(mut v: &'v mut Value, path: &[Step]) -> &'v mut Value {
    for s in path {
        v = match s {
            Step::Key(k) => v.get_mut(k.as_str()).expect("resolved path"),
            Step::Index(i) => v.get_mut(*i).expect("resolved path"),
        };
    }
    v
}

/// "a string", "an integer", ...
pub fn kind(v: &Value) -> String {
    let t = v.type_str();
    let article = if t.starts_with(['a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    };
    format!("{article} {t}")
}

/// A concrete path as dotted text.
pub fn show(path: &[Step]) -> String {
    path.iter()
        .map(|s| match s {
            Step::Key(k) => k.clone(),
            Step::Index(i) => i.to_string(),
        })
        .collect::<Vec<_>>()
        .join(".")
}

fn show_or_root(path: &[Step]) -> String {
    if path.is_empty() {
        "the scene file".into()
    } else {
        show(path)
    }
}

/// `value` as TOML for a message, its numbers short (`1e300`, not 301 digits).
fn shown(value: &Value) -> String {
    match value {
        Value::Float(x) => crate::spec_check::short(*x),
        Value::Array(a) => format!("[{}]", a.iter().map(shown).collect::<Vec<_>>().join(", ")),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc() -> Value {
        toml::from_str("a = [1, 2]\n[t]\nx = 0.5\n[[s]]\nc = [0.0, 3.0]\n[[s]]\nc = [1.0, 3.0]\n")
            .unwrap()
    }

    #[test]
    fn paths_resolve_with_stars_and_bad_ones_say_why() {
        let d = doc();
        assert_eq!(resolve(&d, "t.x").unwrap().len(), 1);
        let both = resolve(&d, "s.*.c.1").unwrap();
        assert_eq!(both.len(), 2);
        assert_eq!(get(&d, &both[1]), &Value::Float(3.0));
        for (key, says) in [
            ("t.y", "no key 'y' in t"),
            ("a.2", "a has 2 elements, no index 2"),
            ("a.x", "expected an index or *"),
            ("t.x.z", "t.x is a float: nothing below it"),
            ("t..x", "not a dotted path"),
        ] {
            let e = format!("{:#}", resolve(&d, key).unwrap_err());
            assert!(e.contains(says), "{key}: {e}");
        }
    }

    /// A value in a message prints short: `set("...power_w", 1e300)` said
    /// `with sources.0.power_w = 1000...` in 301 digits.
    #[test]
    fn values_in_messages_print_short() {
        assert_eq!(shown(&Value::Float(1e300)), "1e300");
        assert_eq!(shown(&Value::Float(-2.5e-300)), "-2.5e-300");
        let a = Value::Array(vec![
            Value::Float(1e300),
            Value::Integer(3),
            Value::Float(0.5),
        ]);
        assert_eq!(shown(&a), "[1e300, 3, 0.5]");
        assert_eq!(shown(&Value::String("x".into())), "\"x\"");
    }
}
