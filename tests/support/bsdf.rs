//! BSDF tables for the tests of `model = "bsdf_table"`: sections built from formulas,
//! the model built from a `[surfaces.*]` body, photons scattered at it.

use super::{assert_balanced, load, temp_folder, trace, write_scene};
use blutrace::characterise::{Options, characterise};
use blutrace::estimator::Estimator;
use blutrace::geometry::SurfaceHit;
use blutrace::optics::bsdf_table::format::{self, Block, ScatterType, Section};
use blutrace::optics::medium::Medium;
use blutrace::optics::surface::{Outcome, SurfaceModel, SurfaceSpec};
use blutrace::rng::PhotonRng;
use blutrace::run::RunResult;
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

/// An asymmetric table of `scatter` on sample rotations `rotations` (degrees), uniform
/// over the hemisphere about the specular direction at AOIs 0 and 60, TIS `tis(rotation)`.
pub fn rotated(scatter: ScatterType, rotations: &[f64], tis: impl Fn(f64) -> f64) -> String {
    let (az, rad) = (steps(90.0, 270.0), steps(15.0, 90.0));
    let one = section(
        scatter,
        (&[0.0, 60.0], &az, &rad),
        false,
        |_| 0.0,
        |_, _| 0.2,
    );
    let blocks = rotations
        .iter()
        .flat_map(|&r| {
            let t = tis(r);
            one.blocks.iter().map(move |b| Block {
                tis: t,
                ..b.clone()
            })
        })
        .collect();
    let s = Section {
        rotations: rotations.to_vec(),
        blocks,
        ..one
    };
    format::write(&[s], &[])
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

/// A sheet's triangles facing up (+z), towards the LED of [`sheet_run`].
pub const UP: &str = "f 1 2 3\nf 1 3 4\n";
/// A sheet's triangles facing down (-z): the LED of [`sheet_run`] lights their back.
pub const DOWN: &str = "f 1 3 2\nf 1 4 3\n";

/// A 200 x 200 mm sheet at z = 0 with triangles `faces` ([`UP`] or [`DOWN`]) under a
/// Lambertian LED at z = 5 facing down, a detector at z = 10: `sheet` is its
/// `[surfaces.sheet]` body, `files` the files beside the scene; 200,000 photons.
pub fn sheet_run(faces: &str, name: &str, sheet: &str, files: &[(&str, &str)]) -> RunResult {
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"sheet.obj\"\n[surfaces.sheet]\n{sheet}\n\
         [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, 5.0]\nnormal = [0.0, 0.0, -1.0]\n\
         u = [1.0, 0.0, 0.0]\nwidth_mm = 2.0\nheight_mm = 2.0\npower_w = 1.0\n\
         [detector]\norigin = [-100.0, -100.0, 10.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [200.0, 200.0]\nbins = [4, 4]\nangular_bins = [3, 4]\n"
    );
    let obj =
        format!("v -100 -100 0\nv 100 -100 0\nv 100 100 0\nv -100 100 0\nusemtl sheet\n{faces}");
    let mut all = vec![("sheet.obj", obj.as_str())];
    all.extend_from_slice(files);
    let run = trace(&load(&write_scene(name, &toml, &all)), 200_000, 5, 2);
    assert_balanced(&run);
    run
}

/// The stack of the film tests: a 0.2 mm film (medium `film`, declared in `media`;
/// 400 x 400 mm, so its edges see almost no light) at z = 0..0.2 over an LED at z = -5
/// and a Lambertian reflector at z = -6, a detector at z = 1 covering the film (it counts
/// light going up). `film_bottom` and `film_top` are the faces' `[surfaces.*]` bodies,
/// `sources` more `[[sources]]` entries; 400,000 photons.
pub fn stack(
    name: &str,
    (film_bottom, film_top): (&str, &str),
    media: &str,
    sources: &str,
    files: &[(&str, &str)],
) -> RunResult {
    let quad = |z: f64, tag: &str, up: bool| {
        let f = if up {
            "f 1 2 3\nf 1 3 4"
        } else {
            "f 1 3 2\nf 1 4 3"
        };
        format!(
            "v -200 -200 {z}\nv 200 -200 {z}\nv 200 200 {z}\nv -200 200 {z}\nusemtl {tag}\n{f}\n"
        )
    };
    let edge = "v -200 -200 0\nv 200 -200 0\nv 200 -200 0.2\nv -200 -200 0.2\nv 200 200 0\nv 200 200 0.2\n\
                v -200 200 0\nv -200 200 0.2\nusemtl film_edge\nf 1 2 3\nf 1 3 4\nf 2 5 6\nf 2 6 3\n\
                f 5 7 8\nf 5 8 6\nf 7 1 4\nf 7 4 8\n";
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"bottom.obj\"\n[[geometry]]\nfile = \"top.obj\"\n\
         [[geometry]]\nfile = \"edge.obj\"\n[[geometry]]\nfile = \"sheet.obj\"\n{media}\n\
         [surfaces.film_bottom]\n{film_bottom}\n[surfaces.film_top]\n{film_top}\n\
         [surfaces.film_edge]\nmodel = \"dielectric\"\ninside = \"film\"\n\
         [surfaces.sheet]\nmodel = \"lambert\"\nalbedo = 0.9\n\
         [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, -5.0]\nnormal = [0.0, 0.0, 1.0]\n\
         u = [1.0, 0.0, 0.0]\nwidth_mm = 2.0\nheight_mm = 2.0\npower_w = 1.0\n\
         [detector]\norigin = [-200.0, -200.0, 1.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [400.0, 400.0]\nbins = [4, 4]\nangular_bins = [6, 4]\n{sources}"
    );
    let (b, t, s) = (
        quad(0.0, "film_bottom", false),
        quad(0.2, "film_top", true),
        quad(-6.0, "sheet", true),
    );
    let mut all = vec![
        ("bottom.obj", b.as_str()),
        ("top.obj", t.as_str()),
        ("edge.obj", edge),
        ("sheet.obj", s.as_str()),
    ];
    all.extend_from_slice(files);
    let run = trace(&load(&write_scene(name, &toml, &all)), 400_000, 9, 2);
    assert_balanced(&run);
    run
}

/// The film of the stack: PET, 1.58, clear.
pub const PET: &str = "[media.film]\nn = 1.58\nabsorption_per_mm = 0.0\n";
/// The film's place in a stack of its tables: index 1, so the far face does nothing.
pub const GAP: &str = "[media.film]\nn = 1.0\nabsorption_per_mm = 0.0\n";
/// A film smooth below and rough on top (GGX, roughness 0.5): the two faces' bodies.
pub const GGX_FILM: (&str, &str) = (
    "model = \"dielectric\"\ninside = \"film\"",
    "model = \"diffuser\"\ninside = \"film\"\nroughness = 0.5",
);

/// The IS BSDF table of the film of `run`'s scene lit on face `tag` (its far face
/// `far`): 300,000 photons at 11 AOIs, 2 x 10 degree cells.
pub fn film_table(run: &RunResult, tag: &str, far: &str) -> String {
    let opts = Options {
        tag: tag.into(),
        photons: 300_000,
        aoi_deg: vec![
            0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 85.0, 89.0,
        ],
        rotations_deg: vec![0.0],
        radial_step_deg: 2.0,
        azimuth_step_deg: 10.0,
        u_axis: None,
        seed: 3,
    };
    let c = characterise(&run.scene, &opts).unwrap();
    assert!(
        c.part.contains("slab of film") && c.part.contains(far),
        "{}",
        c.part
    );
    format::write(&c.sections, &[])
}

/// The detected weight per polar bin of the angular tally (its theta runs fastest),
/// summed over azimuth.
pub fn polar_sums(r: &RunResult) -> Vec<f64> {
    let g = &r.tally.angular;
    (0..g.nx)
        .map(|i| (0..g.ny).map(|j| g.bins[j * g.nx + i].sum.value()).sum())
        .collect()
}
