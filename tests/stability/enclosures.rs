//! Closed, lossless and recycling enclosures.

use super::*;

/// A rotated cube (side 10 mm, centre (1, 2, 3)) whose faces are all `tag`.
pub(super) fn cube_obj(tag: &str) -> String {
    let rot = DMat3::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 1.1);
    let mut o = Obj::default();
    o.cuboid(DVec3::splat(-5.0), DVec3::splat(5.0), [tag; 6]);
    o.mapped(|p| rot * p + DVec3::new(1.0, 2.0, 3.0)).text()
}

/// A closed cube with `surface` on every face, an isotropic source inside, a detector far
/// outside (it can never be reached), and the bounce cap `cap`.
pub(super) fn enclosure(name: &str, surface: &str, cap: u32) -> Scene {
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"cube.obj\"\n[surfaces.wall]\n{surface}\n{}{}[trace]\nmax_bounces = {cap}\n",
        isotropic(DVec3::new(2.0, 3.5, 2.0), "air"),
        detector(DVec3::splat(100.0), DVec3::X, DVec3::Y, [1.0, 1.0], [1, 1])
    );
    scene(name, &toml, &[("cube.obj", &cube_obj("wall"))])
}

pub(super) fn furnace_lambert() -> Row {
    let n = 20_000u64;
    let mut ok = true;
    let mut shown = Vec::new();
    for a in [0.5f64, 0.9, 0.99] {
        let s = enclosure(
            &format!("furnace-{a}"),
            &format!("model = \"lambert\"\nalbedo = {a:?}"),
            100_000,
        );
        let r = run(&s, n, 3);
        let l = &r.tally.ledger;
        let mean = l.interactions as f64 / n as f64;
        let expect = 1.0 / (1.0 - a);
        // Geometric number of bounces: variance a / (1 - a)^2.
        let se = a.sqrt() / (1.0 - a) / (n as f64).sqrt();
        let zz = z(mean, expect, se);
        ok &= zz <= 4.0
            && l.escaped.value() == 0.0
            && l.killed_photons == 0
            && surface_absorbed(&r, "wall") == n as f64
            && balanced(l);
        shown.push(format!("a {a}: {mean:.3} vs {expect:.3} ({zz:.2} SE)"));
    }
    Row {
        id: "furnace-lambert",
        risk: "A closed enclosure of uniform albedo a: any leak at seams or corners, or a biased roulette, changes how long photons live.",
        does: "Analog roulette on the albedo at every hit; watertight triangle test on a rotated cube.",
        expected: "every photon absorbed by the walls (none escapes, none capped); mean surface interactions per photon = 1/(1-a) (geometric law) +- 4 SE, SE = sqrt(a)/(1-a)/sqrt(N), N = 20,000".into(),
        measured: shown.join("; "),
        verdict: verdict(ok, || "the furnace does not match 1/(1-a)".into()),
    }
}

pub(super) fn furnace_albedo_one() -> Row {
    let (n, cap) = (2000u64, 1000u32);
    let mut ok = true;
    let mut shown = Vec::new();
    for (label, surface, est) in [
        (
            "lambert 1",
            "model = \"lambert\"\nalbedo = 1.0",
            Estimator::Analog,
        ),
        (
            "mirror 1",
            "model = \"mirror\"\nreflectance = 1.0",
            Estimator::Analog,
        ),
        (
            "lambert 1, weighted",
            "model = \"lambert\"\nalbedo = 1.0",
            Estimator::Weighted,
        ),
    ] {
        let s = enclosure(
            &format!("albedo1-{}", label.replace([' ', ','], "")),
            surface,
            cap,
        );
        let r = run_with(&s, n, 4, |o| o.estimator = est);
        let l = &r.tally.ledger;
        ok &= l.killed_photons == n
            && l.killed.value() == n as f64
            && l.interactions == n * cap as u64
            && l.escaped.value() == 0.0
            && balanced(l);
        shown.push(format!(
            "{label}: {} of {n} killed at the cap, {} interactions, escaped {}, balanced {}",
            l.killed_photons,
            l.interactions,
            l.escaped.value(),
            balanced(l)
        ));
    }
    Row {
        id: "furnace-albedo-1",
        risk: "A lossless closed enclosure (albedo 1): photons never end; a tracer without a cap hangs, one that drops them silently loses energy.",
        does: "A per-photon bounce cap (`trace.max_bounces`): capped photons are booked as `killed` in the ledger.",
        expected: format!(
            "all {n} photons killed at the cap of {cap} ({}) interactions, 0 escaped, ledger balanced bit for bit; specular mirror cube and weighted estimator alike",
            n * cap as u64
        ),
        measured: shown.join("; "),
        verdict: verdict(ok, || "a lossless enclosure lost or created photons".into()),
    }
}

pub(super) fn furnace_weighted() -> Row {
    // 8 whole chunks: 8 equal photon groups give a batch-means standard error.
    let n = 8 * blutrace::tracer::CHUNK;
    let a = 0.9;
    let s = enclosure(
        "furnace-weighted",
        &format!("model = \"lambert\"\nalbedo = {a:?}"),
        100_000,
    );
    let r = run_with(&s, n, 9, |o| o.estimator = Estimator::Weighted);
    let l = &r.tally.ledger;
    let wall = |t: &blutrace::tally::Tally| {
        let i = s.tags.iter().position(|t| t == "wall").unwrap();
        t.ledger.absorbed_by_surface[i].value() / t.ledger.photons as f64
    };
    let means: Vec<f64> = r
        .groups
        .iter()
        .filter(|g| g.ledger.photons > 0)
        .map(wall)
        .collect();
    let k = means.len() as f64;
    let mean = wall(&r.tally);
    let sd = (means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (k - 1.0)).sqrt();
    let se = sd / k.sqrt();
    let zz = z(mean, 1.0, se);
    let ok = balanced(l) && l.escaped.value() == 0.0 && l.killed_photons == 0 && zz <= 4.0;
    Row {
        id: "furnace-weighted",
        risk: "Weighted estimator in a closed enclosure: photons end only by Russian roulette; partial absorptions and roulette gains must still close the books.",
        does: "Partial absorptions booked as weight before minus after; roulette books its net; the ledger is exact fixed point.",
        expected: format!(
            "albedo {a}, {n} photons: emitted = accounted bit for bit; every photon ends by roulette (none capped or escaped); mean weight absorbed by the walls per photon = 1 +- 4 SE (batch means over {k} groups)"
        ),
        measured: format!(
            "balanced {}; wall absorption {mean:.5} per photon ({zz:.2} SE, SE {se:.1e}); roulette net {:.2}; killed {}, escaped {}",
            balanced(l),
            l.roulette.value(),
            l.killed_photons,
            l.escaped.value()
        ),
        verdict: verdict(ok, || "the weighted ledger is off".into()),
    }
}

/// A 100 x 100 x 10 mm cavity with a 10 x 10 mm exit hole in the middle of its top, a
/// Lambertian LED on its floor and a detector just above the hole. `walls`: the model of
/// the sides and top; `floor`: of the bottom.
pub(super) fn cavity(name: &str, walls: &str, floor: &str, cap: u32) -> Scene {
    let mut o = Obj::default();
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    o.quad(
        "floor",
        p(0.0, 0.0, 0.0),
        p(100.0, 0.0, 0.0),
        p(100.0, 100.0, 0.0),
        p(0.0, 100.0, 0.0),
    );
    o.quad(
        "wall",
        p(0.0, 0.0, 0.0),
        p(0.0, 0.0, 10.0),
        p(100.0, 0.0, 10.0),
        p(100.0, 0.0, 0.0),
    );
    o.quad(
        "wall",
        p(100.0, 0.0, 0.0),
        p(100.0, 0.0, 10.0),
        p(100.0, 100.0, 10.0),
        p(100.0, 100.0, 0.0),
    );
    o.quad(
        "wall",
        p(100.0, 100.0, 0.0),
        p(100.0, 100.0, 10.0),
        p(0.0, 100.0, 10.0),
        p(0.0, 100.0, 0.0),
    );
    o.quad(
        "wall",
        p(0.0, 100.0, 0.0),
        p(0.0, 100.0, 10.0),
        p(0.0, 0.0, 10.0),
        p(0.0, 0.0, 0.0),
    );
    let outer = [
        p(0.0, 0.0, 10.0),
        p(100.0, 0.0, 10.0),
        p(100.0, 100.0, 10.0),
        p(0.0, 100.0, 10.0),
    ];
    let inner = [
        p(45.0, 45.0, 10.0),
        p(55.0, 45.0, 10.0),
        p(55.0, 55.0, 10.0),
        p(45.0, 55.0, 10.0),
    ];
    for i in 0..4 {
        let j = (i + 1) % 4;
        o.quad("wall", outer[i], outer[j], inner[j], inner[i]);
    }
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"cavity.obj\"\n[surfaces.wall]\n{walls}\n[surfaces.floor]\n{floor}\n{}{}[trace]\nmax_bounces = {cap}\n",
        led(p(20.0, 30.0, 0.5), DVec3::Z, 1.0, 1.0, 1.0, "air"),
        detector(
            p(45.0, 45.0, 10.001),
            DVec3::X,
            DVec3::Y,
            [10.0, 10.0],
            [2, 2]
        )
    );
    scene(name, &toml, &[("cavity.obj", &o.text())])
}

/// Trace a cavity at rising bounce caps; the rows' text and whether the answer converged:
/// raising the cap only ever turns capped photons into other fates, and from the first cap
/// that caps nobody on, the tallies are identical.
pub(super) fn cap_ladder(
    label: &str,
    walls: &str,
    floor: &str,
    caps: &[u32],
    n: u64,
) -> (String, bool, f64) {
    let mut prev: Option<(f64, u64, blutrace::tally::Tally)> = None;
    let mut ok = true;
    let mut shown = Vec::new();
    let mut last = 0.0;
    for &cap in caps {
        let s = cavity(&format!("{label}-{cap}"), walls, floor, cap);
        let r = run(&s, n, 13);
        let l = &r.tally.ledger;
        let det = detected(l);
        ok &= balanced(l) && all_finite(&r);
        if let Some((pd, pk, pt)) = &prev {
            ok &= det >= *pd && det - pd <= *pk as f64;
            if *pk == 0 {
                ok &= *pt == r.tally;
            }
        }
        shown.push(format!(
            "cap {cap}: {:.4} ({} capped)",
            det / n as f64,
            l.killed_photons
        ));
        last = det / n as f64;
        prev = Some((det, l.killed_photons, r.tally.clone()));
    }
    ok &= prev.is_some_and(|p| p.1 == 0);
    let se = se_binomial(last, n as f64);
    (
        format!("{label}: {} -> {last:.4} +- {se:.4}", shown.join(", ")),
        ok,
        last,
    )
}

pub(super) fn recycling_cavity() -> Row {
    let n = 4000;
    let caps = [100, 1000, 10_000, 100_000];
    let mut ok = true;
    let mut shown = Vec::new();
    for r in [0.98, 0.99] {
        let lam = format!("model = \"lambert\"\nalbedo = {r:?}");
        let esr = format!("model = \"mirror\"\nreflectance = {r:?}");
        for (label, walls) in [
            (format!("lambert {r}"), &lam),
            (format!("ESR mirror {r} + lambert floor"), &esr),
        ] {
            let (text, good, _) = cap_ladder(&label.replace(' ', "-"), walls, &lam, &caps, n);
            ok &= good;
            shown.push(text);
        }
    }
    Row {
        id: "recycling-cavity",
        risk: "Recycling cavities with reflectance 0.98-0.99 (ESR-like sheets): hundreds of bounces per photon; a cap that truncates the answer looks like a converged one.",
        does: "Capped photons are counted (`killed_photons`); photon streams are per photon, so raising the cap changes only the capped photons.",
        expected: format!(
            "for caps {caps:?} ({n} photons): detected fraction never falls and rises by at most the photons capped at the lower cap; no photon capped at the default cap (1e5), and identical tallies from the first cap that caps none"
        ),
        measured: shown.join("; "),
        verdict: verdict(ok, || {
            "the cavity result is not converged or not monotone in the cap".into()
        }),
    }
}

pub(super) fn recycling_esr_slow() -> Row {
    let n = 20_000;
    let caps = [100, 1000, 10_000, 100_000, 1_000_000];
    let mut ok = true;
    let mut shown = Vec::new();
    let lam = "model = \"lambert\"\nalbedo = 0.999";
    let esr = "model = \"mirror\"\nreflectance = 0.999";
    for (label, walls) in [("lambert-0.999", lam), ("ESR-0.999", esr)] {
        let (text, good, _) = cap_ladder(label, walls, lam, &caps, n);
        ok &= good;
        shown.push(text);
    }
    Row {
        id: "recycling-esr-0.999",
        risk: "Reflectance 0.999 (best ESR): mean path ~200 bounces, tails of thousands.",
        does: "As `recycling-cavity`.",
        expected: format!(
            "for caps {caps:?} ({n} photons): monotone, bounded by the capped photons, converged (identical tallies) once nothing is capped"
        ),
        measured: shown.join("; "),
        verdict: verdict(ok, || "the 0.999 cavity is not converged".into()),
    }
}
