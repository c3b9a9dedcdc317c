//! Tests of the line charts: axis ranges, drawn series, legend corner, placeholder,
//! deterministic bytes.

use super::*;
use crate::output::figure::series_colour;
use crate::output::test_png::{TempFile, decode, preview_path};

/// Pixels of `rgb` in `(xs, ys)` with exactly the colour `c`.
fn count(rgb: &[u8], (xs, ys): &PixelRect, c: RGBColor) -> usize {
    let at = |x: i32, y: i32| 3 * (y as usize * WIDTH as usize + x as usize);
    ys.clone()
        .flat_map(|y| xs.clone().map(move |x| at(x, y)))
        .filter(|&k| rgb[k..k + 3] == [c.0, c.1, c.2])
        .count()
}

fn chart(series: Vec<Series>) -> Chart {
    Chart {
        title: "A test chart".into(),
        x_label: "time (s)".into(),
        y_label: "error".into(),
        x_scale: Scale::Linear,
        y_scale: Scale::Linear,
        series,
    }
}

#[test]
fn axis_ranges_pad_linear_data_and_round_log_data_to_decades() {
    assert_eq!(
        axis_range(Scale::Linear, (0.0, 10.0)).unwrap(),
        (-0.5, 10.5)
    );
    assert_eq!(axis_range(Scale::Linear, (0.0, 0.0)).unwrap(), (-1.0, 1.0));
    let (a, b) = axis_range(Scale::Linear, (-2.0, -2.0)).unwrap();
    assert!((a + 2.2).abs() < 1e-12 && (b + 1.8).abs() < 1e-12);
    let (a, b) = axis_range(Scale::Log10, (0.003, 0.2)).unwrap();
    assert!(
        (a / 1e-3 - 1.0).abs() < 1e-8 && (b - 1.0).abs() < 1e-8,
        "{a} {b}"
    );
    assert!(a < 1e-3 && b > 1.0, "the end decades are inside the range");
    let (a, b) = axis_range(Scale::Log10, (10.0, 10.0)).unwrap();
    assert!(a < 10.0 && b > 10.0 && (a * b - 100.0).abs() < 1e-9);
    assert!(axis_range(Scale::Linear, (-1e308, 1e308)).is_err());
}

#[test]
fn series_are_drawn_in_their_colours_with_gaps_and_lone_points() {
    let nan = f64::NAN;
    let c = Chart {
        x_scale: Scale::Log10,
        y_scale: Scale::Log10,
        series: vec![
            Series::new("line", vec![(1.0, 1.0), (10.0, 0.1), (100.0, 0.01)]),
            // Only the middle point is drawable: a marker without a line.
            Series::new("lone", vec![(2.0, nan), (5.0, 0.5), (-1.0, 0.1)]),
            Series {
                label: "dashed".into(),
                points: vec![(1.0, 0.01), (100.0, 1.0)],
                dashed: true,
                markers: true,
            },
            Series::new("", vec![(0.0, 0.0)]), // nothing drawable on log axes
        ],
        ..chart(Vec::new())
    };
    let (rgb, plot) = render_chart(&c).unwrap();
    assert_eq!(rgb.len(), 3 * (WIDTH * HEIGHT) as usize);
    let plot = plot.unwrap();
    let (line, lone, dashed) = (
        count(&rgb, &plot, series_colour(0)),
        count(&rgb, &plot, series_colour(1)),
        count(&rgb, &plot, series_colour(2)),
    );
    assert!(line > 1000, "{line} pixels of the line");
    assert!(
        (20..400).contains(&lone),
        "{lone} pixels of the lone marker"
    );
    assert!(
        dashed > 300 && dashed < line,
        "{dashed} pixels of the dashed line"
    );
    let all = (0..WIDTH as i32, 0..HEIGHT as i32);
    assert_eq!(count(&rgb, &all, series_colour(3)), 0);
}

#[test]
fn legend_stands_right_of_the_plot_area() {
    let rising = |label: &str| Series::new(label, vec![(0.0, 0.0), (1.0, 1.0), (2.0, 2.0)]);
    let colour_right_of = |rgb: &[u8], x0: i32, i: usize| {
        count(rgb, &(x0..WIDTH as i32, 0..HEIGHT as i32), series_colour(i))
    };
    let (rgb, plot) = render_chart(&chart(vec![rising("a"), rising("")])).unwrap();
    let (xs, _) = plot.unwrap();
    assert!(WIDTH as i32 - xs.end > 60, "room for the legend: {xs:?}");
    // The labelled series has a sample there, the unlabelled one none.
    assert!(colour_right_of(&rgb, xs.end + 1, 0) > 30);
    assert_eq!(colour_right_of(&rgb, xs.end + 1, 1), 0);
    // Without labels the plot area takes the width.
    let (_, plot) = render_chart(&chart(vec![rising(""), rising("")])).unwrap();
    assert!(WIDTH as i32 - plot.unwrap().0.end < 40);
}

#[test]
fn nothing_to_draw_gives_a_placeholder_chart() {
    for c in [
        chart(Vec::new()),
        chart(vec![Series::new("nan", vec![(f64::NAN, 1.0)])]),
        Chart {
            y_scale: Scale::Log10,
            ..chart(vec![Series::new("neg", vec![(1.0, -1.0), (2.0, 0.0)])])
        },
    ] {
        assert!(axis_ranges(&c).is_err());
        assert_eq!(render_chart(&c).unwrap().1, None);
        let f = TempFile::new("placeholder");
        write_chart(&f.0, &c).unwrap();
        let (w, h, rgb) = decode(&f.0);
        assert_eq!((w, h), (WIDTH, HEIGHT));
        let ink = rgb.chunks(3).filter(|p| p[0] < 100).count();
        assert!(ink > 500, "{ink}: the title and reason are written");
    }
}

#[test]
fn same_chart_same_bytes_on_any_thread() {
    let c = Chart {
        x_scale: Scale::Log10,
        ..chart(vec![
            Series {
                label: "markers".into(),
                points: (1..40)
                    .map(|k| (f64::from(k), 1.0 / f64::from(k).sqrt()))
                    .collect(),
                dashed: false,
                markers: true,
            },
            Series::new("line", vec![(1.0, 0.2), (39.0, 0.8)]),
        ])
    };
    let write = |f: &TempFile| {
        write_chart(&f.0, &c).unwrap();
        std::fs::read(&f.0).unwrap()
    };
    let (a, b) = (TempFile::new("chart-a"), TempFile::new("chart-b"));
    let first = write(&a);
    let second = std::thread::scope(|s| s.spawn(|| write(&b)).join().unwrap());
    assert_eq!(first, second);
    let (w, h, rgb) = decode(&a.0);
    assert_eq!((w, h), (WIDTH, HEIGHT));
    assert_eq!(rgb, render_chart(&c).unwrap().0);
}

#[test]
#[ignore = "writes blutrace_chart_*.png to the temporary folder for a visual check"]
fn demo_charts() {
    let c = Chart {
        x_scale: Scale::Log10,
        y_scale: Scale::Log10,
        ..chart(
            (0..6)
                .map(|i| Series {
                    label: format!("series {i}"),
                    points: (1..30)
                        .map(|k| {
                            let t = f64::from(k) * 0.1;
                            (t, 0.01 * f64::from(i + 1) / t.sqrt())
                        })
                        .collect(),
                    dashed: i == 5,
                    markers: i < 5,
                })
                .collect(),
        )
    };
    write_chart(&preview_path("blutrace_chart_log.png"), &c).unwrap();
    let lin = Chart {
        x_scale: Scale::Linear,
        y_scale: Scale::Linear,
        ..c
    };
    write_chart(&preview_path("blutrace_chart_lin.png"), &lin).unwrap();
    write_chart(
        &preview_path("blutrace_chart_empty.png"),
        &chart(Vec::new()),
    )
    .unwrap();
}
