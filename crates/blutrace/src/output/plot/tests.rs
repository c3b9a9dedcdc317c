//! Tests of the chart writer: geometry of the axes, ticks, legend and the PNG itself.

use super::*;
use crate::output::test_png::{TempFile, decode, preview_path};

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
    // Data over a decade keep their range: 1.5 s to 16 s is not padded to 1 s to 100 s.
    let a = fit(Scale::Log10, 1.5f64.log10(), 16f64.log10());
    assert!(a.lo > 1.2f64.log10() && a.hi < 20f64.log10(), "{a:?}");
    assert!(a.log_ticks(8).iter().filter(|t| t.label.is_some()).count() >= 2);
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
            // Drawable or not, a chart is always written (a placeholder when nothing can
            // be drawn).
            write_chart(&f.0, &chart).unwrap_or_else(|e| panic!("{pts:?} {scale:?}: {e:#}"));
            assert_eq!(decode(&f.0).0, 800);
            if !valid {
                assert!(render(&chart).is_err(), "{pts:?} {scale:?}");
            }
        }
    }
}

#[test]
fn charts_with_nothing_to_draw_degrade_to_a_placeholder() {
    let f = TempFile::new("error");
    for chart in [
        Chart::default(),
        Chart {
            title: "log axis, nothing positive".into(),
            y_scale: Scale::Log10,
            series: vec![Series::new("a", vec![(1.0, 0.0), (f64::NAN, 1.0)])],
            ..Chart::default()
        },
    ] {
        write_chart(&f.0, &chart).unwrap();
        let Err(why) = render(&chart) else {
            panic!("{:?} has something to draw", chart.title)
        };
        let p = placeholder(&chart, &format!("{why:#}"));
        // Framed, with text, and nothing else: no series colour anywhere.
        let inked = p.rgb.chunks(3).filter(|c| *c == INK).count();
        assert!(inked > 50, "the reason is written");
        assert!(p.rgb.chunks(3).all(|c| !PALETTE.iter().any(|q| c == q)));
        assert!(f.0.exists());
    }
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
#[ignore = "writes blutrace_*.png charts to the temporary folder for a visual check"]
fn demo_charts() {
    write_chart(
        &preview_path("blutrace_convergence.png"),
        &convergence_chart(),
    )
    .unwrap();
    write_chart(&preview_path("blutrace_density.png"), &density_chart()).unwrap();
    let glyphs = Chart {
        title: "ABCDEFGHIJKLMNOPQRSTUVWXYZ 0123456789".into(),
        x_label: "abcdefghijklmnopqrstuvwxyz .,-+/()%=:;_'*^<>!?|[]".into(),
        y_label: "The quick brown fox (jumps) = 42%".into(),
        series: vec![Series::new("glyph test", vec![(0.0, 1.0), (1.0, 0.0)])],
        ..Chart::default()
    };
    write_chart(&preview_path("blutrace_glyphs.png"), &glyphs).unwrap();
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
    write_chart(&preview_path("blutrace_degenerate.png"), &degenerate).unwrap();
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
    write_chart(&preview_path("blutrace_many.png"), &many).unwrap();
}
