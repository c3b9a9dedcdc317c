//! Fresnel at normal, grazing and critical incidence, energy and roulette.

use super::*;

/// The paper's equation (3), the ratio form: sin^2(i-t)/sin^2(i+t), tan^2(i-t)/tan^2(i+t).
/// 0/0 at normal incidence.
pub(super) fn ratio_form(theta_i: f64, n1: f64, n2: f64) -> f64 {
    let s = n1 / n2 * theta_i.sin();
    if s >= 1.0 {
        return 1.0;
    }
    let theta_t = s.asin();
    let rs = ((theta_i - theta_t).sin() / (theta_i + theta_t).sin()).powi(2);
    let rp = ((theta_i - theta_t).tan() / (theta_i + theta_t).tan()).powi(2);
    0.5 * (rs + rp)
}

/// Transmittance from the transmission amplitudes (independent of the reflectance code):
/// `T_s = 4 n1 n2 ci ct / (n1 ci + n2 ct)^2`, `T_p = 4 n1 n2 ci ct / (n2 ci + n1 ct)^2`, with
/// the routine's own `cos_t` (near the critical angle cos_t is ill-conditioned in cos_i:
/// R and T must be judged on the same cos_t).
pub(super) fn transmittance(cos_i: f64, n1: f64, n2: f64) -> f64 {
    let Some(ct) = fresnel::cos_transmitted(cos_i, n1, n2) else {
        return 0.0;
    };
    let k = 4.0 * n1 * n2 * cos_i * ct;
    0.5 * (k / (n1 * cos_i + n2 * ct).powi(2) + k / (n2 * cos_i + n1 * ct).powi(2))
}

pub(super) const PAIRS: [(f64, f64); 6] = [
    (1.0, PMMA),
    (PMMA, 1.0),
    (1.0, 2.4),
    (2.4, 1.0),
    (1.33, PMMA),
    (PMMA, 1.33),
];

pub(super) fn fresnel_normal() -> Row {
    let mut worst: f64 = 0.0;
    let mut ratio_nan = 0;
    let mut shown = Vec::new();
    for (n1, n2) in PAIRS {
        let r = fresnel::reflectance(1.0, n1, n2);
        let r0 = ((n1 - n2) / (n1 + n2)).powi(2);
        worst = worst.max((r - r0).abs() / r0);
        ratio_nan += ratio_form(0.0, n1, n2).is_nan() as usize;
        if n1 == 1.0 {
            shown.push(format!("R({n1}->{n2}) = {r:.6}"));
        }
    }
    Row {
        id: "fresnel-normal",
        risk: "The paper's ratio form of eq. (3) is 0/0 at normal incidence (NaN, or a guarded special case that drifts from the limit).",
        does: "`fresnel::reflectance` uses the cosine form (Born & Wolf), exact at cos = 1.",
        expected: "R = ((n1-n2)/(n1+n2))^2 within 4 eps (relative), for 6 index pairs incl. n = 2.4; ratio form NaN there".into(),
        measured: format!(
            "max relative error {:.1} eps; {}; ratio form NaN for {ratio_nan}/6 pairs",
            worst / EPS,
            shown.join(", ")
        ),
        verdict: verdict(worst <= 4.0 * EPS && ratio_nan == 6, || {
            "normal incidence is off".into()
        }),
    }
}

pub(super) fn fresnel_grazing() -> Row {
    // 1 - R -> 2 ci (n1/n2 + n2/n1) / sqrt(1 - (n1/n2)^2) as ci -> 0 (from outside).
    let mut worst: f64 = 0.0;
    let mut exact_one = true;
    let mut tir_one = true;
    let mut shown = String::new();
    for (n1, n2) in [(1.0, PMMA), (1.0, 2.4), (1.33, PMMA)] {
        exact_one &= fresnel::reflectance(0.0, n1, n2) == 1.0;
        tir_one &=
            fresnel::reflectance(0.0, n2, n1) == 1.0 && fresnel::reflectance(1e-8, n2, n1) == 1.0;
        let slope = 2.0 * (n1 / n2 + n2 / n1) / (1.0 - (n1 / n2).powi(2)).sqrt();
        for ci in [1e-12, 1e-8, 1e-5] {
            let r = fresnel::reflectance(ci, n1, n2);
            // R near 1 carries a few eps of absolute rounding; the linear law holds to
            // relative O(ci) (the next coefficient is -3.3 to -4.6 for these pairs).
            let err = ((1.0 - r) - slope * ci).abs() / (slope * ci);
            let allowed = ci * 10.0 + 8.0 * EPS / (slope * ci);
            worst = worst.max(err / allowed);
            if n2 == PMMA && n1 == 1.0 && ci == 1e-8 {
                let _ = write!(
                    shown,
                    "1-R(cos 1e-8, air->PMMA) = {:.4e} vs {:.4e}",
                    1.0 - r,
                    slope * ci
                );
            }
        }
    }
    Row {
        id: "fresnel-grazing",
        risk: "theta -> 90 deg: ratio forms lose all digits; R must go to 1 linearly in cos, and exactly 1 at cos = 0 and under TIR.",
        does: "Cosine form with cos_i clamped to [0, 1]; no division by cos_i.",
        expected: "R(cos 0) = 1 exactly; 1 - R = 2 ci (n1/n2 + n2/n1)/sqrt(1-(n1/n2)^2) (1 + O(ci)) for ci = 1e-12..1e-5; R = 1 from the dense side".into(),
        measured: format!(
            "{shown}; worst deviation {:.2} of the allowed O(ci) + rounding; R(0) = 1: {exact_one}; TIR side = 1: {tir_one}",
            worst
        ),
        verdict: verdict(worst <= 1.0 && exact_one && tir_one, || "grazing limit is off".into()),
    }
}

pub(super) fn fresnel_critical() -> Row {
    let mut ok = true;
    let mut shown = Vec::new();
    let mut worst_ratio: f64 = 0.0;
    for n1 in [PMMA, 2.4] {
        let c = fresnel::critical_angle(n1, 1.0).unwrap();
        let above = fresnel::reflectance((c + 1e-6).cos(), n1, 1.0);
        let at = fresnel::reflectance(c.cos(), n1, 1.0);
        let below = fresnel::reflectance((c - 1e-6).cos(), n1, 1.0);
        let reference = ratio_form(c - 1e-6, n1, 1.0);
        worst_ratio = worst_ratio.max((below - reference).abs() / (1.0 - reference));
        // Just below: 1 - R grows like sqrt(delta); the refracted ray is real and grazing.
        let dir = DVec3::new((c - 1e-6).sin(), 0.0, (c - 1e-6).cos());
        let t = fresnel::refract(dir, DVec3::NEG_Z, n1, 1.0);
        let grazing_ok =
            t.is_some_and(|t| (t.length() - 1.0).abs() < 4.0 * EPS && t.z > 0.0 && t.z < 0.01);
        let tir_dir = DVec3::new((c + 1e-6).sin(), 0.0, (c + 1e-6).cos());
        ok &= above == 1.0
            && fresnel::refract(tir_dir, DVec3::NEG_Z, n1, 1.0).is_none()
            && (0.999..=1.0).contains(&at)
            && below < 1.0
            && below > 0.9
            && grazing_ok;
        shown.push(format!(
            "n {n1}: crit {:.4} deg, R(-1e-6) = {below:.6} (ratio form {reference:.6}), R(0) = {at:.9}, R(+1e-6) = {above}",
            c.to_degrees()
        ));
    }
    Row {
        id: "fresnel-critical",
        risk: "At the critical angle sin(t) = 1: cos_t = sqrt(1 - sin^2 t) can go NaN, TIR can start a hair early or late, R can jump.",
        does: "TIR when cos_t^2 = (1 - eta)(1 + eta) + eta^2 cos_i^2 <= 0, else cos_t = sqrt(cos_t^2) > 0: no NaN, R continuous and reaching 1 at the critical angle.",
        expected: "R = 1 exactly 1e-6 rad above (no refracted ray); at the angle R in [0.999, 1]; 1e-6 below R < 1, a real grazing refracted ray, and R equal to the ratio form within 1e-6 of 1 - R".into(),
        measured: format!("{}; ratio-form agreement {:.1e} of 1 - R", shown.join("; "), worst_ratio),
        verdict: verdict(ok && worst_ratio < 1e-6, || "critical-angle behaviour is off".into()),
    }
}

/// Media table: air and one medium of index `n`.
pub(super) fn two_media(n: f64) -> Vec<Medium> {
    vec![
        Medium::clear("air", 1.0, 0.0),
        Medium::clear("glass", n, 0.0),
    ]
}

/// Fraction of `n` photons reflected by the tracer's dielectric roulette at incidence
/// `theta` onto a flat interface (normal +z, `glass` below, air above), and the largest
/// deviation of a transmitted direction from Snell's law.
pub(super) fn roulette(glass_n: f64, theta: f64, from_glass: bool, n: u64) -> (f64, f64) {
    let model = SurfaceModel::Dielectric(Interface {
        inside: 1,
        outside: 0,
    });
    let hit = SurfaceHit {
        t: 1.0,
        prim: 0,
        point: DVec3::ZERO,
        normal: DVec3::Z,
    };
    let media = two_media(glass_n);
    let dir = DVec3::new(
        theta.sin(),
        0.0,
        if from_glass {
            theta.cos()
        } else {
            -theta.cos()
        },
    );
    let (n1, n2) = if from_glass {
        (glass_n, 1.0)
    } else {
        (1.0, glass_n)
    };
    let medium = from_glass as u16;
    let mut reflected = 0u64;
    let mut snell: f64 = 0.0;
    for i in 0..n {
        let mut rng = PhotonRng::new(17, i);
        match model.interact(&media, &hit, dir, medium, Estimator::Analog, &mut rng) {
            Outcome::Scattered {
                dir: d, medium: m, ..
            } => {
                if m == medium {
                    reflected += 1;
                } else {
                    let sin_t = (d.x * d.x + d.y * d.y).sqrt();
                    snell = snell.max((n1 * theta.sin() - n2 * sin_t).abs());
                }
            }
            Outcome::Absorbed => return (f64::NAN, f64::NAN),
        }
    }
    (reflected as f64 / n as f64, snell)
}

pub(super) fn fresnel_no_interface() -> Row {
    let mut max_r: f64 = 0.0;
    for n in [1.0, PMMA, 2.4] {
        for k in 0..=10_000 {
            let ci = k as f64 / 10_000.0;
            max_r = max_r.max(fresnel::reflectance(ci, n, n));
        }
    }
    // The roulette at n = 1 on both sides: every photon crosses, undeviated.
    let mut reflected = 0.0;
    let mut bend: f64 = 0.0;
    let hit = SurfaceHit {
        t: 1.0,
        prim: 0,
        point: DVec3::ZERO,
        normal: DVec3::Z,
    };
    let model = SurfaceModel::Dielectric(Interface {
        inside: 1,
        outside: 0,
    });
    let media = two_media(1.0);
    let n = 20_000;
    for i in 0..n {
        // 19,997 angles over 0..90 deg, then grazing: cos 1e-9, 1e-12, 1e-15.
        let ci = match i {
            19_997 => 1e-9,
            19_998 => 1e-12,
            19_999 => 1e-15,
            _ => (FRAC_PI_2 * (i as f64 + 0.5) / n as f64).cos(),
        };
        let dir = DVec3::new((1.0 - ci * ci).sqrt(), 0.0, -ci).normalize();
        let mut rng = PhotonRng::new(3, i);
        match model.interact(&media, &hit, dir, 0, Estimator::Analog, &mut rng) {
            Outcome::Scattered { dir: d, medium, .. } => {
                reflected += (medium == 0) as u64 as f64;
                bend = bend.max((d - dir).length());
            }
            Outcome::Absorbed => reflected = f64::NAN,
        }
    }
    Row {
        id: "fresnel-no-interface",
        risk: "n1 = n2 (n = 1 on both sides, or index-matched media): 0/0-prone formulas, a spurious grazing reflection, or a bent ray.",
        does: "`reflectance` returns 0 when n1 = n2, at every angle including grazing; `cos_transmitted` computes cos_t^2 as (1 - eta)(1 + eta) + eta^2 cos_i^2, exactly cos_i^2 at eta = 1 (the former 1 - eta^2 (1 - cos_i^2) rounded to 0 below cos_i = 1e-8: a spurious TIR that reflected the photon).",
        expected: "R = 0 at 10,001 angles (0..90 deg incl. grazing) for n = 1, 1.49, 2.4; roulette at n = 1 over 0..90 deg and at cos 1e-9, 1e-12, 1e-15: 0 reflected, direction change < 1e-15".into(),
        measured: format!(
            "max R {max_r}; roulette {reflected} of {n} reflected, max direction change {bend:.1e}"
        ),
        verdict: verdict(max_r == 0.0 && reflected == 0.0 && bend < 1e-15, || {
            "an index-matched interface reflects or bends".into()
        }),
    }
}

pub(super) fn fresnel_diamond() -> Row {
    let n = 2.4;
    let r0 = fresnel::reflectance(1.0, 1.0, n);
    let crit = fresnel::critical_angle(n, 1.0).unwrap();
    let photons = 100_000;
    let mut worst_z: f64 = 0.0;
    let mut worst_snell: f64 = 0.0;
    let mut shown = Vec::new();
    for (theta, inside) in [
        (0.0, false),
        (60f64.to_radians(), false),
        (89.9f64.to_radians(), false),
        (0.0, true),
        (crit - 0.01, true),
        (crit - 1e-6, true),
    ] {
        let (n1, n2) = if inside { (n, 1.0) } else { (1.0, n) };
        let expect = fresnel::reflectance(theta.cos(), n1, n2);
        let (got, snell) = roulette(n, theta, inside, photons);
        let zz = z(got, expect, se_binomial(expect, photons as f64));
        worst_z = worst_z.max(if zz.is_nan() { f64::INFINITY } else { zz });
        worst_snell = worst_snell.max(snell);
        if theta == 0.0 && !inside {
            shown.push(format!("R0 roulette {got:.5} vs {expect:.5}"));
        }
    }
    let (tir, _) = roulette(n, crit + 1e-6, true, 10_000);
    Row {
        id: "fresnel-diamond",
        risk: "A high index (n = 2.4): R0 = 17 %, critical angle 24.6 deg; the roulette or Snell's law could drift where R is large.",
        does: "Same cosine-form routine and Fresnel roulette for every index.",
        expected: format!(
            "R0 = (1.4/3.4)^2 = {:.5}; critical {:.3} deg; roulette = R within 4 SE at 6 angles (1e5 photons each); TIR 1e-6 rad past critical: 100 %; Snell residual < 1e-14",
            (1.4f64 / 3.4).powi(2),
            crit.to_degrees()
        ),
        measured: format!(
            "R0 {r0:.5}; {}; worst {worst_z:.2} SE; TIR {:.4}; Snell residual {worst_snell:.1e}",
            shown.join(", "),
            tir
        ),
        verdict: verdict(
            (r0 - (1.4f64 / 3.4).powi(2)).abs() < 4.0 * EPS
                && worst_z <= 4.0
                && tir == 1.0
                && worst_snell < 1e-14,
            || "n = 2.4 is off".into(),
        ),
    }
}

pub(super) fn fresnel_energy() -> Row {
    let mut worst: f64 = 0.0;
    let mut range_ok = true;
    let mut count = 0;
    for (n1, n2) in PAIRS {
        let crit = fresnel::critical_angle(n1, n2);
        let mut angles: Vec<f64> = (0..=100_000)
            .map(|k| FRAC_PI_2 * k as f64 / 100_000.0)
            .collect();
        if let Some(c) = crit {
            angles.extend([c - 1e-6, c, c + 1e-6]);
        }
        for theta in angles {
            let ci = theta.cos().clamp(0.0, 1.0);
            let r = fresnel::reflectance(ci, n1, n2);
            let t = transmittance(ci, n1, n2);
            range_ok &= (0.0..=1.0).contains(&r);
            worst = worst.max((r + t - 1.0).abs());
            count += 1;
        }
    }
    Row {
        id: "fresnel-energy",
        risk: "R + T != 1 near grazing or critical incidence would create or destroy light at every bounce (thousands per photon).",
        does: "The roulette reflects with probability R and transmits otherwise, so T = 1 - R by construction; R itself must be the physical one.",
        expected: "R from the routine + T from the transmission amplitudes (computed independently) = 1 within 8 eps, R in [0, 1], at 1e5 angles per index pair and +-1e-6 rad around each critical angle".into(),
        measured: format!("max |R + T - 1| = {:.1} eps over {count} angle/index pairs; R in [0, 1]: {range_ok}", worst / EPS),
        verdict: verdict(worst <= 8.0 * EPS && range_ok, || "energy is not conserved".into()),
    }
}

pub(super) fn fresnel_roulette() -> Row {
    let n = 200_000;
    let crit = fresnel::critical_angle(PMMA, 1.0).unwrap();
    let mut worst: f64 = 0.0;
    let mut all = Vec::new();
    for (theta, inside) in [
        (0.0, false),
        (89.99f64.to_radians(), false),
        (0.0, true),
        (crit - 1e-6, true),
        (crit - 0.05, true),
    ] {
        let (n1, n2) = if inside { (PMMA, 1.0) } else { (1.0, PMMA) };
        let expect = fresnel::reflectance(theta.cos(), n1, n2);
        let (got, _) = roulette(PMMA, theta, inside, n);
        let zz = z(got, expect, se_binomial(expect, n as f64));
        worst = worst.max(if zz.is_nan() { f64::INFINITY } else { zz });
        all.push(format!("{:.4}/{:.4}", got, expect));
    }
    let (tir, _) = roulette(PMMA, crit + 1e-6, true, 20_000);
    Row {
        id: "fresnel-roulette",
        risk: "The Russian roulette that picks reflect/transmit could be biased at the corners (R near 0 or 1).",
        does: "One uniform draw against R from the single Fresnel routine; TIR skips the draw.",
        expected: "reflected fraction = R within 4 SE (2e5 photons per angle) at 0, 89.99 deg (outside) and 0, crit - 1e-6, crit - 0.05 rad (inside PMMA); 100 % at crit + 1e-6".into(),
        measured: format!("roulette/R: {}; worst {worst:.2} SE; TIR {tir}", all.join(", ")),
        verdict: verdict(worst <= 4.0 && tir == 1.0, || "the roulette is biased".into()),
    }
}
