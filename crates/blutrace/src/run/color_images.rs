//! The colour images of a spectral run.
//!
//! - `color.exr`: `R`, `G`, `B` = the target's light in linear sRGB (IEC 61966-2-1, D65
//!   white) on the photometric scale (Y = 1 is 1 lux), so any EXR viewer shows its true
//!   colour; `X`, `Y`, `Z` = CIE 1931 tristimulus values (lux-scaled: `Y` is the
//!   illuminance, lm/m² per bin); `stderr.X`, `stderr.Y`, `stderr.Z` their standard
//!   errors; `u_prime`, `v_prime` = CIE 1976 chromaticity per bin (NaN where no light),
//!   `stderr.u_prime`, `stderr.v_prime` their jackknife errors
//!   ([`super::metrics::color::uv_prime_maps`]); `hits` = photons per bin. Header attributes as `flux.exr`'s.
//! - `color.png`: the same light as an sRGB picture, one block of pixels per bin, scaled
//!   so the brightest bin's largest sRGB component is full scale (so it shows colour and
//!   its variation, not absolute brightness).
//! - `delta_uv.png`: Δu'v' of each bin from the whole target's chromaticity (the colour
//!   non-uniformity map), false colour from 0.

use super::RunResult;
use super::images::f32s;
use super::metrics::Map;
use super::metrics::color::{uv_prime_maps, xyz_maps};
use crate::color::{UvPrime, Xyz};
use crate::output::atomic::SetDir;
use crate::output::exr::{Samples, write_channels};
use crate::output::map::{Grid, MapOptions, write_map};
use anyhow::Result;
use std::path::Path;

/// XYZ (D65) to linear sRGB, IEC 61966-2-1:1999.
const XYZ_TO_SRGB: [[f64; 3]; 3] = [
    [3.2406, -1.5372, -0.4986],
    [-0.9689, 1.8758, 0.0415],
    [0.0557, -0.2040, 1.0570],
];

/// Pixels per bin side in `color.png` for maps of fewer than 400 bins across.
fn block(nx: usize) -> usize {
    (400 / nx.max(1)).clamp(1, 16)
}

/// Write the colour images of `run` into `staged` (nothing for a monochrome run).
pub(super) fn write_color_images(run: &RunResult, staged: &SetDir) -> Result<()> {
    let Some(xyz) = xyz_maps(&run.scene, &run.tally) else {
        return Ok(());
    };
    let Some(uv_maps) = uv_prime_maps(&run.scene, &run.tally, &run.groups) else {
        return Ok(());
    };
    let rgb = linear_srgb(&xyz);
    let [u, v] = [&uv_maps[0].value, &uv_maps[1].value];
    let uv: Vec<Option<UvPrime>> = (0..u.len())
        .map(|i| (!u[i].is_nan()).then(|| UvPrime { u: u[i], v: v[i] }))
        .collect();
    write_exr(run, staged, &xyz, &rgb, &uv_maps)?;
    staged.write_with("color.png", |path| {
        write_true_colour(run, path, &xyz[0], &rgb)
    })?;
    staged.write_with("delta_uv.png", |path| write_delta_uv(run, path, &xyz, &uv))?;
    Ok(())
}

/// Linear sRGB per bin, channel-major.
fn linear_srgb(xyz: &[Map; 3]) -> [Vec<f64>; 3] {
    std::array::from_fn(|c| {
        (0..xyz[0].value.len())
            .map(|i| (0..3).map(|k| XYZ_TO_SRGB[c][k] * xyz[k].value[i]).sum())
            .collect()
    })
}

fn write_exr(
    run: &RunResult,
    staged: &SetDir,
    xyz: &[Map; 3],
    rgb: &[Vec<f64>; 3],
    uv: &[Map; 2],
) -> Result<()> {
    let comments = "blutrace colour map: R, G, B = linear sRGB (D65) of the light on the target, \
         Y = 1 being 1 lux; X, Y, Z = CIE 1931 tristimulus values (Y = illuminance, lm/m^2 per \
         bin); stderr.X/Y/Z their standard errors; u_prime, v_prime = CIE 1976 chromaticity \
         per bin, stderr.u_prime/v_prime their standard errors; hits = photons per bin; x along detector_u, y along detector_v";
    let attrs = super::images::map_attributes(run, "lx (lm/m^2)", comments);
    let (r, g, b) = (f32s(&rgb[0]), f32s(&rgb[1]), f32s(&rgb[2]));
    let [x, y, z] = [0, 1, 2].map(|k| f32s(&xyz[k].value));
    let [xe, ye, ze] = [0, 1, 2].map(|k| f32s(&xyz[k].stderr));
    let [u, v] = [0, 1].map(|k| f32s(&uv[k].value));
    let [ue, ve] = [0, 1].map(|k| f32s(&uv[k].stderr));
    let hits: Vec<f32> = xyz[0].hits.iter().map(|&h| h as f32).collect();
    let (nx, ny) = (xyz[0].nx, xyz[0].ny);
    staged.write_with("color.exr", |path| {
        let channels = [
            ("R", Samples::F32(&r)),
            ("G", Samples::F32(&g)),
            ("B", Samples::F32(&b)),
            ("X", Samples::F32(&x)),
            ("Y", Samples::F32(&y)),
            ("Z", Samples::F32(&z)),
            ("stderr.X", Samples::F32(&xe)),
            ("stderr.Y", Samples::F32(&ye)),
            ("stderr.Z", Samples::F32(&ze)),
            ("u_prime", Samples::F32(&u)),
            ("v_prime", Samples::F32(&v)),
            ("stderr.u_prime", Samples::F32(&ue)),
            ("stderr.v_prime", Samples::F32(&ve)),
            ("hits", Samples::F32(&hits)),
        ];
        write_channels(path, nx, ny, &channels, &attrs)
    })?;
    Ok(())
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1], as 8 bits.
fn encode_srgb(linear: f64) -> u8 {
    let c = linear.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

fn write_true_colour(run: &RunResult, path: &Path, shape: &Map, rgb: &[Vec<f64>; 3]) -> Result<()> {
    let (nx, ny, k) = (shape.nx, shape.ny, block(shape.nx));
    let peak = rgb.iter().flatten().fold(0.0f64, |m, &v| m.max(v));
    let scale = if peak > 0.0 { 1.0 / peak } else { 0.0 };
    let (w, h) = (nx * k, ny * k);
    let mut px = vec![0u8; w * h * 3];
    for row in 0..h {
        // Image rows from the top; grid row 0 is the bottom.
        let gy = ny - 1 - row / k;
        for col in 0..w {
            let i = gy * nx + col / k;
            for c in 0..3 {
                px[(row * w + col) * 3 + c] = encode_srgb(rgb[c][i] * scale);
            }
        }
    }
    let comment = format!(
        "{}: true colour (sRGB, D65) of the light on the target, {nx}x{ny} bins, {k} px per bin, \
         brightest bin at full scale, grid row 0 at the bottom",
        run.scene.name
    );
    crate::output::png::encode(path, w as u32, h as u32, &px, &comment)
}

fn write_delta_uv(
    run: &RunResult,
    path: &Path,
    xyz: &[Map; 3],
    uv: &[Option<UvPrime>],
) -> Result<()> {
    let total = |k: usize| xyz[k].value.iter().sum::<f64>();
    let whole = Xyz {
        x: total(0),
        y: total(1),
        z: total(2),
    }
    .uv_prime();
    let values: Vec<f64> = uv
        .iter()
        .map(|p| match (p, whole) {
            (Some(p), Some(w)) => p.delta(w),
            _ => f64::NAN,
        })
        .collect();
    let d = &run.scene.detector;
    let grid = Grid {
        nx: xyz[0].nx,
        ny: xyz[0].ny,
        values: &values,
        x_mm: [0.0, d.size[0]],
        y_mm: [0.0, d.size[1]],
    };
    let opts = MapOptions {
        title: format!(
            "{}: colour non-uniformity, delta u'v' from the target's mean",
            run.scene.name
        ),
        x_label: "detector u (mm)".into(),
        y_label: "detector v (mm)".into(),
        unit: "delta u'v' (CIE 1976)".into(),
        ..MapOptions::default()
    };
    write_map(path, &grid, &opts)
}
