//! The run's images: the EXR files, laid out as image tools read them, `flux.png` and
//! `conoscope.png`.
//!
//! - `flux.exr`: channel `Y` = irradiance on the target plane (W/mm^2 per bin), so that any
//!   viewer shows a grey image (values ~1e-5: scale it, or use `preview.Y`); layer `stderr`
//!   (`stderr.Y`) = its standard error (W/mm^2); layer `hits` (`hits.Y`) = photons scored
//!   per bin; layer `preview` (`preview.Y`) = `Y / (2 * mean)`, display-referred: the mean
//!   shows mid-grey, twice the mean white. Grid x along the detector's `u`, y along `v`, y
//!   up in the image.
//! - `angular.exr`: `Y` = radiant intensity (W/sr per (theta, phi) bin), `stderr.Y`,
//!   `hits.Y`, and when the sources give lumens `luminance.Y` and `luminance_stderr.Y`
//!   (cd/m^2, averaged over the target); x = phi, y = theta.
//!
//! `hits.Y` is a 32-bit float, exact up to 2^24 (16.7 million) photons in one bin: image
//! tools normalise integer channels to [0, 1] on reading (OpenImageIO shows 6 hits of a
//! `uint` channel as 1.4e-9), which a count must not be.
//!
//! Header attributes of both: `software` (`blutrace VERSION`) and `comments` (what the
//! channels hold; the standard EXR attributes, which tools carry into other formats),
//! `units` (of `Y` and `stderr.Y`), `scene`, `scene_hash` (the content hash of
//! `scene::hash`, as in shard files), `seed` and `photons` (text: exact for every `u64`),
//! `detector_origin_mm` (in the scene file's frame, as written there), `detector_u`,
//! `detector_v` (`[x, y, z]`), the bin and target sizes
//! (`bin_size_x_mm`, `bin_size_y_mm`, `size_x_mm`, `size_y_mm`) or the angular bin sizes
//! (`bin_theta_deg`, `bin_phi_deg`). All are EXR `string`s holding numbers in Rust's
//! shortest round-trip form: exact, and read by every tool (OpenEXR's Python module's old
//! `InputFile` API returns `None` for `double` attributes).
//!
//! `conoscope.png` is the angular distribution for people ([`write_conoscope_png`]).
//!
//! `flux.png` is the flux map for people: false colour over the detector in mm from its
//! origin corner, titled with the scene, the photons and the extraction efficiency (all
//! exact, so the picture of a run and of its merged shards are the same bytes).

use super::RunResult;
use super::metrics::{self, Map};
use crate::output::atomic::SetDir;
use crate::output::exr::{Attribute, Samples, write_channels};
use crate::output::figure::thousands;
use crate::output::map::{Grid, MapOptions, write_map};
use crate::output::polar::{PolarGrid, write_polar};
use anyhow::Result;
use glam::DVec3;
use std::path::Path;

/// `flux.png`: the map `flux` over the detector, titled with the scene, photons and
/// extraction efficiency.
pub(super) fn write_flux_png(run: &RunResult, path: &Path, flux: &Map) -> Result<()> {
    let l = &run.tally.ledger;
    let (efficiency, _) = l.detected.mean_and_stderr(l.photons);
    let title = format!(
        "{}: {} photons, extraction efficiency {:.2} %",
        run.scene.name,
        thousands(l.photons),
        100.0 * efficiency
    );
    write_target_png(path, map_on_target(run, flux), title, "irradiance (W/mm²)")
}

/// A map of the detector's bins, over the target in mm.
fn map_on_target<'m>(run: &RunResult, map: &'m Map) -> Grid<'m> {
    let d = &run.scene.detector;
    Grid {
        nx: map.nx,
        ny: map.ny,
        values: &map.value,
        x_mm: [0.0, d.size[0]],
        y_mm: [0.0, d.size[1]],
    }
}

/// A false-colour PNG of `grid` over the target, axes along the detector's u and v.
fn write_target_png(path: &Path, grid: Grid, title: String, unit: &str) -> Result<()> {
    let opts = MapOptions {
        title,
        x_label: "detector u (mm)".into(),
        y_label: "detector v (mm)".into(),
        unit: unit.into(),
        ..MapOptions::default()
    };
    write_map(path, &grid, &opts)
}

/// `conoscope.png`: the angular distribution as a conoscope shows it, luminance (cd/m^2,
/// averaged over the target) when the sources give lumens or spectra, else radiant
/// intensity (W/sr); theta is the radius (0 at the centre, 90 deg at the rim, rings every
/// 20 deg), phi the polar angle from the detector's `u` (right) towards its `v` (up).
pub(super) fn write_conoscope_png(run: &RunResult, path: &Path) -> Result<()> {
    let (map, what, unit) = match metrics::luminance_map(&run.scene, &run.tally) {
        Some(m) => (m, "luminance", "luminance (cd/m²)"),
        None => (
            run.angular_map(),
            "radiant intensity",
            "radiant intensity (W/sr)",
        ),
    };
    let grid = PolarGrid {
        n_theta: map.ny,
        n_phi: map.nx,
        values: &map.value,
        theta_max_deg: 90.0,
        ring_step_deg: 20.0,
    };
    let opts = MapOptions {
        title: format!(
            "{}: {what} by direction, {} photons",
            run.scene.name,
            thousands(run.tally.ledger.photons)
        ),
        unit: unit.into(),
        ..MapOptions::default()
    };
    write_polar(path, &grid, &opts)
}

/// `luminance.exr` and `luminance.png`: the luminance map of the first view within the
/// detector's cone ([`metrics::cone`]), and `luminance-view-K.exr`/`.png` of view K of
/// several; nothing without lumens or spectra.
pub(super) fn write_luminance_map(run: &RunResult, staged: &SetDir) -> Result<()> {
    for k in 0..run.scene.detector.views.len() {
        let Some(map) = metrics::cone::luminance_cone_map(&run.scene, &run.tally, k) else {
            return Ok(());
        };
        let name = match k {
            0 => "luminance".to_string(),
            _ => format!("luminance-view-{k}"),
        };
        write_luminance_view(run, staged, &map, k, &name)?;
    }
    Ok(())
}

/// `NAME.exr` and `NAME.png`: the luminance map `map` of view `k`.
fn write_luminance_view(
    run: &RunResult,
    staged: &SetDir,
    map: &Map,
    k: usize,
    name: &str,
) -> Result<()> {
    let d = &run.scene.detector;
    let cone = d.luminance_cone_deg;
    let [theta, phi] = d.views[k];
    let estimator = run.options.luminance_estimator.name().to_string();
    let mut attrs = map_attributes(
        run,
        "cd/m^2",
        &format!(
            "blutrace luminance map: Y = luminance (cd/m^2) of the light leaving each bin \
             within luminance_cone_deg of the view (theta_deg, phi_deg from the detector \
             normal and detector_u), by the {estimator} estimator, stderr.Y = its standard \
             error, hits.Y = photons that scored per bin; in a spectral run also X, Z on Y's \
             scale with their errors and u_prime, v_prime (CIE 1976); x along detector_u, y \
             along detector_v"
        ),
    );
    attrs.push(("luminance_cone_deg", Attribute::Text(cone.to_string())));
    attrs.push(("view_theta_deg", Attribute::Text(theta.to_string())));
    attrs.push(("view_phi_deg", Attribute::Text(phi.to_string())));
    attrs.push(("luminance_estimator", Attribute::Text(estimator.clone())));
    let (value, stderr, hits) = (f32s(&map.value), f32s(&map.stderr), counts(&map.hits));
    let colour = view_colour(run, k);
    staged.write_with(&format!("{name}.exr"), |path| {
        let mut channels = vec![
            ("Y", Samples::F32(&value)),
            ("stderr.Y", Samples::F32(&stderr)),
            ("hits.Y", Samples::F32(&hits)),
        ];
        for (name, c) in &colour {
            channels.push((name, Samples::F32(c)));
        }
        write_channels(path, map.nx, map.ny, &channels, &attrs)
    })?;
    let view = match k {
        0 if theta == 0.0 => "the normal".to_string(),
        _ => format!("theta {theta} phi {phi} deg"),
    };
    let title = format!(
        "{}: luminance within {cone} deg of {view}, {} photons",
        run.scene.name,
        thousands(run.tally.ledger.photons)
    );
    let unit = "luminance (cd/m²)";
    staged.write_with(&format!("{name}.png"), |path| {
        write_target_png(path, map_on_target(run, map), title.clone(), unit)
    })?;
    Ok(())
}

/// In a spectral run, view `k`'s `X`, `Z` (on `Y`'s cd/m² scale), their errors and
/// `u_prime`, `v_prime` per bin (NaN where no light), as EXR channels.
fn view_colour(run: &RunResult, k: usize) -> Vec<(&'static str, Vec<f32>)> {
    let Some(xyz) = metrics::cone::view_xyz_maps(&run.scene, &run.tally, k) else {
        return Vec::new();
    };
    let uv: Vec<[f64; 2]> = (0..xyz[0].value.len())
        .map(|i| {
            let c = crate::color::Xyz {
                x: xyz[0].value[i],
                y: xyz[1].value[i],
                z: xyz[2].value[i],
            };
            c.uv_prime().map_or([f64::NAN; 2], |p| [p.u, p.v])
        })
        .collect();
    let part = |i: usize| uv.iter().map(|p| p[i]).collect::<Vec<_>>();
    vec![
        ("X", f32s(&xyz[0].value)),
        ("Z", f32s(&xyz[2].value)),
        ("stderr.X", f32s(&xyz[0].stderr)),
        ("stderr.Z", f32s(&xyz[2].stderr)),
        ("u_prime", f32s(&part(0))),
        ("v_prime", f32s(&part(1))),
    ]
}

/// `stokes.exr`, when polarization is traced: `S0` (the flux map) to `S3` per bin with
/// their standard errors and photons, in the detector's frame.
pub(super) fn write_stokes_exr(run: &RunResult, staged: &SetDir) -> Result<()> {
    let Some(maps) = metrics::stokes::stokes_maps(&run.scene, &run.tally) else {
        return Ok(());
    };
    let attrs = map_attributes(
        run,
        "W/mm^2",
        "blutrace Stokes maps: S0..S3 = the Stokes vector's irradiance per bin (W/mm^2; \
         S0 is flux.exr's Y) in the detector's frame (u = detector_u made perpendicular to \
         each photon's direction, S1 > 0 along it; v = direction x u), stderr.S0..S3 = \
         standard errors, hits = photons per bin; x along detector_u, y along detector_v",
    );
    let names = ["S0", "S1", "S2", "S3"];
    let values: Vec<Vec<f32>> = maps.iter().map(|m| f32s(&m.value)).collect();
    let errors: Vec<Vec<f32>> = maps.iter().map(|m| f32s(&m.stderr)).collect();
    let stderr_names = names.map(|n| format!("stderr.{n}"));
    let hits = counts(&maps[0].hits);
    staged.write_with("stokes.exr", |path| {
        let mut channels: Vec<(&str, Samples)> = Vec::new();
        for k in 0..4 {
            channels.push((names[k], Samples::F32(&values[k])));
            channels.push((&stderr_names[k], Samples::F32(&errors[k])));
        }
        channels.push(("hits", Samples::F32(&hits)));
        write_channels(path, maps[0].nx, maps[0].ny, &channels, &attrs)
    })?;
    Ok(())
}

/// `flux.exr` of the map `flux`.
pub(super) fn write_flux_exr(run: &RunResult, staged: &SetDir, flux: &Map) -> Result<()> {
    let attrs = map_attributes(
        run,
        "W/mm^2",
        "blutrace flux map: Y = irradiance on the target plane (W/mm^2 per bin), \
         stderr.Y = its standard error (W/mm^2), hits.Y = photons per bin, \
         preview.Y = Y / (2 * mean) for display; \
         x along detector_u, y along detector_v from detector_origin_mm",
    );
    let (value, stderr, hits) = (f32s(&flux.value), f32s(&flux.stderr), counts(&flux.hits));
    let preview = preview(&flux.value);
    staged.write_with("flux.exr", |path| {
        let channels = [
            ("Y", Samples::F32(&value)),
            ("stderr.Y", Samples::F32(&stderr)),
            ("hits.Y", Samples::F32(&hits)),
            ("preview.Y", Samples::F32(&preview)),
        ];
        write_channels(path, flux.nx, flux.ny, &channels, &attrs)
    })?;
    Ok(())
}

/// `angular.exr`: intensity (W/sr), and luminance (cd/m^2) when the sources give lumens.
pub(super) fn write_angular_exr(run: &RunResult, staged: &SetDir) -> Result<()> {
    let ang = run.angular_map();
    let lum = metrics::luminance_map(&run.scene, &run.tally);
    let mut comments = String::from(
        "blutrace angular map: Y = radiant intensity (W/sr per bin), stderr.Y = its standard \
         error, hits.Y = photons per bin",
    );
    if lum.is_some() {
        comments += ", luminance.Y = luminance (cd/m^2, averaged over the target), \
                     luminance_stderr.Y = its standard error";
    }
    comments += "; x = phi (0 to 360 deg), y = theta (0 to 90 deg from the target normal)";
    let mut attrs = common_attributes(run, "W/sr", &comments);
    let [bin_theta, bin_phi] = run.scene.detector.angular_bin_deg();
    attrs.push(("bin_theta_deg", Attribute::Text(bin_theta.to_string())));
    attrs.push(("bin_phi_deg", Attribute::Text(bin_phi.to_string())));
    if lum.is_some() {
        attrs.push(("luminance_units", Attribute::Text("cd/m^2".into())));
    }
    let (i, ie, hits) = (f32s(&ang.value), f32s(&ang.stderr), counts(&ang.hits));
    let (l, le) = lum.as_ref().map_or((Vec::new(), Vec::new()), |m| {
        (f32s(&m.value), f32s(&m.stderr))
    });
    let mut channels = vec![
        ("Y", Samples::F32(&i)),
        ("stderr.Y", Samples::F32(&ie)),
        ("hits.Y", Samples::F32(&hits)),
    ];
    if lum.is_some() {
        channels.push(("luminance.Y", Samples::F32(&l)));
        channels.push(("luminance_stderr.Y", Samples::F32(&le)));
    }
    staged.write_with("angular.exr", |path| {
        write_channels(path, ang.nx, ang.ny, &channels, &attrs)
    })?;
    Ok(())
}

/// The attributes of a target map (`flux.exr`, `color.exr`): the common ones and the
/// bin and target sizes.
pub(super) fn map_attributes(
    run: &RunResult,
    units: &str,
    comments: &str,
) -> Vec<(&'static str, Attribute)> {
    let d = &run.scene.detector;
    let bin = d.bin_size();
    let mut attrs = common_attributes(run, units, comments);
    for (name, v) in [
        ("bin_size_x_mm", bin[0]),
        ("bin_size_y_mm", bin[1]),
        ("size_x_mm", d.size[0]),
        ("size_y_mm", d.size[1]),
    ] {
        attrs.push((name, Attribute::Text(v.to_string())));
    }
    attrs
}

/// The attributes both images carry.
fn common_attributes(
    run: &RunResult,
    units: &str,
    comments: &str,
) -> Vec<(&'static str, Attribute)> {
    let d = &run.scene.detector;
    let text = |s: String| Attribute::Text(s);
    let vec3 = |v: DVec3| text(format!("[{}, {}, {}]", v.x, v.y, v.z));
    vec![
        (
            "software",
            text(format!("blutrace {}", env!("CARGO_PKG_VERSION"))),
        ),
        ("comments", text(comments.to_owned())),
        ("units", text(units.to_owned())),
        ("scene", text(run.scene.name.clone())),
        (
            "scene_hash",
            text(format!("{:016x}", run.scene.content_hash())),
        ),
        ("seed", text(run.options.seed.to_string())),
        ("photons", text(run.tally.ledger.photons.to_string())),
        ("detector_origin_mm", vec3(d.origin + run.scene.offset)),
        ("detector_u", vec3(d.u)),
        ("detector_v", vec3(d.v)),
    ]
}

pub(super) fn f32s(v: &[f64]) -> Vec<f32> {
    v.iter().map(|&x| x as f32).collect()
}

/// Hit counts as floats: exact to 2^24 per bin, rounded to 7 significant digits past it.
fn counts(v: &[u64]) -> Vec<f32> {
    v.iter().map(|&h| h as f32).collect()
}

/// `value / (2 * mean)`: the map for display, mean at mid-grey (zeros for an empty map).
fn preview(value: &[f64]) -> Vec<f32> {
    let mean = value.iter().sum::<f64>() / value.len().max(1) as f64;
    let scale = if mean > 0.0 { 0.5 / mean } else { 0.0 };
    value.iter().map(|&v| (v * scale) as f32).collect()
}
