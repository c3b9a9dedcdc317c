//! The optimizer's charts: `density.png`, `profile.png` and `density_map.png`.

use super::OptimizeResult;
use super::objective::Evaluation;
use crate::optics::dots::{Density, DensityGrid};
use crate::output::atomic::SetDir;
use crate::output::figure::thousands;
use crate::output::map::{Grid, MapOptions, write_map};
use crate::output::plot::{Chart, Scale, Series, write_chart};
use anyhow::Result;
use std::path::Path;

impl OptimizeResult {
    /// Write `density.png`, `profile.png` and, for a density grid, `density_map.png`.
    pub(super) fn write_charts(&self, out: &SetDir) -> Result<()> {
        out.write_with("density.png", |p| write_chart(p, &self.density_chart()))?;
        out.write_with("profile.png", |p| write_chart(p, &self.profile_chart()))?;
        if let Density::Grid(g) = &self.final_density {
            out.write_with("density_map.png", |p| self.write_density_map(p, g))?;
        }
        Ok(())
    }

    /// Density against position along the axis, initial and final.
    fn density_chart(&self) -> Chart {
        let p = &self.pattern;
        let n = 400;
        let curve = |d: &Density| -> Vec<(f64, f64)> {
            let mut q = p.clone();
            q.grade.density = d.clone();
            (0..=n)
                .map(|i| {
                    let u = p.grade.length * i as f64 / n as f64;
                    (u, q.density_at(u))
                })
                .collect()
        };
        let across = match self.final_density {
            Density::Grid(_) => ", mean across the axis",
            _ => "",
        };
        Chart {
            title: format!("Dot density d(x) on {} ({}{across})", self.tag, self.method),
            x_label: "position along the propagation axis (mm)".into(),
            y_label: "dot density d (area fraction)".into(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            series: vec![
                Series::new("initial", curve(&self.initial_density)),
                Series::new("final", curve(&self.final_density)),
            ],
        }
    }

    /// Flux profile along the axis (relative to its mean), initial and final.
    fn profile_chart(&self) -> Chart {
        let (a, b, what) = match &self.verification {
            Some(v) => (
                &v.initial.evaluation,
                &v.final_design.evaluation,
                "verification re-trace",
            ),
            None => (&self.initial, &self.best, "search traces"),
        };
        let rel = |e: &Evaluation| -> Vec<(f64, f64)> {
            let used: Vec<f64> = e
                .profile
                .value
                .iter()
                .zip(&e.profile.used)
                .filter(|(_, u)| **u)
                .map(|(v, _)| *v)
                .collect();
            let mean = used.iter().sum::<f64>() / used.len().max(1) as f64;
            e.profile
                .u
                .iter()
                .zip(&e.profile.value)
                .map(|(u, v)| (*u, v / mean))
                .collect()
        };
        Chart {
            title: format!("Flux profile along the axis ({what})"),
            x_label: "position along the propagation axis (mm)".into(),
            y_label: "flux / mean".into(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            series: vec![
                Series::new(format!("initial, cv {:.3}", a.objective), rel(a)),
                Series::new(format!("final, cv {:.3}", b.objective), rel(b)),
            ],
        }
    }

    /// False-colour map of a 2-D density grid's knots: columns along the axis (left to
    /// right from the lamp edge), rows across it (the first row at the bottom), each knot
    /// a cell centred on its position in mm.
    fn write_density_map(&self, path: &Path, g: &DensityGrid) -> Result<()> {
        let (nx, ny) = g.shape();
        let values: Vec<f64> = g.values.iter().flatten().copied().collect();
        let p = &self.pattern;
        // The knots span the pattern's length (half of it when mirrored) along the axis.
        let span = if p.grade.mirror {
            p.grade.length / 2.0
        } else {
            p.grade.length
        };
        let grid = Grid {
            nx,
            ny,
            values: &values,
            x_mm: cells_around(0.0, span, nx),
            y_mm: cells_around(g.v_min, g.v_min + g.width, ny),
        };
        let along = if p.grade.mirror {
            "distance from the nearer lamp edge (mm)"
        } else {
            "distance from the lamp edge (mm)"
        };
        let e = match &self.verification {
            Some(v) => &v.final_design.evaluation,
            None => &self.best,
        };
        let opts = MapOptions {
            title: format!(
                "Final dot density on {} ({}): area cv {:.3} at {} photons",
                self.tag,
                self.method,
                e.area_cv,
                thousands(e.photons)
            ),
            x_label: along.into(),
            y_label: "position across the axis (mm)".into(),
            unit: "dot density (area fraction)".into(),
            min: Some(0.0),
            ..MapOptions::default()
        };
        write_map(path, &grid, &opts)
    }
}

/// The span of `n` cells centred on `n` knots evenly spaced from `a` to `b` (one knot: a
/// cell of width `b - a`, or 1 mm if that is zero, centred on `a`).
fn cells_around(a: f64, b: f64, n: usize) -> [f64; 2] {
    let step = if n > 1 {
        (b - a) / (n - 1) as f64
    } else {
        b - a
    };
    let half = if step > 0.0 { step / 2.0 } else { 0.5 };
    [a - half, if n > 1 { b + half } else { a + half }]
}
