//! False-colour PNG previews of 2D grids, for people to look at.
//!
//! [`write_false_colour`] maps each grid value through the perceptually uniform *viridis*
//! colour map ([`viridis`]), enlarges every bin to an integer number of pixels (so the
//! longer side of the map is about 600–800 pixels), puts grid row 0 at the bottom (`y` up)
//! and draws a vertical colour bar on the right labelled with its minimum, middle and
//! maximum values (the built-in 5×7 pixel font of the `font` module). Bins without a
//! meaningful value (NaN, infinite, or negative when the range starts at zero or above)
//! are drawn grey.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use anyhow::{Context, Result, ensure};

use super::colormap::viridis;
use super::font::{LABEL_CHARS, format_label, glyph};

/// The value range of a preview; `None` picks the default.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PreviewOptions {
    /// Value drawn with the darkest colour; default `0`.
    pub min: Option<f64>,
    /// Value drawn with the brightest colour; default: the largest finite value (or `min`
    /// if that is larger).
    pub max: Option<f64>,
    /// The grid's physical size (mm along x, along y): the map keeps its aspect ratio and
    /// gets axes with ticks in mm. None: square bins, no axes.
    pub extent_mm: Option<[f64; 2]>,
    /// The values' unit, written above the colour bar.
    pub unit: Option<&'static str>,
}

/// Colour of bins without a meaningful value.
const INVALID_GREY: [u8; 3] = [128, 128, 128];
const BACKGROUND: [u8; 3] = [255, 255, 255];
const FRAME: [u8; 3] = [64, 64, 64];
const INK: [u8; 3] = [0, 0, 0];

/// Blank border around everything, in pixels.
const MARGIN: usize = 14;
/// Space between the map and the colour bar.
const GAP: usize = 18;
/// Width of the colour bar.
const BAR_W: usize = 24;
/// Minimum height of the colour bar (short maps get a taller bar).
const BAR_MIN_H: usize = 120;
/// Length of the tick marks right of the bar.
const TICK: usize = 5;
/// Space between a tick and its label (wide enough not to read as a minus sign).
const LABEL_GAP: usize = 9;
/// Font magnification: each font pixel is a `FONT_SCALE²` block.
const FONT_SCALE: usize = 2;
/// Horizontal advance of one character (5 pixels + 1 pixel spacing).
const CHAR_W: usize = 6 * FONT_SCALE;
/// Height of one character.
const CHAR_H: usize = 7 * FONT_SCALE;
/// The longer side of the map is enlarged to at least this many pixels.
const TARGET_SIDE: usize = 600;

/// Write a false-colour preview of a `width × height` grid to the PNG file `path`
/// (overwriting it).
///
/// `values` is row-major (`x` fastest) with row 0 at the lowest `y`, drawn at the bottom of
/// the image. The colour range is `opts.min ..= opts.max` (defaults: `0` and the largest
/// finite value); values outside are clamped to the end colours. NaN and infinite values,
/// and negative values when the range starts at or above zero, are drawn grey. Each bin
/// becomes a square of `s × s` pixels with the integer `s ≥ 1` chosen so that the longer
/// side of the map is at least 600 pixels (and below 800 unless the grid is that large
/// already); a labelled colour bar is drawn on the right.
pub fn write_false_colour(
    path: &Path,
    width: usize,
    height: usize,
    values: &[f64],
    opts: &PreviewOptions,
) -> Result<()> {
    let what = || format!("cannot write PNG preview {}", path.display());
    let (lo, hi) = value_range(values, opts).with_context(what)?;
    let (w, h, rgb) = render(width, height, values, (lo, hi), opts).with_context(what)?;
    let comment = format!(
        "viridis false colour of a {width}x{height} grid, range {lo} to {hi}, \
         grid row 0 at the bottom, grey = no value"
    );
    encode(path, w, h, &rgb, &comment).with_context(what)
}

/// Encode `rgb` (8-bit RGB, `w × h`) as a PNG file with a `Comment` text chunk.
pub(crate) fn encode(path: &Path, w: u32, h: u32, rgb: &[u8], comment: &str) -> Result<()> {
    let file = File::create(path).context("cannot create file")?;
    let mut out = BufWriter::new(file);
    let mut encoder = ::png::Encoder::new(&mut out, w, h);
    encoder.set_color(::png::ColorType::Rgb);
    encoder.set_depth(::png::BitDepth::Eight);
    encoder.add_text_chunk("Software".to_string(), "blutrace".to_string())?;
    encoder.add_text_chunk("Comment".to_string(), comment.to_string())?;
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    out.flush().context("cannot flush file")?;
    Ok(())
}

/// The colour range `(lo, hi)` for `values` under `opts`.
fn value_range(values: &[f64], opts: &PreviewOptions) -> Result<(f64, f64)> {
    let lo = opts.min.unwrap_or(0.0);
    ensure!(lo.is_finite(), "preview minimum {lo} is not finite");
    let hi = match opts.max {
        Some(hi) => {
            ensure!(hi.is_finite(), "preview maximum {hi} is not finite");
            ensure!(hi >= lo, "preview maximum {hi} is below the minimum {lo}");
            hi
        }
        None => values
            .iter()
            .copied()
            .filter(|v| is_drawable(*v, lo))
            .fold(lo, f64::max),
    };
    Ok((lo, hi))
}

/// Whether `v` gets a colour (rather than grey) in a range starting at `lo`.
fn is_drawable(v: f64, lo: f64) -> bool {
    v.is_finite() && (v >= 0.0 || lo < 0.0)
}

/// Pixel geometry of a preview.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Layout {
    /// Pixels per bin along each axis.
    scale: usize,
    map_x: usize,
    map_y: usize,
    map_w: usize,
    map_h: usize,
    bar_x: usize,
    bar_y: usize,
    bar_h: usize,
    label_x: usize,
    image_w: usize,
    image_h: usize,
}

impl Layout {
    fn new(width: usize, height: usize, opts: &PreviewOptions) -> Self {
        let (map_w, map_h, scale) = match opts.extent_mm {
            // Physical aspect: the longer side TARGET_SIDE pixels, bins resampled.
            Some([ex, ey]) => {
                let long = ex.max(ey);
                let side = |e: f64| ((TARGET_SIDE as f64 * e / long).round() as usize).max(1);
                (side(ex), side(ey), 0)
            }
            None => {
                let scale = TARGET_SIDE.div_ceil(width.max(height)).max(1);
                (width * scale, height * scale, scale)
            }
        };
        let axes = opts.extent_mm.is_some();
        // Room for the y tick labels left of the map and the x ones below it.
        let left = if axes {
            AXIS_LABEL_CHARS * CHAR_W + TICK + LABEL_GAP
        } else {
            0
        };
        let below = if axes { TICK + 4 + CHAR_H } else { 0 };
        let unit_h = if opts.unit.is_some() { CHAR_H + 8 } else { 0 };
        let content_h = map_h.max(BAR_MIN_H);
        let map_x = MARGIN + left;
        let map_y = MARGIN + unit_h + (content_h - map_h) / 2;
        let bar_x = map_x + map_w + GAP;
        let bar_y = MARGIN + unit_h;
        let label_x = bar_x + BAR_W + TICK + LABEL_GAP;
        let image_w = label_x + LABEL_CHARS * CHAR_W + MARGIN;
        let image_h = MARGIN + unit_h + content_h + below + MARGIN;
        Self {
            scale,
            map_x,
            map_y,
            map_w,
            map_h,
            bar_x,
            bar_y,
            bar_h: content_h,
            label_x,
            image_w,
            image_h,
        }
    }
}

/// Characters kept for a mm tick label left of the map.
const AXIS_LABEL_CHARS: usize = 6;

/// Tick positions for `0..=range`: a step of 1, 2 or 5 times a power of ten giving about
/// five intervals, and the step.
fn mm_ticks(range: f64) -> (Vec<f64>, f64) {
    let raw = range / 5.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * mag);
    let n = (range / step + 1e-9).floor() as usize;
    ((0..=n).map(|k| k as f64 * step).collect(), step)
}

/// A tick label in mm with as many decimals as the step needs.
fn mm_label(v: f64, step: f64) -> String {
    let decimals = if step >= 1.0 {
        0
    } else {
        (-step.log10().floor()) as usize
    };
    format!("{v:.decimals$}")
}

/// An RGB canvas.
struct Canvas {
    w: usize,
    h: usize,
    rgb: Vec<u8>,
}

impl Canvas {
    fn new(w: usize, h: usize, fill: [u8; 3]) -> Self {
        Self {
            w,
            h,
            rgb: fill.repeat(w * h),
        }
    }

    /// Fill the rectangle `[x, x + w) × [y, y + h)` (clipped to the canvas).
    fn fill_rect(&mut self, x: usize, y: usize, w: usize, h: usize, c: [u8; 3]) {
        let (x1, y1) = ((x + w).min(self.w), (y + h).min(self.h));
        for yy in y.min(y1)..y1 {
            let row = yy * self.w;
            for xx in x.min(x1)..x1 {
                self.rgb[3 * (row + xx)..3 * (row + xx) + 3].copy_from_slice(&c);
            }
        }
    }

    /// A one-pixel frame just outside the rectangle `[x, x + w) × [y, y + h)`.
    fn frame(&mut self, x: usize, y: usize, w: usize, h: usize, c: [u8; 3]) {
        let (x0, y0) = (x.saturating_sub(1), y.saturating_sub(1));
        self.fill_rect(x0, y0, w + 2, 1, c);
        self.fill_rect(x0, y + h, w + 2, 1, c);
        self.fill_rect(x0, y0, 1, h + 2, c);
        self.fill_rect(x + w, y0, 1, h + 2, c);
    }

    /// Draw `text` with its top-left corner at `(x, y)`.
    fn text(&mut self, x: usize, y: usize, text: &str, c: [u8; 3]) {
        for (i, ch) in text.chars().enumerate() {
            let rows = glyph(ch);
            for (gy, bits) in rows.iter().enumerate() {
                for gx in 0..5 {
                    if bits & (0b10000 >> gx) != 0 {
                        self.fill_rect(
                            x + i * CHAR_W + gx * FONT_SCALE,
                            y + gy * FONT_SCALE,
                            FONT_SCALE,
                            FONT_SCALE,
                            c,
                        );
                    }
                }
            }
        }
    }
}

/// Render the preview: `(image width, image height, 8-bit RGB pixels)`.
/// `(lo, hi)` is the colour range from [`value_range`].
fn render(
    width: usize,
    height: usize,
    values: &[f64],
    (lo, hi): (f64, f64),
    opts: &PreviewOptions,
) -> Result<(u32, u32, Vec<u8>)> {
    ensure!(width > 0 && height > 0, "empty grid ({width} × {height})");
    let count = width
        .checked_mul(height)
        .with_context(|| format!("grid {width} × {height} is too large"))?;
    ensure!(
        values.len() == count,
        "{} values for a {width} × {height} grid (expected {count})",
        values.len()
    );
    ensure!(
        width <= 1 << 14 && height <= 1 << 14,
        "grid {width} × {height} is too large for a preview (at most 16384 bins per side)"
    );
    if let Some(e) = opts.extent_mm {
        ensure!(
            e.iter().all(|v| v.is_finite() && *v > 0.0),
            "preview extent {e:?} mm is not positive"
        );
    }
    let span = hi - lo;
    let colour = |v: f64| -> [u8; 3] {
        if !is_drawable(v, lo) {
            INVALID_GREY
        } else if span > 0.0 {
            viridis((v - lo) / span)
        } else {
            viridis(0.0)
        }
    };

    let l = Layout::new(width, height, opts);
    let mut canvas = Canvas::new(l.image_w, l.image_h, BACKGROUND);

    // The map, grid row 0 at the bottom: each pixel shows the bin it falls in.
    for py in 0..l.map_h {
        let gy = height - 1 - py * height / l.map_h;
        for px in 0..l.map_w {
            let gx = px * width / l.map_w;
            canvas.fill_rect(
                l.map_x + px,
                l.map_y + py,
                1,
                1,
                colour(values[gy * width + gx]),
            );
        }
    }
    canvas.frame(l.map_x, l.map_y, l.map_w, l.map_h, FRAME);
    if let Some([ex, ey]) = opts.extent_mm {
        draw_mm_axes(&mut canvas, &l, ex, ey);
    }

    // The colour bar, `hi` at the top, its unit above it.
    let denom = (l.bar_h - 1) as f64;
    for j in 0..l.bar_h {
        let t = 1.0 - j as f64 / denom;
        canvas.fill_rect(l.bar_x, l.bar_y + j, BAR_W, 1, viridis(t));
    }
    canvas.frame(l.bar_x, l.bar_y, BAR_W, l.bar_h, FRAME);
    if let Some(unit) = opts.unit {
        canvas.text(l.bar_x, l.bar_y - CHAR_H - 6, unit, INK);
    }

    // Ticks and labels at the top, middle and bottom of the bar.
    let ticks = [(0, hi), (l.bar_h / 2, 0.5 * (lo + hi)), (l.bar_h - 1, lo)];
    for (j, value) in ticks {
        let y = l.bar_y + j;
        canvas.fill_rect(l.bar_x + BAR_W + 1, y, TICK, 1, FRAME);
        let top = (y + 1).saturating_sub(CHAR_H / 2);
        canvas.text(l.label_x, top, &format_label(value), INK);
    }

    let w = u32::try_from(l.image_w).context("preview too wide")?;
    let h = u32::try_from(l.image_h).context("preview too tall")?;
    Ok((w, h, canvas.rgb))
}

/// Ticks in mm below the map (x) and left of it (y), labelled from 0 at the lower left.
fn draw_mm_axes(canvas: &mut Canvas, l: &Layout, ex: f64, ey: f64) {
    let (xt, xs) = mm_ticks(ex);
    for v in xt {
        let px = l.map_x + ((v / ex) * (l.map_w - 1) as f64).round() as usize;
        canvas.fill_rect(px, l.map_y + l.map_h + 1, 1, TICK, FRAME);
        let label = mm_label(v, xs);
        let x = px.saturating_sub(label.len() * CHAR_W / 2);
        canvas.text(x, l.map_y + l.map_h + TICK + 4, &label, INK);
    }
    // The unit, in the free corner below the y labels and left of the x ones.
    canvas.text(MARGIN, l.map_y + l.map_h + TICK + 4, "mm", INK);
    let (yt, ys) = mm_ticks(ey);
    for v in yt {
        let py = l.map_y + l.map_h - 1 - ((v / ey) * (l.map_h - 1) as f64).round() as usize;
        canvas.fill_rect(l.map_x - 1 - TICK, py, TICK, 1, FRAME);
        let label = mm_label(v, ys);
        let x = (l.map_x - 1 - TICK - LABEL_GAP / 2).saturating_sub(label.len() * CHAR_W);
        canvas.text(x, (py + 1).saturating_sub(CHAR_H / 2), &label, INK);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::test_png::{TempFile, decode, preview_path};

    fn pixel(img: &(u32, u32, Vec<u8>), x: usize, y: usize) -> [u8; 3] {
        let i = 3 * (y * img.0 as usize + x);
        [img.2[i], img.2[i + 1], img.2[i + 2]]
    }

    #[test]
    fn png_has_expected_size_and_orientation() {
        let (w, h) = (40, 20);
        // value = grid row (y), with a NaN and a negative value in the top row.
        let mut v: Vec<f64> = (0..w * h).map(|i| (i / w) as f64).collect();
        v[(h - 1) * w] = f64::NAN;
        v[(h - 1) * w + 1] = -1.0;
        let f = TempFile::new("size");
        write_false_colour(&f.0, w, h, &v, &PreviewOptions::default()).unwrap();
        let img = decode(&f.0);

        let l = Layout::new(w, h, &PreviewOptions::default());
        assert_eq!(l.scale, 15);
        assert_eq!((l.map_w, l.map_h), (600, 300));
        assert_eq!((img.0 as usize, img.1 as usize), (l.image_w, l.image_h));
        assert!((600..=1000).contains(&img.0), "{}", img.0);

        let s = l.scale;
        let bottom_left = pixel(&img, l.map_x + s / 2, l.map_y + l.map_h - 1 - s / 2);
        assert_eq!(bottom_left, viridis(0.0));
        let top_right = pixel(&img, l.map_x + l.map_w - 1, l.map_y);
        assert_eq!(top_right, viridis(1.0));
        assert_eq!(pixel(&img, l.map_x, l.map_y), INVALID_GREY);
        assert_eq!(pixel(&img, l.map_x + s, l.map_y), INVALID_GREY);
        // Colour bar: max at the top, min at the bottom.
        assert_eq!(pixel(&img, l.bar_x + 1, l.bar_y), viridis(1.0));
        assert_eq!(
            pixel(&img, l.bar_x + 1, l.bar_y + l.bar_h - 1),
            viridis(0.0)
        );
    }

    #[test]
    fn explicit_range_and_layout_of_odd_grids() {
        let f = TempFile::new("range");
        let v = [-1.0, 0.0, 0.5, 1.0, 2.0, f64::INFINITY];
        let opts = PreviewOptions {
            min: Some(-1.0),
            max: Some(1.0),
            ..PreviewOptions::default()
        };
        write_false_colour(&f.0, 3, 2, &v, &opts).unwrap();
        let img = decode(&f.0);
        let l = Layout::new(3, 2, &opts);
        assert_eq!(l.scale, 200);
        let s = l.scale;
        // Grid row 0 (-1, 0, 0.5) at the bottom; negative values are valid with min < 0.
        assert_eq!(pixel(&img, l.map_x, l.map_y + s), viridis(0.0));
        assert_eq!(pixel(&img, l.map_x + s, l.map_y + s), viridis(0.5));
        assert_eq!(pixel(&img, l.map_x + s, l.map_y), viridis(1.0)); // 2.0 clamped
        assert_eq!(pixel(&img, l.map_x + 2 * s, l.map_y), INVALID_GREY); // +inf

        for (w, h) in [(1, 1), (1000, 3), (3, 1000), (799, 800), (301, 1)] {
            let l = Layout::new(w, h, &PreviewOptions::default());
            let side = l.map_w.max(l.map_h);
            assert!(
                side >= 600.min(w.max(h)) && (side < 800 || l.scale == 1),
                "{w}x{h}"
            );
        }
    }

    #[test]
    fn invalid_input_is_an_error() {
        let f = TempFile::new("bad");
        let d = PreviewOptions::default();
        assert!(write_false_colour(&f.0, 2, 2, &[0.0; 3], &d).is_err());
        assert!(write_false_colour(&f.0, 0, 2, &[], &d).is_err());
        let bad = PreviewOptions {
            min: Some(2.0),
            max: Some(1.0),
            ..PreviewOptions::default()
        };
        assert!(write_false_colour(&f.0, 1, 1, &[0.0], &bad).is_err());
        let bad = PreviewOptions {
            min: Some(f64::NAN),
            max: None,
            ..PreviewOptions::default()
        };
        assert!(write_false_colour(&f.0, 1, 1, &[0.0], &bad).is_err());
        assert!(!f.0.exists());
        // All-zero or all-invalid data still gives an image.
        write_false_colour(&f.0, 2, 1, &[0.0, 0.0], &d).unwrap();
        write_false_colour(&f.0, 2, 1, &[f64::NAN, -3.0], &d).unwrap();
    }

    #[test]
    #[ignore = "writes blutrace_preview_*.png to the temporary folder for a visual check"]
    fn demo_preview() {
        let (w, h) = (64, 40);
        let mut v: Vec<f64> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64, (i / w) as f64);
                1e-3 * (x + 2.0 * y)
            })
            .collect();
        v[0] = f64::NAN; // bottom-left bin grey
        write_false_colour(
            &preview_path("blutrace_preview_demo.png"),
            w,
            h,
            &v,
            &PreviewOptions::default(),
        )
        .unwrap();
        let small: Vec<f64> = (0..15).map(|i| (i as f64 - 2.0) * 2.5e-7).collect();
        let opts = PreviewOptions {
            min: Some(-5e-7),
            max: None,
            ..PreviewOptions::default()
        };
        write_false_colour(
            &preview_path("blutrace_preview_small.png"),
            5,
            3,
            &small,
            &opts,
        )
        .unwrap();
    }

    #[test]
    fn physical_previews_keep_the_aspect_ratio_and_label_mm() {
        assert_eq!(mm_ticks(290.0), (vec![0.0, 100.0, 200.0], 100.0));
        assert_eq!(mm_ticks(215.0).1, 50.0);
        assert_eq!(mm_ticks(0.6).1, 0.2);
        assert_eq!(mm_label(0.4, 0.2), "0.4");
        assert_eq!(mm_label(150.0, 50.0), "150");
        let opts = PreviewOptions {
            extent_mm: Some([290.0, 215.0]),
            unit: Some("W/mm^2"),
            ..PreviewOptions::default()
        };
        // A 100 x 100 grid of a 290 x 215 mm target: the map is 290:215, not square.
        let l = Layout::new(100, 100, &opts);
        assert_eq!(l.map_w, TARGET_SIDE);
        assert_eq!(
            l.map_h,
            (TARGET_SIDE as f64 * 215.0 / 290.0).round() as usize
        );
        let f = TempFile::new("physical");
        let values: Vec<f64> = (0..100 * 100).map(|i| (i % 100) as f64).collect();
        write_false_colour(&f.0, 100, 100, &values, &opts).unwrap();
        let img = decode(&f.0);
        assert_eq!(img.0 as usize, l.image_w);
        // Left of the map is the brightest x = 0 column's opposite: the map's left edge
        // shows column 0 (value 0, darkest), its right edge column 99 (brightest).
        let y = l.map_y + l.map_h / 2;
        assert_eq!(pixel(&img, l.map_x, y), viridis(0.0));
        assert_eq!(pixel(&img, l.map_x + l.map_w - 1, y), viridis(1.0));
    }
}
