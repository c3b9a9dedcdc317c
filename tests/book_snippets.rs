//! Every ```toml block of the book (`docs/book/src`) and the README is read as the loader
//! reads it:
//! - every block parses as TOML;
//! - a whole scene (with `version`, `surfaces`, `sources` and `detector`) is loaded with
//!   every check ([`Scene::load`]) from a temporary folder holding a copy of the bundled
//!   scene folder whose files it names (or nothing, when it names none);
//! - a fragment (`[surfaces.X]`, `[[sources]]`, `[detector]`, ...) has each table read by
//!   the loader's own spec type (unknown keys and wrong types are errors there); a
//!   `[[sources]]`, `[detector]` or `[trace]` table that elides keys (`# ...`) is laid over
//!   a bundled scene's table of its kind first. A fragment of only sources, media,
//!   detector, trace and opaque surfaces that names no file is also spliced into
//!   `scenes/bench-box` (an opaque surface onto its `reflector_sheet`) and loaded with every
//!   check;
//! - every whole scene validates against the scene file's JSON Schema (`blutrace schema`),
//!   and every table of a fragment (completed where it elides keys) against the schema of
//!   its kind;
//! - a block that shows every table of a scene at once rather than one backlight says so
//!   with `<!-- book_snippets: tables -->` on the line before its fence, and is read as a
//!   fragment.

#[path = "book/markdown.rs"]
mod markdown;

use blutrace::scene::Scene;
use blutrace::scene::config::{
    DetectorSpec, GeometrySpec, MediumSpec, ProceduralSpec, SourceSpec, SurfaceEntry, TraceSpec,
};
use blutrace::scene::schema::scene_schema;
use markdown::{pages, repo, split};
use std::collections::BTreeMap;
use std::path::Path;
use toml::{Table, Value};

/// The scene fragments are spliced into.
const BASE: &str = "scenes/bench-box";
/// The marker of a block read table by table, never as a whole scene.
const TABLES_ONLY: &str = "<!-- book_snippets: tables -->";
/// Keys whose value names a file (a spliced fragment naming one is not loaded).
const FILE_KEYS: [&str; 5] = ["file", "back_file", "intensity_file", "phase_file", "files"];

/// One ```toml block: where it is, its text, whether it is marked tables-only.
struct Snippet {
    at: String,
    text: String,
    tables_only: bool,
}

fn snippets_of(page: &Path) -> Vec<Snippet> {
    let text = std::fs::read_to_string(page).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let name = page
        .strip_prefix(repo())
        .unwrap_or(page)
        .display()
        .to_string();
    let (blocks, _) = split(&text);
    blocks
        .into_iter()
        .filter(|b| b.info.split([',', ' ']).next() == Some("toml"))
        .map(|b| Snippet {
            at: format!("{name}:{}", b.line),
            tables_only: b.line >= 2 && lines[b.line - 2].trim() == TABLES_ONLY,
            text: b.text,
        })
        .collect()
}

fn read_toml(path: &str) -> Table {
    toml::from_str(&std::fs::read_to_string(repo().join(path)).unwrap()).unwrap()
}

/// A bundled scene's first source of `kind`, to lay an elided fragment over.
fn base_source(kind: &str) -> Option<Table> {
    [
        "scenes/bench-box/scene.toml",
        "scenes/notebook14/scene.toml",
    ]
    .iter()
    .find_map(|scene| {
        read_toml(scene)["sources"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_table().unwrap())
            .find(|s| s.get("type").and_then(Value::as_str) == Some(kind))
            .cloned()
    })
}

fn overlay(mut base: Table, over: &Table) -> Table {
    for (k, v) in over {
        base.insert(k.clone(), v.clone());
    }
    base
}

/// `over` completed from the bundled table of its kind when it elides keys.
fn completed(over: &Table, base: Option<Table>, elided: bool) -> Table {
    match base {
        Some(base) if elided => overlay(base, over),
        _ => over.clone(),
    }
}

fn typed<T: serde::de::DeserializeOwned>(value: &Value, what: &str) -> Result<T, String> {
    value
        .clone()
        .try_into::<T>()
        .map_err(|e| format!("{what}: {e}"))
}

/// Reads each table of a fragment with the loader's spec type; returns the tables with
/// elided ones completed.
fn read_tables(doc: &Table, elided: bool) -> Result<Table, String> {
    let mut done = doc.clone();
    for (key, value) in doc {
        match key.as_str() {
            "version" | "name" | "description" => {}
            "geometry" => {
                typed::<Vec<GeometrySpec>>(value, key)?;
            }
            "procedural" => {
                typed::<Vec<ProceduralSpec>>(value, key)?;
            }
            "media" => {
                typed::<BTreeMap<String, MediumSpec>>(value, key)?;
            }
            "surfaces" => {
                typed::<BTreeMap<String, SurfaceEntry>>(value, key)?;
            }
            "sources" => {
                let mut sources = Vec::new();
                for (i, s) in value
                    .as_array()
                    .ok_or("sources: not an array")?
                    .iter()
                    .enumerate()
                {
                    let s = s.as_table().ok_or("sources: not tables")?;
                    let kind = s.get("type").and_then(Value::as_str).unwrap_or("");
                    let s = completed(s, base_source(kind), elided);
                    typed::<SourceSpec>(&Value::Table(s.clone()), &format!("sources[{i}]"))?;
                    sources.push(Value::Table(s));
                }
                done.insert(key.clone(), Value::Array(sources));
            }
            "detector" => {
                let base = read_toml(&format!("{BASE}/scene.toml"))["detector"]
                    .as_table()
                    .cloned();
                let d = completed(
                    value.as_table().ok_or("detector: not a table")?,
                    base,
                    elided,
                );
                typed::<DetectorSpec>(&Value::Table(d.clone()), key)?;
                done.insert(key.clone(), Value::Table(d));
            }
            "trace" => {
                typed::<TraceSpec>(value, key)?;
            }
            other => return Err(format!("{other}: not a key of a scene file")),
        }
    }
    Ok(done)
}

fn names_a_file(value: &Value) -> bool {
    match value {
        Value::Table(t) => t
            .iter()
            .any(|(k, v)| FILE_KEYS.contains(&k.as_str()) || names_a_file(v)),
        Value::Array(a) => a.iter().any(names_a_file),
        _ => false,
    }
}

const OPAQUE: [&str; 4] = ["lambert", "phong", "mirror", "absorber"];

/// The fragment laid into the base scene, or `None` when it cannot stand there.
fn spliced(doc: &Table) -> Option<Table> {
    if names_a_file(&Value::Table(doc.clone())) {
        return None;
    }
    let mut base = read_toml(&format!("{BASE}/scene.toml"));
    for (key, value) in doc {
        match key.as_str() {
            "sources" => {
                base.insert(key.clone(), value.clone());
            }
            "detector" | "trace" => {
                let merged = overlay(
                    base[key].as_table().cloned().unwrap_or_default(),
                    value.as_table()?,
                );
                base.insert(key.clone(), Value::Table(merged));
            }
            "media" => {
                let media = base.get_mut("media")?.as_table_mut()?;
                for (name, m) in value.as_table()? {
                    media.insert(name.clone(), m.clone());
                }
            }
            "surfaces" => {
                let tables = value.as_table()?;
                let [(_, surface)] = tables.iter().collect::<Vec<_>>()[..] else {
                    return None;
                };
                let model = surface.get("model")?.as_str()?;
                if !OPAQUE.contains(&model) {
                    return None;
                }
                base["surfaces"]
                    .as_table_mut()?
                    .insert("reflector_sheet".into(), surface.clone());
            }
            _ => return None,
        }
    }
    Some(base)
}

fn is_whole(doc: &Table) -> bool {
    ["version", "surfaces", "sources", "detector"]
        .iter()
        .all(|k| doc.contains_key(*k))
}

/// The bundled scene folder holding every file a whole scene names (geometry), if any.
fn folder_for(doc: &Table) -> Option<std::path::PathBuf> {
    let files: Vec<&str> = doc
        .get("geometry")
        .and_then(Value::as_array)
        .map(|g| {
            g.iter()
                .filter_map(|e| e.get("file").and_then(Value::as_str))
                .collect()
        })
        .unwrap_or_default();
    if files.is_empty() {
        return None;
    }
    std::fs::read_dir(repo().join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|dir| files.iter().all(|f| dir.join(f).is_file()))
}

fn load(doc: &Table, folder: Option<&Path>) -> Result<(), String> {
    let dir = tempfile::tempdir().unwrap();
    if let Some(folder) = folder {
        for entry in std::fs::read_dir(folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_file() {
                std::fs::copy(&path, dir.path().join(path.file_name().unwrap())).unwrap();
            }
        }
    }
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, toml::to_string(doc).unwrap()).unwrap();
    Scene::load(&path).map(drop).map_err(|e| format!("{e:#}"))
}

#[derive(Debug, Default, PartialEq)]
struct Counts {
    whole: usize,
    spliced: usize,
    tables: usize,
}

/// Validates `value` against the scene file's schema, or against its definition `def`.
fn validate(value: &Value, def: Option<&str>) -> Result<(), String> {
    let mut schema = scene_schema();
    if let Some(def) = def {
        let defs = schema["$defs"].clone();
        schema = serde_json::json!({ "$ref": format!("#/$defs/{def}"), "$defs": defs });
    }
    let validator = jsonschema::draft202012::new(&schema).unwrap();
    let json = serde_json::to_value(value).unwrap();
    let errors: Vec<String> = validator
        .iter_errors(&json)
        .map(|e| format!("{}: {e}", e.instance_path()))
        .collect();
    match errors.is_empty() {
        true => Ok(()),
        false => Err(format!(
            "the schema{} refuses it: {}",
            def.map(|d| format!("'s {d}")).unwrap_or_default(),
            errors.join("; ")
        )),
    }
}

/// Validates each table of a (completed) fragment against the schema of its kind.
fn validate_tables(doc: &Table) -> Result<(), String> {
    for (key, value) in doc {
        let each = |def: &str| -> Result<(), String> {
            match value {
                Value::Array(items) => items.iter().try_for_each(|i| validate(i, Some(def))),
                Value::Table(t) => t.values().try_for_each(|i| validate(i, Some(def))),
                _ => Err(format!("{key}: not a table")),
            }
        };
        match key.as_str() {
            "geometry" => each("GeometrySpec")?,
            "procedural" => each("ProceduralSpec")?,
            "media" => each("MediumSpec")?,
            "surfaces" => each("SurfaceEntry")?,
            "sources" => each("SourceSpec")?,
            "detector" => validate(value, Some("DetectorSpec"))?,
            "trace" => validate(value, Some("TraceSpec"))?,
            _ => {}
        }
    }
    Ok(())
}

/// Checks one snippet; says how it was checked.
fn check(s: &Snippet, counts: &mut Counts) -> Result<(), String> {
    let doc: Table = toml::from_str(&s.text).map_err(|e| format!("not TOML: {e}"))?;
    let elided = s.text.lines().any(|l| l.trim() == "# ...");
    if is_whole(&doc) && !s.tables_only {
        let folder = folder_for(&doc);
        counts.whole += 1;
        validate(&Value::Table(doc.clone()), None)?;
        return load(&doc, folder.as_deref());
    }
    let done = read_tables(&doc, elided)?;
    validate_tables(&done)?;
    match spliced(&done) {
        Some(scene) => {
            counts.spliced += 1;
            load(&scene, Some(&repo().join(BASE))).map_err(|e| format!("spliced into {BASE}: {e}"))
        }
        None => {
            counts.tables += 1;
            Ok(())
        }
    }
}

#[test]
fn every_toml_snippet_is_a_scene_or_a_fragment_the_loader_reads() {
    let mut counts = Counts::default();
    let mut failures = Vec::new();
    for page in pages() {
        for s in snippets_of(&page) {
            let before = (counts.whole, counts.spliced);
            if let Err(e) = check(&s, &mut counts) {
                failures.push(format!("{}: {e}", s.at));
            }
            let how = match (counts.whole - before.0, counts.spliced - before.1) {
                (1, _) => "loaded whole",
                (_, 1) => "spliced and loaded",
                _ => "read table by table",
            };
            println!("{}: {how}", s.at);
        }
    }
    println!("toml snippets: {counts:?}");
    assert!(
        failures.is_empty(),
        "snippets the loader refuses:\n{}",
        failures.join("\n")
    );
    // The README's scene is loaded whole; the reference's tables are spliced or read.
    assert!(
        counts.whole >= 1 && counts.spliced >= 3 && counts.tables >= 5,
        "{counts:?}"
    );
}

fn one(text: &str, tables_only: bool) -> (Result<(), String>, Counts) {
    let mut counts = Counts::default();
    let s = Snippet {
        at: "t".into(),
        text: text.into(),
        tables_only,
    };
    (check(&s, &mut counts), counts)
}

#[test]
fn a_snippet_the_loader_would_refuse_is_refused() {
    // An unknown key in a fragment, a wrong type, a value the checks refuse once spliced,
    // and a whole scene that does not load.
    let (r, _) = one(
        "[surfaces.sheet]\nmodel = \"lambert\"\nalbedo = 0.9\ncolour = 1\n",
        false,
    );
    assert!(r.unwrap_err().contains("colour"));
    let (r, _) = one("[detector]\n# ...\nbins = \"many\"\n", false);
    assert!(r.unwrap_err().contains("detector"));
    let (r, c) = one(
        "[surfaces.sheet]\nmodel = \"lambert\"\nalbedo = 1.5\n",
        false,
    );
    assert_eq!(c.spliced, 1);
    assert!(r.unwrap_err().contains("surfaces.reflector_sheet.albedo"));
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    let scene = snippets_of(&repo().join("README.md")).remove(0).text;
    assert!(readme.contains(&scene));
    let (r, c) = one(&scene.replace("radius_mm = 1.5", "radius_mm = -1.5"), false);
    assert_eq!(c.whole, 1);
    assert!(r.unwrap_err().contains("sources[0].radius_mm"));
    let (r, c) = one(&scene, false);
    assert_eq!((r, c.whole), (Ok(()), 1));
    // A key the schema does not know, in a fragment read table by table.
    let (r, _) = one("[[geometry]]\nfile = \"a.obj\"\nunit = \"mm\"\n", false);
    assert!(r.unwrap_err().contains("unit"));
    // Marked: read table by table.
    let (r, c) = one(&scene, true);
    assert_eq!((r, c.whole), (Ok(()), 0));
}
