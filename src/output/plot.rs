//! Line charts as PNG images, for people to look at.
//!
//! [`write_chart`] draws a [`Chart`] — a few [`Series`] of `(x, y)` points — as an
//! 800×560 pixel PNG: white background, a framed plot area with light grid lines, numeric
//! tick labels, axis labels, a title and a legend, all written with the built-in 5×7 pixel
//! font of [`super::png`]. Each axis is linear or logarithmic ([`Scale`]); its range is
//! chosen automatically from the data with a small margin.
//!
//! - Linear axes get about 5 (3–7) "nice" ticks: multiples of 1, 2, 2.5 or 5 times a power
//!   of ten.
//! - Logarithmic axes get ticks at powers of ten labelled like `1e-3` (only every n-th
//!   power when there are many) and always show at least two of them. Up to 6 decades get
//!   minor ticks at 2–9 times a power of ten; up to 2.5 decades get labels at 2 and 5
//!   times a power of ten too (`2e-3`, `5e-3`).
//! - Series are drawn as 2 pixel wide polylines (optionally dashed, optionally with a
//!   marker at every point) in the colours of the Tableau 10 palette, in order. Markers
//!   also differ in shape between series.
//! - Points with a non-finite coordinate, or a non-positive one on a logarithmic axis, are
//!   skipped, and the line is interrupted there; a point left alone gets a marker.
//! - A single point or a constant coordinate gets a range of ±10 % of the value (±1 around
//!   zero) on a linear axis, and ±½ decade on a logarithmic one.
//! - The legend goes into the corner of the plot area that hides the least data.

use std::path::Path;

use anyhow::{Context, Result, bail, ensure};

use super::png::{descends, encode, format_label, glyph};

/// How an axis maps data values to positions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Scale {
    /// Positions proportional to the value.
    #[default]
    Linear,
    /// Positions proportional to `log10` of the value; only positive values are drawn.
    Log10,
}

/// One line of a [`Chart`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Series {
    /// Name shown in the legend; series with an empty label are left out of the legend.
    pub label: String,
    /// `(x, y)` data points, joined by straight lines in this order.
    pub points: Vec<(f64, f64)>,
    /// Draw a dashed rather than a solid line.
    pub dashed: bool,
    /// Draw a marker at every point.
    pub markers: bool,
}

impl Series {
    /// A solid line without markers.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            points,
            dashed: false,
            markers: false,
        }
    }
}

/// A line chart: title, axes and the series to draw (in order, later ones on top).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Chart {
    /// Text above the plot.
    pub title: String,
    /// Label below the horizontal axis.
    pub x_label: String,
    /// Label left of the vertical axis (written bottom to top).
    pub y_label: String,
    /// Scale of the horizontal axis.
    pub x_scale: Scale,
    /// Scale of the vertical axis.
    pub y_scale: Scale,
    /// The lines; series `i` gets colour `i` of the Tableau 10 palette (repeating after 10).
    pub series: Vec<Series>,
}

/// Write `chart` as an 800×560 pixel PNG file to `path` (overwriting it).
///
/// Fails, without creating the file, if the chart has no series or no drawable point (all
/// points non-finite or, on a logarithmic axis, not positive), or if a linear axis range
/// is too wide to represent (beyond `±f64::MAX`).
pub fn write_chart(path: &Path, chart: &Chart) -> Result<()> {
    let what = || format!("cannot write chart {}", path.display());
    let r = render(chart).with_context(what)?;
    let labels: Vec<&str> = chart.series.iter().map(|s| s.label.as_str()).collect();
    let comment = format!(
        "line chart {:?}: x = {:?} ({:?}), y = {:?} ({:?}); series: {}",
        chart.title,
        chart.x_label,
        chart.x_scale,
        chart.y_label,
        chart.y_scale,
        labels.join(", ")
    );
    encode(path, r.width as u32, r.height as u32, &r.rgb, &comment).with_context(what)
}

/// Image size in pixels.
const WIDTH: i64 = 800;
const HEIGHT: i64 = 560;

const BACKGROUND: [u8; 3] = [255, 255, 255];
const INK: [u8; 3] = [0, 0, 0];
const FRAME: [u8; 3] = [64, 64, 64];
const GRID_MAJOR: [u8; 3] = [222, 222, 222];
const GRID_MINOR: [u8; 3] = [240, 240, 240];
const LEGEND_FRAME: [u8; 3] = [160, 160, 160];

/// The Tableau 10 palette (Tableau's 2016 default), in order.
const PALETTE: [[u8; 3]; 10] = [
    [78, 121, 167],  // blue
    [242, 142, 43],  // orange
    [225, 87, 89],   // red
    [118, 183, 178], // teal
    [89, 161, 79],   // green
    [237, 201, 72],  // yellow
    [176, 122, 161], // purple
    [255, 157, 167], // pink
    [156, 117, 95],  // brown
    [186, 176, 172], // grey
];

/// Colour of series `i`.
fn series_colour(i: usize) -> [u8; 3] {
    PALETTE[i % PALETTE.len()]
}

/// Font magnification: each font pixel is a `FONT_SCALE²` block.
const FONT_SCALE: i64 = 2;
/// Horizontal advance of one character (5 pixels + 1 pixel spacing).
const CHAR_W: i64 = 6 * FONT_SCALE;
/// Height of one character.
const CHAR_H: i64 = 7 * FONT_SCALE;
/// Blank border around everything.
const MARGIN: i64 = 12;
/// Length of the major tick marks outside the plot area (minor ones are half as long).
const TICK: i64 = 6;
/// Space between a tick mark and its label.
const TICK_GAP: i64 = 5;
/// Space between tick labels and the axis label.
const LABEL_GAP: i64 = 12;
/// Top of the plot area (room for the title).
const PLOT_TOP: i64 = MARGIN + CHAR_H + 16;
/// Dash pattern of dashed lines: drawn for `DASH_ON` pixels, then blank up to `DASH_PERIOD`.
const DASH_ON: f64 = 10.0;
const DASH_PERIOD: f64 = 16.0;
/// Half the size of a marker.
const MARKER_R: i64 = 4;
/// Length of the line sample in the legend.
const LEGEND_SAMPLE: i64 = 36;
/// Height of one legend row.
const LEGEND_ROW: i64 = 20;
/// Padding inside the legend box, and its distance from the plot frame.
const LEGEND_PAD: i64 = 8;

/// Pixel width of `text` in the font (no trailing spacing).
fn text_width(text: &str) -> i64 {
    let n = text.chars().count() as i64;
    (n * CHAR_W - FONT_SCALE).max(0)
}

/// The set font pixels of `text` as `(column, row)` in font pixels: column 0 is the left
/// edge of the first character (6 columns per character), row 0 the top of the cell (rows
/// 0–6, and 7 for the tails of [`descends`] letters).
fn font_pixels(text: &str) -> impl Iterator<Item = (i64, i64)> + '_ {
    text.chars().enumerate().flat_map(|(i, ch)| {
        let drop = i64::from(descends(ch));
        glyph(ch)
            .into_iter()
            .enumerate()
            .flat_map(move |(gy, bits)| {
                (0..5)
                    .filter(move |gx| bits & (0b10000 >> gx) != 0)
                    .map(move |gx| (6 * i as i64 + gx, gy as i64 + drop))
            })
    })
}

/// A rectangle of pixels `[x, x + w) × [y, y + h)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Rect {
    x: i64,
    y: i64,
    w: i64,
    h: i64,
}

impl Rect {
    const fn new(x: i64, y: i64, w: i64, h: i64) -> Self {
        Self { x, y, w, h }
    }

    fn contains(&self, x: i64, y: i64) -> bool {
        x >= self.x && x < self.x + self.w && y >= self.y && y < self.y + self.h
    }

    /// The pixel column of the horizontal fraction `f` (0 = left edge, 1 = right edge).
    fn px(&self, f: f64) -> f64 {
        self.x as f64 + f * (self.w - 1) as f64
    }

    /// The pixel row of the vertical fraction `f` (0 = bottom edge, 1 = top edge).
    fn py(&self, f: f64) -> f64 {
        self.y as f64 + (1.0 - f) * (self.h - 1) as f64
    }
}

/// The value `v` in axis units (`log10(v)` on a log axis), or `None` if it cannot be drawn.
fn transform(scale: Scale, v: f64) -> Option<f64> {
    match scale {
        Scale::Linear => v.is_finite().then_some(v),
        Scale::Log10 => (v.is_finite() && v > 0.0).then(|| v.log10()),
    }
}

/// An axis: its scale and its range `lo < hi` in axis units (see [`transform`]).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Axis {
    scale: Scale,
    lo: f64,
    hi: f64,
}

/// A tick mark at `frac` (0..=1 along the axis); major ticks have a label.
#[derive(Clone, Debug, PartialEq)]
struct Tick {
    frac: f64,
    label: Option<String>,
}

impl Axis {
    /// The axis covering data from `min` to `max` (in axis units, finite, `min <= max`)
    /// with a margin of 5 % of the span on both sides. A zero (or negligible) span gets
    /// ±10 % of the value (±1 around zero) on a linear axis and ±½ decade on a log axis;
    /// a log axis is widened to whole decades if it would show fewer than two powers of ten.
    fn fit(scale: Scale, min: f64, max: f64) -> Result<Self> {
        let span = max - min;
        let (lo, hi) = match scale {
            Scale::Linear => {
                let size = min.abs().max(max.abs());
                if span <= 1e-12 * size || span == 0.0 {
                    let c = 0.5 * min + 0.5 * max;
                    let half = if c == 0.0 { 1.0 } else { 0.1 * c.abs() };
                    (c - half, c + half)
                } else {
                    let (lo, hi) = (min - 0.05 * span, max + 0.05 * span);
                    if (hi - lo).is_finite() {
                        (lo, hi)
                    } else {
                        (min, max)
                    }
                }
            }
            Scale::Log10 => {
                let (lo, hi) = if span < 1e-9 {
                    (min - 0.5, max + 0.5)
                } else {
                    (min - 0.05 * span, max + 0.05 * span)
                };
                if hi.floor() - lo.ceil() < 1.0 {
                    (lo.floor(), hi.ceil())
                } else {
                    (lo, hi)
                }
            }
        };
        ensure!(
            (hi - lo).is_finite() && hi > lo,
            "data range {min:e} to {max:e} is too wide for a linear axis"
        );
        Ok(Self { scale, lo, hi })
    }

    /// Where the data value `v` lies along the axis: 0 at `lo`, 1 at `hi`; `None` if `v`
    /// cannot be drawn on this axis.
    fn frac(&self, v: f64) -> Option<f64> {
        transform(self.scale, v).map(|t| (t - self.lo) / (self.hi - self.lo))
    }

    /// Tick marks, with at most about `max_labels` labels.
    fn ticks(&self, max_labels: usize) -> Vec<Tick> {
        match self.scale {
            Scale::Linear => self.linear_ticks(),
            Scale::Log10 => self.log_ticks(max_labels),
        }
    }

    /// 4–6 ticks at multiples of a "nice" step, all labelled.
    fn linear_ticks(&self) -> Vec<Tick> {
        let (lo, hi) = (self.lo, self.hi);
        let span = hi - lo;
        let range = |step: f64| {
            let eps = 1e-9;
            ((lo / step - eps).ceil(), (hi / step + eps).floor())
        };
        let mag = 10f64.powf((span / 5.0).log10().floor());
        let mut best: Option<(f64, f64)> = None; // (score, step)
        for m in [0.1, 1.0, 10.0] {
            for f in [1.0, 2.0, 5.0, 2.5] {
                let step = f * m * mag;
                let (a, b) = range(step);
                let count = b - a + 1.0;
                let score = (count - 5.0).abs() + if f == 2.5 { 1.0 } else { 0.0 };
                if step.is_finite() && step > 0.0 && best.is_none_or(|(s, _)| score < s) {
                    best = Some((score, step));
                }
            }
        }
        let Some((_, step)) = best else {
            return Vec::new();
        };
        let (a, b) = range(step);
        let values: Vec<f64> = (0..=((b - a) as i64).clamp(0, 100))
            .map(|i| (a + i as f64) * step)
            .collect();
        let labels = linear_labels(&values, step);
        values
            .iter()
            .zip(labels)
            .map(|(&v, label)| Tick {
                frac: (v - lo) / span,
                label: Some(label),
            })
            .collect()
    }

    /// Ticks at powers of ten (labelled, every `stride`-th one if there are many) and minor
    /// ticks at 2–9 times a power of ten when at most 6 decades are shown; when at most 2.5
    /// decades are shown, the ones at 2 and 5 times a power of ten are labelled too.
    fn log_ticks(&self, max_labels: usize) -> Vec<Tick> {
        let (lo, hi) = (self.lo, self.hi);
        let eps = 1e-9;
        let (a, b) = ((lo - eps).ceil() as i64, (hi + eps).floor() as i64);
        let decades = (b - a + 1).max(0) as usize;
        let stride = decades.div_ceil(max_labels.max(1)).max(1) as i64;
        let frac = |t: f64| (t - lo) / (hi - lo);
        let mut ticks = Vec::new();
        for k in (lo.floor() as i64)..=(hi.ceil() as i64) {
            let t = k as f64;
            if (a..=b).contains(&k) {
                let labelled = k.rem_euclid(stride) == 0;
                ticks.push(Tick {
                    frac: frac(t),
                    label: labelled.then(|| format!("1e{k}")),
                });
            }
            if hi - lo <= 6.0 {
                for m in 2..=9 {
                    let t = t + f64::from(m).log10();
                    if t > lo - eps && t < hi + eps {
                        let labelled = hi - lo <= 2.5 && (m == 2 || m == 5);
                        ticks.push(Tick {
                            frac: frac(t),
                            label: labelled.then(|| format!("{m}e{k}")),
                        });
                    }
                }
            }
        }
        ticks
    }
}

/// Labels for the linear tick `values` (multiples of `step`): fixed-point with just enough
/// decimals for `step` if that is short, else [`format_label`]'s scientific notation
/// (unless its 4 significant digits cannot tell the ticks apart).
fn linear_labels(values: &[f64], step: f64) -> Vec<String> {
    let decimals = (0..=12)
        .find(|&d| {
            let s = step * 10f64.powi(d);
            (s - s.round()).abs() <= 1e-6 * s
        })
        .unwrap_or(12) as usize;
    let fixed: Vec<String> = values
        .iter()
        .map(|&v| {
            let v = if v.abs() < 1e-9 * step { 0.0 } else { v };
            format!("{v:.decimals$}")
        })
        .collect();
    if fixed.iter().all(|s| s.len() <= 8) {
        return fixed;
    }
    let short: Vec<String> = values.iter().map(|&v| format_label(v)).collect();
    if short.windows(2).any(|w| w[0] == w[1]) {
        fixed
    } else {
        short
    }
}

/// Marker shapes, used in turn by the series.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Shape {
    Circle,
    Square,
    Diamond,
    TriangleUp,
    TriangleDown,
}

const SHAPES: [Shape; 5] = [
    Shape::Circle,
    Shape::Square,
    Shape::Diamond,
    Shape::TriangleUp,
    Shape::TriangleDown,
];

impl Shape {
    /// Whether the offset `(dx, dy)` from the centre (`dy` down) is inside the marker.
    fn covers(self, dx: i64, dy: i64) -> bool {
        let r = MARKER_R;
        let tri = |dy: i64| dy.abs() < r && 2 * dx.abs() < dy + r;
        match self {
            Shape::Circle => dx * dx + dy * dy <= r * r + r / 2,
            Shape::Square => dx.abs() < r && dy.abs() < r,
            Shape::Diamond => dx.abs() + dy.abs() <= r,
            Shape::TriangleUp => tri(dy),
            Shape::TriangleDown => tri(-dy),
        }
    }
}

/// An RGB canvas that only draws inside its clip rectangle.
struct Canvas {
    w: i64,
    h: i64,
    rgb: Vec<u8>,
    clip: Rect,
}

impl Canvas {
    fn new(w: i64, h: i64, fill: [u8; 3]) -> Self {
        Self {
            w,
            h,
            rgb: fill.repeat((w * h) as usize),
            clip: Rect::new(0, 0, w, h),
        }
    }

    fn full(&self) -> Rect {
        Rect::new(0, 0, self.w, self.h)
    }

    fn get(&self, x: i64, y: i64) -> [u8; 3] {
        let i = 3 * (y * self.w + x) as usize;
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    fn set(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if self.clip.contains(x, y) && (0..self.w).contains(&x) && (0..self.h).contains(&y) {
            let i = 3 * (y * self.w + x) as usize;
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    fn fill_rect(&mut self, r: Rect, c: [u8; 3]) {
        for y in r.y..r.y + r.h {
            for x in r.x..r.x + r.w {
                self.set(x, y, c);
            }
        }
    }

    /// A one-pixel frame just outside `r`.
    fn frame(&mut self, r: Rect, c: [u8; 3]) {
        let (x0, y0, x1, y1) = (r.x - 1, r.y - 1, r.x + r.w, r.y + r.h);
        self.fill_rect(Rect::new(x0, y0, r.w + 2, 1), c);
        self.fill_rect(Rect::new(x0, y1, r.w + 2, 1), c);
        self.fill_rect(Rect::new(x0, y0, 1, r.h + 2), c);
        self.fill_rect(Rect::new(x1, y0, 1, r.h + 2), c);
    }

    /// Draw `text` with its top-left corner at `(x, y)`.
    fn text(&mut self, x: i64, y: i64, text: &str, c: [u8; 3]) {
        for (col, row) in font_pixels(text) {
            let r = Rect::new(
                x + col * FONT_SCALE,
                y + row * FONT_SCALE,
                FONT_SCALE,
                FONT_SCALE,
            );
            self.fill_rect(r, c);
        }
    }

    /// Draw `text` turned 90° anticlockwise (reading upwards), its left edge at `x` and
    /// its first character's bottom at `y`.
    fn text_up(&mut self, x: i64, y: i64, text: &str, c: [u8; 3]) {
        for (col, row) in font_pixels(text) {
            let r = Rect::new(
                x + row * FONT_SCALE,
                y - (col + 1) * FONT_SCALE,
                FONT_SCALE,
                FONT_SCALE,
            );
            self.fill_rect(r, c);
        }
    }

    /// A 2×2 pixel dot, the pen of all lines.
    fn dot(&mut self, x: i64, y: i64, c: [u8; 3]) {
        self.fill_rect(Rect::new(x, y, 2, 2), c);
    }

    /// A 2 pixel wide polyline through `pts` (Bresenham), dashed if asked; the dash
    /// pattern continues across vertices.
    fn polyline(&mut self, pts: &[(i64, i64)], c: [u8; 3], dashed: bool) {
        let mut phase = 0.0;
        for seg in pts.windows(2) {
            let ((x0, y0), (x1, y1)) = (seg[0], seg[1]);
            let (dx, dy) = ((x1 - x0).abs(), -(y1 - y0).abs());
            let (sx, sy) = ((x1 - x0).signum(), (y1 - y0).signum());
            let steps = dx.max(-dy);
            let step_len = if steps > 0 {
                (dx as f64).hypot(dy as f64) / steps as f64
            } else {
                0.0
            };
            let (mut x, mut y, mut err) = (x0, y0, dx + dy);
            loop {
                if !dashed || phase % DASH_PERIOD < DASH_ON {
                    self.dot(x, y, c);
                }
                if x == x1 && y == y1 {
                    break;
                }
                phase += step_len;
                let e2 = 2 * err;
                if e2 >= dy {
                    err += dy;
                    x += sx;
                }
                if e2 <= dx {
                    err += dx;
                    y += sy;
                }
            }
        }
    }

    /// A filled marker centred on `(x, y)` (the centre of the 2×2 line pen at `(x, y)`).
    fn marker(&mut self, shape: Shape, x: i64, y: i64, c: [u8; 3]) {
        for dy in -MARKER_R..=MARKER_R {
            for dx in -MARKER_R..=MARKER_R {
                if shape.covers(dx, dy) {
                    self.set(x + dx, y + dy, c);
                }
            }
        }
    }

    /// How many pixels of `r` differ from the background and the grid.
    fn busy_pixels(&self, r: Rect) -> usize {
        let mut n = 0;
        for y in r.y.max(0)..(r.y + r.h).min(self.h) {
            for x in r.x.max(0)..(r.x + r.w).min(self.w) {
                if ![BACKGROUND, GRID_MAJOR, GRID_MINOR].contains(&self.get(x, y)) {
                    n += 1;
                }
            }
        }
        n
    }
}

/// The legend: its box and, per entry, the series index and the vertical centre of its row.
#[derive(Clone, Debug, PartialEq)]
struct Legend {
    rect: Rect,
    rows: Vec<(usize, i64)>,
}

/// A rendered chart, with the geometry the tests need.
#[cfg_attr(
    not(test),
    allow(dead_code, reason = "geometry read by the tests only")
)]
struct Rendered {
    width: i64,
    height: i64,
    rgb: Vec<u8>,
    plot: Rect,
    x: Axis,
    y: Axis,
    legend: Option<Legend>,
}

/// The data range `(min, max)` in axis units of the drawable points of `chart`.
fn data_ranges(chart: &Chart) -> Option<((f64, f64), (f64, f64))> {
    let mut r: Option<((f64, f64), (f64, f64))> = None;
    for s in &chart.series {
        for &(x, y) in &s.points {
            let (Some(x), Some(y)) = (transform(chart.x_scale, x), transform(chart.y_scale, y))
            else {
                continue;
            };
            r = Some(match r {
                None => ((x, x), (y, y)),
                Some(((x0, x1), (y0, y1))) => ((x0.min(x), x1.max(x)), (y0.min(y), y1.max(y))),
            });
        }
    }
    r
}

/// Draw `chart`.
fn render(chart: &Chart) -> Result<Rendered> {
    if chart.series.is_empty() {
        bail!("chart {:?} has no series", chart.title);
    }
    let Some(((x_min, x_max), (y_min, y_max))) = data_ranges(chart) else {
        bail!(
            "chart {:?} has no drawable point (every point has a non-finite coordinate, or a \
             non-positive one on a logarithmic axis)",
            chart.title
        );
    };
    let x = Axis::fit(chart.x_scale, x_min, x_max).context("horizontal axis")?;
    let y = Axis::fit(chart.y_scale, y_min, y_max).context("vertical axis")?;

    // Layout: the y tick labels set the left edge of the plot area, the last x tick label
    // the right edge.
    let y_ticks = y.ticks(9);
    let x_ticks = x.ticks(8);
    let y_label_w = y_ticks
        .iter()
        .filter_map(|t| t.label.as_deref().map(text_width))
        .max()
        .unwrap_or(0);
    let y_axis_label_w = if chart.y_label.is_empty() {
        0
    } else {
        CHAR_H + LABEL_GAP
    };
    let left = MARGIN + y_axis_label_w + y_label_w + TICK_GAP + TICK;
    let last_x_label_w = x_ticks
        .iter()
        .rev()
        .find_map(|t| t.label.as_deref().map(text_width))
        .unwrap_or(0);
    let right = WIDTH - MARGIN.max(last_x_label_w / 2 + 4) - 8;
    let x_axis_label_h = if chart.x_label.is_empty() {
        0
    } else {
        CHAR_H + LABEL_GAP
    };
    let bottom = HEIGHT - (MARGIN + x_axis_label_h + CHAR_H + TICK_GAP + TICK);
    let plot = Rect::new(left, PLOT_TOP, right - left, bottom - PLOT_TOP);

    let mut canvas = Canvas::new(WIDTH, HEIGHT, BACKGROUND);

    // Grid lines, minor ones first.
    for major in [false, true] {
        let colour = if major { GRID_MAJOR } else { GRID_MINOR };
        for t in x_ticks.iter().filter(|t| t.label.is_some() == major) {
            let px = plot.px(t.frac).round() as i64;
            canvas.fill_rect(Rect::new(px, plot.y, 1, plot.h), colour);
        }
        for t in y_ticks.iter().filter(|t| t.label.is_some() == major) {
            let py = plot.py(t.frac).round() as i64;
            canvas.fill_rect(Rect::new(plot.x, py, plot.w, 1), colour);
        }
    }

    // The series, clipped to the plot area.
    canvas.clip = plot;
    for (i, s) in chart.series.iter().enumerate() {
        let colour = series_colour(i);
        let pixel = |&(vx, vy): &(f64, f64)| -> Option<(i64, i64)> {
            let (fx, fy) = (x.frac(vx)?, y.frac(vy)?);
            Some((plot.px(fx).round() as i64, plot.py(fy).round() as i64))
        };
        let mapped: Vec<Option<(i64, i64)>> = s.points.iter().map(pixel).collect();
        for run in mapped.split(Option::is_none) {
            let run: Vec<(i64, i64)> = run.iter().flatten().copied().collect();
            match run.len() {
                0 => {}
                // A lone point gets a marker even without `markers`.
                1 => canvas.marker(SHAPES[i % SHAPES.len()], run[0].0, run[0].1, colour),
                _ => canvas.polyline(&run, colour, s.dashed),
            }
        }
        if s.markers {
            for &(px, py) in mapped.iter().flatten() {
                canvas.marker(SHAPES[i % SHAPES.len()], px, py, colour);
            }
        }
    }
    canvas.clip = canvas.full();

    // Frame, ticks and tick labels.
    canvas.frame(plot, FRAME);
    let plot_bottom = plot.y + plot.h;
    let mut free_x = i64::MIN; // labels must not start left of this
    for t in &x_ticks {
        let px = plot.px(t.frac).round() as i64;
        let len = if t.label.is_some() { TICK } else { TICK / 2 };
        canvas.fill_rect(Rect::new(px, plot_bottom + 1, 1, len), FRAME);
        if let Some(label) = &t.label {
            let (w, top) = (text_width(label), plot_bottom + 1 + TICK + TICK_GAP);
            if px - w / 2 >= free_x {
                canvas.text(px - w / 2, top, label, INK);
                free_x = px - w / 2 + w + CHAR_W;
            }
        }
    }
    for t in &y_ticks {
        let py = plot.py(t.frac).round() as i64;
        let len = if t.label.is_some() { TICK } else { TICK / 2 };
        canvas.fill_rect(Rect::new(plot.x - 1 - len, py, len, 1), FRAME);
        if let Some(label) = &t.label {
            let right = plot.x - 1 - TICK - TICK_GAP;
            canvas.text(right - text_width(label), py - CHAR_H / 2, label, INK);
        }
    }

    // Axis labels and title, centred on the plot area as far as the image allows (text
    // too long for the image starts at the left margin and is cut off).
    let centred = |w: i64| {
        let x0 = plot.x + (plot.w - w) / 2;
        x0.min(WIDTH - MARGIN - w).max(MARGIN)
    };
    if !chart.x_label.is_empty() {
        let w = text_width(&chart.x_label);
        let top = HEIGHT - MARGIN - CHAR_H;
        canvas.text(centred(w), top, &chart.x_label, INK);
    }
    if !chart.y_label.is_empty() {
        let w = text_width(&chart.y_label);
        let bottom = (plot.y + (plot.h + w) / 2).min(HEIGHT - 1).max(w);
        canvas.text_up(MARGIN, bottom, &chart.y_label, INK);
    }
    if !chart.title.is_empty() {
        let w = text_width(&chart.title);
        let x0 = centred(w);
        // Bold: the title twice, one pixel apart.
        canvas.text(x0, MARGIN, &chart.title, INK);
        canvas.text(x0 + 1, MARGIN, &chart.title, INK);
    }

    let legend = draw_legend(&mut canvas, chart, plot);
    Ok(Rendered {
        width: WIDTH,
        height: HEIGHT,
        rgb: canvas.rgb,
        plot,
        x,
        y,
        legend,
    })
}

/// Draw the legend in the corner of `plot` covering the fewest data pixels (ties: top
/// right, top left, bottom right, bottom left); `None` if no series has a label.
fn draw_legend(canvas: &mut Canvas, chart: &Chart, plot: Rect) -> Option<Legend> {
    let entries: Vec<usize> = (0..chart.series.len())
        .filter(|&i| !chart.series[i].label.is_empty())
        .collect();
    let label_w = entries
        .iter()
        .map(|&i| text_width(&chart.series[i].label))
        .max()?;
    let w = (LEGEND_PAD + LEGEND_SAMPLE + LEGEND_PAD + label_w + LEGEND_PAD)
        .min(plot.w - 2 * LEGEND_PAD);
    let h = (2 * LEGEND_PAD + entries.len() as i64 * LEGEND_ROW - (LEGEND_ROW - CHAR_H))
        .min(plot.h - 2 * LEGEND_PAD);
    let (x_left, x_right) = (plot.x + LEGEND_PAD, plot.x + plot.w - LEGEND_PAD - w);
    let (y_top, y_bottom) = (plot.y + LEGEND_PAD, plot.y + plot.h - LEGEND_PAD - h);
    let rect = [
        (x_right, y_top),
        (x_left, y_top),
        (x_right, y_bottom),
        (x_left, y_bottom),
    ]
    .into_iter()
    .map(|(x, y)| Rect::new(x, y, w, h))
    .min_by_key(|&r| canvas.busy_pixels(r))?;

    canvas.fill_rect(rect, BACKGROUND);
    canvas.frame(rect, LEGEND_FRAME);
    canvas.clip = rect;
    let mut rows = Vec::new();
    for (row, &i) in entries.iter().enumerate() {
        let s = &chart.series[i];
        let colour = series_colour(i);
        let top = rect.y + LEGEND_PAD + row as i64 * LEGEND_ROW;
        let cy = top + CHAR_H / 2 - 1;
        let x0 = rect.x + LEGEND_PAD;
        canvas.polyline(&[(x0, cy), (x0 + LEGEND_SAMPLE - 2, cy)], colour, s.dashed);
        if s.markers {
            canvas.marker(SHAPES[i % SHAPES.len()], x0 + LEGEND_SAMPLE / 2, cy, colour);
        }
        canvas.text(x0 + LEGEND_SAMPLE + LEGEND_PAD, top, &s.label, INK);
        rows.push((i, cy));
    }
    canvas.clip = canvas.full();
    Some(Legend { rect, rows })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs::File;
    use std::path::PathBuf;

    struct TempFile(PathBuf);

    impl TempFile {
        fn new(tag: &str) -> Self {
            use std::sync::atomic::{AtomicU32, Ordering};
            static N: AtomicU32 = AtomicU32::new(0);
            let n = N.fetch_add(1, Ordering::Relaxed);
            Self(std::env::temp_dir().join(format!(
                "blutrace-plot-{tag}-{}-{n}.png",
                std::process::id()
            )))
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

    fn pixel(r: &Rendered, x: i64, y: i64) -> [u8; 3] {
        let i = 3 * (y * r.width + x) as usize;
        [r.rgb[i], r.rgb[i + 1], r.rgb[i + 2]]
    }

    /// Monte Carlo style convergence data: error ~ c / sqrt(t) with some wobble.
    fn convergence_chart() -> Chart {
        let times: Vec<f64> = (0..14).map(|i| 0.05 * 1.6f64.powi(i)).collect();
        let metric = |c: f64, wobble: f64| -> Vec<(f64, f64)> {
            times
                .iter()
                .enumerate()
                .map(|(i, &t)| (t, c / t.sqrt() * (1.0 + wobble * (i as f64 * 1.7).sin())))
                .collect()
        };
        let t0 = times[0];
        let t1 = times[times.len() - 1];
        let reference = (0..=20)
            .map(|i| {
                let t = t0 * (t1 / t0).powf(f64::from(i) / 20.0);
                (t, 0.02 / t.sqrt())
            })
            .collect();
        Chart {
            title: "Convergence: relative standard error vs. run time".into(),
            x_label: "run time (s)".into(),
            y_label: "relative standard error".into(),
            x_scale: Scale::Log10,
            y_scale: Scale::Log10,
            series: vec![
                Series {
                    markers: true,
                    ..Series::new("total flux", metric(0.004, 0.08))
                },
                Series {
                    markers: true,
                    ..Series::new("uniformity (min/max)", metric(0.012, 0.1))
                },
                Series {
                    markers: true,
                    ..Series::new("mean luminance, centre", metric(0.03, 0.12))
                },
                Series {
                    dashed: true,
                    ..Series::new("~ 1/sqrt(t)", reference)
                },
            ],
        }
    }

    /// Dot density before and after an optimisation.
    fn density_chart() -> Chart {
        let initial = (0..=60)
            .map(|i| {
                let x = -30.0 + i as f64;
                (x, 0.25)
            })
            .collect();
        let fin = (0..=60)
            .map(|i| {
                let x = -30.0 + i as f64;
                (x, 0.08 + 0.5 * (x / 30.0).powi(2) + 0.03 * (x / 4.0).sin())
            })
            .collect();
        Chart {
            title: "Dot density d(x)".into(),
            x_label: "position x (mm)".into(),
            y_label: "dot density d (area fraction)".into(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            series: vec![
                Series::new("initial", initial),
                Series {
                    markers: true,
                    ..Series::new("final", fin)
                },
            ],
        }
    }

    #[test]
    fn png_decodes_at_expected_size() {
        for chart in [convergence_chart(), density_chart()] {
            let f = TempFile::new("size");
            write_chart(&f.0, &chart).unwrap();
            let (w, h, rgb) = decode(&f.0);
            assert_eq!((w, h), (800, 560));
            assert_eq!(&rgb[..3], &BACKGROUND);
            // Something of every series colour is drawn.
            for i in 0..chart.series.len() {
                let c = series_colour(i);
                assert!(rgb.chunks_exact(3).any(|p| p == c), "series {i} not drawn");
            }
        }
    }

    #[test]
    fn linear_mapping() {
        let a = Axis {
            scale: Scale::Linear,
            lo: -2.0,
            hi: 6.0,
        };
        assert_eq!(a.frac(-2.0), Some(0.0));
        assert_eq!(a.frac(6.0), Some(1.0));
        assert_eq!(a.frac(2.0), Some(0.5));
        assert_eq!(a.frac(-4.0), Some(-0.25));
        assert_eq!(a.frac(f64::NAN), None);
        assert_eq!(a.frac(f64::INFINITY), None);
        let r = Rect::new(100, 50, 401, 201);
        assert_eq!((r.px(0.0), r.px(1.0), r.px(0.25)), (100.0, 500.0, 200.0));
        // y points up: fraction 0 at the bottom row, 1 at the top row.
        assert_eq!((r.py(0.0), r.py(1.0), r.py(0.25)), (250.0, 50.0, 200.0));

        // A marker lands where the mapping says.
        let chart = Chart {
            series: vec![Series {
                markers: true,
                ..Series::new("p", vec![(0.0, 0.0), (10.0, 100.0), (3.0, 70.0)])
            }],
            ..Chart::default()
        };
        let r = render(&chart).unwrap();
        assert!((r.x.lo + 0.5).abs() < 1e-12 && (r.x.hi - 10.5).abs() < 1e-12);
        assert!((r.y.lo + 5.0).abs() < 1e-12 && (r.y.hi - 105.0).abs() < 1e-12);
        let px = r.plot.px(r.x.frac(3.0).unwrap()).round() as i64;
        let py = r.plot.py(r.y.frac(70.0).unwrap()).round() as i64;
        assert_eq!(
            px,
            r.plot.x + ((3.5 / 11.0) * (r.plot.w - 1) as f64).round() as i64
        );
        assert_eq!(
            py,
            r.plot.y + ((35.0 / 110.0) * (r.plot.h - 1) as f64).round() as i64
        );
        for (dx, dy) in [(0, 0), (2, 0), (-2, 0), (0, 2), (0, -2)] {
            assert_eq!(pixel(&r, px + dx, py + dy), series_colour(0));
        }
    }

    #[test]
    fn log_mapping() {
        let a = Axis {
            scale: Scale::Log10,
            lo: -3.0,
            hi: 1.0,
        };
        assert_eq!(a.frac(1e-3), Some(0.0));
        assert_eq!(a.frac(10.0), Some(1.0));
        assert!((a.frac(1e-2).unwrap() - 0.25).abs() < 1e-15);
        assert!((a.frac(1.0).unwrap() - 0.75).abs() < 1e-15);
        assert_eq!(a.frac(0.0), None);
        assert_eq!(a.frac(-1.0), None);
        assert_eq!(a.frac(f64::NAN), None);

        let chart = Chart {
            x_scale: Scale::Log10,
            y_scale: Scale::Log10,
            series: vec![Series {
                markers: true,
                ..Series::new(
                    "p",
                    vec![
                        (1e-2, 1.0),
                        (0.0, 5.0),
                        (1e2, 1e-4),
                        (1.0, 1e-2),
                        (f64::NAN, 1.0),
                    ],
                )
            }],
            ..Chart::default()
        };
        let r = render(&chart).unwrap();
        // Four decades plus 5 % on each side.
        assert!((r.x.lo + 2.2).abs() < 1e-12 && (r.x.hi - 2.2).abs() < 1e-12);
        assert!((r.y.lo + 4.2).abs() < 1e-12 && (r.y.hi - 0.2).abs() < 1e-12);
        let px = r.plot.px(r.x.frac(1.0).unwrap()).round() as i64;
        let py = r.plot.py(r.y.frac(1e-2).unwrap()).round() as i64;
        assert_eq!(px, r.plot.x + ((r.plot.w - 1) as f64 * 0.5).round() as i64);
        assert_eq!(
            py,
            r.plot.y + ((r.plot.h - 1) as f64 * 2.2 / 4.4).round() as i64
        );
        assert_eq!(pixel(&r, px, py), series_colour(0));
    }

    #[test]
    fn ticks_are_nice() {
        let lin = |lo, hi| Axis {
            scale: Scale::Linear,
            lo,
            hi,
        };
        let labels =
            |a: Axis| -> Vec<String> { a.ticks(8).into_iter().filter_map(|t| t.label).collect() };
        assert_eq!(
            labels(lin(-0.05, 1.05)),
            ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"]
        );
        assert_eq!(
            labels(lin(-31.5, 31.5)),
            ["-30", "-20", "-10", "0", "10", "20", "30"]
        );
        assert_eq!(
            labels(lin(0.0, 2.6e-7)),
            ["0", "5e-8", "1e-7", "1.5e-7", "2e-7", "2.5e-7"]
        );
        assert_eq!(
            labels(lin(999.9, 1001.1)),
            ["1000.0", "1000.2", "1000.4", "1000.6", "1000.8", "1001.0"]
        );
        let mut state = 12345u64;
        let mut rand = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            let c = (rand() - 0.5) * 10f64.powf(rand() * 20.0 - 10.0);
            let span = 10f64.powf(rand() * 20.0 - 10.0) * (1.0 + c.abs());
            let a = lin(c - span * rand(), c + span * rand() + 1e-300);
            let ticks = a.ticks(8);
            let n = ticks.len();
            assert!(ticks.iter().all(|t| (-1e-9..=1.0 + 1e-9).contains(&t.frac)));
            let l = labels(a);
            if a.hi - a.lo > 1e-9 * a.lo.abs().max(a.hi.abs()) {
                assert!((3..=7).contains(&n), "{a:?}: {n} ticks");
                assert!(l.windows(2).all(|w| w[0] != w[1]), "{l:?}");
            }
            // Short unless the data sit far from zero compared with their spread.
            if a.hi - a.lo > 1e-2 * a.lo.abs().max(a.hi.abs()) {
                assert!(l.iter().all(|s| s.len() <= 10), "{a:?} {l:?}");
            }
        }

        let log = |lo, hi| Axis {
            scale: Scale::Log10,
            lo,
            hi,
        };
        assert_eq!(labels(log(-3.2, 0.5)), ["1e-3", "1e-2", "1e-1", "1e0"]);
        assert_eq!(labels(log(-1.0, 0.0)), ["1e-1", "2e-1", "5e-1", "1e0"]);
        // Majors 1e-3..1e0; minors 7e-4..9e-4, 2e-3..9e-1 and 2, 3.
        assert_eq!(log(-3.2, 0.5).ticks(8).len(), 4 + 3 + 3 * 8 + 2);
        let many = labels(log(-40.0, 40.0));
        assert!(
            many.len() <= 9 && many.contains(&"1e0".to_string()),
            "{many:?}"
        );
    }

    #[test]
    fn ranges_of_degenerate_data() {
        let fit = |s, a, b| Axis::fit(s, a, b).unwrap();
        assert_eq!(
            fit(Scale::Linear, 5.0, 5.0),
            Axis {
                scale: Scale::Linear,
                lo: 4.5,
                hi: 5.5
            }
        );
        assert_eq!(
            fit(Scale::Linear, 0.0, 0.0),
            Axis {
                scale: Scale::Linear,
                lo: -1.0,
                hi: 1.0
            }
        );
        let a = fit(Scale::Linear, 1.0, 1.0 + 1e-15);
        assert!(a.lo < 1.0 && a.hi > 1.0 && a.hi - a.lo > 0.1);
        let a = fit(Scale::Linear, 0.0, f64::MAX);
        assert_eq!((a.lo, a.hi), (0.0, f64::MAX));
        let e = Axis::fit(Scale::Linear, -f64::MAX, f64::MAX).unwrap_err();
        assert!(e.to_string().contains("too wide"), "{e}");
        // Log axes: at least two powers of ten, data strictly inside.
        assert_eq!(
            fit(Scale::Log10, -2.0, -2.0),
            Axis {
                scale: Scale::Log10,
                lo: -3.0,
                hi: -1.0
            }
        );
        let a = fit(Scale::Log10, 0.012f64.log10(), 0.03f64.log10());
        assert_eq!((a.lo, a.hi), (-2.0, -1.0));
        let a = fit(Scale::Log10, -300.0, 300.0);
        assert!(a.lo < -300.0 && a.hi > 300.0);
    }

    #[test]
    fn degenerate_inputs_do_not_panic() {
        let f = TempFile::new("degenerate");
        let charts = [
            vec![(1.0, 2.0)],
            vec![(0.0, 0.0)],
            vec![(1.0, 3.0), (2.0, 3.0), (3.0, 3.0)],
            vec![(4.0, 1.0), (4.0, 2.0)],
            vec![
                (f64::NAN, 1.0),
                (1.0, f64::INFINITY),
                (2.0, 2.0),
                (-1.0, -1.0),
            ],
            vec![(f64::MIN_POSITIVE, f64::MAX), (f64::MAX, f64::MIN_POSITIVE)],
            vec![(1.0, 1.0), (1.0 + 1e-15, 1.0 - 1e-15)],
            vec![(-1e300, 1e300), (1e300, -1e300)],
        ];
        for scale in [Scale::Linear, Scale::Log10] {
            for pts in &charts {
                let mut chart = Chart {
                    title: "x".repeat(200),
                    x_label: "a very long label ".repeat(10),
                    y_label: "another very long label ".repeat(10),
                    x_scale: scale,
                    y_scale: scale,
                    series: (0..14)
                        .map(|i| Series {
                            dashed: i % 2 == 1,
                            markers: i % 3 == 1,
                            ..Series::new(format!("series {i} {}", "y".repeat(i * 5)), pts.clone())
                        })
                        .collect(),
                };
                chart.series.push(Series::new("", vec![]));
                let valid = pts
                    .iter()
                    .any(|&(x, y)| transform(scale, x).is_some() && transform(scale, y).is_some());
                match write_chart(&f.0, &chart) {
                    Ok(()) => assert_eq!(decode(&f.0).0, 800),
                    Err(e) => assert!(!valid, "{pts:?} {scale:?}: {e:#}"),
                }
                if !valid {
                    assert!(write_chart(&f.0, &chart).is_err());
                }
            }
        }
    }

    #[test]
    fn errors_are_clear() {
        let f = TempFile::new("error");
        let e = write_chart(&f.0, &Chart::default()).unwrap_err();
        assert!(format!("{e:#}").contains("no series"), "{e:#}");
        let chart = Chart {
            y_scale: Scale::Log10,
            series: vec![Series::new("a", vec![(1.0, 0.0), (f64::NAN, 1.0)])],
            ..Chart::default()
        };
        let e = write_chart(&f.0, &chart).unwrap_err();
        assert!(format!("{e:#}").contains("no drawable point"), "{e:#}");
        assert!(!f.0.exists());
    }

    #[test]
    fn legend_colours_differ() {
        for (i, a) in PALETTE.iter().enumerate() {
            assert!(PALETTE[..i].iter().all(|b| b != a));
        }
        let chart = convergence_chart();
        let r = render(&chart).unwrap();
        let legend = r.legend.as_ref().unwrap();
        assert_eq!(legend.rows.len(), chart.series.len());
        let colours: Vec<[u8; 3]> = legend
            .rows
            .iter()
            .map(|&(i, cy)| {
                // The first pixels of the line sample are drawn even when dashed.
                let c = pixel(&r, legend.rect.x + LEGEND_PAD + 1, cy);
                assert_eq!(c, series_colour(i));
                c
            })
            .collect();
        for (i, a) in colours.iter().enumerate() {
            assert!(colours[..i].iter().all(|b| b != a));
        }
        // The legend stays inside the plot area.
        let (l, p) = (legend.rect, r.plot);
        assert!(l.x > p.x && l.y > p.y && l.x + l.w < p.x + p.w && l.y + l.h < p.y + p.h);
    }

    #[test]
    #[ignore = "writes /tmp/blutrace_convergence.png and /tmp/blutrace_density.png"]
    fn demo_charts() {
        write_chart(
            Path::new("/tmp/blutrace_convergence.png"),
            &convergence_chart(),
        )
        .unwrap();
        write_chart(Path::new("/tmp/blutrace_density.png"), &density_chart()).unwrap();
        let glyphs = Chart {
            title: "ABCDEFGHIJKLMNOPQRSTUVWXYZ 0123456789".into(),
            x_label: "abcdefghijklmnopqrstuvwxyz .,-+/()%=:;_'*^<>!?|[]".into(),
            y_label: "The quick brown fox (jumps) = 42%".into(),
            series: vec![Series::new("glyph test", vec![(0.0, 1.0), (1.0, 0.0)])],
            ..Chart::default()
        };
        write_chart(Path::new("/tmp/blutrace_glyphs.png"), &glyphs).unwrap();
        let degenerate = Chart {
            title: "Constant y, one lone point, NaN gap".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            x_scale: Scale::Log10,
            y_scale: Scale::Linear,
            series: vec![
                Series::new(
                    "constant",
                    vec![
                        (0.2, 3.0),
                        (0.3, 3.0),
                        (f64::NAN, 3.0),
                        (0.5, 3.0),
                        (0.7, 3.0),
                    ],
                ),
                Series::new("lone point", vec![(0.4, 3.0)]),
            ],
        };
        write_chart(Path::new("/tmp/blutrace_degenerate.png"), &degenerate).unwrap();
        let many = Chart {
            title: "Twelve series, offset data, a title far too long to fit the image width".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            series: (0..12)
                .map(|i| Series {
                    markers: i % 2 == 1,
                    dashed: i % 3 == 2,
                    ..Series::new(
                        format!("series {i}"),
                        (0..20)
                            .map(|j| (1e6 + f64::from(j) * 0.01, f64::from(i * j)))
                            .collect(),
                    )
                })
                .collect(),
            ..Chart::default()
        };
        write_chart(Path::new("/tmp/blutrace_many.png"), &many).unwrap();
    }
}
