//! The viridis colour map of the false-colour previews.

/// Knots of the viridis colour map: `(index in the 256-entry table, sRGB in 0..1)`.
///
/// Every 8th entry (and the last) of `_viridis_data` in matplotlib's
/// `lib/matplotlib/_cm_listed.py`, the colour map by Stéfan van der Walt and Nathaniel
/// Smith (<https://github.com/BIDS/colormap>, released under CC0). Linear interpolation
/// between these knots reproduces the full table within 1.7/255 per channel.
const VIRIDIS_KNOTS: [(u8, [f64; 3]); 33] = [
    (0, [0.267004, 0.004874, 0.329415]),
    (8, [0.277018, 0.050344, 0.375715]),
    (16, [0.282327, 0.094955, 0.417331]),
    (24, [0.282884, 0.135920, 0.453427]),
    (32, [0.278826, 0.175490, 0.483397]),
    (40, [0.270595, 0.214069, 0.507052]),
    (48, [0.258965, 0.251537, 0.524736]),
    (56, [0.244972, 0.287675, 0.537260]),
    (64, [0.229739, 0.322361, 0.545706]),
    (72, [0.214298, 0.355619, 0.551184]),
    (80, [0.199430, 0.387607, 0.554642]),
    (88, [0.185556, 0.418570, 0.556753]),
    (96, [0.172719, 0.448791, 0.557885]),
    (104, [0.160665, 0.478540, 0.558115]),
    (112, [0.149039, 0.508051, 0.557250]),
    (120, [0.137770, 0.537492, 0.554906]),
    (128, [0.127568, 0.566949, 0.550556]),
    (136, [0.120565, 0.596422, 0.543611]),
    (144, [0.120638, 0.625828, 0.533488]),
    (152, [0.132268, 0.655014, 0.519661]),
    (160, [0.157851, 0.683765, 0.501686]),
    (168, [0.196571, 0.711827, 0.479221]),
    (176, [0.246070, 0.738910, 0.452024]),
    (184, [0.304148, 0.764704, 0.419943]),
    (192, [0.369214, 0.788888, 0.382914]),
    (200, [0.440137, 0.811138, 0.340967]),
    (208, [0.515992, 0.831158, 0.294279]),
    (216, [0.595839, 0.848717, 0.243329]),
    (224, [0.678489, 0.863742, 0.189503]),
    (232, [0.762373, 0.876424, 0.137064]),
    (240, [0.845561, 0.887322, 0.099702]),
    (248, [0.926106, 0.897330, 0.104071]),
    (255, [0.993248, 0.906157, 0.143936]),
];

/// Viridis at `t` (clamped to `0..=1`; NaN counts as 0) as sRGB components in `0..=1`.
fn viridis_f64(t: f64) -> [f64; 3] {
    let pos = if t.is_nan() {
        0.0
    } else {
        t.clamp(0.0, 1.0) * 255.0
    };
    let k = VIRIDIS_KNOTS
        .windows(2)
        .position(|w| pos <= f64::from(w[1].0))
        .unwrap_or(VIRIDIS_KNOTS.len() - 2);
    let ((i0, c0), (i1, c1)) = (VIRIDIS_KNOTS[k], VIRIDIS_KNOTS[k + 1]);
    let f = (pos - f64::from(i0)) / f64::from(i1 - i0);
    [0, 1, 2].map(|c| c0[c] + f * (c1[c] - c0[c]))
}

/// The viridis colour map: 8-bit sRGB for `t` in `0..=1` (dark purple at 0, yellow at 1;
/// `t` is clamped, NaN counts as 0).
pub fn viridis(t: f64) -> [u8; 3] {
    viridis_f64(t).map(|c| (c * 255.0).round().clamp(0.0, 255.0) as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// CIE L* (D65) of an 8-bit-scale sRGB colour with components in `0..=1`.
    fn lightness(c: [f64; 3]) -> f64 {
        let lin = |u: f64| {
            if u <= 0.04045 {
                u / 12.92
            } else {
                ((u + 0.055) / 1.055).powf(2.4)
            }
        };
        let y = 0.2126 * lin(c[0]) + 0.7152 * lin(c[1]) + 0.0722 * lin(c[2]);
        if y > 216.0 / 24389.0 {
            116.0 * y.cbrt() - 16.0
        } else {
            y * 24389.0 / 27.0
        }
    }

    #[test]
    fn colour_map_is_monotone_in_lightness() {
        let n = 2000;
        let l: Vec<f64> = (0..=n)
            .map(|i| lightness(viridis_f64(i as f64 / n as f64)))
            .collect();
        assert!(l.windows(2).all(|w| w[1] > w[0]), "not strictly increasing");
        assert!(l[0] < 35.0 && l[n] > 85.0, "{} .. {}", l[0], l[n]);
        // Also after 8-bit rounding, up to rounding noise.
        let l8: Vec<f64> = (0..=255)
            .map(|i| lightness(viridis(i as f64 / 255.0).map(|c| f64::from(c) / 255.0)))
            .collect();
        assert!(l8.windows(2).all(|w| w[1] > w[0] - 0.3));
        assert_eq!(viridis(0.0), [68, 1, 84]);
        assert_eq!(viridis(1.0), [253, 231, 37]);
        assert_eq!(viridis(f64::NAN), viridis(-1.0));
        assert_eq!(viridis(2.0), viridis(1.0));
    }

    #[test]
    fn knots_are_increasing() {
        assert!(VIRIDIS_KNOTS.windows(2).all(|w| w[0].0 < w[1].0));
        assert_eq!(VIRIDIS_KNOTS[VIRIDIS_KNOTS.len() - 1].0, 255);
    }
}
