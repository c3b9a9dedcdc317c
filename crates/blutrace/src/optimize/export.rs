//! The manufacturable dot pattern: every dot on the face with its diameter, as CSV, SVG
//! and DXF.
//!
//! ```text
//! blutrace optimize SCENE --out DIR   # writes DIR/dots.csv, DIR/dots.svg, DIR/dots.dxf
//! ```
//!
//! Coordinates (mm) are written in the printed sheet's frame ([`SheetFrame`]): `x` along the
//! pattern's `axis` (away from the lamp edge), `y` along its `across` direction, both from
//! the corner of the face where they are smallest, so every coordinate is >= 0. Each file
//! states the frame in its header: the corner's position and the two directions in the
//! scene file's coordinates.
//!
//! ```toml
//! [surfaces.lgp_back]
//! model = "dots"
//! origin = [0.0, 0.0, 0.0]   # a point on the lamp edge
//! axis = [1.0, 0.0, 0.0]     # dots.csv x
//! ```
//!
//! The files list the dots the tracer sees, placed as the surface's `placement` says
//! (lattice, jittered or stochastic, see [`crate::optics::dot_placement`]); `virtual`
//! prints nothing and is refused. A dot is listed when its centre lies on the face (inside
//! one of the tag's triangles); its diameter is `2 sqrt(d A / pi)` (lattice, jittered) with
//! `A` the cell area and `d` the density at the cell centre, so the dots cover the fraction
//! `d(x)` of the face around `x`; stochastic dots overlap and are sized
//! `2 sqrt(-ln(1 - d) A / pi)` so that their union covers that fraction. The DXF is plain R12 ASCII: one `CIRCLE`
//! entity per dot on layer `DOTS` (declared in the `TABLES` section), in millimetres; R12
//! has no units variable, so the units and the frame are stated in `999` comments.

use crate::optics::dots::DotPattern;
use anyhow::{Context, Result, bail};
use glam::{DVec2, DVec3};
use std::collections::HashSet;
use std::fmt::Write;

/// One printed dot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dot {
    /// Position along the pattern axis (mm from the origin).
    pub x: f64,
    /// Position across the axis (mm from the origin).
    pub y: f64,
    /// Diameter (mm).
    pub diameter: f64,
}

/// The frame of the printed sheet: where its (0, 0) is and where its axes point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SheetFrame {
    /// The face corner in pattern face coordinates (mm along `axis`, mm along `across`):
    /// subtracted from every dot.
    pub corner: DVec2,
    /// That corner in the scene file's coordinates (mm).
    pub origin: DVec3,
    /// Unit direction of the sheet's x (the pattern's axis).
    pub x: DVec3,
    /// Unit direction of the sheet's y (the pattern's across direction).
    pub y: DVec3,
}

impl SheetFrame {
    /// The frame of the face made of `triangles` (scene coordinates, recentred by
    /// `offset`: file = scene + offset): its corner where both face coordinates are least.
    pub fn of_face(pattern: &DotPattern, triangles: &[[DVec3; 3]], offset: DVec3) -> Self {
        let corner = triangles
            .iter()
            .flatten()
            .map(|&v| pattern.face_coords(v))
            .reduce(DVec2::min)
            .unwrap_or(DVec2::ZERO);
        SheetFrame {
            corner,
            origin: pattern.origin + pattern.axis * corner.x + pattern.across * corner.y + offset,
            x: pattern.axis,
            y: pattern.across,
        }
    }

    /// A dot's position on the sheet (mm).
    fn place(&self, d: &Dot) -> DVec2 {
        DVec2::new(d.x - self.corner.x, d.y - self.corner.y)
    }

    /// One line saying what the coordinates mean.
    fn describe(&self) -> String {
        let v = |p: DVec3| format!("({:.4}, {:.4}, {:.4})", p.x, p.y, p.z);
        format!(
            "units mm; sheet x along {} and y along {} (the dot pattern's axis and across \
             directions), from the face corner at {} mm in the scene file's frame",
            v(self.x),
            v(self.y),
            v(self.origin)
        )
    }
}

/// Most dots an export writes: a 300 x 200 mm face at 0.05 mm pitch (finer than screen
/// printing resolves) is 2.4e7 cells; beyond this a pitch is a simulation choice, not a
/// printable sheet, and the files would run to gigabytes.
pub const MAX_EXPORTED_DOTS: usize = 30_000_000;

/// Every dot whose centre lies on the face made of `triangles` (scene coordinates, the
/// same frame as `pattern.origin`), placed as the pattern's `placement` says, in row
/// order. Dots of zero diameter are left out. A `virtual` pattern prints no dots: that is
/// an error naming the printable placements.
pub fn dots_on_face(pattern: &DotPattern, triangles: &[[DVec3; 3]]) -> Result<Vec<Dot>> {
    if !pattern.placement.printable() {
        bail!(
            "placement \"virtual\" is not printable (each hit meets ink with probability d; there are no dots to print): \
             export a printable placement of the same density instead (\"lattice\", \"jittered\" or \"stochastic\")"
        );
    }
    let area: f64 = triangles
        .iter()
        .map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).length())
        .sum();
    let cells = area / pattern.lattice.cell_area(pattern.pitch);
    if cells.is_nan() || cells > MAX_EXPORTED_DOTS as f64 {
        bail!(
            "the face ({area:.0} mm^2) holds about {cells:.2e} dot cells at pitch {} mm: \
             exports stop at {MAX_EXPORTED_DOTS:.0e} dots (about 1 GB of CSV); \
             choose a coarser pitch_mm for a printable sheet",
            pattern.pitch
        );
    }
    let mut seen = HashSet::new();
    let mut dots = Vec::new();
    for tri in triangles {
        let q = tri.map(|v| pattern.face_coords(v));
        let (lo, hi) = (q[0].min(q[1]).min(q[2]), q[0].max(q[1]).max(q[2]));
        for (i, j) in pattern.cells_over(lo, hi) {
            for (k, d) in pattern.dots_of_cell(i, j).into_iter().enumerate() {
                if inside_triangle(d.centre, q) && seen.insert((j, i, k)) {
                    dots.push(((j, i, k), d));
                }
            }
        }
    }
    dots.sort_by_key(|&(key, _)| key);
    Ok(dots
        .into_iter()
        .map(|(_, d)| Dot {
            x: d.centre.x,
            y: d.centre.y,
            diameter: 2.0 * d.radius,
        })
        .filter(|d| d.diameter > 0.0)
        .collect())
}

/// Point in triangle (2-D), boundary included; works for either winding.
fn inside_triangle(p: DVec2, t: [DVec2; 3]) -> bool {
    let cross = |a: DVec2, b: DVec2, c: DVec2| (b - a).perp_dot(c - a);
    let s = [
        cross(t[0], t[1], p),
        cross(t[1], t[2], p),
        cross(t[2], t[0], p),
    ];
    let eps = 1e-12 * (t[1] - t[0]).length_squared().max(1.0);
    s.iter().all(|&v| v >= -eps) || s.iter().all(|&v| v <= eps)
}

/// `x_mm,y_mm,diameter_mm` on the sheet, after a `#` line stating the frame, positions to
/// 0.1 um.
pub fn to_csv(dots: &[Dot], frame: &SheetFrame) -> String {
    let mut s = String::with_capacity(32 * dots.len() + 256);
    let _ = writeln!(s, "# blutrace dot pattern: {}", frame.describe());
    s.push_str("x_mm,y_mm,diameter_mm\n");
    for d in dots {
        let p = frame.place(d);
        let _ = writeln!(s, "{:.4},{:.4},{:.5}", p.x, p.y, d.diameter);
    }
    s
}

/// Read back what [`to_csv`] wrote (sheet coordinates; `#` lines are comments).
pub fn parse_csv(text: &str) -> Result<Vec<Dot>> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim_start().starts_with('#'));
    match lines.next() {
        Some((_, h)) if h.trim() == "x_mm,y_mm,diameter_mm" => {}
        _ => bail!("dots CSV: expected the header x_mm,y_mm,diameter_mm"),
    }
    lines
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            let v: Vec<f64> = l
                .split(',')
                .map(|f| f.trim().parse::<f64>())
                .collect::<std::result::Result<_, _>>()
                .with_context(|| format!("dots CSV line {}: not three numbers", i + 1))?;
            match v[..] {
                [x, y, diameter] => Ok(Dot { x, y, diameter }),
                _ => bail!(
                    "dots CSV line {}: expected 3 fields, got {}",
                    i + 1,
                    v.len()
                ),
            }
        })
        .collect()
}

/// An SVG drawing of the dots on the sheet in mm (1 user unit = 1 mm), sheet `y` up.
pub fn to_svg(dots: &[Dot], frame: &SheetFrame) -> String {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for d in dots {
        let (r, p) = (0.5 * d.diameter, frame.place(d));
        lo = lo.min(DVec2::new(p.x - r, p.y - r));
        hi = hi.max(DVec2::new(p.x + r, p.y + r));
    }
    if dots.is_empty() {
        (lo, hi) = (DVec2::ZERO, DVec2::ONE);
    }
    let size = hi - lo;
    let mut s = String::with_capacity(48 * dots.len() + 512);
    let _ = writeln!(
        s,
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" \
         width=\"{w:.4}mm\" height=\"{h:.4}mm\" viewBox=\"{x:.4} {y:.4} {w:.4} {h:.4}\">",
        w = size.x,
        h = size.y,
        x = lo.x,
        y = -hi.y,
    );
    let _ = writeln!(
        s,
        "<!-- blutrace dot pattern: {} dots; {} -->",
        dots.len(),
        frame.describe()
    );
    s.push_str("<g transform=\"scale(1,-1)\" fill=\"black\" stroke=\"none\">\n");
    for d in dots {
        let p = frame.place(d);
        let _ = writeln!(
            s,
            "<circle cx=\"{:.4}\" cy=\"{:.4}\" r=\"{:.5}\"/>",
            p.x,
            p.y,
            0.5 * d.diameter
        );
    }
    s.push_str("</g>\n</svg>\n");
    s
}

/// A minimal ASCII DXF (R12): the layer `DOTS` declared, one `CIRCLE` per dot on it, in
/// mm on the sheet; units and frame in `999` comments.
pub fn to_dxf(dots: &[Dot], frame: &SheetFrame) -> String {
    let mut s = String::with_capacity(64 * dots.len() + 1024);
    let _ = write!(
        s,
        "999\nblutrace dot pattern, {} dots\n999\n{}\n",
        dots.len(),
        frame.describe()
    );
    s.push_str(concat!(
        "0\nSECTION\n2\nTABLES\n",
        "0\nTABLE\n2\nLTYPE\n70\n1\n",
        "0\nLTYPE\n2\nCONTINUOUS\n70\n0\n3\nSolid line\n72\n65\n73\n0\n40\n0.0\n",
        "0\nENDTAB\n",
        "0\nTABLE\n2\nLAYER\n70\n1\n",
        "0\nLAYER\n2\nDOTS\n70\n0\n62\n7\n6\nCONTINUOUS\n",
        "0\nENDTAB\n0\nENDSEC\n",
    ));
    s.push_str("0\nSECTION\n2\nENTITIES\n");
    for d in dots {
        let p = frame.place(d);
        let _ = write!(
            s,
            "0\nCIRCLE\n8\nDOTS\n10\n{:.4}\n20\n{:.4}\n30\n0.0\n40\n{:.5}\n",
            p.x,
            p.y,
            0.5 * d.diameter
        );
    }
    s.push_str("0\nENDSEC\n0\nEOF\n");
    s
}
