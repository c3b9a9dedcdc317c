//! The legend of a chart: right of the plot area, one row per labelled series (its line
//! sample, marker and label), in a light frame.

use anyhow::Result;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::Chart;
use super::glyph::{Glyph, LEGEND_SAMPLE};
use crate::output::figure::{Area, drawing, series_colour, text, text_width};

/// Font size of the legend.
const SIZE: f64 = 15.0;
/// Padding inside the frame.
const PAD: i32 = 8;
/// Height of a row.
const ROW: i32 = 22;

/// The labelled series: `(index, label)`.
fn entries(chart: &Chart) -> impl Iterator<Item = (usize, &str)> {
    chart
        .series
        .iter()
        .enumerate()
        .filter(|(_, s)| !s.label.is_empty())
        .map(|(i, s)| (i, s.label.as_str()))
}

/// Width of the legend of `chart` in pixels; 0 when no series has a label.
pub(super) fn width(root: &Area, chart: &Chart) -> u32 {
    let style = text(SIZE);
    entries(chart)
        .map(|(_, label)| text_width(root, label, &style))
        .max()
        .map_or(0, |w| w + (LEGEND_SAMPLE + 3 * PAD) as u32)
}

/// Draw the legend of `chart` with its upper left corner at `(x, y)`.
pub(super) fn draw(root: &Area, chart: &Chart, (x, y): (i32, i32)) -> Result<()> {
    let w = width(root, chart) as i32;
    let rows: Vec<(usize, &str)> = entries(chart).collect();
    if rows.is_empty() {
        return Ok(());
    }
    let h = 2 * PAD + ROW * rows.len() as i32 - (ROW - SIZE as i32) / 2;
    let frame = Rectangle::new([(x, y), (x + w, y + h)], RGBColor(160, 160, 160));
    root.draw(&frame).map_err(drawing)?;
    let style = text(SIZE).pos(Pos::new(HPos::Left, VPos::Center));
    for (k, (i, label)) in rows.into_iter().enumerate() {
        let s = &chart.series[i];
        let cy = y + PAD + ROW / 2 + ROW * k as i32;
        let sample = Glyph {
            at: (x + PAD, cy),
            style: series_colour(i).stroke_width(2),
            marker: s.markers.then_some(i),
            line: Some(s.dashed),
        };
        root.draw(&sample).map_err(drawing)?;
        let at = (x + 2 * PAD + LEGEND_SAMPLE, cy);
        root.draw_text(label, &style, at).map_err(drawing)?;
    }
    Ok(())
}
