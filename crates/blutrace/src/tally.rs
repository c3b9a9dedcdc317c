//! What the photon loop scores: each photon's [`Fate`], the energy [`Ledger`], the
//! per-chunk [`ChunkTally`] of [`Detection`]s and the run's [`Tally`], all built on exact,
//! order-independent accumulators.
//!
//! Every tally keeps the sum and the sum of squares of per-photon contributions, so every
//! output carries its standard error. Sums are kept in 128-bit fixed point with 2^-64
//! resolution (each contribution is rounded once, deterministically): integer addition is
//! associative, so any thread count, chunk order or shard split gives bit-identical
//! totals, and 1e10 photons accumulate without drift. They are read out as f64.

pub mod color;
pub mod meter;

use crate::optics::spectrum::{Light, Secondaries};
use crate::optics::surface::MediumId;
use crate::scene::Scene;
pub use color::{ColorTally, ScoredXyz};
pub use meter::{MeterHit, MeterTally};
use serde::{Deserialize, Serialize};

const FRACTION_BITS: i32 = 64;

/// Most bins a stored grid may have: more than any run tallies (a run's flux and angular
/// grids, kept once per run and once per jackknife group, fit its 4 GiB budget: at most
/// 2.7 million bins; `run` checks the two agree), so a damaged shard file cannot make a
/// reader allocate more than a real run did.
pub const MAX_GRID_BINS: usize = 1 << 22;

/// Most photons one stored tally may hold: its emitted weight, `photons` in 2^-64 units,
/// and every sink within a few times that, stay far inside an `i128` (2^54 is 1.8e16
/// photons a jackknife group, a run of 5.8e17: more than any machine traces).
pub const MAX_STORED_PHOTONS: u64 = 1 << 54;
const SCALE: f64 = 18446744073709551616.0; // 2^64

/// Whether a merge adds another tally or takes one back out (exact: the sums are
/// integers, so taking out a part of a total leaves exactly the sum of the other parts).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sign {
    /// Add the other tally.
    Add,
    /// Take the other tally out (it must be part of this one).
    Remove,
}

impl Sign {
    /// `a += b` or `a -= b`.
    fn apply_i128(self, a: &mut i128, b: i128) {
        match self {
            Sign::Add => *a += b,
            Sign::Remove => *a -= b,
        }
    }

    /// `a += b` or `a -= b` for counts.
    fn apply_u64(self, a: &mut u64, b: u64) {
        match self {
            Sign::Add => *a += b,
            Sign::Remove => *a -= b,
        }
    }
}

/// An exact sum of f64 contributions of either sign.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ExactSum(pub i128);

impl ExactSum {
    /// Add one contribution (rounded to the nearest multiple of 2^-64, ties to even, so
    /// rounding has no bias).
    pub fn add(&mut self, x: f64) {
        self.0 += (x * SCALE).round_ties_even() as i128;
    }

    /// Add another exact sum.
    pub fn merge(&mut self, other: ExactSum) {
        self.merge_signed(other, Sign::Add);
    }

    /// Add another exact sum, or take it out.
    pub fn merge_signed(&mut self, other: ExactSum, sign: Sign) {
        sign.apply_i128(&mut self.0, other.0);
    }

    /// `self + other`, or `None` past the `i128` range.
    pub fn checked_add(self, other: ExactSum) -> Option<ExactSum> {
        self.0.checked_add(other.0).map(ExactSum)
    }

    /// The sum as f64.
    pub fn value(self) -> f64 {
        self.0 as f64 / 2f64.powi(FRACTION_BITS)
    }
}

/// Per-bin statistics: sum of weights, sum of squared weights, photon count.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct BinStats {
    /// Sum of photon weights.
    pub sum: ExactSum,
    /// Sum of squared photon weights.
    pub sumsq: ExactSum,
    /// Number of photons scored.
    pub hits: u64,
}

impl BinStats {
    /// Score one photon of weight `w`.
    pub fn add(&mut self, w: f64) {
        self.sum.add(w);
        self.sumsq.add(w * w);
        self.hits += 1;
    }

    /// Merge another bin.
    pub fn merge(&mut self, o: &BinStats) {
        self.merge_signed(o, Sign::Add);
    }

    /// Merge another bin, or take it out.
    pub fn merge_signed(&mut self, o: &BinStats, sign: Sign) {
        self.sum.merge_signed(o.sum, sign);
        self.sumsq.merge_signed(o.sumsq, sign);
        sign.apply_u64(&mut self.hits, o.hits);
    }

    /// Add another bin, or `None` (self unchanged in part) past the counters' range.
    pub fn checked_merge(&mut self, o: &BinStats) -> Option<()> {
        self.sum = self.sum.checked_add(o.sum)?;
        self.sumsq = self.sumsq.checked_add(o.sumsq)?;
        self.hits = self.hits.checked_add(o.hits)?;
        Some(())
    }

    /// Mean contribution per emitted photon and its standard error, for `n` photons
    /// emitted in all (photons that missed the bin contributed zero).
    pub fn mean_and_stderr(&self, n: u64) -> (f64, f64) {
        mean_and_stderr(self.sum.value(), self.sumsq.value(), n)
    }
}

/// Mean and standard error of the mean from a sum and a sum of squares over `n` samples.
pub fn mean_and_stderr(sum: f64, sumsq: f64, n: u64) -> (f64, f64) {
    if n == 0 {
        return (0.0, 0.0);
    }
    let nf = n as f64;
    let mean = sum / nf;
    if n < 2 {
        return (mean, 0.0);
    }
    let var = ((sumsq / nf - mean * mean) * nf / (nf - 1.0)).max(0.0);
    (mean, (var / nf).sqrt())
}

/// A 2-D grid of bins, row-major (`x` fastest). Serialized sparsely (empty bins left out).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(into = "SparseGrid", try_from = "SparseGrid")]
pub struct Grid {
    /// Bins along x.
    pub nx: usize,
    /// Bins along y.
    pub ny: usize,
    /// The bins.
    pub bins: Vec<BinStats>,
}

impl Grid {
    /// An empty grid.
    pub fn new(nx: usize, ny: usize) -> Self {
        Self {
            nx,
            ny,
            bins: vec![BinStats::default(); nx * ny],
        }
    }

    /// Score weight `w` in bin `(ix, iy)`.
    pub fn add(&mut self, ix: usize, iy: usize, w: f64) {
        self.bins[iy * self.nx + ix].add(w);
    }

    /// Merge another grid of the same shape.
    pub fn merge(&mut self, o: &Grid) {
        self.merge_signed(o, Sign::Add);
    }

    /// Add another grid of the same shape, or `None` past the counters' range.
    pub fn checked_merge(&mut self, o: &Grid) -> Option<()> {
        self.bins
            .iter_mut()
            .zip(&o.bins)
            .try_for_each(|(a, b)| a.checked_merge(b))
    }

    /// Merge another grid of the same shape, or take it out.
    pub fn merge_signed(&mut self, o: &Grid, sign: Sign) {
        for (a, b) in self.bins.iter_mut().zip(&o.bins) {
            a.merge_signed(b, sign);
        }
    }
}

/// The stored form of a [`Grid`]: only bins that scored, as `[index, sum, sumsq, hits]`.
#[derive(Serialize, Deserialize)]
struct SparseGrid {
    nx: usize,
    ny: usize,
    bins: Vec<(usize, i128, i128, u64)>,
}

impl From<Grid> for SparseGrid {
    fn from(g: Grid) -> Self {
        let bins = g
            .bins
            .iter()
            .enumerate()
            .filter(|(_, b)| b.hits > 0 || b.sum.0 != 0)
            .map(|(i, b)| (i, b.sum.0, b.sumsq.0, b.hits))
            .collect();
        SparseGrid {
            nx: g.nx,
            ny: g.ny,
            bins,
        }
    }
}

impl TryFrom<SparseGrid> for Grid {
    type Error = String;

    fn try_from(s: SparseGrid) -> Result<Self, String> {
        // A stored grid is never larger than a run's tally budget allows; checked before
        // allocating, so a damaged file is an error, not an allocation abort.
        if s.nx.checked_mul(s.ny).is_none_or(|n| n > MAX_GRID_BINS) {
            return Err(format!(
                "a {}x{} grid is larger than any run tallies",
                s.nx, s.ny
            ));
        }
        let mut g = Grid::new(s.nx, s.ny);
        for (i, sum, sumsq, hits) in s.bins {
            let bin = g
                .bins
                .get_mut(i)
                .ok_or_else(|| format!("bin index {i} outside a {}x{} grid", s.nx, s.ny))?;
            *bin = BinStats {
                sum: ExactSum(sum),
                sumsq: ExactSum(sumsq),
                hits,
            };
        }
        Ok(g)
    }
}

/// How one photon ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fate {
    /// Reached the target plane.
    Detected,
    /// Absorbed by the surface with this tag index.
    AbsorbedBySurface(u32),
    /// Absorbed inside this medium (Beer-Lambert).
    AbsorbedInMedium(MediumId),
    /// Absorbed by the body of the source with this index.
    AbsorbedBySource(u32),
    /// Left the scene.
    Escaped,
    /// Stopped by the bounce cap.
    Killed,
    /// Ended by Russian roulette (weighted estimator).
    Roulette,
}

/// Where the emitted energy went, in photon weights. Partial absorptions of the weighted
/// estimator are booked as the weight before minus the weight after, so the books close
/// exactly: `emitted == accounted()` bit for bit in every run.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Ledger {
    /// Photons emitted.
    pub photons: u64,
    /// Surface interactions (roulette events).
    pub interactions: u64,
    /// Surface interactions per tag (they add up to `interactions` less the hits on lamp
    /// bodies).
    pub hits_by_tag: Vec<u64>,
    /// Of those, the ones that met the tag's pattern: ink on a dots face, a groove facet
    /// on a grooves face (zero for other models).
    pub feature_hits_by_tag: Vec<u64>,
    /// Emitted weight.
    pub emitted: ExactSum,
    /// Weight detected on the target (sum and sum of squares per photon).
    pub detected: BinStats,
    /// Weight detected on the target per source, in source order: the photon loop books
    /// each detection to its source's bin, and `detected` is their sum, so they add up to
    /// it exactly (sums, sums of squares and counts).
    #[serde(default)]
    pub detected_by_source: Vec<BinStats>,
    /// Weight absorbed per surface tag.
    pub absorbed_by_surface: Vec<ExactSum>,
    /// Weight absorbed per medium.
    pub absorbed_in_medium: Vec<ExactSum>,
    /// Weight absorbed per source, by its lamp body.
    #[serde(default)]
    pub absorbed_by_source: Vec<ExactSum>,
    /// Weight the detector's analyzer absorbed (`[detector] analyzer_deg`; zero without).
    #[serde(default)]
    pub absorbed_by_analyzer: ExactSum,
    /// Weight that left the scene.
    pub escaped: ExactSum,
    /// Weight stopped by the bounce cap.
    pub killed: ExactSum,
    /// Photons stopped by the bounce cap.
    pub killed_photons: u64,
    /// Net weight removed by Russian roulette (killed minus weight given to survivors).
    pub roulette: ExactSum,
}

impl Ledger {
    pub(crate) fn new(tags: usize, media: usize, sources: usize) -> Self {
        Self {
            hits_by_tag: vec![0; tags],
            feature_hits_by_tag: vec![0; tags],
            absorbed_by_surface: vec![ExactSum::default(); tags],
            absorbed_in_medium: vec![ExactSum::default(); media],
            absorbed_by_source: vec![ExactSum::default(); sources],
            detected_by_source: vec![BinStats::default(); sources],
            ..Default::default()
        }
    }

    /// Book the end of a photon of weight `w` emitted by source `source`.
    pub(crate) fn end(&mut self, fate: Fate, w: f64, source: usize) {
        match fate {
            // Booked to its source only: `detected` is their sum ([`Ledger::sum_detected`]).
            Fate::Detected => self.detected_by_source[source].add(w),
            Fate::AbsorbedBySurface(t) => self.absorbed_by_surface[t as usize].add(w),
            Fate::AbsorbedInMedium(m) => self.absorbed_in_medium[m as usize].add(w),
            Fate::AbsorbedBySource(i) => self.absorbed_by_source[i as usize].add(w),
            Fate::Escaped => self.escaped.add(w),
            Fate::Killed => {
                self.killed.add(w);
                self.killed_photons += 1;
            }
            Fate::Roulette => self.roulette.add(w),
        }
    }

    /// Set `detected` to the sum of the per-source detections (exact: integer sums), once
    /// the photons [`Ledger::end`] booked are all traced: the photon loop then pays for one
    /// bin per detection, as it did before detections were kept per source.
    pub(crate) fn sum_detected(&mut self) {
        let mut total = BinStats::default();
        self.detected_by_source.iter().for_each(|b| total.merge(b));
        self.detected = total;
    }

    /// Count one surface interaction on tag `tag`, which met the tag's pattern (ink, a
    /// groove) when `feature`.
    pub(crate) fn hit(&mut self, tag: u32, feature: bool) {
        self.interactions += 1;
        self.hits_by_tag[tag as usize] += 1;
        self.feature_hits_by_tag[tag as usize] += u64::from(feature);
    }

    /// Count `n` interactions with tag `tag` outside its pattern (a run of them).
    pub(crate) fn plain_hits(&mut self, tag: u32, n: u64) {
        self.interactions += n;
        self.hits_by_tag[tag as usize] += n;
    }

    /// Book the weight lost between `before` and `after` at `sink`.
    pub(crate) fn lose(sink: &mut ExactSum, before: f64, after: f64) {
        // Nothing lost (every analog scattering): adding w and -w would leave the sum
        // exactly as it is (rounding is symmetric), so skip the two conversions.
        if before != after {
            sink.add(before);
            sink.add(-after);
        }
    }

    pub(crate) fn merge(&mut self, o: &Ledger) {
        self.merge_signed(o, Sign::Add);
    }

    /// Add another ledger, or take it out.
    pub(crate) fn merge_signed(&mut self, o: &Ledger, sign: Sign) {
        let done = self.combine(
            o,
            |a, b| {
                a.merge_signed(b, sign);
                Some(())
            },
            |a, b| {
                sign.apply_u64(a, b);
                Some(())
            },
        );
        debug_assert!(done.is_some());
    }

    /// Add another ledger, or `None` (this one then in part merged) past the counters'
    /// range: for ledgers read from files.
    pub fn checked_merge(&mut self, o: &Ledger) -> Option<()> {
        self.combine(
            o,
            |a, b| {
                *a = a.checked_add(b)?;
                Some(())
            },
            |a, b| {
                *a = a.checked_add(b)?;
                Some(())
            },
        )
    }

    /// Combine every counter of `o` into this ledger's: weights by `weight`, counts by
    /// `count`, stopping at the first `None`.
    fn combine(
        &mut self,
        o: &Ledger,
        weight: impl Fn(&mut ExactSum, ExactSum) -> Option<()>,
        count: impl Fn(&mut u64, u64) -> Option<()>,
    ) -> Option<()> {
        count(&mut self.photons, o.photons)?;
        count(&mut self.interactions, o.interactions)?;
        for (mine, theirs) in [
            (&mut self.hits_by_tag, &o.hits_by_tag),
            (&mut self.feature_hits_by_tag, &o.feature_hits_by_tag),
        ] {
            for (a, b) in mine.iter_mut().zip(theirs) {
                count(a, *b)?;
            }
        }
        weight(&mut self.emitted, o.emitted)?;
        for (a, b) in std::iter::once((&mut self.detected, &o.detected)).chain(
            self.detected_by_source
                .iter_mut()
                .zip(&o.detected_by_source),
        ) {
            weight(&mut a.sum, b.sum)?;
            weight(&mut a.sumsq, b.sumsq)?;
            count(&mut a.hits, b.hits)?;
        }
        for (mine, theirs) in [
            (&mut self.absorbed_by_surface, &o.absorbed_by_surface),
            (&mut self.absorbed_in_medium, &o.absorbed_in_medium),
            (&mut self.absorbed_by_source, &o.absorbed_by_source),
        ] {
            for (a, b) in mine.iter_mut().zip(theirs) {
                weight(a, *b)?;
            }
        }
        weight(&mut self.absorbed_by_analyzer, o.absorbed_by_analyzer)?;
        weight(&mut self.escaped, o.escaped)?;
        weight(&mut self.killed, o.killed)?;
        count(&mut self.killed_photons, o.killed_photons)?;
        weight(&mut self.roulette, o.roulette)
    }

    /// [`Ledger::accounted`], or `None` past the `i128` range (a damaged file's ledger).
    pub fn checked_accounted(&self) -> Option<ExactSum> {
        let sinks = [
            self.detected.sum,
            self.absorbed_by_analyzer,
            self.escaped,
            self.killed,
            self.roulette,
        ];
        sinks
            .iter()
            .chain(&self.absorbed_by_surface)
            .chain(&self.absorbed_in_medium)
            .chain(&self.absorbed_by_source)
            .try_fold(ExactSum(0), |s, a| s.checked_add(*a))
    }

    /// Sum of all fates' weights (equals `emitted` exactly when the ledger balances), of
    /// a ledger a run scored: its sinks stay far inside the `i128` range (a ledger read
    /// from a file goes through [`Ledger::checked_accounted`] instead).
    pub fn accounted(&self) -> ExactSum {
        self.checked_accounted()
            .expect("a traced run's ledger sums within i128")
    }
}

/// Everything a run scored.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Tally {
    /// Flux bins on the target plane (photon weights).
    pub flux: Grid,
    /// (theta, phi) bins of detected directions (photon weights).
    pub angular: Grid,
    /// Energy ledger.
    pub ledger: Ledger,
    /// X, Y, Z of the detected light, when the sources have spectra ([`color`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub color: Option<ColorTally>,
    /// Per view and flux bin, the light the luminance meter reads (spectral: X, Y, Z;
    /// else radiant weight), when the sources give lumens or spectra ([`meter`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub meter: Option<MeterTally>,
    /// Per flux bin, the detected light's weight times `S1/S0`, `S2/S0`, `S3/S0` in the
    /// detector's frame (sums of either sign), when polarization is traced.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stokes: Option<[Grid; 3]>,
}

impl Tally {
    /// An empty tally shaped for `scene`.
    pub fn new(scene: &Scene) -> Self {
        let d = &scene.detector;
        let flux = Grid::new(d.bins[0], d.bins[1]);
        let angular = Grid::new(d.angular_bins[0], d.angular_bins[1]);
        Self {
            color: scene
                .sources
                .spectral()
                .then(|| ColorTally::new(&flux, &angular)),
            meter: scene.luminous().then(|| {
                let spectral = scene.sources.spectral();
                let places = scene.tags.len() + scene.sources.list.len();
                MeterTally::new(d.views.len(), (flux.nx, flux.ny), spectral, places)
            }),
            stokes: scene
                .polarized
                .then(|| [0, 1, 2].map(|_| Grid::new(d.bins[0], d.bins[1]))),
            flux,
            angular,
            ledger: Ledger::new(
                scene.tags.len(),
                scene.media.len(),
                scene.sources.list.len(),
            ),
        }
    }

    /// What makes this tally one no run of `photons` photons of the scene `empty` was made
    /// for ([`Tally::new`]) could have scored, if anything: another shape (bins, tags,
    /// media, sources), another photon count, emitted weight other than one per photon,
    /// books that do not close, or a sink holding negative weight. Shard files are checked
    /// with it before they are merged, so an edited or damaged one is refused.
    pub fn inconsistency(&self, empty: &Tally, photons: u64) -> Option<String> {
        let l = &self.ledger;
        let shape = |t: &Tally| {
            let l = &t.ledger;
            [
                (t.flux.nx, t.flux.ny, t.flux.bins.len()),
                (t.angular.nx, t.angular.ny, t.angular.bins.len()),
                (
                    l.hits_by_tag.len(),
                    l.feature_hits_by_tag.len(),
                    l.absorbed_by_surface.len(),
                ),
                (
                    l.absorbed_in_medium.len(),
                    l.absorbed_by_source.len(),
                    l.detected_by_source.len(),
                ),
            ]
            .into_iter()
            .chain(t.color.iter().flat_map(ColorTally::shape))
            .chain(t.meter.iter().flat_map(MeterTally::shape))
            .chain(
                t.stokes
                    .iter()
                    .flatten()
                    .map(|g| (g.nx, g.ny, g.bins.len())),
            )
            .collect::<Vec<_>>()
        };
        let sinks = l.absorbed_by_surface.iter().chain(&l.absorbed_in_medium);
        let by_source = l.detected_by_source.iter();
        let negative = sinks
            .chain(&l.absorbed_by_source)
            .chain([&l.escaped, &l.killed, &l.detected.sum, &l.detected.sumsq])
            .chain(by_source.clone().flat_map(|b| [&b.sum, &b.sumsq]))
            .any(|s| s.0 < 0);
        // The per-source detections add up to the detections exactly, or `None` past
        // the counters' range.
        let by_source_total = by_source.clone().try_fold(BinStats::default(), |mut t, b| {
            t.checked_merge(b)?;
            Some(t)
        });
        let bad_bin = |g: &Grid| {
            g.bins
                .iter()
                .any(|b| b.sum.0 < 0 || b.sumsq.0 < 0 || b.hits > photons)
        };
        Some(if shape(self) != shape(empty) {
            "tally shape does not match the scene's detector, tags, media or sources".into()
        } else if l.photons != photons {
            format!("{} photons, but its range holds {photons}", l.photons)
        } else if photons > MAX_STORED_PHOTONS {
            format!("{photons} photons, more than {MAX_STORED_PHOTONS} (no run traces that many)")
        } else if l.emitted.0 != i128::from(photons) << FRACTION_BITS {
            format!(
                "emitted weight {} for {photons} photons of weight 1",
                l.emitted.value()
            )
        } else if l.checked_accounted() != Some(l.emitted) {
            format!(
                "the ledger does not balance: emitted {} but accounted {}",
                l.emitted.value(),
                l.checked_accounted()
                    .map_or("more than a tally holds".into(), |a| a.value().to_string())
            )
        } else if self.stokes.iter().flatten().any(|g| bad_stokes(g, photons)) {
            "a Stokes bin holds more than the detected power, or more photons than were emitted"
                .into()
        } else if negative || l.detected.hits > photons || l.killed_photons > photons {
            "a sink holds negative weight, or more photons than were emitted".into()
        } else if by_source_total != Some(l.detected) {
            "the detections per source do not add up to the detections".into()
        } else if bad_bin(&self.flux)
            || bad_bin(&self.angular)
            || self.color.as_ref().is_some_and(|c| c.has_bad_bin(photons))
            || self.meter.as_ref().is_some_and(|m| m.has_bad_bin(photons))
        {
            "a bin holds negative weight, or more photons than were emitted".into()
        } else {
            return None;
        })
    }

    /// Add another tally of the same scene.
    pub fn merge(&mut self, o: &Tally) {
        self.merge_signed(o, Sign::Add);
    }

    /// Add another tally of the same scene, or `None` past the counters' range: for
    /// tallies read from files ([`Tally::inconsistency`] bounds each one first).
    pub fn checked_merge(&mut self, o: &Tally) -> Option<()> {
        self.flux.checked_merge(&o.flux)?;
        self.angular.checked_merge(&o.angular)?;
        if let (Some(a), Some(b)) = (&mut self.color, &o.color) {
            a.checked_merge(b)?;
        }
        if let (Some(a), Some(b)) = (&mut self.meter, &o.meter) {
            a.checked_merge(b)?;
        }
        if let (Some(a), Some(b)) = (&mut self.stokes, &o.stokes) {
            for (x, y) in a.iter_mut().zip(b) {
                x.checked_merge(y)?;
            }
        }
        self.ledger.checked_merge(&o.ledger)
    }

    /// Add another tally of the same scene, or take out one that is part of this one.
    pub fn merge_signed(&mut self, o: &Tally, sign: Sign) {
        self.flux.merge_signed(&o.flux, sign);
        self.angular.merge_signed(&o.angular, sign);
        if let (Some(a), Some(b)) = (&mut self.color, &o.color) {
            a.merge_signed(b, sign);
        }
        if let (Some(a), Some(b)) = (&mut self.meter, &o.meter) {
            a.merge_signed(b, sign);
        }
        if let (Some(a), Some(b)) = (&mut self.stokes, &o.stokes) {
            a.iter_mut()
                .zip(b)
                .for_each(|(x, y)| x.merge_signed(y, sign));
        }
        self.ledger.merge_signed(&o.ledger, sign);
    }

    /// Add the events of one traced chunk.
    pub fn absorb(&mut self, c: &ChunkTally) {
        self.absorb_scored(c, &c.scored(), &self.scored_xyz(c));
    }

    /// The X, Y, Z of `c`'s detections when this tally keeps colour (else none), for
    /// [`Tally::absorb_scored`].
    pub fn scored_xyz(&self, c: &ChunkTally) -> Vec<ScoredXyz> {
        match self.color {
            Some(_) => ColorTally::scored(&c.detections),
            None => Vec::new(),
        }
    }

    /// Add the events of one traced chunk whose detections are `scored`
    /// ([`ChunkTally::scored`]) with colours `xyz` ([`ColorTally::scored`]; empty when the
    /// tally has no colour).
    pub fn absorb_scored(&mut self, c: &ChunkTally, scored: &[BinStats], xyz: &[ScoredXyz]) {
        for (d, one) in c.detections.iter().zip(scored) {
            self.flux.bins[d.flux_bin as usize].merge(one);
            self.angular.bins[d.angular_bin as usize].merge(one);
        }
        if let Some(color) = &mut self.color {
            color.absorb(&c.detections, xyz);
        }
        if let Some(meter) = &mut self.meter {
            meter.absorb(&c.meter, c.peeled, &c.counted);
        }
        if let Some(stokes) = &mut self.stokes {
            for (d, s) in c.detections.iter().zip(&c.stokes) {
                for (grid, k) in stokes.iter_mut().zip(s) {
                    grid.bins[d.flux_bin as usize].add(d.weight * k);
                }
            }
        }
        self.ledger.merge(&c.ledger);
    }
}

/// Whether a Stokes grid could not come from a run of `photons` photons: a bin whose
/// squares sum is negative, whose sum exceeds what its squares allow (`sum^2 <= hits *
/// sumsq`, Cauchy-Schwarz, up to the rounding of each term to the sums' grid: a nearly
/// unpolarized photon's `S1 w` of 1e-12 adds its value to the sum but its square, below
/// the grid, nothing to the squares), or that holds more photons than were emitted.
fn bad_stokes(g: &Grid, photons: u64) -> bool {
    g.bins.iter().any(|b| {
        let hits = b.hits as f64;
        let grid = hits * 2f64.powi(-FRACTION_BITS);
        let sum = (b.sum.value().abs() - grid).max(0.0);
        let sumsq = b.sumsq.value() + grid;
        b.sumsq.0 < 0 || b.hits > photons || sum * sum > 1.000001 * sumsq * hits
    })
}

/// One detected photon.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detection {
    /// Index of the flux bin.
    pub flux_bin: u32,
    /// Index of the angular bin.
    pub angular_bin: u32,
    /// Photon weight at detection.
    pub weight: f64,
    /// The photon's light (its hero wavelength, for the colour tallies)...
    pub light: Light,
    /// ...and the other wavelengths it carried ([`Secondaries::xyz`] scores them).
    pub secondaries: Secondaries,
}

/// What one chunk of photons scored: a list of detections (cheap to ship between
/// threads) and its ledger.
#[derive(Clone, Debug)]
pub struct ChunkTally {
    /// Index of the chunk (photons `index * CHUNK ..`, [`crate::tracer::CHUNK`]).
    pub index: u64,
    /// Detections, in photon order.
    pub detections: Vec<Detection>,
    /// Each detection's `(S1, S2, S3) / S0` in the detector's frame, when polarization is
    /// traced (else empty: kept apart so that a run without it moves no more bytes).
    pub stokes: Vec<[f64; 3]>,
    /// What the luminance meter read, per photon merged per view and bin (empty without
    /// a luminance map).
    pub meter: Vec<MeterHit>,
    /// Per place a peel-off starts from (each tag, then each lamp body), the peel-offs
    /// tried in this chunk and those that reached the target (the tracer's `meter`).
    pub peel_tries: Vec<[u32; 2]>,
    /// The chunk's backward walks, reused by the meter's peel-offs (scratch, emptied
    /// before the chunk is shipped: [`meter::PeelWalks`]).
    pub peel_walks: meter::PeelWalks,
    /// Radiant weight the meter's peel-off scored, and what it counted in the cones by
    /// cause ([`MeterTally::counted`]).
    pub peeled: ExactSum,
    /// See `peeled`.
    pub counted: Vec<ExactSum>,
    /// The chunk's ledger.
    pub ledger: Ledger,
}

impl ChunkTally {
    /// Each detection scored alone into a bin: rounded to fixed point once, then merged
    /// into a flux and an angular bin of every tally the chunk goes to (the same integers
    /// as scoring it in each).
    pub fn scored(&self) -> Vec<BinStats> {
        self.detections
            .iter()
            .map(|d| {
                let mut one = BinStats::default();
                one.add(d.weight);
                one
            })
            .collect()
    }
}

#[cfg(test)]
mod tests;
