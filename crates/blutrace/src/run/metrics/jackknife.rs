//! Standard errors of the scalar metrics by the delete-one-group jackknife over the
//! [`GROUPS`](super::GROUPS) interleaved photon groups, computed after every round.
//!
//! Leaving a group out is taking it out of the total (exact, as the sums are integers).
//! Only the flux bins and the detected power enter the metrics, and only the bins the
//! group scored in differ from the total's. So each leave-out map starts as a copy of the
//! total's map over the photons left (at most three counts occur, as groups differ by at
//! most one chunk) and recomputes just the group's bins ([`ScoredBins`]), through the
//! same `bin_value` and `Metrics` code as every map: the results are those of rebuilding
//! every map whole, bit for bit. The leave-outs run in parallel on the calling rayon pool
//! (the run's own; sequentially outside one) and are collected in group order.

use super::{FluxValues, Metric, MetricValues, Metrics, bin_value};
use crate::scene::Scene;
use crate::tally::{BinStats, Sign, Tally};
use rayon::prelude::*;
use std::cell::RefCell;

/// For each group, the flux bins it has scored in: the only bins where a map with that
/// group left out differs from the total's.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScoredBins(Vec<BinSet>);

/// A set of flux bins, one bit each.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BinSet(Vec<u64>);

impl ScoredBins {
    /// No bin scored yet, for `groups` groups of `bins` flux bins.
    pub fn new(groups: usize, bins: usize) -> Self {
        Self(vec![BinSet(vec![0; bins.div_ceil(64)]); groups])
    }

    /// The bins each of `groups` holds anything in.
    pub fn of(groups: &[Tally]) -> Self {
        let bins = groups.first().map_or(0, |g| g.flux.bins.len());
        let mut s = Self::new(groups.len(), bins);
        for (set, t) in s.0.iter_mut().zip(groups) {
            for (i, b) in t.flux.bins.iter().enumerate() {
                if *b != BinStats::default() {
                    set.mark(i as u32);
                }
            }
        }
        s
    }

    /// Each group's set.
    pub fn sets_mut(&mut self) -> &mut [BinSet] {
        &mut self.0
    }
}

impl BinSet {
    /// Add flux bin `bin`.
    pub fn mark(&mut self, bin: u32) {
        let bin = bin as usize;
        self.0[bin / 64] |= 1 << (bin % 64);
    }

    /// The bins in the set, in increasing order.
    fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        self.0.iter().enumerate().flat_map(|(w, &word)| {
            let mut rest = word;
            std::iter::from_fn(move || {
                (rest != 0).then(|| {
                    let bit = rest.trailing_zeros() as usize;
                    rest &= rest - 1;
                    w * 64 + bit
                })
            })
        })
    }
}

/// Jackknife standard errors of every metric of `total` from its per-group tallies.
/// Returns NaN errors when fewer than two groups hold photons.
pub fn jackknife(scene: &Scene, total: &Tally, groups: &[Tally]) -> MetricValues {
    stderr_of(&leave_one_out(scene, total, groups))
}

/// Every metric of `total` with each group holding photons left out in turn; `groups`
/// are the per-group tallies whose sum `total` is.
pub fn leave_one_out(scene: &Scene, total: &Tally, groups: &[Tally]) -> Vec<MetricValues> {
    let used = used_groups(total, groups);
    let bases = FluxBases::new(scene, total, used.iter().map(|(_, g)| remaining(total, g)));
    leave_one_out_from(&bases, total, &used, &ScoredBins::of(groups))
}

/// Every metric of the tally `total` and its standard error (jackknife over `groups`,
/// the same photons split by chunk); the per-bin metric, itself an error, gets none. The
/// efficiency, a mean over photons, gets its exact per-photon error, the one the summary
/// reports, so the convergence history and the summary agree.
pub fn with_errors(scene: &Scene, total: &Tally, groups: &[Tally]) -> (MetricValues, MetricValues) {
    let e = estimates(scene, total, groups, &ScoredBins::of(groups));
    (e.values, e.stderr)
}

/// The metrics of a run with their jackknife errors and leave-one-out values.
#[derive(Clone, Debug)]
pub struct Estimates {
    /// Every metric of the total.
    pub values: MetricValues,
    /// Their standard errors, as [`with_errors`] gives them.
    pub stderr: MetricValues,
    /// Every metric with each group holding photons left out in turn, as
    /// [`leave_one_out`] gives them (for the error of any function of the metrics).
    pub leave_out: Vec<MetricValues>,
}

/// [`Estimates`] of `total` over `groups`, whose scored bins are `scored` (noted while
/// scoring, or [`ScoredBins::of`]).
pub fn estimates(scene: &Scene, total: &Tally, groups: &[Tally], scored: &ScoredBins) -> Estimates {
    let used = used_groups(total, groups);
    let n = total.ledger.photons;
    let counts = used.iter().map(|(_, g)| remaining(total, g)).chain([n]);
    let bases = FluxBases::new(scene, total, counts);
    let own = bases.get(n);
    let (eff, eff_se) = total.ledger.detected.mean_and_stderr(n);
    let values = Metrics::of_flux(own.nx, own.ny, &own.value, &own.stderr, eff).values();
    let leave_out = leave_one_out_from(&bases, total, &used, scored);
    let mut stderr = stderr_of(&leave_out);
    stderr[Metric::MeanRelStderr] = 0.0;
    stderr[Metric::Efficiency] = eff_se;
    Estimates {
        values,
        stderr,
        leave_out,
    }
}

/// The jackknife standard error `sqrt((k - 1) / k sum (x_i - mean)^2)` of a statistic
/// from its `k` leave-one-out values (NaN for fewer than two).
pub fn jackknife_stderr(leave_out: &[f64]) -> f64 {
    let k = leave_out.len();
    if k < 2 {
        return f64::NAN;
    }
    let mean = leave_out.iter().sum::<f64>() / k as f64;
    let ss: f64 = leave_out.iter().map(|v| (v - mean).powi(2)).sum();
    ((k - 1) as f64 / k as f64 * ss).sqrt()
}

/// The jackknife standard error of every metric from its leave-one-out values.
fn stderr_of(leave_out: &[MetricValues]) -> MetricValues {
    MetricValues::from_fn(|m| jackknife_stderr(&leave_out.iter().map(|v| v[m]).collect::<Vec<_>>()))
}

/// The groups holding photons, with their indices (an empty group leaves the total as
/// it is).
fn used_groups<'a>(total: &Tally, groups: &'a [Tally]) -> Vec<(usize, &'a Tally)> {
    let used: Vec<(usize, &Tally)> = groups
        .iter()
        .enumerate()
        .filter(|(_, g)| g.ledger.photons > 0)
        .collect();
    debug_assert_eq!(
        used.iter().map(|(_, g)| g.ledger.photons).sum::<u64>(),
        total.ledger.photons,
        "the groups add up to the total"
    );
    used
}

/// Photons of `total` outside group `g`.
fn remaining(total: &Tally, g: &Tally) -> u64 {
    total.ledger.photons - g.ledger.photons
}

fn leave_one_out_from(
    bases: &FluxBases,
    total: &Tally,
    used: &[(usize, &Tally)],
    scored: &ScoredBins,
) -> Vec<MetricValues> {
    in_pool(used, |&(index, g)| {
        SCRATCH.with_borrow_mut(|scratch| {
            let n = remaining(total, g);
            // Gather the group's bins first: a loop of loads alone keeps many cache
            // misses in flight (the groups' tallies are far apart in memory), the maths
            // then runs on bins at hand.
            scratch.rest.clear();
            scratch.rest.extend(scored.0[index].iter().map(|i| {
                let mut rest = total.flux.bins[i];
                rest.merge_signed(&g.flux.bins[i], Sign::Remove);
                (i, rest)
            }));
            let base = bases.get(n);
            let m = &mut scratch.map;
            m.value.clone_from(&base.value);
            m.stderr.clone_from(&base.stderr);
            for (i, b) in &scratch.rest {
                (m.value[*i], m.stderr[*i]) = bin_value(b, n, bases.k);
            }
            let mut detected = total.ledger.detected;
            detected.merge_signed(&g.ledger.detected, Sign::Remove);
            let eff = detected.mean_and_stderr(n).0;
            Metrics::of_flux(base.nx, base.ny, &m.value, &m.stderr, eff).values()
        })
    })
}

thread_local! {
    /// This thread's buffers for leave-out maps, kept from group to group and from round
    /// to round (a run's pool threads live as long as the run).
    static SCRATCH: RefCell<Scratch> = RefCell::default();
    /// The buffers of the last bases this thread built, for its next ones.
    static SPARE_MAPS: RefCell<Vec<FluxValues>> = RefCell::default();
}

/// One thread's buffers for leave-out maps.
#[derive(Default)]
struct Scratch {
    /// The group's bins taken out of the total's.
    rest: Vec<(usize, BinStats)>,
    /// The leave-out map (its `nx`, `ny` unused).
    map: FluxValues,
}

/// In parallel on the current rayon pool when called from one (a run's own, sized by
/// `--threads`), else sequentially, so that no caller starts rayon's global pool behind
/// the user's thread count.
fn in_pool_parallel() -> bool {
    rayon::current_thread_index().is_some()
}

/// `f` of every item, in order ([`in_pool_parallel`]).
fn in_pool<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync + Send) -> Vec<R> {
    if in_pool_parallel() {
        items.par_iter().map(f).collect()
    } else {
        items.iter().map(f).collect()
    }
}

/// The total's flux map over each of a few photon counts (the total's own and those
/// left when a group is taken out).
struct FluxBases {
    /// Watts per unit photon weight over a bin's area.
    k: f64,
    counts: Vec<u64>,
    maps: Vec<FluxValues>,
}

impl FluxBases {
    fn new(scene: &Scene, total: &Tally, counts: impl Iterator<Item = u64>) -> Self {
        let k = scene.sources.total_power() / scene.detector.bin_area();
        let mut counts: Vec<u64> = counts.collect();
        counts.sort_unstable();
        counts.dedup();
        let mut maps = SPARE_MAPS.with_borrow_mut(std::mem::take);
        maps.resize_with(counts.len(), FluxValues::default);
        let g = &total.flux;
        let fill = |(m, &n): (&mut FluxValues, &u64)| {
            (m.nx, m.ny) = (g.nx, g.ny);
            m.value.clear();
            m.stderr.clear();
            for b in &g.bins {
                let (value, stderr) = bin_value(b, n, k);
                m.value.push(value);
                m.stderr.push(stderr);
            }
        };
        if in_pool_parallel() {
            maps.par_iter_mut().zip(&counts).for_each(fill);
        } else {
            maps.iter_mut().zip(&counts).for_each(fill);
        }
        FluxBases { k, counts, maps }
    }

    fn get(&self, n: u64) -> &FluxValues {
        &self.maps[self
            .counts
            .binary_search(&n)
            .expect("a count the bases were built for")]
    }
}

impl Drop for FluxBases {
    fn drop(&mut self) {
        SPARE_MAPS.with_borrow_mut(|spare| *spare = std::mem::take(&mut self.maps));
    }
}
