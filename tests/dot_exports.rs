//! Dot exports and densities: density to dot radius, exported dots that round-trip to the
//! density (CSV, SVG, DXF, the sheet frame), and the bilinear density grid.

mod support;

use blutrace::optics::dots::{Density, DensityGrid, DotPattern, Lattice};
use blutrace::optimize::export::{self, Dot};
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

#[test]
fn density_to_radius_for_square_and_hex_cells() {
    for (lattice, cell) in [(Lattice::Square, 1.0), (Lattice::Hex, 3f64.sqrt() / 2.0)] {
        let pitch = 0.8;
        assert!((lattice.cell_area(pitch) - cell * pitch * pitch).abs() < 1e-12);
        for d in [0.01, 0.2, 0.5] {
            let r = lattice.dot_radius(pitch, d);
            let frac = PI * r * r / lattice.cell_area(pitch);
            assert!((frac - d).abs() < 1e-12, "{lattice:?} d = {d}: {frac}");
        }
        // At the packing limit neighbouring dots just touch: diameter = pitch.
        let r = lattice.dot_radius(pitch, lattice.max_packing());
        assert!((2.0 * r - pitch).abs() < 1e-12, "{lattice:?}: {r}");
        assert_eq!(lattice.dot_radius(pitch, -0.1), 0.0);
    }
}

fn pattern(lattice: Lattice, density: Density) -> DotPattern {
    support::dot_pattern(lattice, density, 30.0)
}

/// Two triangles covering x 0..30, y 0..12 at z = 0.
fn rectangle() -> Vec<[DVec3; 3]> {
    let p = |x: f64, y: f64| DVec3::new(x, y, 0.0);
    vec![
        [p(0.0, 0.0), p(30.0, 0.0), p(30.0, 12.0)],
        [p(0.0, 0.0), p(30.0, 12.0), p(0.0, 12.0)],
    ]
}

/// Ink area of the dots with centres in each strip (width `strip`, the first starting at
/// `offset`) over the strip's area.
fn area_fraction_per_strip(
    dots: &[Dot],
    offset: f64,
    strip: f64,
    n: usize,
    height: f64,
) -> Vec<f64> {
    let mut ink = vec![0.0; n];
    for d in dots {
        let k = ((d.x - offset) / strip).floor();
        if k >= 0.0 && (k as usize) < n {
            ink[k as usize] += PI * d.diameter * d.diameter / 4.0;
        }
    }
    ink.iter().map(|a| a / (strip * height)).collect()
}

#[test]
fn exported_dots_round_trip_to_the_density() {
    let density = Density::Polynomial(vec![0.05, 0.2, 0.4]);
    // Square strips are one column of cells; hex strips are 6 pitches wide and start a
    // quarter pitch in, so every row (shifted or not) has exactly 6 dots in each.
    for (lattice, offset, strip) in [(Lattice::Square, 0.0, 0.5), (Lattice::Hex, 0.125, 3.0)] {
        let p = pattern(lattice, density.clone());
        let dots = export::dots_on_face(&p, &rectangle()).unwrap();
        assert!(
            dots.iter()
                .all(|d| (0.0..=30.0).contains(&d.x) && (0.0..=12.0).contains(&d.y))
        );
        let frame = export::SheetFrame::of_face(&p, &rectangle(), DVec3::ZERO);
        assert_eq!(frame.corner, DVec2::ZERO);
        let csv = export::to_csv(&dots, &frame);
        let back = export::parse_csv(&csv).unwrap();
        assert_eq!(back.len(), dots.len());
        // Rows with centres on the face (y = (j + 1/2) h <= 12): 24 square, 28 hex.
        let rows = (12.0 / p.row_spacing() - 0.5).floor() + 1.0;
        let height = rows * p.row_spacing();
        let n = ((30.0 - offset) / strip) as usize;
        let got = area_fraction_per_strip(&back, offset, strip, n, height);
        for (k, g) in got.iter().enumerate() {
            let u = offset + (k as f64 + 0.5) * strip;
            let want = p.density_at(u);
            assert!(
                (g - want).abs() < 1e-3,
                "{lattice:?} strip {k} at {u} mm: exported area fraction {g:.5}, d(x) = {want:.5}"
            );
        }
    }
    // A tabulated density exports the same way.
    let p = pattern(
        Lattice::Square,
        Density::Table(vec![[0.0, 0.1], [1.0, 0.5]]),
    );
    let dots = export::dots_on_face(&p, &rectangle()).unwrap();
    let got = area_fraction_per_strip(&dots, 0.0, 0.5, 60, 12.0);
    for (k, g) in got.iter().enumerate() {
        let want = p.density_at((k as f64 + 0.5) * 0.5);
        assert!((g - want).abs() < 1e-4, "table strip {k}: {g} vs {want}");
    }
}

/// A 3 x 2 density grid over the 30 x 12 mm face of [`pattern`].
fn grid_pattern() -> DotPattern {
    pattern(
        Lattice::Square,
        Density::Grid(DensityGrid {
            x_max: 1.0,
            v_min: 0.0,
            width: 12.0,
            values: vec![vec![0.1, 0.3, 0.5], vec![0.2, 0.6, 0.1]],
        }),
    )
}

/// The grid of [`grid_pattern`] by hand: bilinear in (u / 15, v / 12).
fn grid_by_hand(u: f64, v: f64) -> f64 {
    let rows = [[0.1, 0.3, 0.5], [0.2, 0.6, 0.1]];
    let fx = (u / 15.0).clamp(0.0, 2.0);
    let i = (fx.floor() as usize).min(1);
    let tx = fx - i as f64;
    let ty = (v / 12.0).clamp(0.0, 1.0);
    let row = |r: [f64; 3]| r[i] + (r[i + 1] - r[i]) * tx;
    row(rows[0]) + (row(rows[1]) - row(rows[0])) * ty
}

#[test]
fn density_grid_is_bilinear_at_cell_centres_and_covers_its_area_fraction() {
    let p = grid_pattern();
    assert_eq!(p.grade.density.problem(), None);
    assert_eq!(p.first_out_of_range(), None);
    // Every exported dot is sized by the bilinear density at its own cell centre.
    let dots = export::dots_on_face(&p, &rectangle()).unwrap();
    assert!(dots.len() > 1000);
    for d in &dots {
        let want = grid_by_hand(d.x, d.y);
        let r = Lattice::Square.dot_radius(0.5, want);
        assert!(
            (d.diameter - 2.0 * r).abs() < 1e-9,
            "dot at ({}, {}): diameter {} for d = {want}",
            d.x,
            d.y,
            d.diameter
        );
        assert!((p.density_at_point(DVec2::new(d.x, d.y)) - want).abs() < 1e-12);
    }
    // The knots themselves, and beyond the grid the nearest edge value.
    assert!((p.density_at_point(DVec2::new(15.0, 12.0)) - 0.6).abs() < 1e-12);
    assert!((p.density_at_point(DVec2::new(40.0, -3.0)) - 0.5).abs() < 1e-12);
    // Covered area fraction of 3 x 3 mm patches (whole cells) = the density there (the
    // mean of a bilinear function over a patch within one grid cell is its centre value).
    for (u0, v0) in [
        (1.0, 1.0),
        (6.0, 7.0),
        (16.0, 2.0),
        (24.0, 8.5),
        (11.5, 4.0),
    ] {
        let n = 300;
        let mut inside = 0usize;
        for i in 0..n {
            for j in 0..n {
                let x = u0 + 3.0 * (i as f64 + 0.5) / n as f64;
                let y = v0 + 3.0 * (j as f64 + 0.5) / n as f64;
                inside += p.covers(DVec3::new(x, y, 0.0)) as usize;
            }
        }
        let got = inside as f64 / (n * n) as f64;
        let want = grid_by_hand(u0 + 1.5, v0 + 1.5);
        assert!(
            (got - want).abs() < 0.01,
            "patch at ({u0}, {v0}): covered {got:.4}, d = {want:.4}"
        );
    }
    // A grid checks its shape and values.
    let bad = |values: Vec<Vec<f64>>| {
        Density::Grid(DensityGrid {
            x_max: 1.0,
            v_min: 0.0,
            width: 12.0,
            values,
        })
        .problem()
    };
    assert!(bad(vec![vec![0.1, 0.2], vec![0.3]]).is_some());
    assert!(bad(vec![vec![0.1, f64::NAN]]).is_some());
    assert!(bad(vec![]).is_some());
}

#[test]
fn svg_and_dxf_hold_every_dot() {
    let p = pattern(Lattice::Hex, Density::Polynomial(vec![0.2]));
    let dots = export::dots_on_face(&p, &rectangle()).unwrap();
    let frame = export::SheetFrame::of_face(&p, &rectangle(), DVec3::ZERO);
    let svg = export::to_svg(&dots, &frame);
    assert_eq!(svg.matches("<circle ").count(), dots.len());
    assert!(svg.starts_with("<?xml") && svg.trim_end().ends_with("</svg>"));
    let dxf = export::to_dxf(&dots, &frame);
    assert_eq!(dxf.matches("\nCIRCLE\n").count(), dots.len());
    assert!(dxf.ends_with("0\nEOF\n"));
    // Radii in the DXF's entities: group code 40 follows every circle.
    let (_, entities) = dxf.split_once("ENTITIES\n").unwrap();
    let radii: Vec<f64> = entities
        .lines()
        .collect::<Vec<_>>()
        .windows(2)
        .filter(|w| w[0] == "40")
        .map(|w| w[1].parse().unwrap())
        .collect();
    assert_eq!(radii.len(), dots.len());
    let r = Lattice::Hex.dot_radius(0.5, 0.2);
    assert!(radii.iter().all(|v| (v - r).abs() < 1e-5));
}

/// Exports are in the sheet's frame: a face whose across coordinates are all negative
/// (as notebook14's back face is: y from -215 to 0 mm) is written from 0 up, with the
/// frame in the header; the DXF declares its layer and reads in ezdxf when it is installed.
#[test]
fn exports_use_the_sheet_frame_with_positive_coordinates() {
    let p = pattern(Lattice::Square, Density::Polynomial(vec![0.3]));
    let below: Vec<[DVec3; 3]> = rectangle()
        .iter()
        .map(|t| t.map(|v| v - DVec3::new(0.0, 12.0, 0.0)))
        .collect();
    let dots = export::dots_on_face(&p, &below).unwrap();
    assert!(dots.iter().all(|d| d.y < 0.0));
    let offset = DVec3::new(100.0, 0.0, 0.0);
    let frame = export::SheetFrame::of_face(&p, &below, offset);
    assert_eq!(frame.origin, DVec3::new(100.0, -12.0, 0.0));
    let csv = export::to_csv(&dots, &frame);
    assert!(
        csv.starts_with("# blutrace dot pattern: units mm"),
        "{csv:.200}"
    );
    assert!(
        csv.lines()
            .next()
            .unwrap()
            .contains("(100.0000, -12.0000, 0.0000)")
    );
    let sheet = export::parse_csv(&csv).unwrap();
    assert!(
        sheet
            .iter()
            .all(|d| (0.0..=30.0).contains(&d.x) && (0.0..=12.0).contains(&d.y))
    );
    for (a, b) in sheet.iter().zip(&dots) {
        assert!((a.y - (b.y + 12.0)).abs() < 1e-4 && (a.x - b.x).abs() < 1e-4);
    }
    let dxf = export::to_dxf(&dots, &frame);
    assert!(dxf.contains("0\nTABLE\n2\nLAYER\n") && dxf.contains("0\nLAYER\n2\nDOTS\n"));
    assert!(
        !dxf.contains("$INSUNITS"),
        "R12 readers do not know $INSUNITS"
    );
    let has_ezdxf = std::process::Command::new("python3")
        .args(["-c", "import ezdxf"])
        .status()
        .is_ok_and(|s| s.success());
    if !has_ezdxf {
        eprintln!("ezdxf not installed: DXF read-back skipped (pip install ezdxf)");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("dots.dxf");
    std::fs::write(&path, &dxf).unwrap();
    let script = "import sys, ezdxf\n\
                  doc = ezdxf.readfile(sys.argv[1])\n\
                  c = doc.modelspace().query('CIRCLE')\n\
                  assert 'DOTS' in doc.layers, 'layer DOTS not declared'\n\
                  assert all(e.dxf.layer == 'DOTS' for e in c)\n\
                  print(len(c), min(e.dxf.center.y for e in c))";
    let out = std::process::Command::new("python3")
        .args(["-c", script, path.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let mut it = text.split_whitespace();
    assert_eq!(it.next().unwrap().parse::<usize>().unwrap(), dots.len());
    assert!(it.next().unwrap().parse::<f64>().unwrap() >= 0.0);
}
