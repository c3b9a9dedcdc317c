//! `blutrace schema`: the scene file's JSON Schema (draft 2020-12), generated from the types
//! that read it. Every bundled scene validates against it; what the loader cannot read (an
//! unknown key, a wrong type, an unknown model, an array of the wrong length) the schema
//! refuses too, and what the loader reads (whatever its later checks say) it accepts.

use blutrace::scene::Scene;
use blutrace::scene::schema::scene_schema;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn validator() -> jsonschema::Validator {
    jsonschema::draft202012::new(&scene_schema())
        .expect("the schema is a valid draft 2020-12 schema")
}

/// A TOML document as the JSON an editor's validator sees.
fn as_json(text: &str) -> Option<Value> {
    let doc: toml::Table = toml::from_str(text).ok()?;
    Some(serde_json::to_value(doc).unwrap())
}

/// The schema's complaints about a scene file's text.
fn complaints(v: &jsonschema::Validator, text: &str) -> Vec<String> {
    let json = as_json(text).expect("TOML");
    v.iter_errors(&json)
        .map(|e| format!("{}: {e}", e.instance_path()))
        .collect()
}

fn scene_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if path.is_dir() {
            scene_files(&path, out);
        } else if name.starts_with("scene") && name.ends_with(".toml") {
            out.push(path);
        }
    }
}

#[test]
fn every_bundled_scene_validates() {
    let v = validator();
    let mut scenes = Vec::new();
    scene_files(&repo().join("scenes"), &mut scenes);
    assert!(scenes.len() >= 15, "{scenes:?}");
    for scene in scenes {
        let errors = complaints(&v, &std::fs::read_to_string(&scene).unwrap());
        assert!(errors.is_empty(), "{}: {errors:#?}", scene.display());
    }
}

#[test]
fn the_command_prints_the_schema() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .arg("schema")
        .output()
        .unwrap();
    assert!(out.status.success());
    let printed: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(printed, scene_schema());
    assert_eq!(
        printed["$schema"],
        "https://json-schema.org/draft/2020-12/schema"
    );
    // Descriptions with units, from the doc comments; surfaces keyed on `model`.
    let text = printed.to_string();
    assert!(text.contains("Radius (mm)"), "no units in the descriptions");
    let surfaces = &printed["$defs"]["SurfaceEntry"]["oneOf"];
    let models: Vec<&str> = surfaces
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["properties"]["model"]["const"].as_str().unwrap())
        .collect();
    assert!(
        models.contains(&"dielectric") && models.contains(&"bsdf_table"),
        "{models:?}"
    );
    assert!(
        !text.contains("[`"),
        "a Rust doc link left in a description"
    );
}

/// A minimal scene the loader reads, to change in one place.
const PLATE: &str = r#"
version = 1
[[procedural]]
type = "direct_lit_box"
tag = "box"
origin = [0.0, 0.0, 0.0]
size_mm = [100.0, 60.0, 20.0]
ridge_height_mm = 0.0
[surfaces.box]
model = "lambert"
albedo = 0.95
[[sources]]
type = "ccfl"
center = [50.0, 30.0, 8.0]
axis = [0.0, 1.0, 0.0]
radius_mm = 1.5
length_mm = 55.0
power_w = 1.0
[detector]
origin = [0.0, 0.0, 20.0]
u = [1.0, 0.0, 0.0]
v = [0.0, 1.0, 0.0]
size_mm = [100.0, 60.0]
"#;

/// Loads `text` as a scene file; the error's text, if any.
fn load(text: &str) -> Result<(), String> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).map(drop).map_err(|e| format!("{e:#}"))
}

#[test]
fn the_schema_refuses_what_the_loader_cannot_read() {
    let v = validator();
    assert_eq!(load(PLATE), Ok(()));
    assert_eq!(complaints(&v, PLATE), Vec::<String>::new());
    let bad = [
        ("version = 1", "version = 1\ncolour = \"red\""), // unknown top-level key
        ("albedo = 0.95", "albedo = 0.95\nalbedoo = 0.9"), // unknown key of a model
        ("albedo = 0.95", "albedo = \"high\""),           // wrong type
        ("model = \"lambert\"", "model = \"lambertian\""), // unknown model
        ("type = \"ccfl\"", "type = \"cfl\""),            // unknown source type
        ("radius_mm = 1.5", "radius_mm = 1.5\nwidth_mm = 3.0"), // an LED's key on a CCFL
        (
            "size_mm = [100.0, 60.0]\n",
            "size_mm = [100.0, 60.0, 1.0]\n",
        ), // array too long
        ("center = [50.0, 30.0, 8.0]", "center = [50.0, 30.0]"), // array too short
        ("[detector]", "[trace]\nphotons = -5\n[detector]"), // negative count
        ("[detector]", "[trace]\npolarization = \"yes\"\n[detector]"), // wrong type
        ("albedo = 0.95", "albedo = 0.95\nback = \"black\""), // not a back
        (
            "albedo = 0.95",
            "albedo = { table = [[400.0, 0.9]], cauchy = [1.5] }",
        ), // two forms
        (
            "power_w = 1.0",
            "power_w = 1.0\npolarization = { linear_deg = 0.0, stokes = [1.0, 0.0, 0.0, 0.0] }",
        ),
        (
            "power_w = 1.0",
            "power_w = 1.0\nspectrum = { blackbody = 6500 }",
        ),
    ];
    for (from, to) in bad {
        assert!(PLATE.contains(from), "{from}");
        let text = PLATE.replacen(from, to, 1);
        assert!(load(&text).is_err(), "the loader reads {to:?}");
        assert!(
            !complaints(&v, &text).is_empty(),
            "the schema accepts {to:?}"
        );
    }
    let good = [
        (
            "albedo = 0.95",
            "albedo = { table = [[400.0, 0.9], [700.0, 0.95]] }\nback = \"absorber\"",
        ),
        (
            "power_w = 1.0",
            "power_w = 1.0\nspectrum = \"cie-led-b5\"\nbody = \"transparent\"",
        ),
        (
            "power_w = 1.0",
            "power_w = 1.0\npolarization = { linear_deg = 30.0 }",
        ),
        ("[detector]", "[trace]\nphotons = 1000\n[detector]"),
    ];
    for (from, to) in good {
        let text = PLATE.replacen(from, to, 1);
        assert_eq!(load(&text), Ok(()), "{to:?}");
        assert_eq!(complaints(&v, &text), Vec::<String>::new(), "{to:?}");
    }
}

/// Whether the loader's error is one of reading the file (its keys, types and array
/// lengths) rather than a later check of values, geometry or files.
fn has_non_finite(value: &toml::Value) -> bool {
    match value {
        toml::Value::Float(x) => !x.is_finite(),
        toml::Value::Array(a) => a.iter().any(has_non_finite),
        toml::Value::Table(t) => t.values().any(has_non_finite),
        _ => false,
    }
}

fn is_reading_error(message: &str) -> bool {
    message.contains("TOML parse error") || message.contains("but it takes")
}

#[test]
fn the_schema_agrees_with_the_loader_on_the_corpus() {
    let v = validator();
    let mut checked = 0;
    let mut refused = 0;
    let mut disagreements = Vec::new();
    let mut cases: Vec<PathBuf> = std::fs::read_dir(repo().join("tests/corpus"))
        .unwrap()
        .map(|e| e.unwrap().path().join("scene.toml"))
        .filter(|p| p.is_file())
        .collect();
    cases.sort();
    for scene in cases {
        // A case whose file is not UTF-8 or not TOML has nothing to validate.
        let Ok(text) = std::fs::read_to_string(&scene) else {
            continue;
        };
        let Some(json) = as_json(&text) else { continue };
        let loader_result = || Scene::load(&scene).map(drop).map_err(|e| format!("{e:#}"));
        if has_non_finite(&toml::from_str(&text).unwrap()) {
            // JSON has no NaN or infinity (it reads them as null): the loader refuses them
            // by value, and a validator never sees them.
            assert!(loader_result().is_err(), "{}", scene.display());
            continue;
        }
        let loader = Scene::load(&scene).map(drop).map_err(|e| format!("{e:#}"));
        let reads = !loader.as_ref().is_err_and(|e| is_reading_error(e));
        let valid = v.is_valid(&json);
        checked += 1;
        refused += usize::from(!reads);
        if reads != valid {
            disagreements.push(format!(
                "{}: loader {loader:?}, schema valid {valid}",
                scene.display()
            ));
        }
    }
    println!("corpus: {checked} scene files compared, {refused} refused at reading");
    assert!(
        checked >= 50 && refused >= 5,
        "{checked} cases, {refused} refused at reading"
    );
    assert!(disagreements.is_empty(), "{}", disagreements.join("\n"));
}

#[test]
fn editors_find_the_current_schema() {
    let config: toml::Table =
        toml::from_str(&std::fs::read_to_string(repo().join(".taplo.toml")).unwrap()).unwrap();
    let rule = &config["rule"][0];
    let include: Vec<&str> = rule["include"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| g.as_str().unwrap())
        .collect();
    assert_eq!(include, ["**/scene*.toml"]);
    let path = rule["schema"]["path"].as_str().unwrap();
    let committed = std::fs::read_to_string(repo().join(path)).unwrap();
    let current = serde_json::to_string_pretty(&scene_schema()).unwrap() + "\n";
    assert!(
        committed == current,
        "{path} is stale: run `cargo run --release -- schema > {}`",
        path.trim_start_matches("./")
    );
}
