//! Every output file of a layout search, written all or nothing: `optimized.toml`,
//! `history.csv`, `optimize.json`, and the verification traces in `initial/` and `final/`.

use super::LayoutResult;
use crate::optimize::scene_edit::{make_paths_absolute, to_toml};
use crate::output::atomic::OutputSet;
use crate::scene::Scene;
use crate::scene::config::SceneFile;
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The files and folders a layout search writes (and replaces) in its output folder.
pub const OUTPUT_NAMES: &[&str] = &[
    "optimized.toml",
    "history.csv",
    "optimize.json",
    "initial",
    "final",
];

impl LayoutResult {
    /// The best design's scene file: the original with the variables' final values, file
    /// paths absolute, so it traces from anywhere.
    pub fn optimized_toml(&self) -> Result<String> {
        let path = &self.scene_file;
        let mut file: SceneFile = self
            .final_doc
            .clone()
            .try_into()
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let base = path.parent().unwrap_or(Path::new("."));
        make_paths_absolute(&mut file, path, base)?;
        let name = file.name.clone().unwrap_or_else(|| {
            base.file_name()
                .map_or("scene".into(), |n| n.to_string_lossy().into_owned())
        });
        file.name = Some(format!("{name}-optimized"));
        let mut out = format!(
            "# Written by `blutrace optimize --vary` ({} on {}) from {}.\n# Changed (file paths are absolute):\n",
            self.method,
            self.objective,
            path.display()
        );
        for v in &self.variables {
            let _ = writeln!(
                out,
                "#   {} = {} (was {})",
                v.name, v.final_value, v.initial
            );
        }
        out.push('\n');
        out.push_str(&to_toml(&file)?);
        Ok(out)
    }

    /// `history.csv`: one row per evaluated design.
    fn history_csv(&self) -> String {
        let mut s = String::from("evaluation,photons,seconds");
        for v in &self.variables {
            let _ = write!(s, ",{}", v.name);
        }
        s.push_str(",objective,objective_stderr,noise_floor,cv_debiased,cv_debiased_stderr,thirteen_point,thirteen_point_stderr,efficiency,efficiency_stderr,delta_uv_13pt_debiased,delta_uv_13pt_debiased_stderr,rejected\n");
        for r in &self.history {
            let _ = write!(s, "{},{},{:.3}", r.evaluation, r.photons, r.seconds);
            for v in &r.values {
                let _ = write!(s, ",{v:.9e}");
            }
            match &r.result {
                Some(e) => {
                    let _ = write!(
                        s,
                        ",{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},",
                        e.objective,
                        e.noise,
                        e.noise_floor,
                        e.cv_debiased,
                        e.cv_debiased_stderr,
                        e.thirteen_point,
                        e.thirteen_point_stderr,
                        e.efficiency,
                        e.efficiency_stderr,
                        e.delta_uv_13pt_debiased.unwrap_or(f64::NAN),
                        e.delta_uv_13pt_debiased_stderr.unwrap_or(f64::NAN)
                    );
                }
                None => s.push_str(",,,,,,,,,,,"),
            }
            let reason = r.rejected.as_deref().unwrap_or("");
            let _ = writeln!(s, "\"{}\"", reason.replace('"', "'").replace('\n', " "));
        }
        s
    }

    /// Write every output into `dir`, all or nothing; returns the files and folders.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        let toml_text = self.optimized_toml()?;
        let file: SceneFile = toml::from_str(&toml_text)
            .map_err(|e| anyhow::anyhow!("optimized scene does not parse: {e}"))?;
        Scene::from_file(&file, &dir.join("optimized.toml"))
            .context("the optimized scene does not load")?;
        let staged = OutputSet::new(dir, OUTPUT_NAMES, &self.initial_run.scene.inputs)?;
        staged.write_bytes("optimized.toml", toml_text.as_bytes())?;
        staged.write_bytes("history.csv", self.history_csv().as_bytes())?;
        staged.write_bytes("optimize.json", &serde_json::to_vec_pretty(self)?)?;
        for (name, run) in [("initial", &self.initial_run), ("final", &self.final_run)] {
            run.write_into(&staged.subdir(name)?)?;
        }
        staged.commit()
    }
}
