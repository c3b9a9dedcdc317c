//! What the luminance meter reads: per view of the detector ([`crate::detector`]), per
//! flux bin, the light reaching it within the view's cone, in the cone estimator's units
//! (photon weight that left within the cone) whichever estimator scored it
//! ([`crate::tracer`]'s meter). Spectral runs keep X, Y, Z; others the luminous weight.
//!
//! Each photon's contributions to one bin of one view are summed before they are scored
//! ([`MeterHit`]s merged per photon), so a bin's sum of squares is over photons, as every
//! tally's is ([`super::BinStats`]), and its errors stay right though one photon scores a
//! bin many times.

use super::{ExactSum, Grid, Sign};
use crate::optics::polarization::Polarization;
use crate::optics::spectrum::{Light, Secondaries};
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Per view, the meter's grids: one (the luminous weight) or, in a spectral run, X, Y, Z.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct MeterTally {
    /// Per view, its grids.
    pub views: Vec<Vec<Grid>>,
    /// Radiant weight the peel-off scored (every view).
    pub peeled: ExactSum,
    /// Radiant weight counted in the cones instead, by the cause that kept the peel-off
    /// from it ([`Cause`] order: each tag, each lamp body, then emission, volume
    /// scattering, and turned within a solid's walk).
    pub counted: Vec<ExactSum>,
}

/// Why light reached a meter's cone without a peel-off that scored it, as
/// [`MeterTally::counted`] indexes it after the tags and lamp bodies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cause {
    /// It met no diffuse event since it was emitted.
    Emission,
    /// Its last event was volume scattering.
    Volume,
    /// A face inside a convex solid's walk turned its direction.
    TurnedInWalk,
}

impl Cause {
    /// The causes after the tags and lamp bodies.
    pub const ALL: [Cause; 3] = [Cause::Emission, Cause::Volume, Cause::TurnedInWalk];

    /// Its index in [`MeterTally::counted`] for a scene of `places` tags and bodies.
    pub fn index(self, places: usize) -> u32 {
        (places + self as usize) as u32
    }
}

/// One photon's light reaching one view's meter in one flux bin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeterHit {
    /// The view.
    pub view: u16,
    /// The flux bin.
    pub flux_bin: u32,
    /// Weight in cone-count units (a photon of this weight leaving within the cone).
    pub weight: f64,
    /// Its X, Y, Z (the weight times the colour matching functions at the wavelengths
    /// it carries), in a spectral run.
    pub xyz: [f64; 3],
}

impl MeterHit {
    /// The hit of `weight` in `view` and `flux_bin` of light `light` that carries the
    /// wavelengths `secondaries` in a spectral run (`None`: a monochrome one).
    pub fn new(
        (view, flux_bin): (u16, u32),
        weight: f64,
        light: Light,
        secondaries: Option<&Secondaries>,
    ) -> MeterHit {
        let xyz = secondaries.map_or([0.0; 3], |s| s.xyz(light, weight));
        MeterHit {
            view,
            flux_bin,
            weight,
            xyz,
        }
    }
}

impl MeterTally {
    /// Empty: `views` views of `nx` x `ny` bins, X, Y, Z when `spectral`.
    /// `places`: the scene's tags and lamp bodies.
    pub fn new(views: usize, (nx, ny): (usize, usize), spectral: bool, places: usize) -> Self {
        let grids = if spectral { 3 } else { 1 };
        MeterTally {
            views: (0..views)
                .map(|_| (0..grids).map(|_| Grid::new(nx, ny)).collect())
                .collect(),
            peeled: ExactSum::default(),
            counted: vec![ExactSum::default(); places + Cause::ALL.len()],
        }
    }

    /// The luminous grid of view `k` (Y in a spectral run).
    pub fn luminous(&self, k: usize) -> &Grid {
        let v = &self.views[k];
        &v[v.len() / 2]
    }

    /// X, Y, Z of view `k`, in a spectral run.
    pub fn xyz(&self, k: usize) -> Option<[&Grid; 3]> {
        let v = &self.views[k];
        (v.len() == 3).then(|| [&v[0], &v[1], &v[2]])
    }

    /// Score a chunk's `hits`, one photon's contributions after another (a photon's hits
    /// to the same view and bin merged already: [`merge_photon_hits`]), and its split
    /// between peel-off and cone count.
    pub fn absorb(&mut self, hits: &[MeterHit], peeled: ExactSum, counted: &[ExactSum]) {
        self.peeled.merge(peeled);
        for (a, b) in self.counted.iter_mut().zip(counted) {
            a.merge(*b);
        }
        for h in hits {
            let grids = &mut self.views[h.view as usize];
            let bin = h.flux_bin as usize;
            if grids.len() == 3 {
                for (g, c) in grids.iter_mut().zip(h.xyz) {
                    g.bins[bin].add(c);
                }
            } else {
                grids[0].bins[bin].add(h.weight);
            }
        }
    }

    /// Every grid.
    fn grids(&self) -> impl Iterator<Item = &Grid> {
        self.views.iter().flatten()
    }

    /// The grids' shapes, and the number of causes as one more.
    pub fn shape(&self) -> Vec<(usize, usize, usize)> {
        let causes = (self.counted.len(), 0, 0);
        self.grids()
            .map(|g| (g.nx, g.ny, g.bins.len()))
            .chain([causes])
            .collect()
    }

    /// The fraction of the light the meter read that the cone count scored, and the
    /// cause of most of it (its index in [`MeterTally::counted`]); `None` when it read
    /// nothing.
    pub fn counted_fraction(&self) -> Option<(f64, usize)> {
        let counted: f64 = self.counted.iter().map(|c| c.value()).sum();
        let all = counted + self.peeled.value();
        let (top, _) = self
            .counted
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.0.cmp(&b.1.0))?;
        (all > 0.0).then_some((counted / all, top))
    }

    /// Whether a bin holds negative weight or more than `photons` photons.
    pub fn has_bad_bin(&self, photons: u64) -> bool {
        let negative = |s: &ExactSum| s.0 < 0;
        if negative(&self.peeled) || self.counted.iter().any(negative) {
            return true;
        }
        self.grids().any(|g| {
            g.bins
                .iter()
                .any(|b| b.sum.0 < 0 || b.sumsq.0 < 0 || b.hits > photons)
        })
    }

    /// Add `o` (or take it out).
    pub fn merge_signed(&mut self, o: &MeterTally, sign: Sign) {
        for (a, b) in self.views.iter_mut().flatten().zip(o.grids()) {
            a.merge_signed(b, sign);
        }
        self.peeled.merge_signed(o.peeled, sign);
        for (a, b) in self.counted.iter_mut().zip(&o.counted) {
            a.merge_signed(*b, sign);
        }
    }

    /// Add `o`, or `None` past the counters' range.
    pub fn checked_merge(&mut self, o: &MeterTally) -> Option<()> {
        for (a, b) in self.views.iter_mut().flatten().zip(o.grids()) {
            a.checked_merge(b)?;
        }
        self.peeled = self.peeled.checked_add(o.peeled)?;
        for (a, b) in self.counted.iter_mut().zip(&o.counted) {
            *a = a.checked_add(*b)?;
        }
        Some(())
    }
}

/// Merge one photon's `hits` (the tail of a chunk's list it scored) to one per view and
/// bin, in (view, bin) order: the sums are then per photon, as [`super::BinStats`] wants.
pub fn merge_photon_hits(hits: &mut Vec<MeterHit>, from: usize) {
    let mine = &mut hits[from..];
    if mine.len() < 2 {
        return;
    }
    mine.sort_by_key(|h| (h.view, h.flux_bin));
    let mut kept = from;
    for i in from + 1..hits.len() {
        let (k, h) = (kept, hits[i]);
        if (hits[k].view, hits[k].flux_bin) == (h.view, h.flux_bin) {
            hits[k].weight += h.weight;
            (0..3).for_each(|c| hits[k].xyz[c] += h.xyz[c]);
        } else {
            kept += 1;
            hits[kept] = h;
        }
    }
    hits.truncate(kept + 1);
}

/// A backward walk of the meter's peel-off from the target down to a diffuse event's
/// face (`tracer::meter_walk`), as the chunk keeps it for reuse.
#[derive(Clone, Copy, Debug)]
pub struct PeelWalk {
    /// The direction drawn in the view's cone.
    pub out: DVec3,
    /// From the point the walk met the face to where it left the target.
    pub shift: DVec3,
    /// The forward light's direction at the face.
    pub dir: DVec3,
    /// The medium that direction runs in.
    pub medium: crate::optics::medium::MediumId,
    /// The walk's throughput (0: it met nothing it may end on).
    pub weight: f64,
    /// The detector's response carried back (polarization traced).
    pub importance: Option<Polarization>,
}

/// One chunk's backward walks per (place, view): the first [`PeelWalks::SIZE`] peel-offs
/// of a place draw theirs, later ones reuse them in turn. Every walk is drawn
/// independently of the events that use it, so each event's estimate stays unbiased;
/// events share walks only within a chunk, so chunks stay independent (the errors'
/// jackknife holds).
#[derive(Clone, Debug, Default)]
pub struct PeelWalks {
    /// Per `place * views + view`, the walks drawn so far and how many uses they served.
    lists: Vec<(Vec<PeelWalk>, u32)>,
}

impl PeelWalks {
    /// Walks a chunk draws per place and view.
    pub const SIZE: usize = 1024;

    /// The walks of key `place * views + view` and their uses so far.
    pub fn slot(&mut self, key: usize) -> (&mut Vec<PeelWalk>, &mut u32) {
        if self.lists.len() <= key {
            self.lists.resize_with(key + 1, Default::default);
        }
        let (list, uses) = &mut self.lists[key];
        (list, uses)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(view: u16, flux_bin: u32, weight: f64) -> MeterHit {
        MeterHit {
            view,
            flux_bin,
            weight,
            xyz: [weight, 2.0 * weight, 3.0 * weight],
        }
    }

    #[test]
    fn a_photons_hits_merge_per_view_and_bin() {
        let mut hits = vec![
            hit(0, 9, 5.0),
            hit(1, 3, 1.0),
            hit(0, 3, 2.0),
            hit(1, 3, 0.5),
        ];
        hits.push(hit(0, 3, 0.25));
        merge_photon_hits(&mut hits, 1);
        assert_eq!(
            hits,
            vec![hit(0, 9, 5.0), hit(0, 3, 2.25), hit(1, 3, 1.5)],
            "the first hit is another photon's and stays"
        );
    }

    #[test]
    fn spectral_views_keep_xyz() {
        let mut t = MeterTally::new(2, (2, 1), true, 0);
        t.absorb(&[hit(1, 1, 2.0)], ExactSum::default(), &[]);
        let [x, y, z] = t.xyz(1).unwrap();
        assert_eq!((x.bins[1].sum.value(), y.bins[1].sum.value()), (2.0, 4.0));
        let one = MeterHit::new((0, 1), 2.0, Light::at_nm(555.0), Some(&Secondaries::NONE));
        let cmf = crate::sources::spectrum::cmf_at(555.0);
        assert_eq!(one.xyz, cmf.map(|c| 2.0 * c));
        assert_eq!(
            MeterHit::new((0, 1), 2.0, Light::MONOCHROME, None).xyz,
            [0.0; 3]
        );
        assert_eq!(t.luminous(1), y);
        assert!(z.bins[1].hits == 1 && t.luminous(0).bins[1].hits == 0);
        assert!(MeterTally::new(1, (2, 1), false, 0).xyz(0).is_none());
    }
}
