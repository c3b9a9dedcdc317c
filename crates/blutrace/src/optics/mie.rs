//! Mie scattering by a homogeneous sphere: efficiencies and asymmetry parameter, and the
//! bulk coefficients of a medium filled with such spheres (see [`super::medium`]).
//!
//! ```toml
//! [media.diffusion_pmma]
//! n = 1.49
//! particles = { radius_um = 2.0, n = 1.43, volume_fraction = 0.001, wavelength_nm = 550.0 }
//! # k = 0.0 (imaginary index of the particles, absorbing if > 0) is optional
//! ```
//!
//! The series is Bohren & Huffman's BHMIE (*Absorption and Scattering of Light by Small
//! Particles*, 1983, appendix A): the logarithmic derivative `D_n(mx)` by downward
//! recurrence (started higher than BHMIE does), the Riccati-Bessel functions by upward
//! recurrence, `x + 4 x^(1/3) + 2` terms. It is tested against Bohren & Huffman's worked example and Wiscombe's MIEV0
//! test cases (NCAR TN-140, 1979).
//!
//! A medium from particles assumes independent scattering (particles far apart compared
//! to the wavelength: volume fractions of a few per cent at most, as in diffuser plates
//! and diffusion light guides) and samples the Henyey-Greenstein phase function with the
//! Mie asymmetry `g`, the usual stand-in for the full Mie phase function, whose forward
//! peak and ripples it leaves out; the transport-relevant `mu_s (1 - g)` is exact.
//!
//! In a spectral scene the coefficients are tabulated over wavelength at load
//! ([`bulk_spectra`]): a Mie evaluation every [`TABLE_STEP_NM`] from 360 to 830 nm, with
//! the particles' and the host's indices read at each, linear between. A monochrome scene
//! evaluates them once, at the particles' `wavelength_nm` ([`bulk`]).

use super::spectrum::{Light, Spectral};
use num_complex::Complex64;
use std::f64::consts::PI;

/// What a sphere does to light, per unit geometric cross-section.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Efficiencies {
    /// Extinction efficiency `Q_ext`.
    pub qext: f64,
    /// Scattering efficiency `Q_sca`.
    pub qsca: f64,
    /// Asymmetry parameter `g`, the mean cosine of the scattering angle.
    pub g: f64,
}

/// Mie efficiencies of a sphere of relative complex index `m` (`n + i k`, `k >= 0`
/// absorbing) and size parameter `x = 2 pi r n_host / lambda_0`.
pub fn efficiencies(m: Complex64, x: f64) -> Efficiencies {
    let nstop = (x + 4.0 * x.cbrt() + 2.0).round() as usize;
    let y = m * x;
    // D_n(y) = psi_n'(y) / psi_n(y), stable downwards from D_nmx = 0. BHMIE starts 15
    // terms above max(nstop, |mx|), which leaves Q_sca 5e-5 short at x = 100 (MIEV0 case
    // 10); 10 % + 50 above converges every test case to all published digits.
    let nmx = ((nstop as f64).max(y.norm()) * 1.1).round() as usize + 50;
    let mut d = vec![Complex64::new(0.0, 0.0); nmx + 1];
    for n in (1..=nmx).rev() {
        let ny = n as f64 / y;
        d[n - 1] = ny - 1.0 / (d[n] + ny);
    }
    let (mut psi0, mut psi1) = (x.cos(), x.sin());
    let (mut chi0, mut chi1) = (-x.sin(), x.cos());
    let mut xi1 = Complex64::new(psi1, -chi1);
    let (mut qsca, mut qext, mut gsum) = (0.0, 0.0, 0.0);
    let (mut a_prev, mut b_prev) = (Complex64::new(0.0, 0.0), Complex64::new(0.0, 0.0));
    for (n, &dn) in d.iter().enumerate().take(nstop + 1).skip(1) {
        let nf = n as f64;
        let psi = (2.0 * nf - 1.0) * psi1 / x - psi0;
        let chi = (2.0 * nf - 1.0) * chi1 / x - chi0;
        let xi = Complex64::new(psi, -chi);
        let da = dn / m + nf / x;
        let db = dn * m + nf / x;
        let a = (da * psi - psi1) / (da * xi - xi1);
        let b = (db * psi - psi1) / (db * xi - xi1);
        let w = 2.0 * nf + 1.0;
        qsca += w * (a.norm_sqr() + b.norm_sqr());
        qext += w * (a.re + b.re);
        gsum += w / (nf * (nf + 1.0)) * (a * b.conj()).re;
        if n > 1 {
            gsum += (nf - 1.0) * (nf + 1.0) / nf * (a_prev * a.conj() + b_prev * b.conj()).re;
        }
        (a_prev, b_prev) = (a, b);
        (psi0, psi1, chi0, chi1) = (psi1, psi, chi1, chi);
        xi1 = Complex64::new(psi1, -chi1);
    }
    Efficiencies {
        qext: 2.0 * qext / (x * x),
        qsca: 2.0 * qsca / (x * x),
        // An index-matched sphere scatters nothing; its g is then immaterial.
        g: if qsca > 0.0 { 2.0 * gsum / qsca } else { 0.0 },
    }
}

/// The bulk coefficients of a medium holding spheres at one size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bulk {
    /// Scattering coefficient (1/mm).
    pub scattering_per_mm: f64,
    /// Absorption coefficient of the particles (1/mm), 0 for `k = 0`.
    pub absorption_per_mm: f64,
    /// Asymmetry parameter.
    pub anisotropy: f64,
    /// The size parameter `x`, for reports.
    pub size_parameter: f64,
}

/// Spheres of radius `radius_um`, complex index `n_p + i k_p`, at `volume_fraction` in a
/// host of index `n_host`, lit at vacuum wavelength `wavelength_nm`: number density
/// `f / (4/3 pi r^3)` times cross-section `Q pi r^2`, i.e. `mu = 3 f Q / (4 r)`.
pub fn bulk(
    radius_um: f64,
    n_p: f64,
    k_p: f64,
    volume_fraction: f64,
    wavelength_nm: f64,
    n_host: f64,
) -> Bulk {
    let x = 2.0 * PI * radius_um * 1e3 * n_host / wavelength_nm;
    let e = efficiencies(Complex64::new(n_p / n_host, k_p / n_host), x);
    let per_q = 3.0 * volume_fraction / (4.0 * radius_um * 1e-3);
    Bulk {
        scattering_per_mm: per_q * e.qsca,
        absorption_per_mm: per_q * (e.qext - e.qsca).max(0.0),
        anisotropy: e.g,
        size_parameter: x,
    }
}

/// The wavelength step of the Mie tabulation of a spectral scene (nm).
pub const TABLE_STEP_NM: f64 = 5.0;

/// The first and last wavelengths of the tabulation (nm): the CIE observer's range.
pub const TABLE_NM: (f64, f64) = (360.0, 830.0);

/// The bulk coefficients of a medium holding spheres at one size, over wavelength.
#[derive(Clone, Debug, PartialEq)]
pub struct BulkSpectra {
    /// Scattering coefficient (1/mm).
    pub scattering_per_mm: Spectral,
    /// Absorption coefficient of the particles (1/mm).
    pub absorption_per_mm: Spectral,
    /// Asymmetry parameter.
    pub anisotropy: Spectral,
}

/// [`bulk`] every [`TABLE_STEP_NM`] over [`TABLE_NM`], linear between: spheres of radius
/// `radius_um`, index `n_p + i k_p`, at `volume_fraction` in a host of index `n_host`,
/// each index read at the wavelength of the evaluation. A quantity that is the same at
/// every node comes back a constant, and so does the absorption of clear spheres (`k_p`
/// zero everywhere): exactly zero, where `Q_ext - Q_sca` leaves rounding of 1e-15.
pub fn bulk_spectra(
    radius_um: f64,
    n_p: &Spectral,
    k_p: &Spectral,
    volume_fraction: f64,
    n_host: &Spectral,
) -> BulkSpectra {
    let nodes: Vec<Bulk> = (0..table_len())
        .map(|i| {
            let nm = node_nm(i);
            let l = Light::at_nm(nm);
            bulk(
                radius_um,
                n_p.at(l),
                k_p.at(l),
                volume_fraction,
                nm,
                n_host.at(l),
            )
        })
        .collect();
    let column = |f: fn(&Bulk) -> f64| -> Spectral {
        let v: Vec<f64> = nodes.iter().map(f).collect();
        if v.iter().all(|&x| x == v[0]) {
            return Spectral::constant(v[0]);
        }
        Spectral::sampled(|nm| between_nodes(&v, nm))
    };
    BulkSpectra {
        scattering_per_mm: column(|b| b.scattering_per_mm),
        absorption_per_mm: if k_p.range() == (0.0, 0.0) {
            Spectral::constant(0.0)
        } else {
            column(|b| b.absorption_per_mm)
        },
        anisotropy: column(|b| b.anisotropy),
    }
}

/// How many wavelengths the tabulation evaluates.
fn table_len() -> usize {
    ((TABLE_NM.1 - TABLE_NM.0) / TABLE_STEP_NM).round() as usize + 1
}

/// The wavelength of node `i` (nm).
fn node_nm(i: usize) -> f64 {
    TABLE_NM.0 + TABLE_STEP_NM * i as f64
}

/// Node values `v` at `nm`: linear between nodes (a node's own value on it), the end
/// values beyond.
fn between_nodes(v: &[f64], nm: f64) -> f64 {
    let x = ((nm - TABLE_NM.0) / TABLE_STEP_NM).clamp(0.0, (v.len() - 1) as f64);
    let i = (x as usize).min(v.len() - 2);
    let f = x - i as f64;
    v[i] + f * (v[i + 1] - v[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(what: &str, got: f64, want: f64, tol: f64) {
        assert!(
            (got - want).abs() <= tol,
            "{what}: got {got:.7}, published {want:.7}"
        );
    }

    #[test]
    fn bohren_huffman_worked_example() {
        // Bohren & Huffman (1983), appendix A: m = 1.55, lambda = 0.6328 um, r = 0.525 um
        // in vacuum: Q_ext = Q_sca = 3.10543, g = 0.63314.
        let x = 2.0 * PI * 0.525 / 0.6328;
        let e = efficiencies(Complex64::new(1.55, 0.0), x);
        close("qext", e.qext, 3.10543, 1e-5);
        close("qsca", e.qsca, 3.10543, 1e-5);
        close("g", e.g, 0.63314, 1e-5);
    }

    #[test]
    fn wiscombe_miev0_test_cases() {
        // Wiscombe, "Mie scattering calculations", NCAR TN-140+STR (1979), test cases 7-11
        // (as tabulated in the test suites of MIEV0's ports): (m, x, Q_sca, g).
        let cases = [
            (Complex64::new(0.75, 0.0), 10.0, 2.232265, 0.896473),
            (Complex64::new(0.75, 0.0), 1000.0, 1.997908, 0.844944),
            (Complex64::new(1.33, 1e-5), 1.0, 0.093923, 0.184517),
            (Complex64::new(1.33, 1e-5), 100.0, 2.096594, 0.868959),
            (Complex64::new(1.33, 1e-5), 10000.0, 1.723857, 0.907840),
        ];
        for (m, x, qsca, g) in cases {
            let e = efficiencies(m, x);
            close(&format!("m {m} x {x} qsca"), e.qsca, qsca, 2e-6);
            close(&format!("m {m} x {x} g"), e.g, g, 2e-6);
            assert!(e.qext >= e.qsca - 1e-12, "absorption must not be negative");
        }
    }

    #[test]
    fn small_spheres_follow_rayleigh() {
        // x << 1: Q_sca = 8/3 x^4 ((m^2 - 1)/(m^2 + 2))^2 and g -> 0.
        let (m, x) = (1.2_f64, 0.01);
        let lorentz = (m * m - 1.0) / (m * m + 2.0);
        let e = efficiencies(Complex64::new(m, 0.0), x);
        let want = 8.0 / 3.0 * x.powi(4) * lorentz * lorentz;
        assert!((e.qsca / want - 1.0).abs() < 1e-3, "{} vs {want}", e.qsca);
        assert!(e.g.abs() < 1e-3);
    }

    #[test]
    fn bulk_coefficients_scale_with_volume_fraction_over_radius() {
        let one = bulk(2.0, 1.43, 0.0, 0.001, 550.0, 1.49);
        let two = bulk(2.0, 1.43, 0.0, 0.002, 550.0, 1.49);
        assert!((two.scattering_per_mm / one.scattering_per_mm - 2.0).abs() < 1e-12);
        assert_eq!(one.absorption_per_mm, 0.0);
        let x = 2.0 * PI * 2000.0 * 1.49 / 550.0;
        let e = efficiencies(Complex64::new(1.43 / 1.49, 0.0), x);
        let want = 3.0 * 0.001 * e.qsca / (4.0 * 2e-3);
        assert!((one.scattering_per_mm - want).abs() < 1e-12 * want);
    }

    #[test]
    fn tabulation_is_the_mie_sum_at_its_nodes_and_linear_between() {
        // PMMA-like host with dispersion, silicone-like spheres: every 5 nm the table is
        // the direct evaluation; halfway between two nodes it is their mean.
        let host = Spectral::sampled(|nm| 1.48 + 4.0e3 / (nm * nm));
        let n_p = Spectral::constant(1.42);
        let k_p = Spectral::constant(0.0);
        let t = bulk_spectra(1.0, &n_p, &k_p, 0.01, &host);
        assert_eq!(t.absorption_per_mm, Spectral::constant(0.0));
        let direct = |nm: f64| {
            let l = Light::at_nm(nm);
            bulk(1.0, 1.42, 0.0, 0.01, nm, host.at(l))
        };
        for nm in [360.0, 450.0, 555.0, 650.0, 830.0] {
            let (b, l) = (direct(nm), Light::at_nm(nm));
            close(
                "mu_s",
                t.scattering_per_mm.at(l),
                b.scattering_per_mm,
                1e-12,
            );
            close("g", t.anisotropy.at(l), b.anisotropy, 1e-12);
        }
        let (a, b) = (direct(450.0), direct(455.0));
        let mid = t.scattering_per_mm.at(Light::at_nm(452.5));
        close(
            "mu_s mid",
            mid,
            0.5 * (a.scattering_per_mm + b.scattering_per_mm),
            1e-9,
        );
        assert!(t.scattering_per_mm.at(Light::at_nm(400.0)) != b.scattering_per_mm);
    }
}
