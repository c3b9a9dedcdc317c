//! False-colour maps of 2D grids as PNG images, for people to look at.
//!
//! [`write_map`] draws a [`Grid`] of values over a rectangle in mm through the viridis
//! colour map ([`viridis`]), grid row 0 at the bottom (`y` up), at the rectangle's
//! physical aspect ratio (the longer side 640 pixels), with a title above, axes with mm
//! ticks and their descriptions, and a colour bar on the right whose tick labels and unit
//! (written along the bar, right of its labels) get space of their own measured in the
//! font, so no text overlaps another. Bins without a meaningful value (NaN, infinite, or
//! negative when the range starts at zero or above) are drawn grey.
//!
//! Each pixel of the map shows the bin it falls in (pixel column `px` of `w` shows column
//! `px * nx / w`), so a map is exact at any grid size and its bytes depend only on the
//! grid and the options.
//!
//! ```text
//!               title
//!  y desc │ ┌──────────────┐  ┌┐ 1.2 │
//!   ticks ┤ │     map      │  ││ 0.6 │ unit
//!         │ └──────────────┘  └┘ 0   │
//!             x ticks, x desc
//! ```

use std::ops::Range;
use std::path::Path;

use anyhow::{Context, Result, ensure};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::figure::{
    Area, DESC_SIZE, FRAME, INVALID_GREY, LABEL_SIZE, TITLE_SIZE, drawing, format_label, render,
    text, text_width, viridis,
};
use super::png::encode;

/// The values of a map: `nx × ny` bins covering `x_mm × y_mm`.
#[derive(Clone, Copy, Debug)]
pub struct Grid<'a> {
    /// Bins along x.
    pub nx: usize,
    /// Bins along y.
    pub ny: usize,
    /// Row-major (`x` fastest), row 0 at the lowest `y`.
    pub values: &'a [f64],
    /// The span of x the bins cover (mm): column 0 starts at `x_mm[0]`.
    pub x_mm: [f64; 2],
    /// The span of y the bins cover (mm): row 0 starts at `y_mm[0]`.
    pub y_mm: [f64; 2],
}

/// What a map says about its values.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MapOptions {
    /// Text above the map.
    pub title: String,
    /// Description of the horizontal axis (its unit is mm).
    pub x_label: String,
    /// Description of the vertical axis.
    pub y_label: String,
    /// The values' quantity and unit, written along the colour bar.
    pub unit: String,
    /// Value drawn with the darkest colour; default `0`.
    pub min: Option<f64>,
    /// Value drawn with the brightest colour; default: the largest finite value (or `min`
    /// if that is larger).
    pub max: Option<f64>,
}

/// Write `grid` as a false-colour map to the PNG file `path` (overwriting it).
///
/// The colour range is `opts.min ..= opts.max` (defaults: `0` and the largest finite
/// value); values outside are clamped to the end colours. Fails on a grid whose size does
/// not match its values, an empty or inverted span, or a bad range.
pub fn write_map(path: &Path, grid: &Grid, opts: &MapOptions) -> Result<()> {
    let what = || format!("cannot write map {}", path.display());
    let r = render_map(grid, opts).with_context(what)?;
    let (lo, hi) = r.range;
    let comment = format!(
        "{}: viridis false colour of a {}x{} grid over x {:?} mm, y {:?} mm, range {lo} to \
         {hi}, grid row 0 at the bottom, grey = no value",
        opts.title, grid.nx, grid.ny, grid.x_mm, grid.y_mm
    );
    encode(path, r.size.0, r.size.1, &r.rgb, &comment).with_context(what)
}

/// A drawn map and where its parts are.
#[derive(Clone, Debug)]
#[cfg_attr(
    not(test),
    allow(dead_code, reason = "where the parts are: read by the tests")
)]
struct Rendered {
    /// Image size (pixels).
    size: (u32, u32),
    /// 8-bit RGB pixels, rows from the top.
    rgb: Vec<u8>,
    /// The colour range.
    range: (f64, f64),
    /// The map's pixels: columns, rows.
    map: PixelRect,
    /// The colour bar's pixels.
    bar: PixelRect,
}

/// A rectangle of pixels: `(columns, rows)`, ends excluded.
pub(crate) type PixelRect = (Range<i32>, Range<i32>);

/// Draw `grid` under `opts`.
fn render_map(grid: &Grid, opts: &MapOptions) -> Result<Rendered> {
    check(grid)?;
    let range = value_range(grid.values, opts)?;
    let layout = Layout::new(grid, opts, range);
    let mut placed = None;
    let rgb = render(layout.size, |root| {
        placed = Some(draw(root, grid, opts, range, &layout)?);
        Ok(())
    })?;
    let (map, bar) = placed.context("the map was not drawn")?;
    Ok(Rendered {
        size: layout.size,
        rgb,
        range,
        map,
        bar,
    })
}

/// Reject grids that cannot be drawn.
fn check(grid: &Grid) -> Result<()> {
    let (nx, ny) = (grid.nx, grid.ny);
    ensure!(nx > 0 && ny > 0, "empty grid ({nx} × {ny})");
    let count = nx
        .checked_mul(ny)
        .with_context(|| format!("grid {nx} × {ny} is too large"))?;
    ensure!(
        grid.values.len() == count,
        "{} values for a {nx} × {ny} grid (expected {count})",
        grid.values.len()
    );
    for (name, [a, b]) in [("x", grid.x_mm), ("y", grid.y_mm)] {
        ensure!(
            a.is_finite() && b.is_finite() && b > a,
            "the map's {name} span {a} to {b} mm is empty"
        );
    }
    Ok(())
}

/// The colour range `(lo, hi)` for `values` under `opts`.
pub(crate) fn value_range(values: &[f64], opts: &MapOptions) -> Result<(f64, f64)> {
    let lo = opts.min.unwrap_or(0.0);
    ensure!(lo.is_finite(), "map minimum {lo} is not finite");
    let hi = match opts.max {
        Some(hi) => {
            ensure!(hi.is_finite(), "map maximum {hi} is not finite");
            ensure!(hi >= lo, "map maximum {hi} is below the minimum {lo}");
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

/// The colour of `v` in the range `(lo, hi)`.
pub(crate) fn colour(v: f64, (lo, hi): (f64, f64)) -> RGBColor {
    if !is_drawable(v, lo) {
        INVALID_GREY
    } else if hi > lo {
        viridis((v - lo) / (hi - lo))
    } else {
        viridis(0.0)
    }
}

/// The range the colour bar's axis shows: `(lo, hi)`, widened when it is empty.
fn bar_range((lo, hi): (f64, f64)) -> (f64, f64) {
    if hi > lo {
        (lo, hi)
    } else {
        (lo, lo + lo.abs().max(1.0))
    }
}

/// The longer side of the map (pixels).
const LONG_SIDE: u32 = 640;
/// The colour bar is at least this tall (a flat map is centred beside it).
const BAR_MIN_H: u32 = 240;
/// Width of the colour bar.
pub(crate) const BAR_W: u32 = 26;
/// Blank border around everything and between the map and the colour bar.
pub(crate) const PAD: u32 = 16;
/// Space between the map and the colour bar.
pub(crate) const GAP: u32 = 28;
/// Length of tick marks; `plotters` puts labels twice as far from the axis.
const TICK: u32 = 5;
/// Height of the title row.
pub(crate) const TITLE_H: u32 = 44;
/// Tick labels wanted on the colour bar.
const BAR_TICKS: usize = 6;

/// Pixel geometry of a map figure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Layout {
    /// Image size.
    size: (u32, u32),
    /// The map's plot area size.
    plot: (u32, u32),
    /// Height of the map and colour bar row (at least the map's).
    content_h: u32,
    /// Width of the y tick labels and description left of the map.
    y_area: u32,
    /// Height of the x tick labels and description below it.
    x_area: u32,
    /// Width of the colour bar's tick labels and unit.
    bar_area: u32,
}

impl Layout {
    /// The layout of `grid` with room for every label, measured in the font.
    fn new(grid: &Grid, opts: &MapOptions, range: (f64, f64)) -> Self {
        let (ex, ey) = (grid.x_mm[1] - grid.x_mm[0], grid.y_mm[1] - grid.y_mm[0]);
        let long = ex.max(ey);
        let side = |e: f64| ((f64::from(LONG_SIDE) * e / long).round() as u32).max(1);
        let plot = (side(ex), side(ey));
        let content_h = plot.1.max(BAR_MIN_H);
        // Text sizes need a drawing area; any will do (drawing on it cannot fail).
        let (mut m, mut bar_area) = (Measures::default(), 0);
        let _ = render((1, 1), |a| {
            m = Measures::of(a, grid, opts, plot);
            bar_area = bar_label_area(a, &opts.unit, range);
            Ok(())
        });
        let desc = m.desc_h + 6;
        let y_area = 2 * TICK + m.y_label_w + 8 + if opts.y_label.is_empty() { 0 } else { desc };
        let x_area = 2 * TICK + m.label_h + 6 + if opts.x_label.is_empty() { 0 } else { desc };
        let w = PAD + y_area + plot.0 + GAP + BAR_W + bar_area + PAD;
        let w = w.max(m.title_w + 2 * PAD);
        let h = TITLE_H + content_h + x_area + PAD;
        Self {
            size: (w, h),
            plot,
            content_h,
            y_area,
            x_area,
            bar_area,
        }
    }
}

/// Text sizes a layout needs (pixels).
#[derive(Clone, Copy, Debug, Default)]
struct Measures {
    /// The widest tick label of the y axis.
    y_label_w: u32,
    /// Height of a tick label.
    label_h: u32,
    /// Height of an axis description.
    desc_h: u32,
    /// Width of the title.
    title_w: u32,
}

impl Measures {
    /// Measure the labels of `grid` drawn under `opts` with a plot area of `plot` pixels.
    fn of(a: &Area, grid: &Grid, opts: &MapOptions, plot: (u32, u32)) -> Self {
        let (label, desc) = (text(LABEL_SIZE), text(DESC_SIZE));
        let widest = |ticks: Vec<f64>| {
            ticks
                .iter()
                .map(|v| text_width(a, &format_label(*v), &label))
                .max()
                .unwrap_or(0)
        };
        Self {
            y_label_w: widest(axis(grid.y_mm).key_points(y_ticks(plot.1))),
            label_h: text_height(a, &label),
            desc_h: text_height(a, &desc),
            title_w: text_width(a, &opts.title, &text(TITLE_SIZE)),
        }
    }
}

/// Height of a line of text in `style` (pixels).
pub(crate) fn text_height(a: &Area, style: &TextStyle) -> u32 {
    a.estimate_text_size("0Ay", style).map_or(0, |(_, h)| h)
}

/// Width right of a colour bar of the range `range` for its tick labels and its `unit`
/// (pixels), measured in the font.
pub(crate) fn bar_label_area(a: &Area, unit: &str, range: (f64, f64)) -> u32 {
    let (lo, hi) = bar_range(range);
    let label = text(LABEL_SIZE);
    let widest = RangedCoordf64::from(lo..hi)
        .key_points(BAR_TICKS)
        .iter()
        .map(|v| text_width(a, &format_label(*v), &label))
        .max()
        .unwrap_or(0);
    let desc = text_height(a, &text(DESC_SIZE)) + 6;
    2 * TICK + widest + 8 + if unit.is_empty() { 0 } else { desc }
}

/// A linear axis over `[a, b]`.
fn axis([a, b]: [f64; 2]) -> RangedCoordf64 {
    RangedCoordf64::from(a..b)
}

/// Tick labels wanted along an axis of `len` pixels.
fn x_ticks(len: u32) -> usize {
    (len / 80).clamp(2, 10) as usize
}

/// Tick labels wanted along a vertical axis of `len` pixels.
fn y_ticks(len: u32) -> usize {
    (len / 60).clamp(2, 10) as usize
}

/// Draw the whole figure.
fn draw(
    root: &Area,
    grid: &Grid,
    opts: &MapOptions,
    range: (f64, f64),
    l: &Layout,
) -> Result<(PixelRect, PixelRect)> {
    let title = text(TITLE_SIZE).pos(Pos::new(HPos::Center, VPos::Center));
    root.draw_text(
        &opts.title,
        &title,
        ((l.size.0 / 2) as i32, (TITLE_H / 2) as i32),
    )
    .map_err(drawing)?;
    let body = root.margin(TITLE_H, PAD, PAD, 0);
    let map_w = l.y_area + l.plot.0 + GAP;
    let (map_area, bar_area) = body.split_horizontally(map_w);
    let map = draw_grid(&map_area, grid, range, opts, l)?;
    let bar = draw_bar(&bar_area, &opts.unit, range, (l.x_area, l.bar_area))?;
    for (xs, ys) in [&map, &bar] {
        let r = [(xs.start - 1, ys.start - 1), (xs.end, ys.end)];
        root.draw(&Rectangle::new(r, FRAME.stroke_width(1)))
            .map_err(drawing)?;
    }
    Ok((map, bar))
}

/// The map with its mm axes, centred in the content row.
fn draw_grid(
    area: &Area,
    grid: &Grid,
    range: (f64, f64),
    opts: &MapOptions,
    l: &Layout,
) -> Result<PixelRect> {
    let above = (l.content_h - l.plot.1) / 2;
    let below = l.content_h - l.plot.1 - above;
    let mut chart = ChartBuilder::on(area)
        .margin_top(above)
        .margin_bottom(below)
        .margin_right(GAP)
        .x_label_area_size(l.x_area)
        .y_label_area_size(l.y_area)
        .build_cartesian_2d(axis(grid.x_mm), axis(grid.y_mm))
        .map_err(drawing)?;
    let fmt = |v: &f64| format_label(*v);
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(x_ticks(l.plot.0))
        .y_labels(y_ticks(l.plot.1))
        .x_label_formatter(&fmt)
        .y_label_formatter(&fmt)
        .set_all_tick_mark_size(TICK)
        .label_style(text(LABEL_SIZE))
        .axis_desc_style(text(DESC_SIZE))
        .axis_style(FRAME)
        .x_desc(opts.x_label.as_str())
        .y_desc(opts.y_label.as_str())
        .draw()
        .map_err(drawing)?;
    let plot = chart.plotting_area().strip_coord_spec();
    fill_pixels(&plot, grid, range)?;
    Ok(plot.get_pixel_range())
}

/// Colour every pixel of `plot` with the bin it falls in (row 0 at the bottom).
fn fill_pixels(
    plot: &DrawingArea<BitMapBackend, Shift>,
    grid: &Grid,
    range: (f64, f64),
) -> Result<()> {
    let (w, h) = plot.dim_in_pixel();
    let (w, h) = (w as usize, h as usize);
    for py in 0..h {
        let gy = grid.ny - 1 - py * grid.ny / h;
        let row = &grid.values[gy * grid.nx..(gy + 1) * grid.nx];
        // Runs of pixels in one bin, one rectangle each.
        let mut px = 0;
        while px < w {
            let gx = px * grid.nx / w;
            let end = ((gx + 1) * w).div_ceil(grid.nx).min(w);
            let c = colour(row[gx], range);
            // Filled rectangles exclude their lower right corner.
            let corners = [(px as i32, py as i32), (end as i32, py as i32 + 1)];
            let r = Rectangle::new(corners, c.filled());
            plot.draw(&r).map_err(drawing)?;
            px = end;
        }
    }
    Ok(())
}

/// The colour bar of `range` in `area` (from its top to `bottom` pixels above its
/// bottom): `hi` at the top, tick labels and the `unit` right of it, in `label_area`
/// pixels ([`bar_label_area`]).
pub(crate) fn draw_bar(
    area: &Area,
    unit: &str,
    range: (f64, f64),
    (bottom, label_area): (u32, u32),
) -> Result<PixelRect> {
    let (lo, hi) = bar_range(range);
    // The area is wider than the bar and its labels when the title is wider than the rest.
    let right = area.dim_in_pixel().0.saturating_sub(BAR_W + label_area);
    let mut chart = ChartBuilder::on(area)
        .margin_bottom(bottom)
        .margin_right(right)
        .right_y_label_area_size(label_area)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(drawing)?;
    let fmt = |v: &f64| format_label(*v);
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(BAR_TICKS)
        .y_label_formatter(&fmt)
        .set_all_tick_mark_size(TICK)
        .label_style(text(LABEL_SIZE))
        .axis_desc_style(text(DESC_SIZE))
        .axis_style(FRAME)
        .y_desc(unit)
        .draw()
        .map_err(drawing)?;
    let bar = chart.plotting_area().strip_coord_spec();
    let (w, h) = bar.dim_in_pixel();
    let denom = f64::from(h.max(2) - 1);
    for j in 0..h {
        let t = 1.0 - f64::from(j) / denom;
        let r = Rectangle::new(
            [(0, j as i32), (w as i32, j as i32 + 1)],
            viridis(t).filled(),
        );
        bar.draw(&r).map_err(drawing)?;
    }
    Ok(bar.get_pixel_range())
}

#[cfg(test)]
#[path = "map_tests.rs"]
mod tests;
