//! Every output file of an optimization, written all or nothing.

use super::{OptimizeResult, export};
use crate::optics::dots::Density;
use crate::output::atomic::OutputSet;
use crate::scene::Scene;
use crate::scene::config::SceneFile;
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Every file and folder `blutrace optimize` writes.
pub const OUTPUT_NAMES: &[&str] = &[
    "optimized.toml",
    "history.csv",
    "density.png",
    "profile.png",
    "density_map.png",
    "dots.csv",
    "dots.svg",
    "dots.dxf",
    "optimize.json",
    "initial",
    "final",
];

impl OptimizeResult {
    /// `history.csv`: one row per iteration.
    fn history_csv(&self) -> String {
        let mut s = String::from(
            "iteration,evaluations,photons,seconds,objective,objective_noise,noise_floor,area_cv,map_cv,thirteen_point,cv,delta_uv_13pt_debiased,step",
        );
        match &self.final_density {
            Density::Polynomial(c) => (0..c.len()).for_each(|k| {
                let _ = write!(s, ",c{k}");
            }),
            Density::Table(k) => k.iter().for_each(|[x, _]| {
                let _ = write!(s, ",d@{x:.5}");
            }),
            Density::Grid(g) => {
                let (nx, ny) = g.shape();
                for j in 0..ny {
                    for i in 0..nx {
                        let _ = write!(s, ",d{i}_{j}");
                    }
                }
            }
        }
        s.push('\n');
        for r in &self.history {
            let _ = write!(
                s,
                "{},{},{},{:.3},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{}",
                r.iteration,
                r.evaluations,
                r.photons,
                r.seconds,
                r.objective,
                r.noise,
                r.noise_floor,
                r.area_cv,
                r.map_cv,
                r.thirteen_point,
                r.cv,
                r.delta_uv_13pt_debiased,
                r.step
            );
            for p in &r.params {
                let _ = write!(s, ",{p:.9e}");
            }
            s.push('\n');
        }
        s
    }

    /// Write every output into `dir` as one set ([`OutputSet`]): it replaces the folder's
    /// previous contents only when everything has been written; returns the files and
    /// folders written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        let toml_text = self.optimized_toml()?;
        // The optimized scene must load as it is.
        let dest = dir.join("optimized.toml");
        let file: SceneFile = toml::from_str(&toml_text)
            .map_err(|e| anyhow::anyhow!("optimized scene does not parse: {e}"))?;
        Scene::from_file(&file, &dest).context("the optimized scene does not load")?;

        let staged = OutputSet::new(dir, OUTPUT_NAMES, &self.initial_run.scene.inputs)?;
        staged.write_bytes("optimized.toml", toml_text.as_bytes())?;
        staged.write_bytes("history.csv", self.history_csv().as_bytes())?;
        self.write_charts(&staged)?;
        let sheet = &self.sheet;
        if let Some(dots) = &self.dots {
            staged.write_bytes("dots.csv", export::to_csv(dots, sheet).as_bytes())?;
            staged.write_bytes("dots.svg", export::to_svg(dots, sheet).as_bytes())?;
            staged.write_bytes("dots.dxf", export::to_dxf(dots, sheet).as_bytes())?;
        }
        staged.write_bytes("optimize.json", &serde_json::to_vec_pretty(self)?)?;

        for (name, run) in [("initial", &self.initial_run), ("final", &self.final_run)] {
            run.write_into(&staged.subdir(name)?)?;
        }
        staged.commit()
    }
}
