//! The chart canvas: clipped pixels, text, lines and series markers.

use super::*;

/// Marker shapes, used in turn by the series.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Shape {
    Circle,
    Square,
    Diamond,
    TriangleUp,
    TriangleDown,
}

pub(super) const SHAPES: [Shape; 5] = [
    Shape::Circle,
    Shape::Square,
    Shape::Diamond,
    Shape::TriangleUp,
    Shape::TriangleDown,
];

impl Shape {
    /// Whether the offset `(dx, dy)` from the centre (`dy` down) is inside the marker.
    pub(super) fn covers(self, dx: i64, dy: i64) -> bool {
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
pub(super) struct Canvas {
    pub(super) w: i64,
    pub(super) h: i64,
    pub(super) rgb: Vec<u8>,
    pub(super) clip: Rect,
}

impl Canvas {
    pub(super) fn new(w: i64, h: i64, fill: [u8; 3]) -> Self {
        Self {
            w,
            h,
            rgb: fill.repeat((w * h) as usize),
            clip: Rect::new(0, 0, w, h),
        }
    }

    pub(super) fn full(&self) -> Rect {
        Rect::new(0, 0, self.w, self.h)
    }

    pub(super) fn get(&self, x: i64, y: i64) -> [u8; 3] {
        let i = 3 * (y * self.w + x) as usize;
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    pub(super) fn set(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if self.clip.contains(x, y) && (0..self.w).contains(&x) && (0..self.h).contains(&y) {
            let i = 3 * (y * self.w + x) as usize;
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    pub(super) fn fill_rect(&mut self, r: Rect, c: [u8; 3]) {
        for y in r.y..r.y + r.h {
            for x in r.x..r.x + r.w {
                self.set(x, y, c);
            }
        }
    }

    /// A one-pixel frame just outside `r`.
    pub(super) fn frame(&mut self, r: Rect, c: [u8; 3]) {
        let (x0, y0, x1, y1) = (r.x - 1, r.y - 1, r.x + r.w, r.y + r.h);
        self.fill_rect(Rect::new(x0, y0, r.w + 2, 1), c);
        self.fill_rect(Rect::new(x0, y1, r.w + 2, 1), c);
        self.fill_rect(Rect::new(x0, y0, 1, r.h + 2), c);
        self.fill_rect(Rect::new(x1, y0, 1, r.h + 2), c);
    }

    /// Draw `text` with its top-left corner at `(x, y)`.
    pub(super) fn text(&mut self, x: i64, y: i64, text: &str, c: [u8; 3]) {
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
    pub(super) fn text_up(&mut self, x: i64, y: i64, text: &str, c: [u8; 3]) {
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
    pub(super) fn dot(&mut self, x: i64, y: i64, c: [u8; 3]) {
        self.fill_rect(Rect::new(x, y, 2, 2), c);
    }

    /// A 2 pixel wide polyline through `pts` (Bresenham), dashed if asked; the dash
    /// pattern continues across vertices.
    pub(super) fn polyline(&mut self, pts: &[(i64, i64)], c: [u8; 3], dashed: bool) {
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
    pub(super) fn marker(&mut self, shape: Shape, x: i64, y: i64, c: [u8; 3]) {
        for dy in -MARKER_R..=MARKER_R {
            for dx in -MARKER_R..=MARKER_R {
                if shape.covers(dx, dy) {
                    self.set(x + dx, y + dy, c);
                }
            }
        }
    }

    /// How many pixels of `r` differ from the background and the grid.
    pub(super) fn busy_pixels(&self, r: Rect) -> usize {
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
