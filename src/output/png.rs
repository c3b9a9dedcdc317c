//! False-colour PNG previews of 2D grids, for people to look at.
//!
//! [`write_false_colour`] maps each grid value through the perceptually uniform *viridis*
//! colour map ([`viridis`]), enlarges every bin to an integer number of pixels (so the
//! longer side of the map is about 600–800 pixels), puts grid row 0 at the bottom (`y` up)
//! and draws a vertical colour bar on the right labelled with its minimum, middle and
//! maximum values (a built-in 5×7 pixel font). Bins without a meaningful value (NaN,
//! infinite, or negative when the range starts at zero or above) are drawn grey.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use anyhow::{Context, Result, ensure};

/// The value range of a preview; `None` picks the default.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PreviewOptions {
    /// Value drawn with the darkest colour; default `0`.
    pub min: Option<f64>,
    /// Value drawn with the brightest colour; default: the largest finite value (or `min`
    /// if that is larger).
    pub max: Option<f64>,
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
/// Labels are at most this many characters long (see [`format_label`]).
const LABEL_CHARS: usize = 10;
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
    let (w, h, rgb) = render(width, height, values, lo, hi).with_context(what)?;
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
    fn new(width: usize, height: usize) -> Self {
        let longest = width.max(height);
        let scale = TARGET_SIDE.div_ceil(longest).max(1);
        let (map_w, map_h) = (width * scale, height * scale);
        let content_h = map_h.max(BAR_MIN_H);
        let map_x = MARGIN;
        let map_y = MARGIN + (content_h - map_h) / 2;
        let bar_x = map_x + map_w + GAP;
        let bar_y = MARGIN;
        let label_x = bar_x + BAR_W + TICK + LABEL_GAP;
        let image_w = label_x + LABEL_CHARS * CHAR_W + MARGIN;
        let image_h = MARGIN + content_h + MARGIN;
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
/// `lo..=hi` is the colour range from [`value_range`].
fn render(
    width: usize,
    height: usize,
    values: &[f64],
    lo: f64,
    hi: f64,
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

    let l = Layout::new(width, height);
    let mut canvas = Canvas::new(l.image_w, l.image_h, BACKGROUND);

    // The map, grid row 0 at the bottom.
    for (gy, row) in values.chunks_exact(width).enumerate() {
        let py = l.map_y + (height - 1 - gy) * l.scale;
        for (gx, &v) in row.iter().enumerate() {
            canvas.fill_rect(l.map_x + gx * l.scale, py, l.scale, l.scale, colour(v));
        }
    }
    canvas.frame(l.map_x, l.map_y, l.map_w, l.map_h, FRAME);

    // The colour bar, `hi` at the top.
    let denom = (l.bar_h - 1) as f64;
    for j in 0..l.bar_h {
        let t = 1.0 - j as f64 / denom;
        canvas.fill_rect(l.bar_x, l.bar_y + j, BAR_W, 1, viridis(t));
    }
    canvas.frame(l.bar_x, l.bar_y, BAR_W, l.bar_h, FRAME);

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

/// A short label for `v`: at most [`LABEL_CHARS`] characters, up to 4 significant digits.
pub(crate) fn format_label(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        return "0".to_string();
    }
    if (1e-3..1e5).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        let s = format!("{v:.decimals$}");
        let s = if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.')
        } else {
            &s
        };
        return s.to_string();
    }
    // Scientific notation, dropping digits if the exponent is long (e.g. `-1.2e-300`).
    let mut label = String::new();
    for precision in (0..=3).rev() {
        let s = format!("{v:.precision$e}");
        label = match s.split_once('e') {
            Some((mantissa, exp)) if mantissa.contains('.') => {
                format!(
                    "{}e{exp}",
                    mantissa.trim_end_matches('0').trim_end_matches('.')
                )
            }
            _ => s,
        };
        if label.len() <= LABEL_CHARS {
            break;
        }
    }
    label
}

/// A 5×7 bitmap glyph, one byte per row from the top, bit 4 = leftmost pixel. Covers the
/// ASCII letters, the digits, space and `. , - + / ( ) [ ] % = : ; _ ' * ^ < > ! ? | ~`;
/// anything else is blank. The glyphs of [`descends`] letters are to be drawn one row
/// lower than the others.
pub(crate) fn glyph(c: char) -> [u8; 7] {
    match c {
        '0' => [
            0b01110, 0b10001, 0b10011, 0b10101, 0b11001, 0b10001, 0b01110,
        ],
        '1' => [
            0b00100, 0b01100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110,
        ],
        '2' => [
            0b01110, 0b10001, 0b00001, 0b00010, 0b00100, 0b01000, 0b11111,
        ],
        '3' => [
            0b11111, 0b00010, 0b00100, 0b00010, 0b00001, 0b10001, 0b01110,
        ],
        '4' => [
            0b00010, 0b00110, 0b01010, 0b10010, 0b11111, 0b00010, 0b00010,
        ],
        '5' => [
            0b11111, 0b10000, 0b11110, 0b00001, 0b00001, 0b10001, 0b01110,
        ],
        '6' => [
            0b00110, 0b01000, 0b10000, 0b11110, 0b10001, 0b10001, 0b01110,
        ],
        '7' => [
            0b11111, 0b00001, 0b00010, 0b00100, 0b01000, 0b01000, 0b01000,
        ],
        '8' => [
            0b01110, 0b10001, 0b10001, 0b01110, 0b10001, 0b10001, 0b01110,
        ],
        '9' => [
            0b01110, 0b10001, 0b10001, 0b01111, 0b00001, 0b00010, 0b01100,
        ],
        '.' => [0, 0, 0, 0, 0, 0b01100, 0b01100],
        '-' => [0, 0, 0, 0b11111, 0, 0, 0],
        '+' => [0, 0b00100, 0b00100, 0b11111, 0b00100, 0b00100, 0],
        'e' => [0, 0, 0b01110, 0b10001, 0b11111, 0b10000, 0b01110],
        'A' => [
            0b01110, 0b10001, 0b10001, 0b10001, 0b11111, 0b10001, 0b10001,
        ],
        'B' => [
            0b11110, 0b10001, 0b10001, 0b11110, 0b10001, 0b10001, 0b11110,
        ],
        'C' => [
            0b01110, 0b10001, 0b10000, 0b10000, 0b10000, 0b10001, 0b01110,
        ],
        'D' => [
            0b11100, 0b10010, 0b10001, 0b10001, 0b10001, 0b10010, 0b11100,
        ],
        'E' => [
            0b11111, 0b10000, 0b10000, 0b11110, 0b10000, 0b10000, 0b11111,
        ],
        'F' => [
            0b11111, 0b10000, 0b10000, 0b11110, 0b10000, 0b10000, 0b10000,
        ],
        'G' => [
            0b01110, 0b10001, 0b10000, 0b10111, 0b10001, 0b10001, 0b01111,
        ],
        'H' => [
            0b10001, 0b10001, 0b10001, 0b11111, 0b10001, 0b10001, 0b10001,
        ],
        'I' => [
            0b01110, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110,
        ],
        'J' => [
            0b00111, 0b00010, 0b00010, 0b00010, 0b00010, 0b10010, 0b01100,
        ],
        'K' => [
            0b10001, 0b10010, 0b10100, 0b11000, 0b10100, 0b10010, 0b10001,
        ],
        'L' => [
            0b10000, 0b10000, 0b10000, 0b10000, 0b10000, 0b10000, 0b11111,
        ],
        'M' => [
            0b10001, 0b11011, 0b10101, 0b10101, 0b10001, 0b10001, 0b10001,
        ],
        'N' => [
            0b10001, 0b10001, 0b11001, 0b10101, 0b10011, 0b10001, 0b10001,
        ],
        'O' => [
            0b01110, 0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b01110,
        ],
        'P' => [
            0b11110, 0b10001, 0b10001, 0b11110, 0b10000, 0b10000, 0b10000,
        ],
        'Q' => [
            0b01110, 0b10001, 0b10001, 0b10001, 0b10101, 0b10010, 0b01101,
        ],
        'R' => [
            0b11110, 0b10001, 0b10001, 0b11110, 0b10100, 0b10010, 0b10001,
        ],
        'S' => [
            0b01111, 0b10000, 0b10000, 0b01110, 0b00001, 0b00001, 0b11110,
        ],
        'T' => [
            0b11111, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100,
        ],
        'U' => [
            0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b01110,
        ],
        'V' => [
            0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b01010, 0b00100,
        ],
        'W' => [
            0b10001, 0b10001, 0b10001, 0b10101, 0b10101, 0b10101, 0b01010,
        ],
        'X' => [
            0b10001, 0b10001, 0b01010, 0b00100, 0b01010, 0b10001, 0b10001,
        ],
        'Y' => [
            0b10001, 0b10001, 0b10001, 0b01010, 0b00100, 0b00100, 0b00100,
        ],
        'Z' => [
            0b11111, 0b00001, 0b00010, 0b00100, 0b01000, 0b10000, 0b11111,
        ],
        'a' => [0, 0, 0b01110, 0b00001, 0b01111, 0b10001, 0b01111],
        'b' => [
            0b10000, 0b10000, 0b10110, 0b11001, 0b10001, 0b10001, 0b11110,
        ],
        'c' => [0, 0, 0b01110, 0b10000, 0b10000, 0b10001, 0b01110],
        'd' => [
            0b00001, 0b00001, 0b01101, 0b10011, 0b10001, 0b10001, 0b01111,
        ],
        'f' => [
            0b00110, 0b01001, 0b01000, 0b11100, 0b01000, 0b01000, 0b01000,
        ],
        'g' => [0, 0b01111, 0b10001, 0b10001, 0b01111, 0b00001, 0b01110],
        'h' => [
            0b10000, 0b10000, 0b10110, 0b11001, 0b10001, 0b10001, 0b10001,
        ],
        'i' => [0b00100, 0, 0b01100, 0b00100, 0b00100, 0b00100, 0b01110],
        'j' => [0b00010, 0, 0b00110, 0b00010, 0b00010, 0b10010, 0b01100],
        'k' => [
            0b10000, 0b10000, 0b10010, 0b10100, 0b11000, 0b10100, 0b10010,
        ],
        'l' => [
            0b01100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110,
        ],
        'm' => [0, 0, 0b11010, 0b10101, 0b10101, 0b10001, 0b10001],
        'n' => [0, 0, 0b10110, 0b11001, 0b10001, 0b10001, 0b10001],
        'o' => [0, 0, 0b01110, 0b10001, 0b10001, 0b10001, 0b01110],
        'p' => [0, 0b11110, 0b10001, 0b10001, 0b11110, 0b10000, 0b10000],
        'q' => [0, 0b01111, 0b10001, 0b10001, 0b01111, 0b00001, 0b00001],
        'r' => [0, 0, 0b10110, 0b11001, 0b10000, 0b10000, 0b10000],
        's' => [0, 0, 0b01110, 0b10000, 0b01110, 0b00001, 0b11110],
        't' => [
            0b01000, 0b01000, 0b11100, 0b01000, 0b01000, 0b01001, 0b00110,
        ],
        'u' => [0, 0, 0b10001, 0b10001, 0b10001, 0b10011, 0b01101],
        'v' => [0, 0, 0b10001, 0b10001, 0b10001, 0b01010, 0b00100],
        'w' => [0, 0, 0b10001, 0b10001, 0b10101, 0b10101, 0b01010],
        'x' => [0, 0, 0b10001, 0b01010, 0b00100, 0b01010, 0b10001],
        'y' => [0, 0b10001, 0b10001, 0b10001, 0b01111, 0b00001, 0b01110],
        'z' => [0, 0, 0b11111, 0b00010, 0b00100, 0b01000, 0b11111],
        ',' => [0, 0, 0, 0, 0b01100, 0b00100, 0b01000],
        '/' => [0, 0b00001, 0b00010, 0b00100, 0b01000, 0b10000, 0],
        '(' => [
            0b00010, 0b00100, 0b01000, 0b01000, 0b01000, 0b00100, 0b00010,
        ],
        ')' => [
            0b01000, 0b00100, 0b00010, 0b00010, 0b00010, 0b00100, 0b01000,
        ],
        '[' => [
            0b01110, 0b01000, 0b01000, 0b01000, 0b01000, 0b01000, 0b01110,
        ],
        ']' => [
            0b01110, 0b00010, 0b00010, 0b00010, 0b00010, 0b00010, 0b01110,
        ],
        '%' => [
            0b11000, 0b11001, 0b00010, 0b00100, 0b01000, 0b10011, 0b00011,
        ],
        '=' => [0, 0, 0b11111, 0, 0b11111, 0, 0],
        ':' => [0, 0b01100, 0b01100, 0, 0b01100, 0b01100, 0],
        ';' => [0, 0b01100, 0b01100, 0, 0b01100, 0b00100, 0b01000],
        '_' => [0, 0, 0, 0, 0, 0, 0b11111],
        '\'' => [0b01100, 0b00100, 0b01000, 0, 0, 0, 0],
        '*' => [0, 0b00100, 0b10101, 0b01110, 0b10101, 0b00100, 0],
        '^' => [0b00100, 0b01010, 0b10001, 0, 0, 0, 0],
        '<' => [
            0b00010, 0b00100, 0b01000, 0b10000, 0b01000, 0b00100, 0b00010,
        ],
        '>' => [
            0b01000, 0b00100, 0b00010, 0b00001, 0b00010, 0b00100, 0b01000,
        ],
        '!' => [0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0, 0b00100],
        '?' => [0b01110, 0b10001, 0b00001, 0b00010, 0b00100, 0, 0b00100],
        '|' => [
            0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100,
        ],
        '~' => [0, 0, 0b01000, 0b10101, 0b00010, 0, 0],
        _ => [0; 7],
    }
}

/// Whether the [`glyph`] of `c` hangs one row below the baseline (`g`, `p`, `q`, `y`): it
/// is to be drawn one font row lower than the others, which needs an 8th row below the cell.
pub(crate) fn descends(c: char) -> bool {
    matches!(c, 'g' | 'p' | 'q' | 'y')
}

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
    use std::path::PathBuf;

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

    struct TempFile(PathBuf);

    impl TempFile {
        fn new(tag: &str) -> Self {
            use std::sync::atomic::{AtomicU32, Ordering};
            static N: AtomicU32 = AtomicU32::new(0);
            let n = N.fetch_add(1, Ordering::Relaxed);
            Self(
                std::env::temp_dir()
                    .join(format!("blutrace-png-{tag}-{}-{n}.png", std::process::id())),
            )
        }
    }

    impl Drop for TempFile {
        fn drop(&mut self) {
            let _ = std::fs::remove_file(&self.0);
        }
    }

    /// Decode an 8-bit RGB PNG: `(width, height, pixels)`.
    fn decode(path: &Path) -> (u32, u32, Vec<u8>) {
        let file = std::io::BufReader::new(File::open(path).unwrap());
        let mut reader = ::png::Decoder::new(file).read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(info.color_type, ::png::ColorType::Rgb);
        assert_eq!(info.bit_depth, ::png::BitDepth::Eight);
        buf.truncate(info.buffer_size());
        (info.width, info.height, buf)
    }

    fn pixel(img: &(u32, u32, Vec<u8>), x: usize, y: usize) -> [u8; 3] {
        let i = 3 * (y * img.0 as usize + x);
        [img.2[i], img.2[i + 1], img.2[i + 2]]
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

        let l = Layout::new(w, h);
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
        };
        write_false_colour(&f.0, 3, 2, &v, &opts).unwrap();
        let img = decode(&f.0);
        let l = Layout::new(3, 2);
        assert_eq!(l.scale, 200);
        let s = l.scale;
        // Grid row 0 (-1, 0, 0.5) at the bottom; negative values are valid with min < 0.
        assert_eq!(pixel(&img, l.map_x, l.map_y + s), viridis(0.0));
        assert_eq!(pixel(&img, l.map_x + s, l.map_y + s), viridis(0.5));
        assert_eq!(pixel(&img, l.map_x + s, l.map_y), viridis(1.0)); // 2.0 clamped
        assert_eq!(pixel(&img, l.map_x + 2 * s, l.map_y), INVALID_GREY); // +inf

        for (w, h) in [(1, 1), (1000, 3), (3, 1000), (799, 800), (301, 1)] {
            let l = Layout::new(w, h);
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
        };
        assert!(write_false_colour(&f.0, 1, 1, &[0.0], &bad).is_err());
        let bad = PreviewOptions {
            min: Some(f64::NAN),
            max: None,
        };
        assert!(write_false_colour(&f.0, 1, 1, &[0.0], &bad).is_err());
        assert!(!f.0.exists());
        // All-zero or all-invalid data still gives an image.
        write_false_colour(&f.0, 2, 1, &[0.0, 0.0], &d).unwrap();
        write_false_colour(&f.0, 2, 1, &[f64::NAN, -3.0], &d).unwrap();
    }

    #[test]
    fn labels_are_short() {
        for (v, s) in [
            (0.0, "0"),
            (1.0, "1"),
            (0.5, "0.5"),
            (123.456, "123.5"),
            (-0.001234, "-0.001234"),
            (12345.0, "12345"),
            (1e10, "1e10"),
            (-1.23456e-10, "-1.235e-10"),
        ] {
            assert_eq!(format_label(v), s);
        }
        for i in -300..300 {
            let v = -7.777_777_7 * 10f64.powi(i);
            assert!(format_label(v).len() <= LABEL_CHARS, "{}", format_label(v));
        }
    }

    #[test]
    #[ignore = "writes /tmp/blutrace_preview_*.png for a visual check"]
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
            Path::new("/tmp/blutrace_preview_demo.png"),
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
        };
        write_false_colour(
            Path::new("/tmp/blutrace_preview_small.png"),
            5,
            3,
            &small,
            &opts,
        )
        .unwrap();
    }
}
