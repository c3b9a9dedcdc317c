//! What the PNG charts and maps share: the embedded font, the colour map, the palette,
//! number labels, and drawing with `plotters` into an RGB buffer (which `png` encodes).
//!
//! Text is drawn with DejaVu Sans, embedded in the binary (the `dejavu` crate), so a
//! machine without any system font draws the same pixels: nothing is looked up at run
//! time. The font is registered with `plotters` once, under the family `sans-serif`
//! that `plotters` uses by default.
//!
//! Every figure is drawn into an RGB buffer on one thread, with no clock, locale or
//! system font involved, so the same inputs give the same bytes.

use std::sync::Once;

use anyhow::{Result, anyhow};
use plotters::prelude::*;
use plotters::style::{FontStyle, RGBColor, register_font};

/// The drawing area a figure is drawn on: an RGB buffer, pixel coordinates.
pub(crate) type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// The family name the font is registered under (the `plotters` default family).
pub(crate) const FONT: &str = "sans-serif";
/// Font size (pixels) of titles.
pub(crate) const TITLE_SIZE: f64 = 22.0;
/// Font size of axis descriptions (and legends).
pub(crate) const DESC_SIZE: f64 = 17.0;
/// Font size of tick labels.
pub(crate) const LABEL_SIZE: f64 = 15.0;

/// Colour of bins without a meaningful value.
pub(crate) const INVALID_GREY: RGBColor = RGBColor(128, 128, 128);
/// Colour of frames and tick marks.
pub(crate) const FRAME: RGBColor = RGBColor(64, 64, 64);

/// Register the embedded font with `plotters` (once per process).
///
/// DejaVu Sans 2.37 from the `dejavu` crate. Licence of the font: the Bitstream Vera
/// Fonts licence with the DejaVu changes in the public domain (a permissive licence that
/// allows embedding and redistribution; `assets/dejavu-fonts-ttf-2.37/LICENSE` in that
/// crate); the crate itself is MIT or Apache-2.0.
fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid TrueType font (tested by `font_draws_text`); a failure
        // here would leave text out of the figures, which the tests catch.
        let _ = register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
    });
}

/// A text style of the embedded font at `size` pixels.
pub(crate) fn text(size: f64) -> TextStyle<'static> {
    register_fonts();
    (FONT, size).into_font().color(&BLACK)
}

/// The viridis colour map (`colorous::VIRIDIS`) at `t`, clamped to `0..=1`; NaN counts
/// as 0.
pub fn viridis(t: f64) -> RGBColor {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let c = colorous::VIRIDIS.eval_continuous(t);
    RGBColor(c.r, c.g, c.b)
}

/// Colour `i` of the Tableau 10 palette (repeating after 10), for the lines of charts.
pub(crate) fn series_colour(i: usize) -> RGBColor {
    let c = colorous::TABLEAU10[i % colorous::TABLEAU10.len()];
    RGBColor(c.r, c.g, c.b)
}

/// A short number label: plain with up to four significant digits in `1e-3..1e5`, else
/// scientific (`2.5e-7`), trailing zeros dropped.
pub(crate) fn format_label(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        return "0".into();
    }
    let trim = |s: &str| -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s.to_string()
        }
    };
    if (1e-3..1e5).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        return trim(&format!("{v:.decimals$}"));
    }
    let s = format!("{v:.2e}");
    match s.split_once('e') {
        Some((mantissa, exp)) => format!("{}e{exp}", trim(mantissa)),
        None => s,
    }
}

/// `n` with its digits in groups of three: `12,500,000`.
pub fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Pixel width of `s` in `style`.
pub(crate) fn text_width(area: &Area, s: &str, style: &TextStyle) -> u32 {
    area.estimate_text_size(s, style).map_or(0, |(w, _)| w)
}

/// Draw a `w × h` pixel figure on a white background: 8-bit RGB pixels.
pub(crate) fn render(
    (w, h): (u32, u32),
    draw: impl FnOnce(&Area) -> Result<()>,
) -> Result<Vec<u8>> {
    register_fonts();
    let mut rgb = vec![255u8; 3 * w as usize * h as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        draw(&root)?;
        root.present()
            .map_err(|e| anyhow!("cannot draw the figure: {e}"))?;
    }
    Ok(rgb)
}

/// Turn a `plotters` drawing error into an `anyhow` one.
pub(crate) fn drawing<E: std::error::Error + Send + Sync>(
    e: DrawingAreaErrorKind<E>,
) -> anyhow::Error {
    anyhow!("cannot draw the figure: {e}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn font_draws_text() {
        let rgb = render((120, 40), |a| {
            a.draw_text("Wmm 123", &text(20.0), (5, 5)).map_err(drawing)
        })
        .unwrap();
        let dark = rgb.chunks(3).filter(|p| p[0] < 128).count();
        assert!(dark > 50, "only {dark} dark pixels: the font drew nothing");
        let area_w = render((10, 10), |a| {
            let s = text(20.0);
            assert!(text_width(a, "WWWW", &s) > text_width(a, "ii", &s));
            assert!(text_width(a, "ii", &s) > 0);
            Ok(())
        });
        area_w.unwrap();
    }

    #[test]
    fn viridis_is_the_reference_map() {
        // matplotlib's viridis at 0, 0.5 and 1 (8-bit).
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        let RGBColor(r, g, b) = viridis(0.5);
        assert!(r.abs_diff(33) <= 1 && g.abs_diff(145) <= 1 && b.abs_diff(140) <= 1);
        assert_eq!(viridis(f64::NAN), viridis(-1.0));
        assert_eq!(viridis(2.0), viridis(1.0));
    }

    #[test]
    fn labels_are_short() {
        assert_eq!(format_label(0.0), "0");
        assert_eq!(format_label(0.5), "0.5");
        assert_eq!(format_label(150.0), "150");
        assert_eq!(format_label(0.0125), "0.0125");
        assert_eq!(format_label(2.5e-7), "2.5e-7");
        assert_eq!(format_label(-1e6), "-1e6");
        assert_eq!(format_label(1.23456e-4), "1.23e-4");
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(1000), "1,000");
        assert_eq!(thousands(12_500_000), "12,500,000");
    }
}
