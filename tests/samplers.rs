//! Chi-square tests of every direction sampler against its density.
//!
//! One harness ([`chi_square`]): directions are binned over cells of `(cos theta, phi)`
//! about an axis, each cell's expected count is the sampler's density (per steradian)
//! integrated over the cell, and Pearson's statistic must stay below a bound far in the
//! tail of the chi-square distribution (`df + 6 sqrt(2 df)`). Samples outside the grid
//! (and samplers that return nothing, as the Phong lobe below the surface) fall into one
//! extra cell whose expected probability is what the grid's cells leave over, so a wrong
//! normalization fails too. The harness's own self-test checks that it rejects a sampler
//! tested against a wrong density.

use blutrace::optics::diffuser::sample_visible_normal;
use blutrace::optics::fresnel;
use blutrace::optics::phase;
use blutrace::optics::phong::Phong;
use blutrace::optics::sampling;
use blutrace::rng::PhotonRng;
use blutrace::sources::intensity::IntensityProfile;
use blutrace::sources::led::{FlatLed, LedProfile};
use blutrace::sources::{Emitter, Source};
use glam::DVec3;
use std::f64::consts::{PI, TAU};
use std::path::Path;
use std::sync::Arc;

/// Samples per test.
const N: usize = 400_000;

/// The grid of cells about `axis`: `cos theta` edges (increasing) and `n_phi` equal
/// azimuth sectors, measured in a fixed basis of its own.
struct Grid {
    axis: DVec3,
    cos_edges: Vec<f64>,
    n_phi: usize,
}

impl Grid {
    fn new(axis: DVec3, cos_lo: f64, n_cos: usize, n_phi: usize) -> Self {
        let cos_edges = (0..=n_cos)
            .map(|i| cos_lo + (1.0 - cos_lo) * i as f64 / n_cos as f64)
            .collect();
        Self {
            axis: axis.normalize(),
            cos_edges,
            n_phi,
        }
    }

    fn basis(&self) -> (DVec3, DVec3) {
        let helper = if self.axis.x.abs() < 0.9 {
            DVec3::X
        } else {
            DVec3::Y
        };
        let t = self.axis.cross(helper).normalize();
        (t, self.axis.cross(t))
    }

    fn n_cells(&self) -> usize {
        (self.cos_edges.len() - 1) * self.n_phi
    }

    /// The cell of unit `w`, or `None` outside the grid.
    fn cell(&self, w: DVec3) -> Option<usize> {
        let c = w.dot(self.axis);
        let e = &self.cos_edges;
        if c < e[0] || c > e[e.len() - 1] {
            return None;
        }
        let i = (e.partition_point(|&x| x <= c) - 1).min(e.len() - 2);
        let (t, b) = self.basis();
        let phi = w.dot(b).atan2(w.dot(t)).rem_euclid(TAU);
        let j = ((phi / TAU * self.n_phi as f64) as usize).min(self.n_phi - 1);
        Some(i * self.n_phi + j)
    }

    /// The density (per steradian) integrated over each cell, by the midpoint rule on
    /// `sub x sub` points per cell.
    fn probabilities(&self, pdf: &dyn Fn(DVec3) -> f64, sub: usize) -> Vec<f64> {
        let (t, b) = self.basis();
        let dphi = TAU / self.n_phi as f64;
        let mut p = Vec::with_capacity(self.n_cells());
        for w in self.cos_edges.windows(2) {
            let dc = (w[1] - w[0]) / sub as f64;
            for j in 0..self.n_phi {
                let mut sum = 0.0;
                for a in 0..sub {
                    let c = w[0] + (a as f64 + 0.5) * dc;
                    let s = (1.0 - c * c).max(0.0).sqrt();
                    for k in 0..sub {
                        let phi = dphi * (j as f64 + (k as f64 + 0.5) / sub as f64);
                        let dir = t * (s * phi.cos()) + b * (s * phi.sin()) + self.axis * c;
                        sum += pdf(dir);
                    }
                }
                p.push(sum * dc * dphi / sub as f64);
            }
        }
        p
    }
}

/// Pearson's statistic and its degrees of freedom for `n` draws of `sample` (`None`: no
/// direction) against `pdf` on `grid`; cells expecting fewer than 5 are pooled.
fn chi_square(
    grid: &Grid,
    n: usize,
    sample: &mut dyn FnMut(usize) -> Option<DVec3>,
    pdf: &dyn Fn(DVec3) -> f64,
    sub: usize,
) -> (f64, usize) {
    let mut p = grid.probabilities(pdf, sub);
    let rest = 1.0 - p.iter().sum::<f64>();
    assert!(rest > -1e-3, "the density integrates to {} > 1", 1.0 - rest);
    p.push(rest.max(0.0));
    let mut counts = vec![0usize; p.len()];
    for i in 0..n {
        let cell = sample(i).and_then(|w| {
            assert!((w.length() - 1.0).abs() < 1e-9, "not a unit vector: {w:?}");
            grid.cell(w)
        });
        counts[cell.unwrap_or(p.len() - 1)] += 1;
    }
    let (mut chi2, mut cells) = (0.0, 0);
    let (mut pooled_e, mut pooled_o) = (0.0, 0.0);
    for (pk, ok) in p.iter().zip(&counts) {
        let (e, o) = (pk * n as f64, *ok as f64);
        if e < 5.0 {
            pooled_e += e;
            pooled_o += o;
            continue;
        }
        chi2 += (o - e) * (o - e) / e;
        cells += 1;
    }
    if pooled_e >= 5.0 {
        chi2 += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
        cells += 1;
    } else {
        // Too few expected to test as a cell: only a gross excess would show there.
        assert!(
            pooled_o <= 5.0 + 10.0 * pooled_e,
            "{pooled_o} draws in cells expecting {pooled_e}"
        );
    }
    (chi2, cells - 1)
}

/// The bound on the statistic: about 6 standard deviations above its mean.
fn bound(df: usize) -> f64 {
    df as f64 + 6.0 * (2.0 * df as f64).sqrt()
}

/// The sampler passes the chi-square test against `pdf`.
fn assert_fits(
    what: &str,
    grid: &Grid,
    sample: &mut dyn FnMut(usize) -> Option<DVec3>,
    pdf: &dyn Fn(DVec3) -> f64,
    sub: usize,
) {
    let (chi2, df) = chi_square(grid, N, sample, pdf, sub);
    eprintln!(
        "{what}: chi2 = {chi2:.1} with {df} df (bound {:.1})",
        bound(df)
    );
    assert!(df >= 10, "{what}: only {df} degrees of freedom");
    assert!(
        chi2 < bound(df),
        "{what}: chi2 = {chi2:.1} with {df} df (bound {:.1})",
        bound(df)
    );
}

/// Two uniforms per draw, from the photon generator.
fn uniforms(seed: u64, i: usize) -> (f64, f64) {
    let mut rng = PhotonRng::new(seed, i as u64);
    (rng.uniform(), rng.uniform())
}

fn tilted_axis() -> DVec3 {
    DVec3::new(0.3, -0.5, 0.8).normalize()
}

fn cos_power_pdf(axis: DVec3, m: f64) -> impl Fn(DVec3) -> f64 {
    move |w: DVec3| {
        let c = w.dot(axis);
        if c > 0.0 {
            (m + 1.0) / TAU * c.powf(m)
        } else {
            0.0
        }
    }
}

#[test]
fn the_harness_rejects_a_wrong_density() {
    // Lambertian directions tested as if uniform over the hemisphere, and as cos^2.
    let axis = tilted_axis();
    let grid = Grid::new(axis, 0.0, 10, 8);
    let mut lambert = |i| {
        let (u1, u2) = uniforms(11, i);
        Some(sampling::lambertian(axis, u1, u2))
    };
    for (what, m) in [("uniform", 0.0), ("cos^2", 2.0)] {
        let (chi2, df) = chi_square(&grid, N, &mut lambert, &cos_power_pdf(axis, m), 8);
        assert!(
            chi2 > 10.0 * bound(df),
            "{what}: chi2 = {chi2:.1} with {df} df"
        );
    }
    // A density with a small error in one direction only: cos theta with 3% moved
    // from one half of the azimuths to the other.
    let skewed = |w: DVec3| {
        let (t, _) = grid.basis();
        cos_power_pdf(axis, 1.0)(w) * (1.0 + 0.03 * w.dot(t).signum())
    };
    let (chi2, df) = chi_square(&grid, N, &mut lambert, &skewed, 8);
    assert!(chi2 > bound(df), "skewed: chi2 = {chi2:.1} with {df} df");
}

#[test]
fn lambertian_directions_follow_cos_theta_over_pi() {
    let axis = tilted_axis();
    let grid = Grid::new(axis, 0.0, 10, 12);
    assert_fits(
        "lambertian",
        &grid,
        &mut |i| {
            let (u1, u2) = uniforms(1, i);
            Some(sampling::lambertian(axis, u1, u2))
        },
        &cos_power_pdf(axis, 1.0),
        8,
    );
}

#[test]
fn cos_power_directions_follow_cos_m() {
    let axis = tilted_axis();
    for m in [0.0, 1.0, 3.0, 20.0] {
        // Narrow lobes get a grid over where they are.
        let cos_lo = if m > 10.0 { 0.7 } else { 0.0 };
        let grid = Grid::new(axis, cos_lo, 12, 8);
        assert_fits(
            &format!("cos^{m}"),
            &grid,
            &mut |i| {
                let (u1, u2) = uniforms(2, i);
                Some(sampling::cos_power(axis, m, u1, u2))
            },
            &cos_power_pdf(axis, m),
            8,
        );
    }
}

#[test]
fn phong_directions_follow_the_phong_brdf_and_lose_the_lobe_below_the_surface() {
    // Oblique incidence, so part of the specular lobe falls below the surface: those
    // draws return no direction and land in the extra cell, with probability
    // `specular` times the lobe's share below the surface.
    let facing = tilted_axis();
    for (specular, exponent, incidence_deg) in [(0.7, 5.0, 70.0), (0.4, 30.0, 45.0)] {
        let p = Phong {
            reflectance: 0.9.into(),
            specular,
            exponent,
        };
        let (t, _) = Grid::new(facing, 0.0, 1, 1).basis();
        let a = f64::to_radians(incidence_deg);
        let dir = t * a.sin() - facing * a.cos();
        let mirror = fresnel::reflect(dir, facing);
        let lobe = cos_power_pdf(mirror, exponent);
        let pdf = |w: DVec3| {
            if w.dot(facing) <= 0.0 {
                return 0.0;
            }
            (1.0 - specular) * w.dot(facing) / PI + specular * lobe(w)
        };
        let grid = Grid::new(facing, 0.0, 12, 12);
        assert_fits(
            &format!("phong s={specular} n={exponent}"),
            &grid,
            &mut |i| {
                let mut rng = PhotonRng::new(3, i as u64);
                p.direction(facing, dir, &mut rng)
            },
            &pdf,
            16,
        );
    }
}

/// GGX distribution of visible normals: `G1(wi) max(0, wi . m) D(m) / (wi . n)`.
fn ggx_visible_pdf(n: DVec3, wi: DVec3, alpha: f64) -> impl Fn(DVec3) -> f64 {
    let a2 = alpha * alpha;
    let ci = wi.dot(n);
    let g1 = 2.0 * ci / (ci + (a2 + (1.0 - a2) * ci * ci).sqrt());
    move |m: DVec3| {
        let cm = m.dot(n);
        if cm <= 0.0 {
            return 0.0;
        }
        let d = a2 / (PI * ((a2 - 1.0) * cm * cm + 1.0).powi(2));
        g1 * wi.dot(m).max(0.0) * d / ci
    }
}

#[test]
fn ggx_visible_normals_follow_the_distribution_of_visible_normals() {
    let n = tilted_axis();
    let (t, _) = Grid::new(n, 0.0, 1, 1).basis();
    for alpha in [0.3, 0.8] {
        for theta_deg in [0.0, 50.0, 80.0] {
            let a = f64::to_radians(theta_deg);
            let wi = t * a.sin() + n * a.cos();
            let cos_lo = if alpha < 0.5 { 0.6 } else { 0.0 };
            let grid = Grid::new(n, cos_lo, 12, 12);
            assert_fits(
                &format!("GGX alpha={alpha} theta_i={theta_deg}"),
                &grid,
                &mut |i| {
                    let (u1, u2) = uniforms(4, i);
                    Some(sample_visible_normal(n, wi, alpha, u1, u2))
                },
                &ggx_visible_pdf(n, wi, alpha),
                16,
            );
        }
    }
}

#[test]
fn measured_led_directions_follow_the_intensity_profile() {
    // The bundled measured LED and a synthetic batwing table (dip on the axis, peak at
    // 60 degrees, nothing beyond 80), emitted by the LED source itself.
    let bundled = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/phone-led/led.ies");
    let batwing =
        IntensityProfile::from_table(&[0.0, 20.0, 40.0, 60.0, 80.0], &[0.3, 0.5, 0.8, 1.0, 0.0])
            .unwrap();
    for (what, profile) in [
        ("led.ies", IntensityProfile::read(&bundled).unwrap()),
        ("batwing", batwing),
    ] {
        let normal = tilted_axis();
        let (u, _) = Grid::new(normal, 0.0, 1, 1).basis();
        let profile = Arc::new(profile);
        let source = Source {
            name: what.into(),
            power_w: 1.0,
            lumens: None,
            spectrum: None,
            polarization: None,
            emitter: Emitter::Led(FlatLed {
                center: DVec3::ZERO,
                normal,
                u,
                width: 2.0,
                height: 1.0,
                profile: LedProfile::Measured(profile.clone()),
            }),
            medium: 0,
            body: None,
        };
        // Intensity is power per steradian: the density is I / (2 pi int I sin theta).
        let steps = 200_000;
        let h = 0.5 * PI / steps as f64;
        let total: f64 = (0..steps)
            .map(|k| {
                let th = (k as f64 + 0.5) * h;
                profile.intensity(th) * th.sin() * h
            })
            .sum::<f64>()
            * TAU;
        let pdf = |w: DVec3| profile.intensity(w.dot(normal).clamp(-1.0, 1.0).acos()) / total;
        let grid = Grid::new(normal, 0.0, 12, 8);
        assert_fits(
            what,
            &grid,
            &mut |i| {
                let mut rng = PhotonRng::new(5, i as u64);
                Some(source.emit(&mut rng).0.dir)
            },
            &pdf,
            16,
        );
    }
}

#[test]
fn henyey_greenstein_directions_follow_the_phase_function_with_mean_cosine_g() {
    // Scattering about a tilted travel direction. The cos theta edges crowd towards the
    // forward direction (1 - cos theta = 2 (i/n)^3) so that the g = 0.9 peak, about 0.006
    // wide in cos theta, spans several rows.
    let axis = tilted_axis();
    let n_cos = 30;
    let cos_edges = (0..=n_cos)
        .rev()
        .map(|i| 1.0 - 2.0 * (i as f64 / n_cos as f64).powi(3))
        .collect();
    let grid = Grid {
        axis,
        cos_edges,
        n_phi: 8,
    };
    for g in [-0.5, 0.0, 0.9] {
        let draw = |i| {
            let (u1, u2) = uniforms(41, i);
            phase::scatter(axis, g, u1, u2)
        };
        assert_fits(
            &format!("Henyey-Greenstein g = {g}"),
            &grid,
            &mut |i| Some(draw(i)),
            &|w: DVec3| phase::hg_density(g, w.dot(axis)),
            16,
        );
        // The mean cosine is g; the variance of cos theta is (1 - g^2) / 3 (the second
        // Legendre moment of the phase function is g^2).
        let mean = (0..N).map(|i| draw(i).dot(axis)).sum::<f64>() / N as f64;
        let stderr = ((1.0 - g * g) / 3.0 / N as f64).sqrt();
        assert!(
            (mean - g).abs() < 4.0 * stderr,
            "g = {g}: mean cosine {mean:.5} (stderr {stderr:.1e})"
        );
    }
}

#[test]
fn tabulated_phase_function_directions_follow_the_table() {
    // A forward peak with a weak backward lobe, linear between knots (per steradian).
    let rows = [
        [0.0, 10.0],
        [5.0, 6.0],
        [20.0, 1.0],
        [60.0, 0.2],
        [120.0, 0.1],
        [170.0, 0.5],
        [180.0, 0.6],
    ];
    let table = phase::PhaseTable::new(&rows).unwrap();
    // The expected density, from the rows alone: linear in the angle, normalized here.
    let raw = |th: f64| {
        let deg = th.to_degrees();
        let i = rows
            .iter()
            .position(|r| r[0] >= deg)
            .unwrap_or(rows.len() - 1)
            .max(1);
        let ([a0, v0], [a1, v1]) = (rows[i - 1], rows[i]);
        v0 + (v1 - v0) * ((deg - a0) / (a1 - a0)).clamp(0.0, 1.0)
    };
    let n = 200_000;
    let norm: f64 = (0..n)
        .map(|i| {
            let th = (i as f64 + 0.5) * PI / n as f64;
            TAU * raw(th) * th.sin() * PI / n as f64
        })
        .sum();
    let mean: f64 = (0..n)
        .map(|i| {
            let th = (i as f64 + 0.5) * PI / n as f64;
            TAU * raw(th) * th.sin() * th.cos() * PI / n as f64
        })
        .sum::<f64>()
        / norm;
    assert!(
        (table.mean_cosine - mean).abs() < 1e-5,
        "{} vs {mean}",
        table.mean_cosine
    );
    let axis = tilted_axis();
    let n_cos = 30;
    let grid = Grid {
        axis,
        cos_edges: (0..=n_cos)
            .rev()
            .map(|i| 1.0 - 2.0 * (i as f64 / n_cos as f64).powi(2))
            .collect(),
        n_phi: 8,
    };
    assert_fits(
        "phase table",
        &grid,
        &mut |i| {
            let (u1, u2) = uniforms(43, i);
            Some(sampling::around(axis, table.cos_theta(u1), u2))
        },
        &|w: DVec3| raw(w.dot(axis).clamp(-1.0, 1.0).acos()) / norm,
        16,
    );
    for bad in [
        vec![[0.0, 1.0]],
        vec![[0.0, 1.0], [90.0, 1.0]],
        vec![[0.0, 1.0], [90.0, -1.0], [180.0, 1.0]],
        vec![[0.0, 1.0], [90.0, 1.0], [90.0, 1.0], [180.0, 1.0]],
        vec![[0.0, 0.0], [180.0, 0.0]],
        vec![[0.0, f64::NAN], [180.0, 1.0]],
    ] {
        assert!(phase::PhaseTable::new(&bad).is_err(), "{bad:?}");
    }
}
