//! Line charts as PNG images, for people to look at.
//!
//! [`write_chart`] draws a [`Chart`] — a few [`Series`] of `(x, y)` points — as an
//! 800×560 pixel PNG: white background, a framed plot area with light grid lines, numeric
//! tick labels, axis labels, a title and a legend, all written with the built-in 5×7 pixel
//! font of the `font` module. Each axis is linear or logarithmic ([`Scale`]); its range is
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

use super::font::{descends, format_label, glyph};
use super::png::encode;
use axis::{Axis, transform};
use canvas::{Canvas, SHAPES};

mod axis;
mod canvas;

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
/// A chart never costs a run its results: when there is nothing to draw (no series, no
/// drawable point: all points non-finite or, on a logarithmic axis, not positive; or an
/// axis range too wide to represent), the file is a framed placeholder with the title and
/// the reason. Fails only if the file cannot be written.
pub fn write_chart(path: &Path, chart: &Chart) -> Result<()> {
    let what = || format!("cannot write chart {}", path.display());
    let r = render(chart).unwrap_or_else(|why| placeholder(chart, &format!("{why:#}")));
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

/// A chart with nothing to draw: its frame, its title and why, wrapped to the width.
fn placeholder(chart: &Chart, why: &str) -> Rendered {
    let mut canvas = Canvas::new(WIDTH, HEIGHT, BACKGROUND);
    let plot = Rect::new(
        MARGIN,
        PLOT_TOP,
        WIDTH - 2 * MARGIN,
        HEIGHT - PLOT_TOP - MARGIN,
    );
    canvas.frame(plot, FRAME);
    let centred = |canvas: &mut Canvas, y: i64, line: &str| {
        canvas.text((WIDTH - text_width(line)) / 2, y, line, INK);
    };
    centred(&mut canvas, MARGIN / 2, &chart.title);
    let mut lines = vec![String::from("nothing to draw:")];
    let max_chars = ((plot.w - 40) / text_width("m").max(1)) as usize;
    for word in why.split_whitespace() {
        let last = lines.last_mut().expect("one line at least");
        if last.len() + 1 + word.len() > max_chars && !last.is_empty() {
            lines.push(word.to_string());
        } else {
            if !last.is_empty() {
                last.push(' ');
            }
            last.push_str(word);
        }
    }
    let top = plot.y + plot.h / 2 - (lines.len() as i64 * (CHAR_H + 6)) / 2;
    for (k, line) in lines.iter().enumerate() {
        centred(&mut canvas, top + k as i64 * (CHAR_H + 6), line);
    }
    Rendered {
        width: WIDTH,
        height: HEIGHT,
        rgb: canvas.rgb,
        plot,
        x: Axis::fit(Scale::Linear, 0.0, 1.0).expect("a unit axis fits"),
        y: Axis::fit(Scale::Linear, 0.0, 1.0).expect("a unit axis fits"),
        legend: None,
    }
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
mod tests;
