//! The markers of series and the samples of the legend, drawn straight on the backend.
//!
//! One element type for both, so that a legend entry (line, dash and marker) is a single
//! element: `plotters`' composed elements carry the backend in their type, which a buffer
//! backend (borrowing its pixels) cannot lend for `'static`, as the legend requires.

use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;
use plotters_backend::{BackendCoord, DrawingErrorKind};

/// Length of the line sample in the legend (pixels).
pub(super) const LEGEND_SAMPLE: i32 = 34;

/// A marker at a point, or a legend sample (a line with an optional marker) from it.
pub(super) struct Glyph<C> {
    /// Where: a data point for a marker, the left end of a legend sample.
    pub at: C,
    /// Colour and line width.
    pub style: ShapeStyle,
    /// Marker shape, by series index (disc, triangle, square, cross, repeating).
    pub marker: Option<usize>,
    /// A legend sample: its line, dashed or not.
    pub line: Option<bool>,
}

impl<'a, C: 'a> PointCollection<'a, C> for &'a Glyph<C> {
    type Point = &'a C;
    type IntoIter = std::iter::Once<&'a C>;

    fn point_iter(self) -> Self::IntoIter {
        std::iter::once(&self.at)
    }
}

impl<C, DB: DrawingBackend> Drawable<DB> for Glyph<C> {
    fn draw<I: Iterator<Item = BackendCoord>>(
        &self,
        mut pos: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
        let Some((x, y)) = pos.next() else {
            return Ok(());
        };
        let centre = match self.line {
            None => (x, y),
            Some(dashed) => {
                let dashes: &[(i32, i32)] = if dashed {
                    &[(0, 10), (16, 26)]
                } else {
                    &[(0, LEGEND_SAMPLE)]
                };
                for &(a, b) in dashes {
                    backend.draw_path([(x + a, y), (x + b, y)], &self.style)?;
                }
                (x + LEGEND_SAMPLE / 2, y)
            }
        };
        match self.marker {
            Some(shape) => draw_marker(backend, shape, centre, &self.style),
            None => Ok(()),
        }
    }
}

/// Draw marker `shape` (mod 4: disc, triangle, square, cross) centred on `(x, y)`.
fn draw_marker<DB: DrawingBackend>(
    backend: &mut DB,
    shape: usize,
    (x, y): BackendCoord,
    style: &ShapeStyle,
) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
    let fill = style.filled();
    match shape % 4 {
        0 => backend.draw_circle((x, y), 4, &fill, true),
        1 => backend.fill_polygon([(x, y - 5), (x - 5, y + 4), (x + 5, y + 4)], &fill),
        // Filled rectangles exclude their lower right corner: 7 × 7 pixels.
        2 => backend.draw_rect((x - 3, y - 3), (x + 4, y + 4), &fill, true),
        _ => {
            backend.draw_path([(x - 4, y - 4), (x + 4, y + 4)], style)?;
            backend.draw_path([(x - 4, y + 4), (x + 4, y - 4)], style)
        }
    }
}
