//! Polar false-colour plots of (theta, phi) grids as PNG images: a conoscope's view.
//!
//! [`write_polar`] draws a [`PolarGrid`] as a disc: theta is the radius (0 at the centre,
//! the grid's largest theta at the rim), phi the polar angle (0 to the right, growing
//! counter-clockwise), through the viridis colour map of [`super::map`], with the same
//! title row and colour bar as a map. Rings every [`PolarGrid::ring_step_deg`] degrees are
//! drawn in white and labelled along the phi = 0 spoke; phi is labelled at 0, 90, 180 and
//! 270 degrees outside the rim.
//!
//! Each pixel inside the disc shows the bin its centre falls in, so the image depends only
//! on the grid and the options (the same bytes for the same values).
//!
//! ```text
//!              title
//!            90°
//!         ╭───────╮         ┌┐ 1.2 │
//!   180°  │  ○ 20° │  0°    ││ 0.6 │ unit
//!         ╰───────╯         └┘ 0   │
//!            270°
//! ```

use std::f64::consts::TAU;
use std::path::Path;

use anyhow::{Context, Result, ensure};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::figure::{Area, FRAME, LABEL_SIZE, TITLE_SIZE, drawing, render, text, text_width};
use super::map::{
    BAR_W, GAP, MapOptions, PAD, TITLE_H, bar_label_area, colour, draw_bar, text_height,
    value_range,
};
use super::png::encode;

/// The values of a polar plot: `n_theta` rings of `n_phi` bins.
#[derive(Clone, Copy, Debug)]
pub struct PolarGrid<'a> {
    /// Bins along theta (rings, from the centre out).
    pub n_theta: usize,
    /// Bins along phi (sectors, from phi = 0 counter-clockwise).
    pub n_phi: usize,
    /// Row-major, phi fastest: `values[it * n_phi + ip]`.
    pub values: &'a [f64],
    /// Theta at the rim (degrees): the bins split `0..theta_max_deg` evenly.
    pub theta_max_deg: f64,
    /// Rings (and their labels) every this many degrees of theta.
    pub ring_step_deg: f64,
}

/// Diameter of the disc (pixels).
const DISC: u32 = 560;
/// Room around the disc for the phi labels (pixels).
const RIM: u32 = 46;
/// Colour of the rings and spokes over the disc.
const RING: RGBColor = RGBColor(255, 255, 255);

/// Write `grid` as a polar false-colour plot to the PNG file `path` (overwriting it),
/// titled and with a colour bar of `opts` (`x_label` and `y_label` are not used). The
/// colour range is as for [`super::map::write_map`]. Fails on a grid whose size does not
/// match its values, or a bad theta range or range of values.
pub fn write_polar(path: &Path, grid: &PolarGrid, opts: &MapOptions) -> Result<()> {
    let what = || format!("cannot write polar plot {}", path.display());
    let (size, rgb, (lo, hi)) = render_polar(grid, opts).with_context(what)?;
    let comment = format!(
        "{}: viridis false colour of {} theta x {} phi bins, theta 0 at the centre to {} deg \
         at the rim, phi 0 to the right and counter-clockwise, range {lo} to {hi}, grey = \
         no value",
        opts.title, grid.n_theta, grid.n_phi, grid.theta_max_deg
    );
    encode(path, size.0, size.1, &rgb, &comment).with_context(what)
}

/// A drawn figure: image size (pixels), 8-bit RGB pixels (rows from the top) and the
/// colour range.
type Drawn = ((u32, u32), Vec<u8>, (f64, f64));

/// Draw `grid` under `opts`.
fn render_polar(grid: &PolarGrid, opts: &MapOptions) -> Result<Drawn> {
    let (nt, np) = (grid.n_theta, grid.n_phi);
    ensure!(nt > 0 && np > 0, "empty grid ({nt} × {np})");
    ensure!(
        nt.checked_mul(np) == Some(grid.values.len()),
        "{} values for {nt} × {np} bins",
        grid.values.len()
    );
    ensure!(
        grid.theta_max_deg.is_finite() && grid.theta_max_deg > 0.0,
        "theta range 0 to {} deg is empty",
        grid.theta_max_deg
    );
    ensure!(
        grid.ring_step_deg.is_finite() && grid.ring_step_deg > 0.0,
        "ring step {} deg is not positive",
        grid.ring_step_deg
    );
    let range = value_range(grid.values, opts)?;
    let (mut bar_area, mut title_w) = (0, 0);
    let _ = render((1, 1), |a| {
        bar_area = bar_label_area(a, &opts.unit, range);
        title_w = text_width(a, &opts.title, &text(TITLE_SIZE));
        Ok(())
    });
    let disc_w = 2 * RIM + DISC;
    let w = (PAD + disc_w + GAP + BAR_W + bar_area + PAD).max(title_w + 2 * PAD);
    let h = TITLE_H + disc_w + PAD;
    let rgb = render((w, h), |root| {
        let title = text(TITLE_SIZE).pos(Pos::new(HPos::Center, VPos::Center));
        root.draw_text(&opts.title, &title, ((w / 2) as i32, (TITLE_H / 2) as i32))
            .map_err(drawing)?;
        let body = root.margin(TITLE_H, PAD, PAD, 0);
        let (disc_area, bar) = body.split_horizontally(disc_w + GAP);
        draw_disc(&disc_area, grid, range)?;
        let bar = bar.margin(RIM, 0, 0, 0);
        let (xs, ys) = draw_bar(&bar, &opts.unit, range, (RIM, bar_area))?;
        let r = [(xs.start - 1, ys.start - 1), (xs.end, ys.end)];
        root.draw(&Rectangle::new(r, FRAME.stroke_width(1)))
            .map_err(drawing)
    })?;
    Ok(((w, h), rgb, range))
}

/// The bin index `0..n` of `x` in `0..span`.
fn bin(x: f64, span: f64, n: usize) -> usize {
    ((x / span * n as f64) as usize).min(n - 1)
}

/// The disc, its rings, spokes and labels, in `area` (its top left `RIM` pixels from the
/// disc's bounding square).
fn draw_disc(area: &Area, grid: &PolarGrid, range: (f64, f64)) -> Result<()> {
    let radius = f64::from(DISC) / 2.0;
    let c = (
        RIM as i32 + (DISC / 2) as i32,
        RIM as i32 + (DISC / 2) as i32,
    );
    for py in 0..DISC {
        for px in 0..DISC {
            let dx = f64::from(px) + 0.5 - radius;
            let dy = radius - (f64::from(py) + 0.5);
            let r = dx.hypot(dy) / radius;
            if r > 1.0 {
                continue;
            }
            let it = bin(r, 1.0, grid.n_theta);
            let ip = bin(dy.atan2(dx).rem_euclid(TAU), TAU, grid.n_phi);
            let v = grid.values[it * grid.n_phi + ip];
            let p = ((RIM + px) as i32, (RIM + py) as i32);
            area.draw_pixel(p, &colour(v, range)).map_err(drawing)?;
        }
    }
    let label = text(LABEL_SIZE);
    let rim = radius as i32;
    for k in 0..4 {
        let (sx, sy) = [(1, 0), (0, -1), (-1, 0), (0, 1)][k];
        let spoke = [c, (c.0 + sx * rim, c.1 + sy * rim)];
        area.draw(&PathElement::new(spoke, RING.stroke_width(1)))
            .map_err(drawing)?;
        let at = (c.0 + sx * (rim + 6), c.1 + sy * (rim + 6));
        let pos = match k {
            0 => Pos::new(HPos::Left, VPos::Center),
            1 => Pos::new(HPos::Center, VPos::Bottom),
            2 => Pos::new(HPos::Right, VPos::Center),
            _ => Pos::new(HPos::Center, VPos::Top),
        };
        let phi = format!("φ {}°", 90 * k);
        area.draw_text(&phi, &label.pos(pos), at).map_err(drawing)?;
    }
    let h = text_height(area, &label) as i32;
    let mut theta = grid.ring_step_deg;
    while theta < grid.theta_max_deg - 1e-9 {
        let r = (radius * theta / grid.theta_max_deg).round() as i32;
        area.draw(&Circle::new(c, r, RING.stroke_width(1)))
            .map_err(drawing)?;
        let s = format!("{theta}°");
        let tw = text_width(area, &s, &label) as i32;
        let box_ = [(c.0 + r + 2, c.1 + 3), (c.0 + r + tw + 6, c.1 + h + 5)];
        area.draw(&Rectangle::new(box_, WHITE.filled()))
            .map_err(drawing)?;
        area.draw_text(&s, &label, (c.0 + r + 4, c.1 + 4))
            .map_err(drawing)?;
        theta += grid.ring_step_deg;
    }
    let rim_circle = Circle::new(c, rim, FRAME.stroke_width(1));
    area.draw(&rim_circle).map_err(drawing)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pixel's colour at `(x, y)` of an RGB image `w` pixels wide.
    fn pixel(rgb: &[u8], w: u32, (x, y): (u32, u32)) -> [u8; 3] {
        let i = 3 * (y * w + x) as usize;
        [rgb[i], rgb[i + 1], rgb[i + 2]]
    }

    /// Theta grows outwards and phi counter-clockwise from the right: a grid bright only
    /// in its outer ring's first phi bin lights the disc right of the centre near the rim,
    /// and nothing at the centre or left.
    #[test]
    fn theta_is_the_radius_and_phi_the_angle() {
        let (nt, np) = (3, 4);
        let mut values = vec![0.0; nt * np];
        values[2 * np] = 1.0; // outer ring, phi 0..90: upper right quadrant
        let grid = PolarGrid {
            n_theta: nt,
            n_phi: np,
            values: &values,
            theta_max_deg: 90.0,
            ring_step_deg: 20.0,
        };
        let opts = MapOptions {
            title: "t".into(),
            unit: "u".into(),
            ..MapOptions::default()
        };
        let ((w, _), rgb, range) = render_polar(&grid, &opts).unwrap();
        assert_eq!(range, (0.0, 1.0));
        let top = TITLE_H;
        let centre = (PAD + RIM + DISC / 2, top + RIM + DISC / 2);
        let bright = colour(1.0, range);
        let dark = colour(0.0, range);
        let d = (0.85 * f64::from(DISC) / 2.0 * std::f64::consts::FRAC_1_SQRT_2) as u32;
        let bright = [bright.0, bright.1, bright.2];
        let dark = [dark.0, dark.1, dark.2];
        assert_eq!(pixel(&rgb, w, (centre.0 + d, centre.1 - d)), bright);
        assert_eq!(pixel(&rgb, w, (centre.0 - d, centre.1 - d)), dark);
        assert_eq!(pixel(&rgb, w, (centre.0 + d, centre.1 + d)), dark);
        assert_eq!(pixel(&rgb, w, (centre.0 + 5, centre.1 - 9)), dark);
        let again = render_polar(&grid, &opts).unwrap();
        assert_eq!(again.1, rgb, "the same pixels every time");
    }

    #[test]
    fn bad_grids_are_errors() {
        let values = [1.0; 6];
        let grid = |nt, theta_max_deg| PolarGrid {
            n_theta: nt,
            n_phi: 3,
            values: &values,
            theta_max_deg,
            ring_step_deg: 10.0,
        };
        let opts = MapOptions::default();
        assert!(render_polar(&grid(3, 90.0), &opts).is_err());
        assert!(render_polar(&grid(2, 0.0), &opts).is_err());
        assert!(render_polar(&grid(2, f64::NAN), &opts).is_err());
        assert!(render_polar(&grid(2, 90.0), &opts).is_ok());
    }
}
