//! `optimized.toml`: the original scene file with the final density, edited as the typed
//! [`SceneFile`] and written by the `toml` crate (keys in alphabetical order):
//!
//! ```toml
//! name = "notebook14-optimized"   # the original name with -optimized
//!
//! [[geometry]]
//! file = "/abs/path/notebook14.obj"   # file paths made absolute
//!
//! [surfaces.lgp_back]
//! model = "dots"
//! density_table = [[0.01, 0.013], ...]   # or density = [...] or density_grid = {...}
//! ```
//!
//! Keys the original left at their defaults are written out with their values.

use super::OptimizeResult;
use crate::optics::dots::Density;
use crate::scene::config::{SceneFile, SurfaceSpec};
use anyhow::{Context, Result, bail};
use std::fmt::Write as _;
use std::path::Path;

impl OptimizeResult {
    /// The scene file of the final design: the original with the new density, geometry
    /// and other file paths made absolute, so it traces from anywhere.
    pub fn optimized_toml(&self) -> Result<String> {
        let path = &self.scene_file;
        // The file as the scene was loaded from it (not read again: it may have changed).
        let mut file = self.initial_run.scene.file();
        let base = path.parent().unwrap_or(Path::new("."));
        make_paths_absolute(&mut file, path, base)?;
        let surface = file
            .surfaces
            .get_mut(&self.tag)
            .with_context(|| format!("{}: no [surfaces.{}]", path.display(), self.tag))?;
        set_density(&mut surface.spec, &self.final_density)
            .with_context(|| format!("{}: [surfaces.{}]", path.display(), self.tag))?;
        let name = file.name.clone().unwrap_or_else(|| {
            base.file_name()
                .map_or("scene".into(), |n| n.to_string_lossy().into_owned())
        });
        file.name = Some(format!("{name}-optimized"));
        let body = to_toml(&file)?;
        let mut out = String::new();
        let _ = writeln!(
            out,
            "# Written by `blutrace optimize --method {}` from {}.\n# Only [surfaces.{}] density changed; file paths are absolute.\n",
            self.method,
            path.display(),
            self.tag
        );
        out.push_str(&body);
        Ok(out)
    }
}

/// `file` as TOML. Through a `toml::Value`, whose tables sort their keys: the sections
/// and keys come out in alphabetical order, not in the structs' field order.
pub(super) fn to_toml(file: &SceneFile) -> Result<String> {
    let value = toml::Value::try_from(file).context("cannot write the optimized scene")?;
    toml::to_string(&value).context("cannot write the optimized scene as TOML")
}

/// The scene file at `path`, parsed.
#[cfg(test)]
fn read_scene_file(path: &Path) -> Result<SceneFile> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read scene file", path.display()))?;
    toml::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// The keys whose strings (or arrays of strings) are file paths relative to the scene
/// file, wherever they stand: geometry, ray, spectrum and BSDF table files (`file`), a
/// BSDF table's `back_file`, an LED's `intensity_file`.
const PATH_KEYS: [&str; 3] = ["file", "back_file", "intensity_file"];

/// Make every file path of `file` absolute (they are relative to `base`, the folder of
/// the scene file `path`), so the file loads from any folder: an optimized scene is
/// written elsewhere. Errors name the key of a file that cannot be found, and a path
/// that stays relative (one under a key [`PATH_KEYS`] does not list).
pub(super) fn make_paths_absolute(file: &mut SceneFile, path: &Path, base: &Path) -> Result<()> {
    let mut doc = toml::Value::try_from(&*file).context("cannot write the optimized scene")?;
    absolute_paths(&mut doc, "", path, base)?;
    *file = doc
        .try_into()
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let declared = (file.geometry.iter().map(|g| g.file.clone()))
        .chain(file.surfaces.values().flat_map(|s| s.files()))
        .chain(file.sources.iter().flat_map(|s| s.files()));
    if let Some(f) = declared.into_iter().find(|f| !f.is_absolute()) {
        bail!(
            "{}: cannot write the optimized scene: the path {} stays relative to the scene's folder",
            path.display(),
            f.display()
        );
    }
    Ok(())
}

/// Make the paths under [`PATH_KEYS`] in `v` (at key path `at`) absolute.
fn absolute_paths(v: &mut toml::Value, at: &str, path: &Path, base: &Path) -> Result<()> {
    use toml::Value;
    let absolute = |p: &mut String, at: &str| -> Result<()> {
        let joined = base.join(&*p);
        let found = joined.canonicalize().with_context(|| {
            format!("{}: {at}: cannot find {}", path.display(), joined.display())
        })?;
        *p = found.to_string_lossy().into_owned();
        Ok(())
    };
    match v {
        Value::Table(t) => {
            for (k, x) in t.iter_mut() {
                let at = if at.is_empty() {
                    k.clone()
                } else {
                    format!("{at}.{k}")
                };
                match x {
                    Value::String(p) if PATH_KEYS.contains(&k.as_str()) => absolute(p, &at)?,
                    Value::Array(a) if PATH_KEYS.contains(&k.as_str()) => {
                        for (i, x) in a.iter_mut().enumerate() {
                            if let Value::String(p) = x {
                                absolute(p, &format!("{at}[{i}]"))?;
                            }
                        }
                    }
                    x => absolute_paths(x, &at, path, base)?,
                }
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter_mut().enumerate() {
                absolute_paths(x, &format!("{at}[{i}]"), path, base)?;
            }
        }
        _ => {}
    }
    Ok(())
}

/// Check, before a search, that the scene's optimized file can be written: every file it
/// names is found and made absolute (not found after hours of search).
pub(super) fn check_exportable(scene: &crate::scene::Scene) -> Result<()> {
    let mut file = scene.file();
    let base = scene.path.parent().unwrap_or(Path::new("."));
    make_paths_absolute(&mut file, &scene.path, base)
}

/// Replace the density of the dots surface `spec` by `density`.
fn set_density(spec: &mut SurfaceSpec, density: &Density) -> Result<()> {
    let SurfaceSpec::Dots(dots) = spec else {
        bail!("not a model = \"dots\" surface");
    };
    dots.set_density(density);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::dots::DensityGrid;

    /// A scene file as JSON, to compare two of them.
    fn json(file: &SceneFile) -> serde_json::Value {
        serde_json::to_value(file).unwrap()
    }

    #[test]
    fn every_bundled_scene_survives_the_round_trip() {
        let scenes = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes");
        let mut n = 0;
        for entry in std::fs::read_dir(&scenes).unwrap() {
            let path = entry.unwrap().path().join("scene.toml");
            if !path.exists() {
                continue;
            }
            let file = read_scene_file(&path).unwrap();
            let again: SceneFile = toml::from_str(&to_toml(&file).unwrap()).unwrap();
            assert_eq!(json(&file), json(&again), "{}", path.display());
            n += 1;
        }
        assert!(n > 0, "no scenes under {}", scenes.display());
    }

    /// Ray, spectrum and BSDF files, an LED's table and a lamp body's table: every path
    /// key is made absolute wherever it stands, strings that are not paths are left, and
    /// a missing file is named by its key.
    #[test]
    fn every_path_key_is_made_absolute_wherever_it_stands() {
        let dir = tempfile::tempdir().unwrap();
        let files = [
            "a.obj", "r.rays", "s.csv", "f.bsdf", "b.bsdf", "k.bsdf", "led.ies",
        ];
        for f in files {
            std::fs::write(dir.path().join(f), "").unwrap();
        }
        let mut doc: toml::Value = toml::from_str(
            "name = \"file\"\n[[geometry]]\nfile = \"a.obj\"\n\
             [surfaces.s]\nfile = [\"f.bsdf\", \"b.bsdf\"]\nback_file = \"k.bsdf\"\n\
             [[sources]]\nfile = \"r.rays\"\nspectrum = { file = \"s.csv\" }\n\
             body = { model = \"bsdf_table\", file = \"f.bsdf\" }\n\
             [[sources]]\nintensity_file = \"led.ies\"\nspectrum = \"cie-led-b5\"\n",
        )
        .unwrap();
        let path = dir.path().join("scene.toml");
        absolute_paths(&mut doc, "", &path, dir.path()).unwrap();
        let root = dir.path().canonicalize().unwrap();
        let abs = |f: &str| root.join(f).to_string_lossy().into_owned();
        let s = &doc["sources"][0];
        assert_eq!(doc["geometry"][0]["file"].as_str(), Some(&*abs("a.obj")));
        assert_eq!(
            doc["surfaces"]["s"]["file"][1].as_str(),
            Some(&*abs("b.bsdf"))
        );
        assert_eq!(
            doc["surfaces"]["s"]["back_file"].as_str(),
            Some(&*abs("k.bsdf"))
        );
        assert_eq!(s["file"].as_str(), Some(&*abs("r.rays")));
        assert_eq!(s["spectrum"]["file"].as_str(), Some(&*abs("s.csv")));
        assert_eq!(s["body"]["file"].as_str(), Some(&*abs("f.bsdf")));
        let led = &doc["sources"][1];
        assert_eq!(led["intensity_file"].as_str(), Some(&*abs("led.ies")));
        assert_eq!(led["spectrum"].as_str(), Some("cie-led-b5"));
        assert_eq!(doc["name"].as_str(), Some("file"));
        let mut gone: toml::Value =
            toml::from_str("[[sources]]\nspectrum = { file = \"gone.csv\" }\n").unwrap();
        let e = format!(
            "{:#}",
            absolute_paths(&mut gone, "", &path, dir.path()).unwrap_err()
        );
        assert!(
            e.contains("sources[0].spectrum.file") && e.contains("gone.csv"),
            "{e}"
        );
    }

    #[test]
    fn the_density_is_replaced_and_the_paths_made_absolute() {
        let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("scenes/notebook14/scene.toml");
        let mut file = read_scene_file(&path).unwrap();
        make_paths_absolute(&mut file, &path, path.parent().unwrap()).unwrap();
        assert!(file.geometry.iter().all(|g| g.file.is_absolute()));
        let spec = &mut file.surfaces.get_mut("lgp_back").unwrap().spec;
        let grid = DensityGrid {
            x_max: 1.0,
            v_min: -2.0,
            width: 4.0,
            values: vec![vec![0.1, 0.2], vec![0.3, 0.4]],
        };
        for density in [
            Density::Table(vec![[0.0, 0.1], [1.0, 0.3]]),
            Density::Grid(grid),
            Density::Polynomial(vec![0.1, 0.05]),
        ] {
            set_density(spec, &density).unwrap();
            let text = toml::to_string(&toml::Value::try_from(&*spec).unwrap()).unwrap();
            let keys = ["density =", "density_table", "density_grid"];
            let present: Vec<_> = keys.iter().filter(|k| text.contains(*k)).collect();
            assert_eq!(present.len(), 1, "{text}");
            // The same density comes back from the TOML (a grid's x_max is the
            // pattern's, not the file's).
            let SurfaceSpec::Dots(back) = toml::from_str::<SurfaceSpec>(&text).unwrap() else {
                panic!("{text}");
            };
            let ctx = crate::spec_check::Ctx(&path);
            let x_max = 1.0;
            let (again, _) =
                Density::from_keys(&ctx, "s", back.density_keys(), None, x_max).unwrap();
            assert_eq!(again, density, "{text}");
        }
        let mut other = file.surfaces.get("lgp_front").unwrap().spec.clone();
        assert!(set_density(&mut other, &Density::Polynomial(vec![0.1])).is_err());
    }
}
