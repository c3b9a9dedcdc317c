//! The JSON Schema (draft 2020-12) of the scene file, generated from the types that read
//! it ([`SceneFile`] and the specs under it, through `schemars`): what `blutrace schema`
//! prints and what editors check scene files against (`.taplo.toml`). Doc comments become
//! descriptions, with their units. Tables the loader closes (`deny_unknown_fields`) are
//! closed here (`additionalProperties: false`); tables read by a key that picks their type
//! (`[surfaces.*]`'s `model`, `[[sources]]`' `type`) are a `oneOf` of one closed table per
//! choice, the key a `const` in each.
//!
//! The schema checks keys and types, as the loader's reading does; the loader's checks of
//! values (ranges, geometry, files) come after and have no counterpart here.

use super::config::SceneFile;
use schemars::{JsonSchema, Schema, SchemaGenerator, json_schema};
use serde_json::Value;

/// The scene file's schema as JSON.
pub fn scene_schema() -> Value {
    let mut schema = schemars::schema_for!(SceneFile);
    let object = schema.ensure_object();
    object.insert("title".into(), "blutrace scene file".into());
    let mut value = Value::Object(object.clone());
    tidy_descriptions(&mut value);
    value
}

/// Descriptions as plain text: a doc comment's wrapped lines joined, its links to Rust
/// items (`[`super::mie`]`) written as the item's name.
fn tidy_descriptions(value: &mut Value) {
    match value {
        Value::Object(map) => {
            for (key, v) in map.iter_mut() {
                match v {
                    Value::String(text) if key == "description" => *text = tidy(text),
                    v => tidy_descriptions(v),
                }
            }
        }
        Value::Array(items) => items.iter_mut().for_each(tidy_descriptions),
        _ => {}
    }
}

fn tidy(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(start) = rest.find("[`") {
        let Some(len) = rest[start..].find("`]") else {
            break;
        };
        let path = &rest[start + 2..start + len];
        let name = path.rsplit("::").next().unwrap_or(path);
        out.push_str(&rest[..start]);
        out.push('`');
        out.push_str(name.rsplit('@').next().unwrap_or(name));
        out.push('`');
        rest = &rest[start + len + 2..];
    }
    out.push_str(rest);
    out.split("\n\n")
        .map(|paragraph| paragraph.replace('\n', " "))
        .collect::<Vec<_>>()
        .join("\n\n")
}

/// The schema of a spec (`T`, a closed table) as one choice of a table whose `tag` key
/// picks the type: `T`'s own table with `tag = name` added (a `const`) and required, and
/// any `extra` properties (the `back` every `[surfaces.*]` table may carry).
pub fn tagged<T: JsonSchema>(
    generator: &mut SchemaGenerator,
    tag: &str,
    name: &str,
    description: &str,
    extra: &[(&str, Schema)],
) -> Schema {
    let mut schema = T::json_schema(generator);
    let object = schema.ensure_object();
    let properties = object
        .entry("properties")
        .or_insert_with(|| Value::Object(Default::default()));
    if let Value::Object(properties) = properties {
        properties.insert(tag.into(), json_schema!({ "const": name }).to_value());
        for (key, value) in extra {
            properties.insert((*key).into(), value.clone().to_value());
        }
    }
    let required = object
        .entry("required")
        .or_insert_with(|| Value::Array(Vec::new()));
    if let Value::Array(required) = required {
        required.insert(0, tag.into());
    }
    object.insert("title".into(), format!("{tag} = \"{name}\"").into());
    if !description.is_empty() {
        object.insert("description".into(), description.into());
    }
    schema
}

/// A `oneOf` of `choices`, with a description.
pub fn one_of(description: &str, choices: Vec<Schema>) -> Schema {
    let choices: Vec<Value> = choices.into_iter().map(Schema::to_value).collect();
    json_schema!({ "description": description, "oneOf": choices })
}
