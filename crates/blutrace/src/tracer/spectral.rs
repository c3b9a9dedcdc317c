//! What a photon's secondary wavelengths
//! ([`crate::optics::spectrum::Secondaries`], hero-wavelength sampling) make
//! of each event its hero takes: the tracer's one place for them, called after an event
//! only when the photon carries them (a monochrome scene never does).

use super::Photon;
use crate::optics::medium::{Interface, Medium, MediumId};
use crate::optics::spectrum::{Light, Secondaries, Spectral};
use crate::optics::surface::{Estimator, Feature, SurfaceModel};
use crate::scene::Scene;
use crate::sources::Emission;

/// Which wavelengths a photon of a spectral source carries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Carried {
    /// The hero and its secondaries (what runs do).
    Hero,
    /// One wavelength, the hero's (the tests' reference: the tracer before hero
    /// wavelengths).
    #[cfg_attr(not(test), allow(dead_code))]
    One,
    /// One wavelength, the emission's `k`-th of its stratified set (0: the hero): the
    /// same random numbers at each of the set's wavelengths in turn, for the tests'
    /// measure of correlated paths.
    #[cfg_attr(not(test), allow(dead_code))]
    Stratum(usize),
}

impl Carried {
    /// The light a photon of emission `e` (in `scene`) is traced at, and the secondaries
    /// it carries.
    pub(super) fn of(self, e: &Emission, scene: &Scene) -> (Light, Secondaries) {
        match self {
            Carried::Hero => (e.light, e.secondaries),
            Carried::One | Carried::Stratum(0) => (e.light, Secondaries::NONE),
            Carried::Stratum(k) => {
                let mut s = e.secondaries;
                draw(&mut s, scene);
                (s.light(k - 1).unwrap_or(e.light), Secondaries::NONE)
            }
        }
    }
}

/// Draw the wavelengths of `s` from its source's spectrum in `scene`, if not yet drawn.
#[inline]
fn draw(s: &mut Secondaries, scene: &Scene) {
    if let Some(i) = s.undrawn() {
        let spectrum = scene.sources.list[i].spectrum.as_ref();
        let spectrum = spectrum.expect("secondaries come from a source's spectrum");
        s.draw(|v| spectrum.sample(v));
    }
}

/// What a surface event is to the secondaries.
enum SurfaceEvent<'m> {
    /// The same for every wavelength.
    Neutral,
    /// Survival of this albedo or reflectance (opaque reflection, ink).
    Albedo(&'m Spectral),
    /// The path depends on the wavelength (dispersive refraction, a spectral polarizer):
    /// no secondary would go where the hero goes.
    Splits,
}

/// What the hero's scattering off `model` (meeting its `feature`) is to the secondaries.
fn surface_event<'m>(
    model: &'m SurfaceModel,
    feature: Feature,
    media: &[Medium],
) -> SurfaceEvent<'m> {
    let by_interface = |i: Interface| {
        let dispersive = |m| media[m as usize].n.is_spectral();
        if dispersive(i.inside) || dispersive(i.outside) {
            SurfaceEvent::Splits
        } else {
            SurfaceEvent::Neutral
        }
    };
    match model {
        SurfaceModel::Lambert(m) => SurfaceEvent::Albedo(&m.albedo),
        SurfaceModel::Phong(m) => SurfaceEvent::Albedo(&m.reflectance),
        SurfaceModel::Mirror(m) => SurfaceEvent::Albedo(&m.reflectance),
        SurfaceModel::Dots(m) if feature == Feature::Ink => SurfaceEvent::Albedo(&m.ink_albedo),
        SurfaceModel::Polarizer(m) if m.is_spectral() => SurfaceEvent::Splits,
        // Absorber: nothing survives it; a measured BSDF table is one for every wavelength.
        SurfaceModel::Absorber(_) | SurfaceModel::Polarizer(_) | SurfaceModel::BsdfTable(_) => {
            SurfaceEvent::Neutral
        }
        SurfaceModel::Dielectric(_)
        | SurfaceModel::Dots(_)
        | SurfaceModel::Grooves(_)
        | SurfaceModel::Diffuser(_) => model
            .interface()
            .map_or(SurfaceEvent::Neutral, by_interface),
    }
}

impl Photon {
    /// The hero was scattered by `model` (meeting its `feature`) in `scene`: its
    /// secondaries follow.
    #[inline]
    pub(super) fn scattered_by(
        &mut self,
        model: &SurfaceModel,
        feature: Feature,
        scene: &Scene,
        estimator: Estimator,
    ) {
        if !self.secondaries.live() {
            return;
        }
        match surface_event(model, feature, &scene.media) {
            SurfaceEvent::Neutral => {}
            SurfaceEvent::Albedo(q) if !q.is_spectral() => {}
            SurfaceEvent::Albedo(q) => {
                draw(&mut self.secondaries, scene);
                self.secondaries.survived(estimator, q, self.light);
            }
            SurfaceEvent::Splits => self.secondaries.end(),
        }
    }

    /// The hero crossed `t` mm of medium `m` of `scene` (clear, or flew that far through
    /// a scattering one without being absorbed): its secondaries' absorption there.
    #[inline]
    pub(super) fn crossed(&mut self, m: MediumId, t: f64, scene: &Scene, estimator: Estimator) {
        if !self.secondaries.live() {
            return;
        }
        let a = &scene.media[m as usize].absorption_per_mm;
        if a.is_spectral() {
            draw(&mut self.secondaries, scene);
            self.secondaries.crossed(estimator, a, self.light, t);
        }
    }

    /// Its secondaries as a detection scores them (their wavelengths drawn).
    #[inline]
    pub(super) fn detected_secondaries(&mut self, scene: &Scene) -> Secondaries {
        draw(&mut self.secondaries, scene);
        self.secondaries
    }

    /// The hero is about to fly through scattering `medium`: a free path or phase
    /// function that depends on the wavelength is the hero's alone.
    #[inline]
    pub(super) fn enters_scattering(&mut self, medium: &Medium) {
        let s = &medium.scattering;
        if self.secondaries.live() && (s.per_mm.is_spectral() || s.anisotropy.is_spectral()) {
            self.secondaries.end();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Carried;
    use crate::color::Xyz;
    use crate::optics::spectrum::Spectral;
    use crate::optics::surface::Estimator;
    use crate::scene::Scene;
    use crate::tracer::{Tracer, assert_same_chunks, bundled};

    /// Bands along the guide (x) the profile is read in.
    const BANDS: usize = 5;

    /// X, Y, Z per band along x, then of the whole target, of chunk `chunk`.
    fn chunk_xyz(t: &Tracer, chunk: u64) -> [[f64; 3]; BANDS + 1] {
        let c = t.trace_chunk(5, chunk, u64::MAX);
        let nx = t.scene.detector.bins[0];
        let mut out = [[0.0; 3]; BANDS + 1];
        for d in &c.detections {
            let band = (d.flux_bin as usize % nx) * BANDS / nx;
            let xyz = d.secondaries.xyz(d.light, d.weight);
            for i in 0..3 {
                out[band][i] += xyz[i];
                out[BANDS][i] += xyz[i];
            }
        }
        out
    }

    fn uv(xyz: [f64; 3]) -> [f64; 2] {
        let [x, y, z] = xyz;
        let p = Xyz { x, y, z }.uv_prime().expect("light");
        [p.u, p.v]
    }

    /// u', v' per band and of the whole target from `chunks`, with jackknife standard
    /// errors over `groups` groups of them: `[u', se, v', se]`.
    fn colour(t: &Tracer, chunks: std::ops::Range<u64>, groups: usize) -> Vec<[f64; 4]> {
        colour_of(chunks.map(|c| chunk_xyz(t, c)), groups)
    }

    /// [`colour`] of chunks' X, Y, Z per band.
    fn colour_of(
        chunks: impl Iterator<Item = [[f64; 3]; BANDS + 1]>,
        groups: usize,
    ) -> Vec<[f64; 4]> {
        let per: Vec<_> = chunks.collect();
        let size = per.len() / groups;
        let group: Vec<[[f64; 3]; BANDS + 1]> = per
            .chunks(size)
            .map(|g| {
                let mut s = [[0.0; 3]; BANDS + 1];
                g.iter().for_each(|c| {
                    (0..=BANDS).for_each(|b| (0..3).for_each(|i| s[b][i] += c[b][i]))
                });
                s
            })
            .collect();
        (0..=BANDS)
            .map(|b| {
                let total: [f64; 3] = std::array::from_fn(|i| group.iter().map(|g| g[b][i]).sum());
                let all = uv(total);
                let loo: Vec<_> = group
                    .iter()
                    .map(|g| uv(std::array::from_fn(|i| total[i] - g[b][i])))
                    .collect();
                let n = loo.len() as f64;
                let se = |k: usize| {
                    let m = loo.iter().map(|p| p[k]).sum::<f64>() / n;
                    ((n - 1.0) / n * loo.iter().map(|p| (p[k] - m).powi(2)).sum::<f64>()).sqrt()
                };
                [all[0], se(0), all[1], se(1)]
            })
            .collect()
    }

    /// notebook14-color with a PMMA of one index (1.49), its absorption still a table: no
    /// event there depends on the wavelength but absorption and the hero path is shared.
    fn clear_index_notebook() -> Scene {
        let mut scene = bundled("notebook14-color");
        let pmma = scene.media.iter_mut().find(|m| m.name == "pmma").unwrap();
        pmma.n = Spectral::constant(1.49);
        assert!(pmma.absorption_per_mm.is_spectral());
        scene
    }

    /// Hero wavelengths against one wavelength per photon at 10x the photons: the same
    /// u', v' of the whole target and per band along the guide (within 4 standard
    /// errors), and at equal photons a v' error at least 3x smaller.
    #[test]
    fn hero_wavelengths_agree_with_one_wavelength_at_ten_times_the_photons() {
        let scene = clear_index_notebook();
        let accel =
            crate::accel::build(crate::accel::BackendChoice::Bvh, scene.mesh.clone()).unwrap();
        let facets = scene.mesh.facets();
        for estimator in [Estimator::Analog, Estimator::Weighted] {
            let hero = Tracer::new(&scene, accel.as_ref(), estimator, true, &facets);
            let mut single = Tracer::new(&scene, accel.as_ref(), estimator, true, &facets);
            single.wavelengths = Carried::One;
            let h = colour(&hero, 0..20, 20);
            let s = colour(&single, 1000..1200, 20);
            for (b, (h, s)) in h.iter().zip(&s).enumerate() {
                for k in [0, 2] {
                    let se = h[k + 1].hypot(s[k + 1]);
                    assert!(
                        (h[k] - s[k]).abs() < 4.0 * se,
                        "{estimator:?} band {b} {}: hero {h:?} single {s:?}",
                        ["u'", "", "v'"][k]
                    );
                }
                let single_at_equal_photons = s[3] * 10f64.sqrt();
                assert!(
                    h[3] * 3.0 < single_at_equal_photons,
                    "{estimator:?} band {b}: v' error {} vs {single_at_equal_photons}",
                    h[3]
                );
            }
        }
    }

    /// The bundled (dispersive) notebook14-color: one wavelength per photon (what the
    /// secondaries' end at the entry refraction leaves) against the four wavelengths of
    /// a stratified set traced one after the other with the same random numbers
    /// (correlated paths: four traces per photon), at equal cost (4x the photons for
    /// one wavelength). Prints the v' errors per band along the guide; correlated paths
    /// beat termination where theirs is smaller. Ignored: a measurement (README, "Hero
    /// wavelengths").
    #[test]
    #[ignore]
    fn correlated_paths_against_termination_on_dispersive_pmma() {
        let scene = bundled("notebook14-color");
        let accel =
            crate::accel::build(crate::accel::BackendChoice::Bvh, scene.mesh.clone()).unwrap();
        let facets = scene.mesh.facets();
        let tracer = |w| {
            let mut t = Tracer::new(&scene, accel.as_ref(), Estimator::Analog, true, &facets);
            t.wavelengths = w;
            t
        };
        let strata: Vec<_> = (0..4).map(|k| tracer(Carried::Stratum(k))).collect();
        let crn = colour_of(
            (0..40).map(|c| {
                let each: Vec<_> = strata.iter().map(|t| chunk_xyz(t, c)).collect();
                std::array::from_fn(|b| {
                    std::array::from_fn(|i| each.iter().map(|x| x[b][i]).sum::<f64>() / 4.0)
                })
            }),
            20,
        );
        let one = colour(&tracer(Carried::One), 1000..1160, 20);
        for (b, (c, o)) in crn.iter().zip(&one).enumerate() {
            println!(
                "band {b}: v' {:.5} +- {:.5} correlated, {:.5} +- {:.5} one wavelength at 4x photons",
                c[2], c[3], o[2], o[3]
            );
        }
    }

    /// How far the secondaries' throughput ratios spread on the clear-index notebook:
    /// prints quantiles of each detection's largest ratio. Ignored: a measurement.
    #[test]
    #[ignore]
    fn ratio_weights_spread() {
        let scene = clear_index_notebook();
        let accel =
            crate::accel::build(crate::accel::BackendChoice::Bvh, scene.mesh.clone()).unwrap();
        let facets = scene.mesh.facets();
        for estimator in [Estimator::Analog, Estimator::Weighted] {
            let t = Tracer::new(&scene, accel.as_ref(), estimator, true, &facets);
            let mut r: Vec<f64> = (0..20)
                .flat_map(|c| t.trace_chunk(5, c, u64::MAX).detections)
                .map(|d| d.secondaries.largest_ratio())
                .collect();
            r.sort_by(f64::total_cmp);
            let q = |f: f64| r[((r.len() - 1) as f64 * f) as usize];
            println!(
                "{estimator:?}: {} detections, largest ratio median {:.3}, 99% {:.3}, 99.99% {:.3}, max {:.3}",
                r.len(),
                q(0.5),
                q(0.99),
                q(0.9999),
                q(1.0)
            );
        }
    }

    /// Where every photon refracts into the guide through a dispersive face (the
    /// bundled notebook14-color: Sellmeier PMMA) the secondaries end there: the run is the
    /// one-wavelength run, bit for bit.
    #[test]
    fn secondaries_end_at_a_dispersive_refraction() {
        for estimator in [Estimator::Analog, Estimator::Weighted] {
            let chunks = assert_same_chunks(
                "notebook14-color",
                estimator,
                |_| {},
                |t| t.wavelengths = Carried::One,
            );
            assert!(
                chunks
                    .iter()
                    .all(|c| c.detections.iter().all(|d| !d.secondaries.live()))
            );
            assert!(chunks.iter().any(|c| !c.detections.is_empty()));
        }
    }
}
