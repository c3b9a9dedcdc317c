//! Dots at the extremes of density.

use super::*;

pub(super) fn dots_density_extremes() -> Row {
    // 20 um pitch on a face 1.5 m long, tilted and 10 m from the origin; 1e6 uniform
    // points per case.
    let axis = DVec3::new(1.0, 2.0, -0.5).normalize();
    let normal = perp(axis);
    let across = normal.cross(axis);
    let origin = DVec3::new(9_000.0, -10_000.0, 11_000.0);
    let n = 1_000_000u64;
    let mut worst: f64 = 0.0;
    let mut shown = Vec::new();
    for lattice in [Lattice::Square, Lattice::Hex] {
        for d in [1e-4, 0.5, lattice.max_packing()] {
            let p = DotPattern {
                lattice,
                pitch: 0.02,
                origin,
                axis,
                across,
                grade: Gradation {
                    density: Density::Polynomial(vec![d]),
                    length: 1500.0,
                    x_unit: XUnit::Normalized,
                    mirror: false,
                },
                placement: Placement::Lattice,
                placement_seed: 0,
            };
            let mut g = PhotonRng::new(41, (d * 1e6) as u64);
            let hits = (0..n)
                .filter(|_| {
                    p.covers(
                        origin + axis * (1500.0 * g.uniform()) + across * (200.0 * g.uniform()),
                    )
                })
                .count() as f64;
            let frac = hits / n as f64;
            let zz = z(frac, d, se_binomial(d, n as f64));
            worst = worst.max(zz);
            shown.push(format!("{lattice:?} {d:.4}: {frac:.5} ({zz:.1} SE)"));
        }
    }
    Row {
        id: "dots-density-extremes",
        risk: "Density near 0 (dots of 0.2 um radius on a 20 um pitch) or at the packing limit (touching dots): radius rounding, double counting across cells, lattice lookups 1e6 pitches from the pattern origin.",
        does: "Each point is tested against the dot of its nearest lattice centre only; radius sqrt(d A_cell / pi).",
        expected: "covered fraction of 1e6 uniform points = density +- 4 SE for d = 1e-4, 0.5 and the packing limit, square and hex, on a tilted 1.5 m face 17 m from the origin".into(),
        measured: format!("{}; worst {worst:.2} SE", shown.join(", ")),
        verdict: verdict(worst <= 4.0, || "dot coverage is off".into()),
    }
}

/// A small plate whose back face carries dots of `lattice` with polynomial `density`.
pub(super) fn dots_toml(lattice: &str, density: &str) -> String {
    format!(
        "version = 1\n[[geometry]]\nfile = \"plate.obj\"\n[media.pmma]\nn = 1.49\n\
         [surfaces.face]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.dots]\nmodel = \"dots\"\ninside = \"pmma\"\nink_albedo = 0.9\nlattice = \"{lattice}\"\npitch_mm = 0.5\n\
         origin = [-10.0, 0.0, -0.5]\naxis = [1.0, 0.0, 0.0]\nlength_mm = 20.0\ndensity = {density}\n{}{}",
        led(
            DVec3::new(-10.001, 0.0, 0.0),
            DVec3::X,
            10.0,
            0.5,
            1.0,
            "air"
        ),
        detector(
            DVec3::new(-10.0, -10.0, 0.6),
            DVec3::X,
            DVec3::Y,
            [20.0, 20.0],
            [10, 10]
        )
    )
}

pub(super) fn dots_polynomial_range() -> Row {
    let mut plate = Obj::default();
    plate.cuboid(
        DVec3::new(-10.0, -10.0, -0.5),
        DVec3::new(10.0, 10.0, 0.5),
        ["face", "face", "face", "face", "dots", "face"],
    );
    let obj = plate.text();
    let mut ok = true;
    let mut shown = Vec::new();
    for (label, lattice, density) in [
        ("above pi/4", "square", "[0.1, 1.0]"),
        ("above the hex limit", "hex", "[0.95]"),
        ("negative", "square", "[0.2, -0.5]"),
        ("NaN", "square", "[nan]"),
        ("infinite", "square", "[0.1, inf]"),
    ] {
        match try_scene(
            &format!("poly-{}", label.replace(' ', "")),
            &dots_toml(lattice, density),
            &[("plate.obj", &obj)],
        ) {
            Ok(_) => {
                ok = false;
                shown.push(format!("{label}: loaded"));
            }
            Err(e) => {
                ok &= e.contains("surfaces.dots.density");
                shown.push(format!(
                    "{label}: error '{}'",
                    e.split(": ").skip(1).collect::<Vec<_>>().join(": ")
                ));
            }
        }
    }
    // A dip of depth 1e-9 between two of the 4097 check points: d = (x - x0)^2 - 1e-9.
    let x0 = 1000.5 / 4096.0;
    let density = format!("[{:?}, {:?}, 1.0]", x0 * x0 - 1e-9, -2.0 * x0);
    let dip = match try_scene(
        "poly-dip",
        &dots_toml("square", &density),
        &[("plate.obj", &obj)],
    ) {
        Ok(s) => {
            let r = run(&s, 20_000, 2);
            let good = all_finite(&r) && balanced(&r.tally.ledger);
            ok &= good;
            format!(
                "a dip of -1e-9 between check points: loads (bounded: h^2/8 max|d''| = {:.1e}), traces without NaN: {good}",
                2.0 / 8.0 / 4096f64.powi(2)
            )
        }
        Err(e) => format!("a dip of -1e-9 between check points: error '{e}'"),
    };
    shown.push(dip);
    Row {
        id: "dots-polynomial-range",
        risk: "A density polynomial that leaves [0, packing limit] somewhere along the guide: negative radii (NaN), or overlapping dots whose coverage is not the density.",
        does: "Loading checks d(x) at 4097 points along the span and refuses any value outside [0, limit] or not finite, naming the field, position and value. Between check points a polynomial can only stray by h^2/8 max|d''|; there the dot radius is clamped (no dot below 0, touching dots at the limit).",
        expected: "errors naming surfaces.dots.density for d > pi/4 (square), d > 0.9069 (hex), d < 0, NaN and infinite coefficients; a sub-grid dip of 1e-9 loads and traces without NaN".into(),
        measured: shown.join("; "),
        verdict: verdict(ok, || "an out-of-range density is not refused".into()),
    }
}
