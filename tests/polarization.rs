//! Polarized transport against closed forms: the 60-degree slab (exact Fresnel for s
//! and p, and the transmitted light's polarization), Malus's law through two polarizer
//! sheets, and a recycling cavity under a reflective polarizer. Each fails with the
//! averaged Fresnel, or with polarizers that do not carry the state.

mod support;

use blutrace::run::RunResult;
use support::{load, trace, write_scene};

/// A square of side `2 half` at height `z` facing up, tag `tag`, its vertices numbered
/// from `first + 1` in the OBJ file.
fn sheet(tag: &str, z: f64, half: f64, first: usize) -> String {
    let v = |x: f64, y: f64| format!("v {x} {y} {z}\n");
    let corners = v(-half, -half) + &v(half, -half) + &v(half, half) + &v(-half, half);
    let [a, b, c, d] = [1, 2, 3, 4].map(|i| i + first);
    format!("{corners}usemtl {tag}\nf {a} {b} {c}\nf {a} {c} {d}\n")
}

/// A detector at z = -3, counting light going down (-z), its frame u = x, v = -y.
const DOWN: &str = "[detector]\norigin = [-300.0, 300.0, -3.0]\nu = [1.0, 0.0, 0.0]\n\
                    v = [0.0, -1.0, 0.0]\nsize_mm = [600.0, 600.0]\nbins = [2, 2]\n";

fn run(name: &str, toml: &str, files: &[(&str, &str)], photons: u64) -> RunResult {
    let scene = load(&write_scene(name, toml, files));
    trace(&scene, photons, 3, 2)
}

fn efficiency(r: &RunResult) -> (f64, f64) {
    let s = r.summary();
    (s.extraction_efficiency, s.extraction_efficiency_stderr)
}

/// A collimated beam at 60 degrees through a lossless 1 mm PMMA slab (n 1.49): with s
/// and p traced apart, `T = ((1 - Rs)/(1 + Rs) + (1 - Rp)/(1 + Rp)) / 2 = 0.8505`, the
/// transmitted light polarized `S1/S0 = (Tp - Ts)/(Tp + Ts) = 0.1712` along the plane of
/// incidence; the averaged Fresnel gives 0.8394, and no polarization.
#[test]
fn the_sixty_degree_slab_transmits_s_and_p_apart() {
    let (s, c) = 60f64.to_radians().sin_cos();
    let rays = format!("0 0 5  {s} 0 {}  1.0\n", -c);
    let obj = support::box_obj([-250.0, -250.0, -0.5], [250.0, 250.0, 0.5], ["slab"; 6]);
    let toml = |pol: bool| {
        format!(
            "version = 1\n[[geometry]]\nfile = \"slab.obj\"\n[media.pmma]\nn = 1.49\n\
             [surfaces.slab]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
             [[sources]]\ntype = \"rayfile\"\nfile = \"beam.rays\"\nbody = \"transparent\"\n\
             {DOWN}[trace]\npolarization = {pol}\n"
        )
    };
    let files = [("slab.obj", obj.as_str()), ("beam.rays", rays.as_str())];
    let n = 200_000;
    let polarized = run("slab-pol", &toml(true), &files, n);
    let (t, se) = efficiency(&polarized);
    assert!(
        (t - 0.8505).abs() < 4.0 * se + 1e-4,
        "polarized T {t} ± {se}"
    );
    let p = polarized
        .summary()
        .polarization
        .expect("polarization traced");
    assert!(
        (p.s1.value - 0.1712).abs() < 4.0 * p.s1.stderr + 5e-4,
        "{p:?}"
    );
    assert!(
        p.s2.value.abs() < 4.0 * p.s2.stderr + 1e-9 && p.s3.value.abs() < 1e-9,
        "{p:?}"
    );
    let averaged = run("slab-avg", &toml(false), &files, n);
    let (a, sa) = efficiency(&averaged);
    assert!(
        (a - 0.8394).abs() < 4.0 * sa + 1e-4,
        "averaged T {a} ± {sa}"
    );
    assert!(averaged.summary().polarization.is_none());
}

/// A scene of sheets in air under a beam going straight down from z = 5, `sheets` its
/// `[surfaces.*]` entries, `obj` their geometry.
fn sheets_scene(obj: &str, sheets: &str, name: &str, photons: u64) -> RunResult {
    polarized_beam(obj, sheets, "", name, photons)
}

/// [`sheets_scene`] with the beam's `polarization = ...` line `state` (or none).
fn polarized_beam(obj: &str, sheets: &str, state: &str, name: &str, photons: u64) -> RunResult {
    let rays = "0 0 5  0 0 -1  1.0\n";
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"sheets.obj\"\n{sheets}\
         [[sources]]\ntype = \"rayfile\"\nfile = \"beam.rays\"\nbody = \"transparent\"\n{state}\n{DOWN}"
    );
    run(
        name,
        &toml,
        &[("sheets.obj", obj), ("beam.rays", rays)],
        photons,
    )
}

/// A source's polarization, relative to its u axis (a ray file's x): linear at 30
/// degrees passes `cos^2 30 = 0.75` of an ideal polarizer along x, circular light half,
/// linear across it nothing; with no polarizer the target sees the source's state.
#[test]
fn a_polarized_source_starts_its_photons_in_its_state() {
    let obj = sheet("film", 0.0, 100.0, 0);
    let film = polarizer("film", 0.0, 0.0);
    for (state, want) in [
        ("polarization = { linear_deg = 30.0 }", 0.75),
        ("polarization = { stokes = [2.0, 0.0, 0.0, 2.0] }", 0.5),
        ("polarization = { linear_deg = 90.0 }", 0.0),
    ] {
        let r = polarized_beam(&obj, &film, state, "source-state", 20_000);
        let (t, se) = efficiency(&r);
        assert!(
            (t - want).abs() < 4.0 * se + 1e-9,
            "{state}: {t} ± {se}, want {want}"
        );
    }
    // A sheet out of the beam's way: the target sees the source's state; both frames are
    // u = x, v = direction x u = -y for light going down.
    let aside = "[surfaces.film]\nmodel = \"lambert\"\nalbedo = 0.5\n";
    let state = "polarization = { linear_deg = 30.0 }";
    let r = polarized_beam(
        &sheet("film", -10.0, 1.0, 0),
        aside,
        state,
        "source-seen",
        2_000,
    );
    let p = r
        .summary()
        .polarization
        .expect("a polarized source traces polarization");
    let s2 = 0.75f64.sqrt();
    assert!(
        (p.s1.value - 0.5).abs() < 1e-9 && (p.s2.value - s2).abs() < 1e-9,
        "{p:?}"
    );
    // Told not to trace polarization, the source's light starts unpolarized: it says so
    // (it said nothing, and the state given was silently dropped).
    let off = format!("{state}\n[trace]\npolarization = false");
    let r = polarized_beam(
        &sheet("film", -10.0, 1.0, 0),
        aside,
        &off,
        "source-off",
        1_000,
    );
    let s = r.summary();
    assert!(s.polarization.is_none());
    assert!(
        s.warnings
            .iter()
            .any(|w| w.starts_with("sources[0].polarization is not traced")),
        "{:?}",
        s.warnings
    );
}

fn polarizer(tag: &str, axis_deg: f64, block_reflectance: f64) -> String {
    let (s, c) = axis_deg.to_radians().sin_cos();
    format!(
        "[surfaces.{tag}]\nmodel = \"polarizer\"\naxis = [{c}, {s}, 0.0]\n\
         pass_transmittance = 1.0\nblock_transmittance = 0.0\nblock_reflectance = {block_reflectance}\n"
    )
}

/// Malus: unpolarized light through two ideal absorbing polarizers `theta` apart passes
/// `cos^2(theta) / 2`, polarized along the second's axis.
#[test]
fn two_polarizers_pass_malus_law() {
    let obj = sheet("first", 1.0, 100.0, 0) + &sheet("second", 0.0, 100.0, 4);
    for theta in [0.0, 30.0, 60.0, 90.0] {
        let sheets = polarizer("first", 0.0, 0.0) + &polarizer("second", theta, 0.0);
        let r = sheets_scene(&obj, &sheets, "malus", 40_000);
        let (t, se) = efficiency(&r);
        let want = 0.5 * f64::to_radians(theta).cos().powi(2);
        assert!(
            (t - want).abs() < 4.0 * se + 1e-9,
            "{theta}: {t} ± {se}, want {want}"
        );
        if theta < 90.0 {
            // Along the second axis, seen in the detector's frame (v = -y).
            let p = r.summary().polarization.unwrap();
            let two = 2.0 * f64::to_radians(theta);
            assert!((p.s1.value - two.cos()).abs() < 1e-9, "{theta}: {p:?}");
            assert!((p.s2.value + two.sin()).abs() < 1e-9, "{theta}: {p:?}");
            assert!((p.dop.value - 1.0).abs() < 1e-9);
            assert_stokes_exr(&r, [two.cos(), -two.sin(), 0.0]);
        }
    }
}

/// A recycling cavity: an LED on a wide Lambertian floor of albedo 0.9 under a reflective
/// polarizer (pass transmitted, block reflected, both wholly): `0.5 / (1 - 0.9/2)`
/// = 0.9091 of the emitted power leaves, all of it polarized; an absorbing polarizer
/// passes 0.5.
#[test]
fn a_reflective_polarizer_recycles_what_it_blocks() {
    let obj = sheet("floor", 0.0, 2000.0, 0) + &sheet("film", 1.0, 2000.0, 4);
    let cavity = |block_reflectance: f64| {
        format!(
            "version = 1\n[[geometry]]\nfile = \"cavity.obj\"\n\
             [surfaces.floor]\nmodel = \"lambert\"\nalbedo = 0.9\n{}\
             [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, 0.01]\nnormal = [0.0, 0.0, 1.0]\n\
             u = [1.0, 0.0, 0.0]\nwidth_mm = 0.5\nheight_mm = 0.5\npower_w = 1.0\nbody = \"transparent\"\n\
             [detector]\norigin = [-2000.0, -2000.0, 2.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
             size_mm = [4000.0, 4000.0]\nbins = [2, 2]\n",
            polarizer("film", 0.0, block_reflectance)
        )
    };
    let files = [("cavity.obj", obj.as_str())];
    let r = run("recycle", &cavity(1.0), &files, 100_000);
    let (t, se) = efficiency(&r);
    let want = 0.5 / (1.0 - 0.45);
    assert!(
        (t - want).abs() < 4.0 * se + 2e-3,
        "recycled {t} ± {se}, want {want}"
    );
    // Each photon leaves in the pass state, which the dichroic model turns with the
    // direction: the summed S1 is the Lambertian mean of cos 2psi, psi the angle between
    // the pass field and the detector's u made perpendicular to the direction.
    let p = r.summary().polarization.unwrap();
    let s1 = lambertian_mean_s1_through_an_x_polarizer();
    assert!(
        (p.s1.value - s1).abs() < 4.0 * p.s1.stderr + 1e-3,
        "{p:?} vs {s1}"
    );
    assert!(
        p.s2.value.abs() < 4.0 * p.s2.stderr && p.s3.value == 0.0,
        "{p:?}"
    );
    let r = run("absorb", &cavity(0.0), &files, 100_000);
    let (t, se) = efficiency(&r);
    assert!((t - 0.5).abs() < 4.0 * se + 2e-3, "absorbing {t} ± {se}");
}

/// The mean over a Lambertian hemisphere (about +z) of `cos 2psi`, with `psi` the angle
/// between the pass field of a polarizer passing x (block axis y made perpendicular to
/// the direction `d`, the pass field `d x` that) and x made perpendicular to `d`.
fn lambertian_mean_s1_through_an_x_polarizer() -> f64 {
    use glam::DVec3;
    let (nt, np) = (400, 400);
    let (mut sum, mut weight) = (0.0, 0.0);
    for i in 0..nt {
        let theta = (i as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
        for j in 0..np {
            let phi = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
            let d = DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            let b = (DVec3::Y - d.y * d).normalize();
            let pass = d.cross(b);
            let u = (DVec3::X - d.x * d).normalize();
            let w = theta.cos() * theta.sin();
            sum += w * (2.0 * pass.dot(u).powi(2) - 1.0);
            weight += w;
        }
    }
    sum / weight
}

/// Total internal reflection retards p against s: a beam linear at 45 degrees to the
/// plane of incidence enters a right-angle PMMA prism through a leg at normal incidence,
/// reflects totally off the hypotenuse at 45 degrees and leaves through the other leg:
/// `|S3/S0| = sin(delta)`, `tan(delta/2) = cos_i sqrt(sin_i^2 - n^2) / sin_i^2` with
/// n = 1/1.49, 0.573 (normal incidence keeps s and p in step).
#[test]
fn total_internal_reflection_turns_linear_light_elliptic() {
    // Cross-section (x, z): (0,0), (10,0), (0,10), along y from -50 to 50; tags per face.
    let obj = "v 0 -50 0\nv 10 -50 0\nv 0 -50 10\nv 0 50 0\nv 10 50 0\nv 0 50 10\nusemtl prism\n\
               f 1 3 2\nf 4 5 6\nf 1 2 5\nf 1 5 4\nf 1 4 6\nf 1 6 3\nf 2 3 6\nf 2 6 5\n";
    let toml = "version = 1\n[[geometry]]\nfile = \"prism.obj\"\n[media.pmma]\nn = 1.49\n\
                [surfaces.prism]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
                [[sources]]\ntype = \"rayfile\"\nfile = \"beam.rays\"\nbody = \"transparent\"\n\
                polarization = { linear_deg = 45.0 }\n\
                [detector]\norigin = [-5.0, -50.0, 0.0]\nu = [0.0, 0.0, 1.0]\nv = [0.0, 1.0, 0.0]\n\
                size_mm = [10.0, 100.0]\nbins = [2, 2]\n";
    let rays = "3 0 -5  0 0 1  1.0\n";
    let r = run(
        "tir",
        toml,
        &[("prism.obj", obj), ("beam.rays", rays)],
        20_000,
    );
    let p = r
        .summary()
        .polarization
        .expect("a polarized source traces polarization");
    let n: f64 = 1.0 / 1.49;
    let (s, c) = 45f64.to_radians().sin_cos();
    let want = (2.0 * (c * (s * s - n * n).sqrt() / (s * s)).atan()).sin();
    assert!((want - 0.573).abs() < 1e-3);
    // A few photons come back after three reflections (two partial ones): 2e-3 allowed.
    assert!(
        (p.s3.value.abs() - want).abs() < 2e-3,
        "{p:?}, want |S3| {want}"
    );
    assert!((p.dop.value - 1.0).abs() < 2e-3, "{p:?}");
}

/// Brewster's angle: p-polarized light reflects nothing off a PMMA slab (nor off its far
/// face, where the inside angle is Brewster's too), s light some.
#[test]
fn brewsters_angle_reflects_no_p_light() {
    let brewster = 1.49f64.atan();
    let (s, c) = brewster.sin_cos();
    let rays = format!("0 0 5  {s} 0 {}  1.0\n", -c);
    let obj = support::box_obj([-250.0, -250.0, -0.5], [250.0, 250.0, 0.5], ["slab"; 6]);
    let up = "[detector]\norigin = [-300.0, -300.0, 6.0]\nu = [1.0, 0.0, 0.0]\n\
              v = [0.0, 1.0, 0.0]\nsize_mm = [600.0, 600.0]\nbins = [2, 2]\n";
    let reflected = |deg: f64| {
        let toml = format!(
            "version = 1\n[[geometry]]\nfile = \"slab.obj\"\n[media.pmma]\nn = 1.49\n\
             [surfaces.slab]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
             [[sources]]\ntype = \"rayfile\"\nfile = \"beam.rays\"\nbody = \"transparent\"\n\
             polarization = {{ linear_deg = {deg} }}\n{up}"
        );
        let files = [("slab.obj", obj.as_str()), ("beam.rays", rays.as_str())];
        efficiency(&run("brewster", &toml, &files, 20_000)).0
    };
    // The ray file's u is x, in the plane of incidence: 0 degrees is p, 90 is s.
    assert_eq!(reflected(0.0), 0.0);
    assert!(reflected(90.0) > 0.2, "s light reflects from both faces");
}

/// The Stokes sums are exact: shards (through their JSON files' round trip) merge to the
/// single run's bit for bit, whatever the threads; polarization is part of the content
/// hash, so shards traced with and without it do not merge.
#[test]
fn polarized_shards_merge_to_the_single_run_bit_for_bit() {
    use blutrace::run::{RunOptions, Shard};
    use blutrace::shard::{self, ShardFile};
    let obj = sheet("floor", 0.0, 50.0, 0) + &sheet("film", 1.0, 50.0, 4);
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"cavity.obj\"\n\
         [surfaces.floor]\nmodel = \"lambert\"\nalbedo = 0.8\n{}\
         [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, 0.01]\nnormal = [0.0, 0.0, 1.0]\n\
         u = [1.0, 0.0, 0.0]\nwidth_mm = 0.5\nheight_mm = 0.5\npower_w = 1.0\n\
         [detector]\norigin = [-50.0, -50.0, 2.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [100.0, 100.0]\nbins = [4, 4]\n",
        polarizer("film", 20.0, 0.9)
    );
    let dir = write_scene("pol-shards", &toml, &[("cavity.obj", obj.as_str())]);
    let scene = load(&dir);
    let options = RunOptions {
        photons: 60_000,
        seed: 5,
        threads: Some(2),
        ..RunOptions::default()
    };
    let single = support::trace_opts(&scene, &options);
    let one_thread = support::trace_opts(
        &scene,
        &RunOptions {
            threads: Some(1),
            ..options.clone()
        },
    );
    assert_eq!(single.tally, one_thread.tally);
    let shards: Vec<_> = (0..3)
        .map(|index| {
            let shard = Some(Shard { index, count: 3 });
            let run = support::trace_opts(
                &scene,
                &RunOptions {
                    shard,
                    ..options.clone()
                },
            );
            let text = serde_json::to_string(&ShardFile::of(&run).unwrap()).unwrap();
            let file: ShardFile = serde_json::from_str(&text).unwrap();
            (format!("shard {index}/3").into(), file)
        })
        .collect();
    let merged = shard::merge(&shards, &scene).unwrap();
    assert_eq!(merged.tally.stokes, single.tally.stokes);
    let s1 = &single.tally.stokes.as_ref().unwrap()[0];
    assert!(
        s1.bins.iter().any(|b| b.sum.0 != 0),
        "the light is polarized"
    );
    let averaged = std::fs::read_to_string(&*dir).unwrap() + "[trace]\npolarization = false\n";
    let averaged = averaged.replace(
        &polarizer("film", 20.0, 0.9),
        "[surfaces.film]\nmodel = \"lambert\"\nalbedo = 0.5\n",
    );
    let other = write_scene("pol-shards-off", &averaged, &[("cavity.obj", obj.as_str())]);
    let with = averaged.replace("polarization = false", "polarization = true");
    let on = write_scene("pol-shards-on", &with, &[("cavity.obj", obj.as_str())]);
    assert_ne!(load(&other).content_hash(), load(&on).content_hash());
}

/// `stokes.exr` of `r`: in every lit bin `S1..S3` over `S0` are `want`, `S0` is flux.exr's
/// `Y`, and every channel has its standard error.
fn assert_stokes_exr(r: &RunResult, want: [f64; 3]) {
    use blutrace::output::exr::read_channels;
    let dir = support::temp_folder("stokes-exr");
    let out = dir.path().join("out");
    r.write(&out).unwrap();
    let (_, _, channels, _) = read_channels(&out.join("stokes.exr")).unwrap();
    let (_, _, flux, _) = read_channels(&out.join("flux.exr")).unwrap();
    let get = |set: &[(String, Vec<f32>)], name: &str| {
        set.iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.clone())
            .unwrap()
    };
    let s0 = get(&channels, "S0");
    assert_eq!(s0, get(&flux, "Y"));
    for name in ["stderr.S0", "stderr.S1", "stderr.S2", "stderr.S3", "hits"] {
        assert_eq!(get(&channels, name).len(), s0.len(), "{name}");
    }
    let lit: Vec<usize> = (0..s0.len()).filter(|&i| s0[i] > 0.0).collect();
    assert!(!lit.is_empty());
    for (k, name) in ["S1", "S2", "S3"].into_iter().enumerate() {
        let s = get(&channels, name);
        for &i in &lit {
            assert!(
                (f64::from(s[i] / s0[i]) - want[k]).abs() < 1e-5,
                "{name} bin {i}"
            );
        }
    }
}
