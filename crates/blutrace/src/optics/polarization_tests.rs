//! Closed forms of polarized optics, each test failing when its physics is wrong.

use super::*;

const PMMA: f64 = 1.49;

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

/// The Stokes vector of a field `(e_u, e_v)` (complex amplitudes, `exp(-i w t)`).
fn stokes_of(eu: Complex64, ev: Complex64) -> Stokes {
    let x = eu * ev.conj();
    Stokes([
        eu.norm_sqr() + ev.norm_sqr(),
        eu.norm_sqr() - ev.norm_sqr(),
        2.0 * x.re,
        -2.0 * x.im,
    ])
}

#[test]
fn stokes_conventions_match_the_field() {
    let i = Complex64::i();
    let one = Complex64::from(1.0);
    // Linear at 45 degrees, and the circular state turning from u towards v.
    let s = stokes_of(one, one);
    assert_eq!(s.0, [2.0, 0.0, 2.0, 0.0]);
    assert_eq!(stokes_of(one, i).0, [2.0, 0.0, 0.0, 2.0]);
    // A diattenuator acting on the field acts on its Stokes vector the same way.
    let (au, av) = (
        Complex64::from_polar(0.9, 0.4),
        Complex64::from_polar(0.5, -1.1),
    );
    let field = (Complex64::new(0.3, 0.7), Complex64::new(-0.8, 0.2));
    let by_field = stokes_of(au * field.0, av * field.1);
    let m = Mueller::diattenuator(au.norm_sqr(), av.norm_sqr(), au * av.conj());
    let by_matrix = m.apply(stokes_of(field.0, field.1));
    for k in 0..4 {
        assert!(
            close(by_field.0[k], by_matrix.0[k], 1e-12),
            "{by_field:?} {by_matrix:?}"
        );
    }
}

#[test]
fn a_turned_frame_turns_linear_states() {
    let s = Stokes::linear_deg(30.0).rotated_frame(10f64.to_radians());
    let want = Stokes::linear_deg(20.0);
    for k in 0..4 {
        assert!(close(s.0[k], want.0[k], 1e-15));
    }
    let d = DVec3::Z;
    assert!(close(
        frame_angle(d, DVec3::X, DVec3::Y),
        std::f64::consts::FRAC_PI_2,
        1e-15
    ));
    let r = Stokes::linear_deg(0.0).reframed(d, DVec3::X, DVec3::Y);
    assert!(
        close(r.0[1], -1.0, 1e-15),
        "x-polarized is -S1 in a y frame: {r:?}"
    );
}

/// Malus: unpolarized light through two ideal absorbing polarizers whose pass axes are
/// `theta` apart passes `cos^2(theta) / 2`.
#[test]
fn malus_law_for_two_ideal_polarizers() {
    let ideal = polarizer_transmission(1.0, 0.0);
    for deg in [0.0, 20.0, 45.0, 60.0, 90.0] {
        let first = ideal.apply(Stokes::UNPOLARIZED);
        let second = ideal.apply(first.rotated_frame(f64::to_radians(deg)));
        let want = 0.5 * f64::to_radians(deg).cos().powi(2);
        assert!(close(second.power(), want, 1e-15), "{deg}: {second:?}");
    }
}

/// The 60 degree slab of issue 46: lossless PMMA, 1 mm, incoherent multiple reflections
/// traced for s and p apart: `T = (1 - R)/(1 + R)` each, `(Ts + Tp)/2 = 0.8505` and
/// `S1/S0 = (Ts - Tp)/(Ts + Tp)` (here `u = s`, so S1 > 0 is s: the issue's
/// `(Tp - Ts)/(Tp + Ts) = 0.1712` with the sign of a p frame).
#[test]
fn the_sixty_degree_slab_in_closed_form() {
    let cos_i = 60f64.to_radians().cos();
    let m = fresnel_reflection(cos_i, 1.0, PMMA);
    let (rs, rp) = (m.0[0][0] + m.0[0][1], m.0[0][0] - m.0[0][1]);
    let (ts, tp) = ((1.0 - rs) / (1.0 + rs), (1.0 - rp) / (1.0 + rp));
    assert!(
        close(ts, 0.7049, 5e-5) && close(tp, 0.9961, 5e-5),
        "{ts} {tp}"
    );
    assert!(close(0.5 * (ts + tp), 0.8505, 5e-5));
    assert!(close((tp - ts) / (tp + ts), 0.1712, 5e-5));
}

#[test]
fn brewster_angle_reflects_no_p_light() {
    let brewster = PMMA.atan();
    let m = fresnel_reflection(brewster.cos(), 1.0, PMMA);
    let p = Stokes([1.0, -1.0, 0.0, 0.0]);
    assert!(m.apply(p).power() < 1e-30, "{:?}", m.apply(p));
    assert!(m.apply(Stokes([1.0, 1.0, 0.0, 0.0])).power() > 0.1);
    // From inside too: tan(theta_B) = n2 / n1.
    let inside = (1.0 / PMMA).atan();
    assert!(fresnel_reflection(inside.cos(), PMMA, 1.0).apply(p).power() < 1e-30);
}

/// Total internal reflection inside PMMA turns 45-degree linear light elliptic:
/// `|S3/S0| = sin(delta)` with `tan(delta/2) = cos_i sqrt(sin_i^2 - n^2) / sin_i^2`,
/// n = 1/1.49: 0.573 at 45 degrees, 0.701 at 52.0 degrees (the largest retardance).
#[test]
fn total_internal_reflection_retardance() {
    let n = 1.0 / PMMA;
    let closed = |deg: f64| {
        let (s, c) = deg.to_radians().sin_cos();
        (2.0 * (c * (s * s - n * n).sqrt() / (s * s)).atan()).sin()
    };
    for (deg, want) in [(45.0, 0.573), (52.0, 0.701), (70.0, closed(70.0))] {
        let m = fresnel_reflection(f64::to_radians(deg).cos(), PMMA, 1.0);
        let out = m.apply(Stokes::linear_deg(45.0));
        assert!(close(out.power(), 1.0, 1e-14), "TIR keeps all: {out:?}");
        assert!(close(out.dop(), 1.0, 1e-14));
        let s3 = (out.0[3] / out.0[0]).abs();
        assert!(
            close(s3, want, 1e-3) && close(s3, closed(deg), 1e-12),
            "{deg}: {s3}"
        );
    }
    // The largest retardance: cos(theta) = sqrt((1 - n^2) / (1 + n^2)).
    let best = ((1.0 - n * n) / (1.0 + n * n)).sqrt().acos().to_degrees();
    assert!(close(best, 52.0, 0.05), "{best}");
}

/// Every event conserves or loses power for every state: reflected plus transmitted
/// power is exactly the incident one at a dielectric, at most it at a polarizer.
#[test]
fn every_mueller_matrix_conserves_energy() {
    let states = [
        Stokes::UNPOLARIZED,
        Stokes([1.0, 1.0, 0.0, 0.0]),
        Stokes([1.0, -1.0, 0.0, 0.0]),
        Stokes::linear_deg(30.0),
        Stokes([1.0, 0.0, 0.0, 1.0]),
        Stokes([1.0, 0.3, -0.4, -0.5]),
    ];
    for k in 0..=90 {
        let cos_i = f64::to_radians(k as f64).cos();
        for (n1, n2) in [(1.0, PMMA), (PMMA, 1.0), (1.0, 2.4)] {
            let r = fresnel_reflection(cos_i, n1, n2);
            let t = fresnel_transmission(cos_i, n1, n2);
            for s in states {
                let sum = r.apply(s).power() + t.map_or(0.0, |t| t.apply(s).power());
                assert!(close(sum, 1.0, 1e-12), "{k} deg {n1}->{n2} {s:?}: {sum}");
                for m in [Some(r), t].into_iter().flatten() {
                    assert!(m.apply(s).dop() <= 1.0 + 1e-12);
                }
            }
        }
    }
    // Unpolarized light sees the averaged Fresnel reflectance.
    let r = fresnel_reflection(0.5, 1.0, PMMA)
        .apply(Stokes::UNPOLARIZED)
        .power();
    assert!(close(
        r,
        super::super::fresnel::reflectance(0.5, 1.0, PMMA),
        1e-15
    ));
    // An ideal reflective polarizer (pass 1, block reflected 1) loses nothing.
    let (t, r) = (
        polarizer_transmission(1.0, 0.0),
        polarizer_reflection(0.0, 1.0),
    );
    for s in states {
        assert!(close(t.apply(s).power() + r.apply(s).power(), 1.0, 1e-15));
    }
}

/// A mirror, and the reflection of a dielectric at normal incidence, turn the handedness
/// of circular light (in the frame of each wave) and keep linear states' lab direction.
#[test]
fn reflection_turns_circular_handedness() {
    let circ = Stokes([1.0, 0.0, 0.0, 1.0]);
    assert!(close(mirror(0.9).apply(circ).0[3], -0.9, 1e-15));
    let out = fresnel_reflection(1.0, 1.0, PMMA).apply(circ).normalized();
    assert!(close(out.0[3], -1.0, 1e-12), "{out:?}");
    let out = fresnel_transmission(1.0, 1.0, PMMA)
        .unwrap()
        .apply(circ)
        .normalized();
    assert!(
        close(out.0[3], 1.0, 1e-12),
        "transmission keeps it: {out:?}"
    );
}

#[test]
fn s_axis_and_block_direction() {
    let d = DVec3::new(0.6, 0.0, -0.8);
    assert_eq!(s_axis(d, DVec3::Z, DVec3::X), DVec3::NEG_Y);
    let normal_incidence = s_axis(DVec3::NEG_Z, DVec3::Z, DVec3::X);
    assert!(close(normal_incidence.dot(DVec3::X), 1.0, 1e-15));
    let b = block_direction(d, DVec3::X).unwrap();
    assert!(close(b.dot(d), 0.0, 1e-15) && close(b.length(), 1.0, 1e-15));
    assert!(block_direction(DVec3::X, DVec3::X).is_none());
}

/// One event of a chain: the facet normal (towards the light met), the indices, and the
/// branch taken.
struct Event {
    facing: DVec3,
    n: (f64, f64),
    reflect: bool,
}

/// The direction leaving event `e` for light along `d`.
fn leave(d: DVec3, facing: DVec3, n: (f64, f64), reflect: bool) -> DVec3 {
    match reflect {
        true => crate::optics::fresnel::reflect(d, facing).normalize(),
        false => crate::optics::fresnel::refract(d, facing, n.0, n.1).unwrap(),
    }
}

/// A random chain of six Fresnel events from `d0`, and the direction it leaves along.
fn random_chain(d0: DVec3, u: &mut impl FnMut() -> f64) -> (Vec<Event>, DVec3) {
    let (mut d, mut inside, mut events) = (d0, false, Vec::new());
    for _ in 0..6 {
        let tilt = DVec3::new(u() - 0.5, u() - 0.5, u() - 0.5);
        let facing = (-d + tilt).normalize();
        let n = if inside { (1.58, 1.0) } else { (1.0, 1.58) };
        let tir = crate::optics::fresnel::refract(d, facing, n.0, n.1).is_none();
        let reflect = u() < 0.4 || tir;
        d = leave(d, facing, n, reflect);
        inside ^= !reflect;
        events.push(Event { facing, n, reflect });
    }
    (events, d)
}

/// A polarized chain of Fresnel events read forwards (light) and backwards (a
/// detector's response carried by the same functions) gives the same signal: the
/// reciprocity [`response`] relies on, with total internal reflection's retardance
/// turning S2 into S3 on the way.
#[test]
fn backward_response_through_fresnel_chains_matches_forward_light() {
    let mut rng = crate::rng::PhotonRng::new(11, 3);
    let mut u = || rng.uniform();
    for chain in 0..200 {
        let d0 = DVec3::new(u() - 0.5, u() - 0.5, u() - 0.5).normalize();
        let (events, d_end) = random_chain(d0, &mut u);
        let light = Polarization {
            stokes: Stokes([1.0, 0.3 * u(), -0.5 * u(), 0.6 * u()]),
            u: any_frame(d0),
        };
        let det = Polarization {
            stokes: Stokes([1.0, 0.4, -0.3, 0.5]),
            u: any_frame(d_end),
        };
        // Forwards: the light's power through each branch, then the detector's functional.
        let (mut w, mut state, mut dir) = (1.0, light, d0);
        for e in &events {
            let (p, s) = fresnel_branch(dir, e.facing, e.n, &state, e.reflect).unwrap();
            (w, state, dir) = (w * p, s, leave(dir, e.facing, e.n, e.reflect));
        }
        let (sf, di) = (state.stokes_in(dir, det.u).0, det.stokes.0);
        let forward = w * (0..4).map(|i| di[i] * sf[i]).sum::<f64>();
        // Backwards: the detector's vector, time-reversed, through the reversed events.
        let mut imp = Polarization {
            stokes: Stokes([di[0], di[1], -di[2], di[3]]),
            u: det.u,
        };
        let (mut wb, mut back) = (1.0, -dir);
        for e in events.iter().rev() {
            let (facing, n) = match e.reflect {
                true => (e.facing, e.n),
                false => (-e.facing, (e.n.1, e.n.0)),
            };
            let (p, s) = fresnel_branch(back, facing, n, &imp, e.reflect).unwrap();
            (wb, imp, back) = (wb * p, s, leave(back, facing, n, e.reflect));
        }
        assert!(
            (back + d0).length() < 1e-9,
            "chain {chain}: the reversed path"
        );
        let backward = wb * response(&imp, &light, d0);
        assert!(
            (forward - backward).abs() < 1e-10,
            "chain {chain}: forward {forward}, backward {backward}"
        );
    }
}

/// A polarizer sheet's transmission and reflection read forwards and backwards give the
/// same signal (its matrices have the reversed light's form `Q M^T Q`), so the meter's
/// backward walk may cross it.
#[test]
fn backward_response_through_polarizer_sheets_matches_forward_light() {
    let d = DVec3::new(0.3, -0.2, 0.9).normalize();
    let block = block_direction(d, DVec3::X).unwrap();
    let light = Polarization {
        stokes: Stokes([1.0, -0.2, 0.5, 0.3]),
        u: any_frame(d),
    };
    let det = Stokes([1.0, 0.4, -0.3, 0.5]);
    for m in [
        polarizer_transmission(0.9, 0.02),
        polarizer_reflection(0.05, 0.9),
    ] {
        let s = m.apply(light.stokes_in(d, block)).0;
        let forward: f64 = (0..4).map(|i| det.0[i] * s[i]).sum();
        let imp = Stokes([det.0[0], det.0[1], -det.0[2], det.0[3]]);
        let back = Polarization {
            stokes: m.apply(imp),
            u: block,
        };
        let backward = response(&back, &light, d);
        assert!(
            (forward - backward).abs() < 1e-12,
            "{forward} vs {backward}"
        );
    }
}
