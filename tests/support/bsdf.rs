//! BSDF tables for the tests of `model = "bsdf_table"`: sections built from formulas,
//! the model built from a `[surfaces.*]` body, photons scattered at it.

use super::temp_folder;
use blutrace::estimator::Estimator;
use blutrace::geometry::SurfaceHit;
use blutrace::optics::bsdf_table::format::{self, Block, ScatterType, Section};
use blutrace::optics::medium::Medium;
use blutrace::optics::surface::{Outcome, SurfaceModel, SurfaceSpec};
use blutrace::rng::PhotonRng;
use blutrace::spec_check::Ctx;
use glam::DVec3;
use std::f64::consts::PI;

/// A table section of `scatter` with BSDF `f(azimuth_deg, radial_deg)` and TIS `tis(aoi)`.
pub fn section(
    scatter: ScatterType,
    (aoi, azimuth, radial): (&[f64], &[f64], &[f64]),
    plane_symmetric: bool,
    tis: impl Fn(f64) -> f64,
    f: impl Fn(f64, f64) -> f64,
) -> Section {
    let blocks = aoi
        .iter()
        .map(|&a| Block {
            tis: tis(a),
            line: 0,
            values: azimuth
                .iter()
                .map(|&p| radial.iter().map(|&r| f(p, r)).collect())
                .collect(),
        })
        .collect();
    Section {
        scatter,
        channel: None,
        plane_symmetric,
        rotations: vec![0.0],
        aoi: aoi.to_vec(),
        azimuth: azimuth.to_vec(),
        radial: radial.to_vec(),
        blocks,
    }
}

pub fn steps(step: f64, max: f64) -> Vec<f64> {
    (0..=(max / step).round() as usize)
        .map(|i| i as f64 * step)
        .collect()
}

/// A Lambertian reflector of albedo `albedo` as a table: BRDF albedo / pi, TIS albedo.
pub fn lambert_table(albedo: f64) -> String {
    let (aoi, az, rad) = (steps(20.0, 80.0), steps(30.0, 180.0), steps(10.0, 180.0));
    let s = section(
        ScatterType::Brdf,
        (&aoi, &az, &rad),
        true,
        |_| albedo,
        |_, _| albedo / PI,
    );
    format::write(&[s], &["Lambertian".into()])
}

/// The model `table` (a `[surfaces.*]` body) builds with `files` beside the scene.
pub fn model(table: &str, files: &[(&str, &str)]) -> anyhow::Result<SurfaceModel> {
    let dir = temp_folder("bsdf-model");
    for (f, text) in files {
        std::fs::write(dir.path().join(f), text).unwrap();
    }
    let spec: SurfaceSpec = toml::from_str(table)?;
    let media = [
        Medium::clear("air", 1.0, 0.0),
        Medium::clear("pet", 1.58, 0.0),
    ];
    let path = dir.path().join("scene.toml");
    spec.build(&Ctx(&path), "surfaces.film", &media)
}

/// Scatter `n` photons arriving at `theta_deg` (from +z, onto z = 0 of normal +z) and
/// return the directions that left (reflected or transmitted) and their weights.
pub fn scatter(m: &SurfaceModel, theta_deg: f64, n: u64, est: Estimator) -> Vec<(DVec3, f64)> {
    scatter_on(m, theta_deg, 1.0, n, est)
        .into_iter()
        .map(|(d, w, _)| (d, w))
        .collect()
}

/// [`scatter`] from the side `side` says (+1: from +z, on the front; -1: from -z, on the
/// back of the face at z = 0 of normal +z), with the medium each photon left into.
pub fn scatter_on(
    m: &SurfaceModel,
    theta_deg: f64,
    side: f64,
    n: u64,
    est: Estimator,
) -> Vec<(DVec3, f64, u16)> {
    let media = [
        Medium::clear("air", 1.0, 0.0),
        Medium::clear("pet", 1.58, 0.0),
    ];
    let t = theta_deg.to_radians();
    let d = DVec3::new(t.sin(), 0.0, -side * t.cos());
    let hit = SurfaceHit {
        t: 1.0,
        prim: 0,
        point: DVec3::ZERO,
        normal: DVec3::Z,
    };
    let from = if side > 0.0 { 0 } else { 1 };
    (0..n)
        .filter_map(|i| {
            let mut rng = PhotonRng::new(11, i);
            match m.interact(&media, &hit, d, from, est, &mut rng) {
                Outcome::Scattered {
                    dir,
                    weight,
                    medium,
                } => Some((dir, weight, medium)),
                Outcome::Absorbed => None,
            }
        })
        .collect()
}
