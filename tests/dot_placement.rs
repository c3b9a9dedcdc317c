//! Dot placement (issue 15): the lattice's correlated hits, the randomized placements and
//! the virtual-dot reference, on the edge-lit slab of `support::edge_lit_slab`.
//!
//! ```text
//! cargo test --release --test dot_placement                                  # CI checks
//! cargo test --release --test dot_placement -- --ignored --nocapture table   # README table
//! ```
//!
//! The reference for a hit's chance of meeting ink is the virtual model: every hit meets
//! ink with probability `d`, independently, so its per-hit ink fraction is `d` with the
//! binomial error `sqrt(d (1 - d) / hits)` (a martingale: each hit is a fresh draw whatever
//! came before), and a placement whose hits are uncorrelated extracts like it.

#[path = "support/mod.rs"]
mod support;

use blutrace::estimator::Estimator;
use blutrace::optics::dots::{Density, DotPattern, Lattice, Placement};
use blutrace::optics::model::Arrival;
use blutrace::optics::spectrum::Light;
use blutrace::optimize::export;
use blutrace::rng::PhotonRng;
use blutrace::run::{RunOptions, RunResult};
use blutrace::scene::Scene;
use glam::{DVec2, DVec3};
use support::{edge_lit_slab, trace_opts};

/// The `[surfaces.dots]` fields of a slab with constant density `d` and black ink.
fn dots(placement: &str, d: f64) -> String {
    format!(
        "ink_albedo = 0.0\nlattice = \"square\"\npitch_mm = 0.5\ndensity = [{d}]\nplacement = \"{placement}\"\n"
    )
}

fn slab(placement: &str, d: f64) -> Scene {
    edge_lit_slab(&format!("{placement}-{d}"), &dots(placement, d))
}

fn trace(scene: &Scene, photons: u64, estimator: Estimator, threads: usize) -> RunResult {
    trace_opts(
        scene,
        &RunOptions {
            photons,
            seed: 5,
            threads: Some(threads),
            estimator,
            ..RunOptions::default()
        },
    )
}

/// What a run of the slab says about its dots: hits on the dotted face, ink hits, the
/// power (fraction of emitted) absorbed by the ink and detected beyond the far edge.
struct Books {
    hits: u64,
    ink_hits: u64,
    ink_power: f64,
    far_edge: (f64, f64),
}

fn books(r: &RunResult) -> Books {
    let tag = r.scene.tags.iter().position(|t| t == "dots").unwrap();
    let l = &r.tally.ledger;
    Books {
        hits: l.hits_by_tag[tag],
        ink_hits: l.feature_hits_by_tag[tag],
        ink_power: l.absorbed_by_surface[tag].value() / l.photons as f64,
        far_edge: l.detected.mean_and_stderr(l.photons),
    }
}

impl Books {
    fn ink_fraction(&self) -> f64 {
        self.ink_hits as f64 / self.hits as f64
    }
}

/// A pattern on the plane z = 0 (face coordinates = x, y) with constant density.
fn pattern(lattice: Lattice, placement: Placement, seed: u64, d: f64) -> DotPattern {
    DotPattern {
        placement,
        placement_seed: seed,
        ..support::dot_pattern(lattice, Density::Polynomial(vec![d]), 1000.0)
    }
}

#[test]
fn virtual_dots_meet_ink_at_the_density_per_hit_analog_and_weighted_agree() {
    let d = 0.3;
    let scene = edge_lit_slab(
        "virtual-grey",
        "ink_albedo = 0.6\nlattice = \"hex\"\npitch_mm = 0.5\ndensity = [0.3]\nplacement = \"virtual\"\n",
    );
    let mut far = Vec::new();
    for est in [Estimator::Analog, Estimator::Weighted] {
        let r = trace(&scene, 40_000, est, 2);
        support::assert_balanced(&r);
        let b = books(&r);
        let se = (d * (1.0 - d) / b.hits as f64).sqrt();
        let z = (b.ink_fraction() - d) / se;
        assert!(
            z.abs() < 4.0,
            "{est:?}: ink fraction {:.5} over {} hits, d = {d} ({z:.1} SE)",
            b.ink_fraction(),
            b.hits
        );
        // The per-tag counts add up to the interactions less the hits on the lamp's body
        // (light back out of the entry edge), and the summary shows them.
        let l = &r.tally.ledger;
        let tagged = l.hits_by_tag.iter().sum::<u64>();
        assert!(tagged <= l.interactions && tagged > l.interactions * 9 / 10);
        let s = r.summary();
        assert_eq!(s.ledger.hits_by_tag["dots"], b.hits);
        assert_eq!(s.ledger.ink_hits_by_tag["dots"], b.ink_hits);
        assert!(!s.ledger.ink_hits_by_tag.contains_key("face"));
        far.push(b.far_edge);
    }
    let ((a, sa), (w, sw)) = (far[0], far[1]);
    let z = (a - w) / (sa * sa + sw * sw).sqrt();
    assert!(
        z.abs() < 4.0,
        "far edge: analog {a:.5} ± {sa:.5}, weighted {w:.5} ± {sw:.5} ({z:.1} SE)"
    );
}

#[test]
fn hit_counts_do_not_depend_on_threads() {
    let scene = slab("stochastic", 0.3);
    let one = trace(&scene, 3 * 4096 + 17, Estimator::Analog, 1);
    let two = trace(&scene, 3 * 4096 + 17, Estimator::Analog, 2);
    assert_eq!(one.tally.ledger, two.tally.ledger);
    assert!(books(&one).ink_hits > 0);
}

#[test]
fn stochastic_screen_covers_the_density_at_every_point() {
    // Each sample: a fresh screen (seed) and a uniform point. The chance that a point is
    // covered is d exactly (a Boolean model), so the hits are binomial(n, d).
    let n = 200_000u64;
    for lattice in [Lattice::Square, Lattice::Hex] {
        for d in [0.02, 0.3, 0.6, lattice.max_packing()] {
            let mut g = PhotonRng::new(3, (d * 1e4) as u64);
            let covered = (0..n)
                .filter(|&k| {
                    let p = pattern(lattice, Placement::Stochastic, k, d);
                    p.covers(DVec3::new(1000.0 * g.uniform(), 1000.0 * g.uniform(), 0.0))
                })
                .count() as f64;
            let se = (d * (1.0 - d) / n as f64).sqrt();
            let z = (covered / n as f64 - d) / se;
            assert!(
                z.abs() < 4.0,
                "{lattice:?} d={d}: {covered} of {n} ({z:.1} SE)"
            );
        }
    }
    // One screen over a 60 x 60 mm patch: the covered fraction of a fixed screen scatters
    // about d by sqrt(integral of the covariance / area), 0.0025 here (Boolean model,
    // d = 0.3, one dot per 0.25 mm^2); 360,000 stratified points add 0.0008.
    let p = pattern(Lattice::Square, Placement::Stochastic, 11, 0.3);
    let m = 600;
    let covered = (0..m * m)
        .filter(|k| {
            let (i, j) = (k % m, k / m);
            let q = DVec2::new(i as f64 + 0.5, j as f64 + 0.5) * (60.0 / m as f64);
            p.covers(DVec3::new(100.0 + q.x, 100.0 + q.y, 0.0))
        })
        .count() as f64
        / (m * m) as f64;
    assert!((covered - 0.3).abs() < 0.011, "one screen covers {covered}");
}

#[test]
fn jittered_dots_cover_the_density_without_overlap() {
    for lattice in [Lattice::Square, Lattice::Hex] {
        for d in [0.05, 0.3, 0.6] {
            let p = pattern(lattice, Placement::Jittered, 7, d);
            // Stratified points over 10 x 10 mm: each dot lies inside its cell, so the
            // covered fraction is d up to the patch's edge cells.
            let m = 600;
            let covered = (0..m * m)
                .filter(|k| {
                    let (i, j) = (k % m, k / m);
                    let q = DVec2::new(i as f64 + 0.5, j as f64 + 0.5) * (10.0 / m as f64);
                    p.covers(DVec3::new(20.0 + q.x, 20.0 + q.y, 0.0))
                })
                .count() as f64
                / (m * m) as f64;
            assert!((covered - d).abs() < 0.01, "{lattice:?} d={d}: {covered}");
            // Every exported dot keeps clear of every other and moved off its centre.
            let face = [[
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(6.0, 0.0, 0.0),
                DVec3::new(0.0, 6.0, 0.0),
            ]];
            let dots = export::dots_on_face(&p, &face).unwrap();
            let lat =
                export::dots_on_face(&pattern(lattice, Placement::Lattice, 0, d), &face).unwrap();
            assert!(dots.len() > 50);
            let moved = dots
                .iter()
                .zip(&lat)
                .filter(|(a, b)| (a.x - b.x).hypot(a.y - b.y) > 1e-6)
                .count();
            assert!(moved > dots.len() / 2, "{lattice:?} d={d}: {moved} moved");
            for (k, a) in dots.iter().enumerate() {
                for b in &dots[k + 1..] {
                    let gap = (a.x - b.x).hypot(a.y - b.y) - 0.5 * (a.diameter + b.diameter);
                    assert!(gap > -1e-9, "{lattice:?} d={d}: overlap {gap}");
                }
            }
        }
    }
}

#[test]
fn exports_refuse_a_pitch_that_would_print_billions_of_dots() {
    let face = [[
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(300.0, 0.0, 0.0),
        DVec3::new(0.0, 200.0, 0.0),
    ]];
    let mut fine = pattern(Lattice::Square, Placement::Lattice, 0, 0.3);
    fine.pitch = 1e-3; // 3e10 cells on 3e4 mm^2
    let e = export::dots_on_face(&fine, &face).unwrap_err().to_string();
    assert!(
        e.contains("3.00e10 dot cells") && e.contains("pitch_mm"),
        "{e}"
    );
    // At the cap's own scale it still exports (0.1 mm pitch: 3e6 cells on this face).
    fine.pitch = 0.1;
    fine.grade.density = Density::Polynomial(vec![0.0]);
    assert!(export::dots_on_face(&fine, &face).unwrap().is_empty());
}

#[test]
fn random_placements_are_deterministic_and_seeded() {
    let face = [[
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(8.0, 0.0, 0.0),
        DVec3::new(0.0, 8.0, 0.0),
    ]];
    for placement in [Placement::Jittered, Placement::Stochastic] {
        let a = export::dots_on_face(&pattern(Lattice::Hex, placement, 9, 0.3), &face).unwrap();
        let b = export::dots_on_face(&pattern(Lattice::Hex, placement, 9, 0.3), &face).unwrap();
        let c = export::dots_on_face(&pattern(Lattice::Hex, placement, 10, 0.3), &face).unwrap();
        assert_eq!(a, b, "{placement:?}: same seed, same dots");
        assert_ne!(a, c, "{placement:?}: another seed, another screen");
        // The exported dots are the ones the tracer sees: the centre of every dot is covered.
        let p = pattern(Lattice::Hex, placement, 9, 0.3);
        assert!(a.iter().all(|d| p.covers(DVec3::new(d.x, d.y, 0.0))));
    }
}

#[test]
fn stochastic_extracts_like_virtual_dots_on_a_slab() {
    // Black ink: a photon meets ink once at most, so the ink's power and the far edge's
    // are set by how often its hits fall between dots.
    for d in [0.3, 0.6] {
        let v = books(&trace(&slab("virtual", d), 150_000, Estimator::Analog, 2));
        let s = books(&trace(
            &slab("stochastic", d),
            150_000,
            Estimator::Analog,
            2,
        ));
        let se = |b: &Books| (b.ink_power * (1.0 - b.ink_power) / 150_000.0).sqrt();
        let z = (s.ink_power - v.ink_power) / se(&v).hypot(se(&s));
        assert!(
            z.abs() < 4.0,
            "d={d}: ink power stochastic {:.5}, virtual {:.5} ({z:.1} SE)",
            s.ink_power,
            v.ink_power
        );
        let (a, sa) = s.far_edge;
        let (b, sb) = v.far_edge;
        let z = (a - b) / sa.hypot(sb);
        assert!(
            z.abs() < 4.0,
            "d={d}: far edge {a:.5} vs {b:.5} ({z:.1} SE)"
        );
    }
}

/// A collimated beam inside the slab along y = 40 mm, the line between two rows of a
/// square lattice (pitch 0.5: dot centres at y = 39.75 and 40.25, radius 0.155 at
/// d = 0.3), going down at 30 degrees: it is totally reflected at both faces and steps
/// along the row, 120 mm long, some 20 times on the dotted face.
fn beam_slab(placement: &str) -> Scene {
    support::edge_lit_slab_lit_by(
        &format!("beam-{placement}"),
        &dots(placement, 0.3),
        "[[sources]]\ntype = \"led\"\nmedium = \"pmma\"\ncenter = [0.01, 40.0, 2.9]\n\
         normal = [0.8660254037844387, 0.0, -0.5]\nu = [0.0, 1.0, 0.0]\nwidth_mm = 0.001\n\
         height_mm = 0.001\ncos_exponent = 1e12\npower_w = 1.0\n",
    )
}

#[test]
fn lattice_beam_between_rows_meets_no_ink() {
    let lattice = books(&trace(&beam_slab("lattice"), 20_000, Estimator::Analog, 2));
    assert!(lattice.hits > 100_000, "{} hits", lattice.hits);
    assert_eq!(lattice.ink_hits, 0, "the beam between rows met ink");
    assert!(lattice.far_edge.0 > 0.9, "far edge {:?}", lattice.far_edge);
    // The same beam under virtual dots meets ink at its first hits.
    let v = books(&trace(&beam_slab("virtual"), 20_000, Estimator::Analog, 2));
    let se = (0.3f64 * 0.7 / v.hits as f64).sqrt();
    assert!(
        (v.ink_fraction() - 0.3).abs() < 4.0 * se,
        "virtual: {}",
        v.ink_fraction()
    );
    assert!(v.far_edge.0 < 0.05, "virtual far edge {:?}", v.far_edge);
}

/// A 10 x 10 x 1 mm plate with square dots (d = 0.3) and `dots` more dots fields.
fn small_plate(name: &str, dots: &str) -> support::SceneDir {
    let guide = support::box_obj(
        [0.0, 0.0, 0.0],
        [10.0, 10.0, 1.0],
        ["edge", "edge", "edge", "edge", "dots", "edge"],
    );
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"g.obj\"\n[media.pmma]\nn = 1.49\n\
         [surfaces.edge]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.dots]\nmodel = \"dots\"\ninside = \"pmma\"\nink_albedo = 0.9\nlattice = \"square\"\n\
         pitch_mm = 0.5\norigin = [0.0, 0.0, 0.0]\naxis = [1.0, 0.0, 0.0]\nlength_mm = 10.0\n\
         density = [0.3]\n{dots}\n\
         [[sources]]\ntype = \"led\"\ncenter = [-0.01, 5.0, 0.5]\nnormal = [1.0, 0.0, 0.0]\n\
         u = [0.0, 1.0, 0.0]\nwidth_mm = 10.0\nheight_mm = 1.0\npower_w = 1.0\n\
         [detector]\norigin = [0.0, 0.0, 1.5]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [10.0, 10.0]\nbins = [4, 4]\n"
    );
    support::write_scene(name, &toml, &[("g.obj", &guide)])
}

#[test]
fn bad_placements_are_refused_naming_the_field() {
    let err = |dots: &str| match Scene::load(&small_plate("bad-placement", dots)) {
        Ok(_) => panic!("{dots}: loaded"),
        Err(e) => format!("{e:#}"),
    };
    let e = err("placement = \"random\"");
    assert!(
        e.contains("surfaces.dots.placement") && e.contains("unknown placement \"random\""),
        "{e}"
    );
    assert!(e.contains("scene.toml"), "the file is named: {e}");
    let e = err("placement = \"stochastic\"\nplacement_seed = -3");
    assert!(
        e.contains("surfaces.dots.placement_seed") && e.contains("out of range"),
        "{e}"
    );
    let e = err("placement_seed = 4");
    assert!(
        e.contains("surfaces.dots.placement_seed") && e.contains("lattice"),
        "{e}"
    );
    // Virtual dots cannot be exported.
    let p = pattern(Lattice::Square, Placement::Virtual, 0, 0.3);
    let face = [[DVec3::ZERO, DVec3::X, DVec3::Y]];
    let e = format!("{:#}", export::dots_on_face(&p, &face).unwrap_err());
    assert!(e.contains("\"virtual\" is not printable"), "{e}");
    assert!(!p.covers(DVec3::new(0.25, 0.25, 0.0)));
}

#[test]
fn optimize_exports_virtual_dots_only_as_a_printable_placement() {
    use blutrace::optimize::{Method, OptimizeOptions, optimize};
    let opts = OptimizeOptions {
        method: Method::Feedback,
        photons: 8_000,
        max_iter: 1,
        verify_photons: 0,
        threads: Some(2),
        ..OptimizeOptions::default()
    };
    let dir = small_plate("opt-virtual", "placement = \"virtual\"\nplacement_seed = 3");
    let scene = support::load(&dir);
    let out = tempfile::tempdir().unwrap();
    // Virtual: optimized, but no dot files.
    let r = optimize(&scene, &opts, &mut |_| {}).unwrap();
    assert!(r.dots.is_none() && r.dots_placement.is_none());
    r.write(&out.path().join("a")).unwrap();
    assert!(out.path().join("a/optimized.toml").is_file());
    assert!(!out.path().join("a/dots.csv").exists());
    let json = std::fs::read_to_string(out.path().join("a/optimize.json")).unwrap();
    assert!(json.contains("\"dots_placement\": null"), "{json}");
    // On request, a stochastic sheet of the same density, drawn with the surface's seed.
    let asked = OptimizeOptions {
        export_placement: Some(Placement::Stochastic),
        ..opts.clone()
    };
    let r = optimize(&scene, &asked, &mut |_| {}).unwrap();
    assert_eq!(r.dots_placement, Some(Placement::Stochastic));
    r.write(&out.path().join("b")).unwrap();
    let csv = std::fs::read_to_string(out.path().join("b/dots.csv")).unwrap();
    let dots = export::parse_csv(&csv).unwrap();
    assert_eq!(dots.len(), r.dots.as_ref().unwrap().len());
    let mut printed = r.pattern.clone();
    printed.placement = Placement::Stochastic;
    assert_eq!(printed.placement_seed, 3);
    assert!(
        r.dots
            .as_ref()
            .unwrap()
            .iter()
            .all(|d| printed.covers(printed.origin + printed.axis * d.x + printed.across * d.y)),
        "the files hold the stochastic screen of the surface's seed"
    );
    // A printable surface is exported as traced: asking for another placement is an error.
    let lattice_dir = small_plate("opt-lattice", "");
    let lattice = support::load(&lattice_dir);
    let e = format!("{:#}", optimize(&lattice, &asked, &mut |_| {}).unwrap_err());
    assert!(
        e.contains("option `export_placement` is for virtual patterns"),
        "{e}"
    );
    // And the command line refuses virtual as an export placement, saying why.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .args([
            "optimize",
            dir.to_str().unwrap(),
            "--export-placement",
            "virtual",
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains("not printable"),
        "{stderr}"
    );
}

/// The README's table: per-hit ink fraction, ink power and far-edge power of each
/// placement on the slab, black ink, d = 0.3 and 0.6, 1e6 photons each.
#[test]
#[ignore]
fn table() {
    println!(
        "| d | placement | per-hit ink fraction | power into ink | power out of the far edge |"
    );
    println!("|---|---|---|---|---|");
    for d in [0.3, 0.6] {
        for placement in ["lattice", "jittered", "stochastic", "virtual"] {
            let scene = slab(placement, d);
            let r = trace(&scene, 1_000_000, Estimator::Analog, 2);
            let b = books(&r);
            let f = b.ink_fraction();
            let n = r.tally.ledger.photons as f64;
            println!(
                "| {d} | {placement} | {f:.4} ± {:.4} | {:.4} ± {:.4} | {:.4} ± {:.4} |",
                (f * (1.0 - f) / b.hits as f64).sqrt(),
                b.ink_power,
                (b.ink_power * (1.0 - b.ink_power) / n).sqrt(),
                b.far_edge.0,
                b.far_edge.1
            );
        }
        // Where most photons meet ink (x < 20 mm), this one screen covers a little less
        // or more than d: a fixed random screen's coverage scatters about d.
        let p = pattern(Lattice::Square, Placement::Stochastic, 0, d);
        let covered = (0..400 * 1600)
            .filter(|k| {
                let (i, j) = (k % 400, k / 400);
                p.covers(DVec3::new(i as f64 + 0.5, j as f64 + 0.5, 0.0) / 20.0)
            })
            .count() as f64
            / (400.0 * 1600.0);
        println!("stochastic screen (seed 0) covers {covered:.4} of x < 20 mm at d = {d}");
    }
}

/// The README's second table: the guide of `support::guide_scene` (graded hex dots
/// d = 0.1 + 0.3 x, ink albedo 0.9, a white sheet behind, the target above), its
/// extraction and the flux on the last sixth of the target (x > 100 mm), per placement;
/// and the lattice's gap on the slab at other pitches.
#[test]
#[ignore]
fn table_guide() {
    println!("| placement | extraction | flux at x > 100 mm (fraction of emitted) |");
    println!("|---|---|---|");
    let stochastic = (0..4).map(|k| format!("stochastic\"\nplacement_seed = {k}"));
    for placement in ["lattice\"".to_string(), "jittered\"".to_string()]
        .into_iter()
        .chain(stochastic)
        .chain(["virtual\"".to_string()])
    {
        let scene = support::guide_scene_with("guide", &format!("placement = \"{placement}"));
        let placement = placement
            .replace("\"\nplacement_seed = ", ", seed ")
            .replace('"', "");
        let r = trace(&scene, 1_000_000, Estimator::Analog, 2);
        let l = &r.tally.ledger;
        let (e, se) = l.detected.mean_and_stderr(l.photons);
        let f = &r.tally.flux;
        let (mut sum, mut sumsq) = (0.0, 0.0);
        for iy in 0..f.ny {
            for ix in 20..f.nx {
                let b = &f.bins[iy * f.nx + ix];
                sum += b.sum.value();
                sumsq += b.sumsq.value();
            }
        }
        let (m, sm) = blutrace::tally::mean_and_stderr(sum, sumsq, l.photons);
        println!("| {placement} | {e:.4} ± {se:.4} | {m:.4} ± {sm:.4} |");
    }
    println!();
    println!("| slab, d = 0.3, lattice pitch (mm) | per-hit ink fraction | power into ink |");
    println!("|---|---|---|");
    for pitch in [0.05, 0.1, 0.5, 1.0] {
        let scene = edge_lit_slab(
            &format!("pitch-{pitch}"),
            &dots("lattice", 0.3).replace("pitch_mm = 0.5", &format!("pitch_mm = {pitch}")),
        );
        let b = books(&trace(&scene, 1_000_000, Estimator::Analog, 2));
        println!("| {pitch} | {:.4} | {:.4} |", b.ink_fraction(), b.ink_power);
    }
}

/// Walk `photons` photons through an infinite slab `0 <= z <= 3` of the `scene`'s PMMA,
/// entering at x = 0 (a Lambertian strip in air, refracted), until they leave the slab,
/// meet black ink or pass x = 120 mm: the back face `z = 0` is the scene's `back` tag
/// (dots or grooves), the front its `front` tag. With `random_phase` every back hit sees
/// the pattern shifted by a fresh uniform fraction of its pitch along x and y: the hits
/// are then uncorrelated (virtual dots, or "virtual grooves"). Returns the per-hit
/// feature fraction and the fraction of photons that pass x = 120 mm.
fn walk(scene: &Scene, pitch: f64, random_phase: bool, photons: u64) -> (f64, f64) {
    use blutrace::geometry::SurfaceHit;
    use blutrace::optics::surface::{Feature, Outcome};
    let tag = |t: &str| &scene.surfaces[scene.tags.iter().position(|x| x == t).unwrap()];
    let (back, front) = (tag("back"), tag("front"));
    let pmma = scene.media.iter().position(|m| m.name == "pmma").unwrap() as u16;
    let (mut hits, mut features, mut far) = (0u64, 0u64, 0u64);
    for i in 0..photons {
        let mut rng = PhotonRng::new(77, i);
        let a = blutrace::optics::sampling::cos_power(DVec3::X, 1.0, rng.uniform(), rng.uniform());
        let t = DVec3::new(0.0, a.y, a.z) / 1.49;
        let mut dir = t + DVec3::X * (1.0 - t.length_squared()).sqrt();
        let mut p = DVec3::new(0.0, 0.0, 3.0 * rng.uniform());
        for _ in 0..100_000 {
            let z = if dir.z < 0.0 { 0.0 } else { 3.0 };
            p += dir * ((z - p.z) / dir.z);
            p.z = z;
            if p.x >= 120.0 {
                far += 1;
                break;
            }
            let (model, normal, shift) = if z == 0.0 {
                let s = DVec3::new(rng.uniform(), rng.uniform(), 0.0) * pitch;
                (
                    back,
                    DVec3::NEG_Z,
                    if random_phase { s } else { DVec3::ZERO },
                )
            } else {
                (front, DVec3::Z, DVec3::ZERO)
            };
            let hit = SurfaceHit {
                t: 1.0,
                prim: 0,
                point: p + shift,
                normal,
            };
            let at = Arrival {
                media: &scene.media,
                hit: &hit,
                dir,
                medium: pmma,
                est: Estimator::Analog,
                light: Light::MONOCHROME,
                pol: None,
                pol_out: &std::cell::Cell::new(None),
                shift_out: &std::cell::Cell::new(DVec3::ZERO),
            };
            let (out, feature) = model.interact_on(&at, &mut rng);
            if z == 0.0 {
                hits += 1;
                features += u64::from(feature != Feature::Plain);
            }
            match out {
                Outcome::Scattered { dir: d, medium, .. } if medium == pmma && p.x > 0.0 => dir = d,
                _ => break,
            }
        }
    }
    (features as f64 / hits as f64, far as f64 / photons as f64)
}

/// A scene holding the PMMA and the two faces [`walk`] uses; `back` is the back face's
/// `[surfaces.back]` body.
fn walk_scene(name: &str, back: &str) -> Scene {
    let obj = support::box_obj(
        [0.0, 0.0, 0.0],
        [10.0, 10.0, 3.0],
        ["front", "front", "front", "front", "back", "front"],
    );
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"g.obj\"\n[media.pmma]\nn = 1.49\n\
         [surfaces.front]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.back]\ninside = \"pmma\"\norigin = [0.0, 0.0, 0.0]\naxis = [1.0, 0.0, 0.0]\n\
         length_mm = 120.0\n{back}\n\
         [[sources]]\ntype = \"led\"\ncenter = [-0.01, 5.0, 1.5]\nnormal = [1.0, 0.0, 0.0]\n\
         u = [0.0, 1.0, 0.0]\nwidth_mm = 10.0\nheight_mm = 3.0\npower_w = 1.0\n\
         [detector]\norigin = [0.0, 0.0, 3.5]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [10.0, 10.0]\nbins = [2, 2]\n"
    );
    support::load(&support::write_scene(name, &toml, &[("g.obj", &obj)]))
}

/// The grooves question: do a groove pattern's regular pitch correlate a trapped
/// photon's hits as a dot lattice does? Each pattern walked with its hits where they
/// fall and with a random phase per hit (uncorrelated); the dots rows check the walk
/// against the tracer's table above.
#[test]
#[ignore]
fn grooves_table() {
    println!(
        "| back face | per-hit feature fraction: as placed | random phase | far edge: as placed | random phase |"
    );
    println!("|---|---|---|---|---|");
    let cases = [
        (
            "dots, square, d = 0.3",
            0.5,
            "model = \"dots\"\nink_albedo = 0.0\nlattice = \"square\"\npitch_mm = 0.5\ndensity = [0.3]",
        ),
        (
            "cut V-grooves 110 deg, fill 0.1",
            0.4,
            "model = \"grooves\"\nrelief = \"cut\"\napex_deg = 110.0\npitch_mm = 0.4\ndensity = [0.1]",
        ),
        (
            "cut V-grooves 110 deg, fill 0.3",
            0.4,
            "model = \"grooves\"\nrelief = \"cut\"\napex_deg = 110.0\npitch_mm = 0.4\ndensity = [0.3]",
        ),
        (
            "cut V-grooves 110 deg, fill 0.3, pitch 0.05",
            0.05,
            "model = \"grooves\"\nrelief = \"cut\"\napex_deg = 110.0\npitch_mm = 0.05\ndensity = [0.3]",
        ),
    ];
    let n = 400_000;
    for (k, (label, pitch, back)) in cases.iter().enumerate() {
        let scene = walk_scene(&format!("walk-{k}"), back);
        let (fa, ea) = walk(&scene, *pitch, false, n);
        let (fr, er) = walk(&scene, *pitch, true, n);
        let se = |p: f64| (p * (1.0 - p) / n as f64).sqrt();
        println!(
            "| {label} | {fa:.4} | {fr:.4} | {ea:.4} ± {:.4} | {er:.4} ± {:.4} |",
            se(ea),
            se(er)
        );
    }
}
