//! Line charts as PNG images, for people to look at, drawn with `plotters`.
//!
//! [`write_chart`] draws a [`Chart`] — a few [`Series`] of `(x, y)` points — as an
//! 800×560 pixel PNG: white background, a title, a framed plot area with light grid
//! lines, numeric tick labels, axis descriptions and a legend, in the embedded font of
//! [`super::figure`]. Each axis is linear or logarithmic ([`Scale`]); its range is chosen
//! from the data.
//!
//! - A linear axis spans the data with 5 % to spare on each side; a single value gets
//!   ±10 % of it (±1 around zero). `plotters` picks "nice" ticks (1, 2, 5 times a power
//!   of ten).
//! - A logarithmic axis spans whole decades around the data (so its ends are labelled
//!   powers of ten), with light grid lines between them.
//! - Series are 2 pixel wide lines (optionally dashed, optionally with a marker at every
//!   point) in the colours of the Tableau 10 palette, in order; markers also differ in
//!   shape between series.
//! - Points with a non-finite coordinate, or a non-positive one on a logarithmic axis, are
//!   skipped, and the line is interrupted there; a point left alone gets a marker.
//! - The legend stands right of the plot area, so it hides no data.
//! - With nothing to draw, the chart is a framed placeholder with the title and the reason.

use std::ops::Range;
use std::path::Path;

use anyhow::{Context, Result, bail, ensure};
use plotters::coord::ranged1d::{AsRangedCoord, Ranged, ValueFormatter};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::figure::{
    Area, DESC_SIZE, FRAME, LABEL_SIZE, TITLE_SIZE, drawing, format_label, render, series_colour,
    text, text_width,
};
use super::png::encode;
use glyph::Glyph;

mod glyph;
mod legend;

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

/// Image size in pixels.
const WIDTH: u32 = 800;
const HEIGHT: u32 = 560;
/// Blank border around everything.
const PAD: u32 = 14;
/// Length of tick marks; `plotters` puts labels twice as far from the axis.
const TICK: u32 = 5;
/// Space between the plot area and the legend right of it.
const LEGEND_GAP: u32 = 16;
/// Tick labels wanted on the horizontal and the vertical axis.
const X_TICKS: usize = 8;
const Y_TICKS: usize = 8;

/// Write `chart` as an 800×560 pixel PNG file to `path` (overwriting it).
///
/// A chart never costs a run its results: when there is nothing to draw (no series, no
/// drawable point: all points non-finite or, on a logarithmic axis, not positive; or an
/// axis range too wide to represent), the file is a framed placeholder with the title and
/// the reason. Fails only if the file cannot be written.
pub fn write_chart(path: &Path, chart: &Chart) -> Result<()> {
    let what = || format!("cannot write chart {}", path.display());
    let (rgb, _) = render_chart(chart).with_context(what)?;
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
    encode(path, WIDTH, HEIGHT, &rgb, &comment).with_context(what)
}

/// A rectangle of pixels: `(columns, rows)`, ends excluded.
type PixelRect = (Range<i32>, Range<i32>);

/// The pixels of `chart` (or of its placeholder), and its plot area (None: placeholder).
fn render_chart(chart: &Chart) -> Result<(Vec<u8>, Option<PixelRect>)> {
    match axis_ranges(chart) {
        Ok(ranges) => {
            let mut plot = None;
            let rgb = render((WIDTH, HEIGHT), |root| {
                plot = Some(draw_chart(root, chart, ranges)?);
                Ok(())
            })?;
            Ok((rgb, plot))
        }
        Err(why) => {
            let why = format!("{why:#}");
            let rgb = render((WIDTH, HEIGHT), |root| placeholder(root, chart, &why))?;
            Ok((rgb, None))
        }
    }
}

/// The position of `v` on an axis of `scale`, or None if it cannot be drawn there.
fn transform(scale: Scale, v: f64) -> Option<f64> {
    match scale {
        Scale::Linear => v.is_finite().then_some(v),
        Scale::Log10 => (v.is_finite() && v > 0.0).then(|| v.log10()),
    }
}

/// The drawable points of `chart`: `(x, y)` with both coordinates drawable.
fn drawable(chart: &Chart) -> impl Iterator<Item = (f64, f64)> + '_ {
    chart
        .series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .filter(|&(x, y)| {
            transform(chart.x_scale, x).is_some() && transform(chart.y_scale, y).is_some()
        })
}

/// The axis ranges (data values) of `chart`; an error says why there is nothing to draw.
fn axis_ranges(chart: &Chart) -> Result<((f64, f64), (f64, f64))> {
    if chart.series.is_empty() {
        bail!("chart {:?} has no series", chart.title);
    }
    let mut points = drawable(chart).peekable();
    if points.peek().is_none() {
        bail!(
            "chart {:?} has no drawable point (every point has a non-finite coordinate, or a \
             non-positive one on a logarithmic axis)",
            chart.title
        );
    }
    let span = |lo: (f64, f64), (x, y): (f64, f64)| (lo.0.min(x), lo.1.max(y));
    let init = (
        (f64::INFINITY, f64::NEG_INFINITY),
        (f64::INFINITY, f64::NEG_INFINITY),
    );
    let (xs, ys) = points.fold(init, |(xs, ys), (x, y)| {
        (span(xs, (x, x)), span(ys, (y, y)))
    });
    let x = axis_range(chart.x_scale, xs).context("horizontal axis")?;
    let y = axis_range(chart.y_scale, ys).context("vertical axis")?;
    Ok((x, y))
}

/// The range an axis of `scale` shows for data spanning `(lo, hi)`.
fn axis_range(scale: Scale, (lo, hi): (f64, f64)) -> Result<(f64, f64)> {
    let (a, b) = match scale {
        Scale::Linear if hi > lo => (lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo)),
        Scale::Linear if lo == 0.0 => (-1.0, 1.0),
        Scale::Linear => (lo - 0.1 * lo.abs(), lo + 0.1 * lo.abs()),
        Scale::Log10 => {
            let (a, b) = (lo.log10().floor(), hi.log10().ceil());
            let (a, b) = if b > a { (a, b) } else { (a - 0.5, b + 0.5) };
            // A hair wider, so that rounding in `plotters` keeps the end decades labelled.
            (10f64.powf(a) * (1.0 - 1e-9), 10f64.powf(b) * (1.0 + 1e-9))
        }
    };
    ensure!(
        a.is_finite() && b.is_finite() && (b - a).is_finite() && b > a,
        "the data range {lo} to {hi} is too wide to draw"
    );
    Ok((a, b))
}

/// Draw `chart` over the axis ranges `(x, y)`; returns the plot area.
fn draw_chart(root: &Area, chart: &Chart, (x, y): ((f64, f64), (f64, f64))) -> Result<PixelRect> {
    let lin = |(a, b): (f64, f64)| a..b;
    let log = |(a, b): (f64, f64)| (a..b).log_scale();
    match (chart.x_scale, chart.y_scale) {
        (Scale::Linear, Scale::Linear) => draw_axes(root, chart, lin(x), lin(y)),
        (Scale::Linear, Scale::Log10) => draw_axes(root, chart, lin(x), log(y)),
        (Scale::Log10, Scale::Linear) => draw_axes(root, chart, log(x), lin(y)),
        (Scale::Log10, Scale::Log10) => draw_axes(root, chart, log(x), log(y)),
    }
}

/// The widest tick label of `coord` (pixels) and the last one's width.
fn label_widths<C: Ranged<ValueType = f64>>(root: &Area, coord: &C, n: usize) -> (u32, u32) {
    let style = text(LABEL_SIZE);
    let widths: Vec<u32> = coord
        .key_points(n)
        .iter()
        .map(|v| text_width(root, &format_label(*v), &style))
        .collect();
    (
        widths.iter().copied().max().unwrap_or(0),
        widths.last().copied().unwrap_or(0),
    )
}

/// Room for the text around the plot area, measured in the font (pixels): left of it
/// (y tick labels and description), below it (x tick labels and description) and right of
/// it (the legend, or half the last x tick label).
fn label_room<X, Y>(root: &Area, chart: &Chart, x: &X, y: &Y) -> (u32, u32, u32)
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let (y_label_w, _) = label_widths(root, y, Y_TICKS);
    let (_, last_x_w) = label_widths(root, x, X_TICKS);
    let height = |s: &TextStyle| root.estimate_text_size("Ay", s).map_or(0, |(_, h)| h);
    let desc = |label: &str| match label {
        "" => 0,
        _ => height(&text(DESC_SIZE)) + 6,
    };
    let y_area = 2 * TICK + y_label_w + 8 + desc(&chart.y_label);
    let x_area = 2 * TICK + height(&text(LABEL_SIZE)) + 8 + desc(&chart.x_label);
    let right = match legend::width(root, chart) {
        0 => PAD.max(last_x_w / 2 + 6),
        w => w + LEGEND_GAP + PAD,
    };
    (y_area, x_area, right)
}

/// Draw the chart on the axes `x` and `y` (linear or logarithmic ranges).
fn draw_axes<X, Y>(root: &Area, chart: &Chart, x: X, y: Y) -> Result<PixelRect>
where
    X: AsRangedCoord<Value = f64> + Clone,
    Y: AsRangedCoord<Value = f64> + Clone,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let (xc, yc): (X::CoordDescType, Y::CoordDescType) = (x.clone().into(), y.clone().into());
    let (y_area, x_area, right) = label_room(root, chart, &xc, &yc);
    let mut c = ChartBuilder::on(root)
        .caption(&chart.title, text(TITLE_SIZE))
        .margin(PAD)
        .margin_right(right)
        .x_label_area_size(x_area)
        .y_label_area_size(y_area)
        .build_cartesian_2d(x, y)
        .map_err(drawing)?;
    let fmt = |v: &f64| format_label(*v);
    c.configure_mesh()
        .x_labels(X_TICKS)
        .y_labels(Y_TICKS)
        .x_label_formatter(&fmt)
        .y_label_formatter(&fmt)
        .set_all_tick_mark_size(TICK)
        .bold_line_style(RGBColor(222, 222, 222))
        .light_line_style(RGBColor(242, 242, 242))
        .max_light_lines(4)
        .label_style(text(LABEL_SIZE))
        .axis_desc_style(text(DESC_SIZE))
        .axis_style(FRAME)
        .x_desc(chart.x_label.as_str())
        .y_desc(chart.y_label.as_str())
        .draw()
        .map_err(drawing)?;
    for (i, s) in chart.series.iter().enumerate() {
        draw_series(&mut c, chart, i, s)?;
    }
    let (xs, ys) = c.plotting_area().get_pixel_range();
    legend::draw(root, chart, (xs.end + LEGEND_GAP as i32, ys.start))?;
    let r = [(xs.start, ys.start), (xs.end - 1, ys.end - 1)];
    root.draw(&Rectangle::new(r, FRAME.stroke_width(1)))
        .map_err(drawing)?;
    Ok((xs, ys))
}

/// The chart context `draw_axes` draws series into.
type Ctx<'a, 'b, X, Y> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<X, Y>>;

/// Draw series `i`: its runs of drawable points as lines, and its markers.
fn draw_series<'a, 'b: 'a, X, Y>(
    c: &mut Ctx<'a, 'b, X, Y>,
    chart: &Chart,
    i: usize,
    s: &Series,
) -> Result<()>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let style = series_colour(i).stroke_width(2);
    let ok = |&(x, y): &(f64, f64)| {
        transform(chart.x_scale, x).is_some() && transform(chart.y_scale, y).is_some()
    };
    let runs: Vec<Vec<(f64, f64)>> = s
        .points
        .split(|p| !ok(p))
        .filter(|r| !r.is_empty())
        .map(<[_]>::to_vec)
        .collect();
    for run in &runs {
        if run.len() == 1 && !s.markers {
            c.draw_series([marker(i, run[0], style)]).map_err(drawing)?;
        } else if s.dashed {
            c.draw_series(DashedLineSeries::new(run.iter().copied(), 10, 6, style))
                .map_err(drawing)?;
        } else {
            c.draw_series(LineSeries::new(run.iter().copied(), style))
                .map_err(drawing)?;
        }
        if s.markers {
            c.draw_series(run.iter().map(|&p| marker(i, p, style)))
                .map_err(drawing)?;
        }
    }
    Ok(())
}

/// The marker of series `i` at the data point `at`.
fn marker(i: usize, at: (f64, f64), style: ShapeStyle) -> Glyph<(f64, f64)> {
    Glyph {
        at,
        style,
        marker: Some(i),
        line: None,
    }
}

/// A chart with nothing to draw: its frame, its title and why, wrapped to the width.
fn placeholder(root: &Area, chart: &Chart, why: &str) -> Result<()> {
    let title = text(TITLE_SIZE).pos(Pos::new(HPos::Center, VPos::Top));
    root.draw_text(&chart.title, &title, ((WIDTH / 2) as i32, PAD as i32))
        .map_err(drawing)?;
    let top = 2 * PAD + 24;
    let frame = [
        (PAD as i32, top as i32),
        ((WIDTH - PAD) as i32, (HEIGHT - PAD) as i32),
    ];
    root.draw(&Rectangle::new(frame, FRAME.stroke_width(1)))
        .map_err(drawing)?;
    let style = text(DESC_SIZE).pos(Pos::new(HPos::Center, VPos::Top));
    let max_w = WIDTH - 2 * PAD - 60;
    let mut lines = vec![String::from("nothing to draw:")];
    for word in why.split_whitespace() {
        let last = lines.last_mut().expect("one line at least");
        let longer = format!("{last} {word}");
        if !last.is_empty() && text_width(root, &longer, &style) > max_w {
            lines.push(word.to_string());
        } else {
            *last = longer.trim_start().to_string();
        }
    }
    let line_h = 24;
    let y0 = (top + HEIGHT - PAD) as i32 / 2 - line_h * lines.len() as i32 / 2;
    for (k, line) in lines.iter().enumerate() {
        let at = ((WIDTH / 2) as i32, y0 + line_h * k as i32);
        root.draw_text(line, &style, at).map_err(drawing)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests;
