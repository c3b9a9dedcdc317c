//! The feedback method: a tabulated density, one knot per strip, updated by damped ratios
//! after each trace.
//!
//! ```text
//! blutrace optimize SCENE --method feedback [--alpha 0.7] [--smoothing 0.25] [--max-iter 15]
//! ```
//!
//! Each round traces the current design and updates every knot by
//! `d <- d * (target / measured)^alpha`, where `measured` is the mean flux of the profile
//! strips over the knot's interval and `target` the median of the strips inside the
//! objective's margins (`--edge-margin-mm`; the median, not the mean, so a few strips that
//! cannot be fixed, such as light leaking at a lamp edge, do not pull the level); then `d`
//! is clamped to `[min printable, max packing]` and optionally smoothed with its
//! neighbours. The rounds stop at the objective bound (`--target-cv`), the iteration cap,
//! or after [`STALL_ROUNDS`] rounds that gain less than the objective's noise. With
//! mirrored patterns (lamps on both edges) the two halves share their knots, which halves
//! the noise per knot.
//!
//! With `--dims 2 [--cells NX,NY]` the density is a grid of `NX` x `NY` knots over the
//! face (along the axis and across it, see [`crate::optics::dots`]), for non-uniformity
//! that varies across the axis too (side-view LEDs, corner-lit guides): every knot is
//! updated the same way from the mean flux of the map bins nearest to it, the target being
//! the median over the knot cells, clamped, and optionally smoothed with a 3 x 3 kernel
//! (`--smoothing` weighs the mean of the 8 neighbours). The rounds are judged, and the best
//! design picked, by the area cv (the cv of the map's bins without the margins) instead of
//! the profile's (debiased by its noise floor), and the result is written as a
//! `density_grid`. The default grid is 56 x 28 knots.
//!
//! The 1-D result is written as a `density_table`:
//!
//! ```toml
//! [surfaces.lgp_back]
//! density_table = [[0.01, 0.013], [0.03, 0.011], ...]   # [x, d], x as x_unit says
//! ```

use super::objective::Profile;
use crate::optics::dots::{DensityGrid, DotPattern};
use crate::run::metrics::{Map, median};
use crate::scene::Scene;

/// The search stops after this many rounds in a row that do not beat the best objective
/// by more than its standard error (the design has converged to the noise level).
pub const STALL_ROUNDS: usize = 3;

/// Settings of one update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Damping exponent (1: full ratio; smaller is slower and steadier).
    pub alpha: f64,
    /// Weight of the neighbours' mean in the smoothing pass (0: none).
    pub smoothing: f64,
    /// Smallest printable density.
    pub min: f64,
    /// Largest density (the lattice's packing limit).
    pub max: f64,
}

/// `n` knot positions (polynomial variable) at the centres of equal intervals over the
/// pattern's span of x.
pub fn knot_positions(pattern: &DotPattern, n: usize) -> Vec<f64> {
    let x_max = pattern.x_max();
    (0..n.max(2))
        .map(|j| (j as f64 + 0.5) / n.max(2) as f64 * x_max)
        .collect()
}

/// The number of knots for `strips` profile strips: one per strip, or one per mirrored
/// pair of strips.
pub fn knot_count(pattern: &DotPattern, strips: usize) -> usize {
    if pattern.grade.mirror {
        strips.div_ceil(2).max(2)
    } else {
        strips.max(2)
    }
}

/// Mean measured flux per knot interval (NaN where no strip falls). Strips in the
/// objective's margins count here too: their density is still steered towards the
/// target, it just does not enter the objective.
fn measured_per_knot(pattern: &DotPattern, knots: &[f64], profile: &Profile) -> Vec<f64> {
    let n = knots.len();
    let x_max = pattern.x_max();
    let mut sum = vec![0.0; n];
    let mut count = vec![0usize; n];
    for k in 0..profile.u.len() {
        if !profile.populated[k] {
            continue;
        }
        let x = pattern.x_of(profile.u[k]);
        let j = ((x / x_max * n as f64).max(0.0) as usize).min(n - 1);
        sum[j] += profile.value[k];
        count[j] += 1;
    }
    sum.iter()
        .zip(&count)
        .map(|(s, &c)| if c > 0 { s / c as f64 } else { f64::NAN })
        .collect()
}

/// `d (target / measured)^alpha`, the ratio limited to `[1/4, 4]`, clamped to `[min, max]`;
/// a dark knot (no flux at all) gets the largest step the damping allows, one without a
/// measurement (NaN) keeps its density.
fn damped_step(d: f64, measured: f64, target: f64, s: &Settings) -> f64 {
    if measured.is_nan() {
        return d;
    }
    let ratio = if measured > 0.0 {
        target / measured
    } else {
        4.0
    };
    (d * ratio.clamp(0.25, 4.0).powf(s.alpha)).clamp(s.min, s.max)
}

/// One feedback update of the knot densities `d` from a traced profile.
pub fn update(pattern: &DotPattern, knots: &[f64], d: &mut [f64], profile: &Profile, s: &Settings) {
    let target = profile.median();
    let measured = measured_per_knot(pattern, knots, profile);
    if !(target > 0.0 && target.is_finite()) {
        return;
    }
    for (dj, m) in d.iter_mut().zip(&measured) {
        *dj = damped_step(*dj, *m, target, s);
    }
    if s.smoothing > 0.0 && d.len() > 2 {
        let old = d.to_vec();
        for j in 0..d.len() {
            let nb: Vec<f64> = [j.checked_sub(1), Some(j + 1)]
                .into_iter()
                .flatten()
                .filter_map(|i| old.get(i).copied())
                .collect();
            let mean = nb.iter().sum::<f64>() / nb.len() as f64;
            d[j] = ((1.0 - s.smoothing) * old[j] + s.smoothing * mean).clamp(s.min, s.max);
        }
    }
}

/// The density grid the 2-D feedback starts from: `nx` x `ny` knots (at least 2 each
/// way, see `check_method_options`) over the pattern's
/// span of x and `v_min..=v_min + width` across, valued as `pattern`'s own density at each
/// knot (clamped to `[min, max]`).
pub fn initial_grid(
    pattern: &DotPattern,
    v_min: f64,
    width: f64,
    (nx, ny): (usize, usize),
    min: f64,
    max: f64,
) -> DensityGrid {
    let x_max = pattern.x_max();
    let values = (0..ny)
        .map(|j| {
            let v = v_min + width * j as f64 / (ny - 1) as f64;
            (0..nx)
                .map(|i| {
                    let x = x_max * i as f64 / (nx - 1) as f64;
                    pattern.grade.density.at(x, v).clamp(min, max)
                })
                .collect()
        })
        .collect();
    DensityGrid {
        x_max,
        v_min,
        width,
        values,
    }
}

/// Mean flux of the map's bins (of `scene`'s detector) nearest to each knot of `grid`
/// (`[row][column]`); knots no bin is nearest to get their neighbours' mean
/// (`fill_empty_cells`). Bins outside the pattern's span are left out.
pub fn measured_per_cell(
    scene: &Scene,
    pattern: &DotPattern,
    grid: &DensityGrid,
    map: &Map,
) -> Vec<Vec<f64>> {
    let (nx, ny) = grid.shape();
    let mut sum = vec![vec![0.0; nx]; ny];
    let mut count = vec![vec![0usize; nx]; ny];
    let d = &scene.detector;
    for iy in 0..map.ny {
        for ix in 0..map.nx {
            let centre = d.grid_centre([map.nx, map.ny], ix, iy);
            let q = pattern.face_coords(centre);
            if !(0.0..pattern.grade.length).contains(&q.x)
                || q.y < grid.v_min
                || q.y > grid.v_min + grid.width
            {
                continue;
            }
            let (i, j) = grid.nearest_knot(pattern.x_of(q.x), q.y);
            sum[j][i] += map.value[iy * map.nx + ix];
            count[j][i] += 1;
        }
    }
    let mut measured: Vec<Vec<f64>> = sum
        .iter()
        .zip(&count)
        .map(|(s, c)| {
            s.iter()
                .zip(c)
                .map(|(s, &c)| if c > 0 { s / c as f64 } else { f64::NAN })
                .collect()
        })
        .collect();
    fill_empty_cells(&mut measured);
    measured
}

/// Give every empty (NaN) cell the mean of its measured neighbours (3 x 3), repeated
/// until every cell has a value: a grid finer than the map leaves knots that no bin is
/// nearest to, and a knot left alone while its neighbours move would print a stripe.
/// A grid with no measured cell at all is left as it is.
fn fill_empty_cells(values: &mut [Vec<f64>]) {
    loop {
        let old = values.to_vec();
        let (mut filled, mut empty) = (false, false);
        for (j, row) in values.iter_mut().enumerate() {
            for (i, v) in row.iter_mut().enumerate().filter(|(_, v)| v.is_nan()) {
                let measured: Vec<f64> = neighbours(&old, i, j).filter(|m| m.is_finite()).collect();
                if measured.is_empty() {
                    empty = true;
                } else {
                    *v = measured.iter().sum::<f64>() / measured.len() as f64;
                    filled = true;
                }
            }
        }
        if !(empty && filled) {
            return;
        }
    }
}

/// The (up to 8) values around `[j][i]` in its 3 x 3 window.
fn neighbours(values: &[Vec<f64>], i: usize, j: usize) -> impl Iterator<Item = f64> + '_ {
    let rows = j.saturating_sub(1)..(j + 2).min(values.len());
    rows.flat_map(move |jj| {
        let row = &values[jj];
        let cols = i.saturating_sub(1)..(i + 2).min(row.len());
        cols.filter(move |&ii| (ii, jj) != (i, j))
            .map(move |ii| row[ii])
    })
}

/// One 2-D feedback update of the grid's knots from the flux per knot cell: every knot
/// gets `d <- d (target / measured)^alpha` with `target` the median over the cells, is
/// clamped to `[min, max]`, then optionally smoothed with the mean of its (up to 8)
/// neighbours in a 3 x 3 kernel.
pub fn update_grid(grid: &mut DensityGrid, measured: &[Vec<f64>], s: &Settings) {
    let all: Vec<f64> = measured
        .iter()
        .flatten()
        .copied()
        .filter(|m| m.is_finite())
        .collect();
    let target = median(all);
    if !(target > 0.0 && target.is_finite()) {
        return;
    }
    for (row, mrow) in grid.values.iter_mut().zip(measured) {
        for (dj, m) in row.iter_mut().zip(mrow) {
            *dj = damped_step(*dj, *m, target, s);
        }
    }
    if s.smoothing > 0.0 {
        let old = grid.values.clone();
        for (j, row) in grid.values.iter_mut().enumerate() {
            for (i, v) in row.iter_mut().enumerate() {
                let around: Vec<f64> = neighbours(&old, i, j).collect();
                if !around.is_empty() {
                    let mean = around.iter().sum::<f64>() / around.len() as f64;
                    *v = ((1.0 - s.smoothing) * old[j][i] + s.smoothing * mean).clamp(s.min, s.max);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_cells_take_their_neighbours_mean() {
        let nan = f64::NAN;
        let mut v = vec![
            vec![1.0, nan, 3.0, nan],
            vec![nan, nan, nan, nan],
            vec![nan, nan, nan, 5.0],
        ];
        fill_empty_cells(&mut v);
        assert!(v.iter().flatten().all(|x| x.is_finite()), "{v:?}");
        assert_eq!(v[0][1], 2.0);
        assert_eq!(v[1][0], 1.0);
        assert_eq!(v[1][3], (3.0 + 5.0) / 2.0);
        let mut none = vec![vec![nan; 3]; 2];
        fill_empty_cells(&mut none);
        assert!(none.iter().flatten().all(|x| x.is_nan()));
    }

    #[test]
    fn grid_update_moves_knots_toward_the_median_within_bounds() {
        let mut grid = DensityGrid {
            x_max: 1.0,
            v_min: 0.0,
            width: 1.0,
            values: vec![vec![0.2, 0.2, 0.2], vec![0.2, 0.2, 0.7]],
        };
        let settings = Settings {
            alpha: 0.5,
            smoothing: 0.0,
            min: 0.01,
            max: 0.75,
        };
        // Median 1: a knot at twice the median is scaled by 2^-alpha, one at half by
        // 2^alpha (and clamped to the packing limit).
        let measured = vec![vec![1.0, 2.0, 1.0], vec![1.0, 1.0, 0.5]];
        update_grid(&mut grid, &measured, &settings);
        assert_eq!(grid.values[0][0], 0.2);
        assert!((grid.values[0][1] - 0.2 / 2f64.sqrt()).abs() < 1e-15);
        assert_eq!(grid.values[1][2], 0.75);
    }
}
