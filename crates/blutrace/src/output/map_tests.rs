//! Tests of the false-colour maps: size, orientation, colours of bins and of the colour
//! bar, labels clear of each other, deterministic bytes.

use super::*;
use crate::output::test_png::{TempFile, decode, preview_path};

fn pixel(r: &Rendered, x: i32, y: i32) -> RGBColor {
    let i = 3 * (y as usize * r.size.0 as usize + x as usize);
    RGBColor(r.rgb[i], r.rgb[i + 1], r.rgb[i + 2])
}

/// The centre pixel of bin `(i, j)` (row 0 at the bottom) of an `nx × ny` map.
fn bin_centre(r: &Rendered, (nx, ny): (usize, usize), (i, j): (usize, usize)) -> (i32, i32) {
    let (xs, ys) = &r.map;
    let (w, h) = (f64::from(xs.end - xs.start), f64::from(ys.end - ys.start));
    let x = xs.start + ((i as f64 + 0.5) / nx as f64 * w) as i32;
    let y = ys.end - 1 - ((j as f64 + 0.5) / ny as f64 * h) as i32;
    (x, y)
}

fn opts() -> MapOptions {
    MapOptions {
        title: "test map: 1000 photons".into(),
        x_label: "x (mm)".into(),
        y_label: "y (mm)".into(),
        unit: "irradiance (W/mm²)".into(),
        ..MapOptions::default()
    }
}

/// `value = grid row`, with a NaN and a negative value in the top row.
fn rows(nx: usize, ny: usize) -> Vec<f64> {
    let mut v: Vec<f64> = (0..nx * ny).map(|i| (i / nx) as f64).collect();
    v[(ny - 1) * nx] = f64::NAN;
    v[(ny - 1) * nx + 1] = -1.0;
    v
}

#[test]
fn map_has_the_physical_aspect_and_row_zero_at_the_bottom() {
    let (nx, ny) = (40, 20);
    let v = rows(nx, ny);
    let grid = Grid {
        nx,
        ny,
        values: &v,
        x_mm: [0.0, 290.0],
        y_mm: [0.0, 215.0],
    };
    let r = render_map(&grid, &opts()).unwrap();
    let (xs, ys) = &r.map;
    assert_eq!(xs.end - xs.start, 640);
    assert_eq!(ys.end - ys.start, (640.0f64 * 215.0 / 290.0).round() as i32);
    let at = |i, j| {
        let (x, y) = bin_centre(&r, (nx, ny), (i, j));
        pixel(&r, x, y)
    };
    // Row 0 (value 0) at the bottom, the top row (the maximum) at the top.
    assert_eq!(at(5, 0), viridis(0.0));
    assert_eq!(at(5, ny - 1), viridis(1.0));
    assert_eq!(at(3, 7), viridis(7.0 / (ny - 1) as f64));
    // NaN, and a negative value with the range starting at 0: grey.
    assert_eq!(at(0, ny - 1), INVALID_GREY);
    assert_eq!(at(1, ny - 1), INVALID_GREY);
    // The corners of the map are its bins' colours (no frame or text over them).
    assert_eq!(pixel(&r, xs.start, ys.end - 1), viridis(0.0));
    assert_eq!(pixel(&r, xs.end - 1, ys.start), viridis(1.0));
}

#[test]
fn every_map_pixel_shows_its_bin_and_the_bar_shows_the_colour_map() {
    let (nx, ny) = (7, 5);
    let v: Vec<f64> = (0..nx * ny).map(|i| i as f64 / 17.0 - 1.0).collect();
    let o = MapOptions {
        min: Some(-1.0),
        max: Some(1.0),
        ..opts()
    };
    let grid = Grid {
        nx,
        ny,
        values: &v,
        x_mm: [-3.0, 4.0],
        y_mm: [10.0, 15.0],
    };
    let r = render_map(&grid, &o).unwrap();
    let (xs, ys) = r.map.clone();
    let (w, h) = ((xs.end - xs.start) as usize, (ys.end - ys.start) as usize);
    for py in 0..h {
        for px in 0..w {
            let (gx, gy) = (px * nx / w, ny - 1 - py * ny / h);
            let want = colour(v[gy * nx + gx], (-1.0, 1.0));
            let got = pixel(&r, xs.start + px as i32, ys.start + py as i32);
            assert_eq!(got, want, "pixel ({px}, {py}) of bin ({gx}, {gy})");
        }
    }
    // The colour bar: the maximum at the top, the minimum at the bottom, linear between.
    let (bx, by) = r.bar.clone();
    let bh = by.end - by.start;
    let x = (bx.start + bx.end) / 2;
    assert_eq!(pixel(&r, x, by.start), viridis(1.0));
    assert_eq!(pixel(&r, x, by.end - 1), viridis(0.0));
    for j in [bh / 4, bh / 2, 3 * bh / 4] {
        let t = 1.0 - f64::from(j) / f64::from(bh - 1);
        assert_eq!(pixel(&r, x, by.start + j), viridis(t), "bar row {j}");
        // The value the bar's axis puts at that row (-1 at the bottom, 1 at the top) has
        // that colour in the map too, within a row's step.
        let value = -1.0 + 2.0 * t;
        let RGBColor(a, b, c) = colour(value, (-1.0, 1.0));
        let RGBColor(d, e, f) = pixel(&r, x, by.start + j);
        assert!(a.abs_diff(d) <= 2 && b.abs_diff(e) <= 2 && c.abs_diff(f) <= 2);
    }
}

/// Columns of `r` from `x0` to `x1` holding a dark (text) pixel in the rows `ys`.
fn inked_columns(r: &Rendered, x0: i32, x1: i32, ys: Range<i32>) -> Vec<bool> {
    (x0..x1)
        .map(|x| {
            ys.clone().any(|y| {
                let RGBColor(a, b, c) = pixel(r, x, y);
                a < 110 && b < 110 && c < 110
            })
        })
        .collect()
}

#[test]
fn bar_labels_and_unit_do_not_overlap() {
    for (max, unit) in [
        (1.234e-5, "irradiance (W/mm²)"),
        (0.8, "dot density"),
        (3e6, "W"),
    ] {
        let v = [0.0, max, max / 2.0, max / 3.0];
        let grid = Grid {
            nx: 2,
            ny: 2,
            values: &v,
            x_mm: [0.0, 100.0],
            y_mm: [0.0, 60.0],
        };
        let o = MapOptions {
            unit: unit.into(),
            // A title wider than the map and bar widens the image, not the bar.
            title: format!("{unit}: {}", "a very long title ".repeat(4)),
            ..opts()
        };
        let r = render_map(&grid, &o).unwrap();
        assert_eq!(r.bar.0.len(), BAR_W as usize);
        // Right of the bar (in its rows and the half label beyond them, below the title):
        // the tick labels, a blank gap, the unit; nothing at the image's edge.
        let rows = r.bar.1.start - 10..r.bar.1.end + 10;
        let cols = inked_columns(&r, r.bar.0.end + 1, r.size.0 as i32, rows.clone());
        let runs = cols
            .split(|inked| !inked)
            .filter(|run| !run.is_empty())
            .count();
        let gaps = cols.windows(2).filter(|w| w[0] && !w[1]).count();
        assert!(
            runs >= 2 && gaps >= 2,
            "{unit}: labels and unit touch ({runs} runs)"
        );
        assert!(
            !cols[cols.len() - 4..].iter().any(|c| *c),
            "{unit}: text at the edge"
        );
        // Between the map and the bar, in the bar's rows: nothing.
        let between = inked_columns(&r, r.map.0.end + 1, r.bar.0.start - 1, r.bar.1.clone());
        assert!(
            between.iter().all(|c| !c),
            "{unit}: ink between map and bar"
        );
    }
}

#[test]
fn same_map_same_bytes_on_any_thread() {
    let v: Vec<f64> = (0..300).map(|i| (i as f64 * 0.37).sin().abs()).collect();
    let write = |f: &TempFile| {
        let grid = Grid {
            nx: 20,
            ny: 15,
            values: &v,
            x_mm: [0.0, 20.0],
            y_mm: [0.0, 15.0],
        };
        write_map(&f.0, &grid, &opts()).unwrap();
        std::fs::read(&f.0).unwrap()
    };
    let (a, b) = (TempFile::new("det-a"), TempFile::new("det-b"));
    let first = write(&a);
    let second = std::thread::scope(|s| s.spawn(|| write(&b)).join().unwrap());
    assert_eq!(first, second);
    let img = decode(&a.0);
    let r = render_map(
        &Grid {
            nx: 20,
            ny: 15,
            values: &v,
            x_mm: [0.0, 20.0],
            y_mm: [0.0, 15.0],
        },
        &opts(),
    )
    .unwrap();
    assert_eq!((img.0, img.1), r.size);
    assert_eq!(img.2, r.rgb);
}

#[test]
fn invalid_input_is_an_error() {
    let f = TempFile::new("bad");
    let o = opts();
    let grid = |nx, ny, values, x_mm| Grid {
        nx,
        ny,
        values,
        x_mm,
        y_mm: [0.0, 1.0],
    };
    assert!(write_map(&f.0, &grid(2, 2, &[0.0; 3], [0.0, 1.0]), &o).is_err());
    assert!(write_map(&f.0, &grid(0, 2, &[], [0.0, 1.0]), &o).is_err());
    assert!(write_map(&f.0, &grid(1, 1, &[0.0], [1.0, 1.0]), &o).is_err());
    let bad = MapOptions {
        min: Some(2.0),
        max: Some(1.0),
        ..opts()
    };
    assert!(write_map(&f.0, &grid(1, 1, &[0.0], [0.0, 1.0]), &bad).is_err());
    let bad = MapOptions {
        min: Some(f64::NAN),
        ..opts()
    };
    assert!(write_map(&f.0, &grid(1, 1, &[0.0], [0.0, 1.0]), &bad).is_err());
    assert!(!f.0.exists());
    // All-zero or all-invalid data still gives an image.
    write_map(&f.0, &grid(2, 1, &[0.0, 0.0], [0.0, 1.0]), &o).unwrap();
    write_map(&f.0, &grid(2, 1, &[f64::NAN, -3.0], [0.0, 1.0]), &o).unwrap();
    assert!(f.0.exists());
}

#[test]
#[ignore = "writes blutrace_map_*.png to the temporary folder for a visual check"]
fn demo_maps() {
    let (w, h) = (64, 40);
    let mut v: Vec<f64> = (0..w * h)
        .map(|i| 1e-6 * ((i % w) as f64 + 2.0 * (i / w) as f64))
        .collect();
    v[0] = f64::NAN;
    let grid = Grid {
        nx: w,
        ny: h,
        values: &v,
        x_mm: [0.0, 290.0],
        y_mm: [0.0, 215.0],
    };
    write_map(&preview_path("blutrace_map_demo.png"), &grid, &opts()).unwrap();
    let flat = Grid {
        x_mm: [0.0, 290.0],
        y_mm: [0.0, 20.0],
        ..grid
    };
    write_map(&preview_path("blutrace_map_flat.png"), &flat, &opts()).unwrap();
}
