//! What a photon's secondary wavelengths
//! ([`crate::optics::spectrum::Secondaries`], hero-wavelength sampling) make
//! of each event its hero takes: the tracer's one place for them, called after an event
//! only when the photon carries them (a monochrome scene never does).

use super::Photon;
use crate::optics::medium::{Interface, Medium};
use crate::optics::spectrum::Spectral;
use crate::optics::surface::{Estimator, Feature, SurfaceModel};

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
    /// The hero was scattered by `model` (meeting its `feature`): its secondaries follow.
    #[inline]
    pub(super) fn scattered_by(
        &mut self,
        model: &SurfaceModel,
        feature: Feature,
        media: &[Medium],
        estimator: Estimator,
    ) {
        if !self.secondaries.live() {
            return;
        }
        match surface_event(model, feature, media) {
            SurfaceEvent::Neutral => {}
            SurfaceEvent::Albedo(q) => self.secondaries.survived(estimator, q, self.light),
            SurfaceEvent::Splits => self.secondaries.end(),
        }
    }

    /// The hero crossed `t` mm of `medium` (clear, or flew that far through a scattering
    /// one without being absorbed): its secondaries' absorption there.
    #[inline]
    pub(super) fn crossed(&mut self, medium: &Medium, t: f64, estimator: Estimator) {
        if self.secondaries.live() {
            let a = &medium.absorption_per_mm;
            self.secondaries.crossed(estimator, a, self.light, t);
        }
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
        let per: Vec<_> = chunks.map(|c| chunk_xyz(t, c)).collect();
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
            single.hero = false;
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

    /// Where every photon refracts into the guide through a dispersive face (the
    /// bundled notebook14-color: Sellmeier PMMA) the secondaries end there: the run is the
    /// one-wavelength run, bit for bit.
    #[test]
    fn secondaries_end_at_a_dispersive_refraction() {
        for estimator in [Estimator::Analog, Estimator::Weighted] {
            let chunks =
                assert_same_chunks("notebook14-color", estimator, |_| {}, |t| t.hero = false);
            assert!(
                chunks
                    .iter()
                    .all(|c| c.detections.iter().all(|d| !d.secondaries.live()))
            );
            assert!(chunks.iter().any(|c| !c.detections.is_empty()));
        }
    }
}
