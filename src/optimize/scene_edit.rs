//! `optimized.toml`: the original scene file with the final density.

use super::OptimizeResult;
use crate::optics::dots::Density;
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::Path;

impl OptimizeResult {
    /// The scene file of the final design: the original with the new density, geometry
    /// and other file paths made absolute, so it traces from anywhere.
    pub fn optimized_toml(&self) -> Result<String> {
        let path = &self.scene_file;
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("{}: cannot read scene file", path.display()))?;
        let mut doc: toml::Table =
            toml::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let base = path.parent().unwrap_or(Path::new("."));
        let absolute = |v: &mut toml::Value| -> Result<()> {
            if let toml::Value::String(s) = v {
                let p = base.join(&*s);
                let p = p
                    .canonicalize()
                    .with_context(|| format!("{}: cannot find {}", path.display(), p.display()))?;
                *s = p.to_string_lossy().into_owned();
            }
            Ok(())
        };
        for section in ["geometry", "sources"] {
            if let Some(toml::Value::Array(items)) = doc.get_mut(section) {
                for item in items.iter_mut() {
                    if let toml::Value::Table(t) = item {
                        for (k, v) in t.iter_mut() {
                            if k == "file" || k.ends_with("_file") {
                                absolute(v)?;
                            }
                        }
                    }
                }
            }
        }
        let surface = doc
            .get_mut("surfaces")
            .and_then(|s| s.as_table_mut())
            .and_then(|s| s.get_mut(&self.tag))
            .and_then(|s| s.as_table_mut())
            .with_context(|| format!("{}: no [surfaces.{}]", path.display(), self.tag))?;
        surface.remove("density");
        surface.remove("density_table");
        surface.remove("density_grid");
        match &self.final_density {
            Density::Polynomial(c) => {
                let c = c.iter().map(|&v| toml::Value::Float(v)).collect();
                surface.insert("density".into(), toml::Value::Array(c));
            }
            Density::Table(k) => {
                let knots = k
                    .iter()
                    .map(|[x, d]| {
                        toml::Value::Array(vec![toml::Value::Float(*x), toml::Value::Float(*d)])
                    })
                    .collect();
                surface.insert("density_table".into(), toml::Value::Array(knots));
            }
            Density::Grid(g) => {
                let mut t = toml::Table::new();
                t.insert("width_mm".into(), toml::Value::Float(g.width));
                t.insert("v_min_mm".into(), toml::Value::Float(g.v_min));
                let rows = g
                    .values
                    .iter()
                    .map(|r| toml::Value::Array(r.iter().map(|&v| toml::Value::Float(v)).collect()))
                    .collect();
                t.insert("values".into(), toml::Value::Array(rows));
                surface.insert("density_grid".into(), toml::Value::Table(t));
            }
        }
        let name = doc
            .get("name")
            .and_then(|n| n.as_str())
            .map(str::to_owned)
            .unwrap_or_else(|| {
                base.file_name()
                    .map_or("scene".into(), |n| n.to_string_lossy().into_owned())
            });
        doc.insert(
            "name".into(),
            toml::Value::String(format!("{name}-optimized")),
        );
        let body = toml::to_string(&doc).context("cannot write the optimized scene as TOML")?;
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
