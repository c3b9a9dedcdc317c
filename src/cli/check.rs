//! `blutrace check`: validate a scene and print what it uses, per geometry file and tag
//! with sizes in mm (or `--json` for scripts).

use anyhow::Result;
use blutrace::accel::BackendChoice;
use blutrace::optics::medium::Medium;
use blutrace::optics::two_sided;
use blutrace::scene::Scene;
use blutrace::scene::geometry_report::BoxMm;
use blutrace::sources::rayfile::RayFileSummary;
use blutrace::sources::spectrum::EmissionSpectrum;
use std::path::Path;

/// "  x from .. to .. mm" for a check line.
fn bounds(b: Option<BoxMm>) -> String {
    let Some(b) = b else {
        return String::new();
    };
    let size: Vec<String> = (0..3)
        .map(|i| format!("{:.3}", b.max[i] - b.min[i]))
        .collect();
    format!(
        ", {} mm, from {:.3?} to {:.3?}",
        size.join(" x "),
        b.min,
        b.max
    )
}

/// ", scattering ... /mm, g ..." for a check line (empty for a clear medium), with the
/// particles the coefficients come from.
fn scattering(m: &Medium) -> String {
    let s = &m.scattering;
    if !s.scatters() {
        return String::new();
    }
    let from = match &m.particles {
        Some(p) => format!(" (Mie: {})", p.describe(s.per_mm.is_spectral())),
        None => String::new(),
    };
    let phase = if s.table.is_some() {
        "measured phase function, mean cosine"
    } else {
        "anisotropy g ="
    };
    let (mu_s, g, reduced) = (&s.per_mm, &s.anisotropy, s.reduced_per_mm());
    if !mu_s.is_spectral() && !g.is_spectral() {
        return format!(
            ", scattering {:.6} /mm, {phase} {:.4}, reduced {:.6} /mm{from}",
            mu_s.nominal(),
            g.nominal(),
            reduced.nominal()
        );
    }
    format!(
        ", scattering {} /mm, {phase} {}, reduced {} /mm{from}",
        spread(mu_s, 6),
        spread(g, 4),
        spread(&reduced, 6)
    )
}

/// The lines `check` prints under a ray file source: its text fields, rays, flux, bounds
/// and spectrum.
fn rayfile_lines(r: &RayFileSummary, spectrum: Option<&EmissionSpectrum>) {
    say!(
        "  ray file {}: {} rays, total {:.6} {}",
        r.file,
        r.rays,
        r.total_flux,
        r.flux_unit
    );
    for (name, text) in &r.text {
        say!("    {name:<23} {text}");
    }
    let b = |x: [[f64; 3]; 2]| format!("from {:.4?} to {:.4?}", x[0], x[1]);
    say!("    start points (file) {}", b(r.bounds_file));
    say!("    start points (mm)   {}", b(r.bounds_scene_mm));
    let efficacy = spectrum.map_or(String::new(), |s| {
        format!("; {:.1} lm/W", s.efficacy_lm_per_w())
    });
    say!("    wavelengths         {}{efficacy}", r.spectrum);
}

/// "a..b over 360-830 nm" of a spectral quantity, with `digits` decimals.
fn spread(q: &blutrace::optics::spectrum::Spectral, digits: usize) -> String {
    let (lo, hi) = q.range();
    format!("{lo:.digits$}..{hi:.digits$} over 360-830 nm")
}

pub(super) fn check(path: &Path, json: bool) -> Result<()> {
    let scene = Scene::load(path)?;
    if json {
        let report = blutrace::scene::check_report::check_json(&scene, path)?;
        say!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    let tally_bytes = blutrace::run::check_tally_budget(&scene)?;
    say!("scene      {} ({})", scene.name, path.display());
    say!(
        "geometry   {} triangles, {} tags",
        scene.mesh.len(),
        scene.tags.len()
    );
    for g in &scene.geometry {
        say!(
            "  file {:<25} {:>8} triangles{}",
            g.file,
            g.triangles,
            bounds(g.bounds_mm)
        );
        for (tag, t) in &g.tags {
            say!(
                "    tag {tag:<22} {:>8} triangles{}",
                t.triangles,
                bounds(Some(t.bounds_mm))
            );
        }
    }
    for (t, ((tag, model), n)) in scene
        .tags
        .iter()
        .zip(&scene.surfaces)
        .zip(scene.triangles_per_tag())
        .enumerate()
    {
        let placement = match model {
            blutrace::optics::surface::SurfaceModel::Dots(d) => {
                format!(", {} placement", d.pattern.placement.name())
            }
            _ => String::new(),
        };
        let back = two_sided::back_kind(model, scene.backs[t].as_ref())
            .map_or(String::new(), |b| format!(", back {b}"));
        let facing = two_sided::facing(&scene.mesh, t as u32)
            .iter()
            .map(|(way, k)| format!("{way} {k}"))
            .collect::<Vec<_>>()
            .join(", ");
        say!(
            "  tag {tag:<20} {:<11} {n} triangles{placement}{back}; facing {facing}",
            model.kind()
        );
    }
    for (i, m) in scene.media.iter().enumerate() {
        let path = match scene.convex_solid(i as u16) {
            Some(s) => format!("convex fast path ({} planes)", s.plane_count()),
            None if i == 0 => "ambient".to_string(),
            None => "backend (not a lone convex solid)".to_string(),
        };
        say!(
            "medium     {:<20} n = {}, absorption {} /mm{}; {path}",
            m.name,
            m.n,
            m.absorption_per_mm,
            scattering(m)
        );
    }
    let backend = blutrace::accel::build(BackendChoice::Auto, scene.mesh.clone())?;
    say!("backend    auto picks {}", backend.name());
    for s in &scene.sources.list {
        let body = s
            .body
            .as_ref()
            .map_or("transparent (no body)".to_string(), |b| b.describe());
        let medium = &scene.media[s.medium as usize].name;
        say!(
            "source     {:<20} {:.3} W in {medium}; body: {body}",
            s.name,
            s.power_w
        );
        if let blutrace::sources::Emitter::RayFile(r) = &s.emitter {
            rayfile_lines(&r.summary(), s.spectrum.as_deref());
        } else if let Some(sp) = &s.spectrum {
            say!("           {:<20} {}", "", sp.describe());
        }
    }
    let d = &scene.detector;
    say!(
        "detector   {} x {} mm, {} x {} bins, {} x {} angular bins; tallies {:.1} MiB (at most {} GiB)",
        d.size[0],
        d.size[1],
        d.bins[0],
        d.bins[1],
        d.angular_bins[0],
        d.angular_bins[1],
        tally_bytes as f64 / (1u64 << 20) as f64,
        blutrace::run::TALLY_BUDGET_BYTES >> 30
    );
    say!(
        "trace      {} photons, seed {}, bounce cap {}; {}",
        scene.default_photons,
        scene.default_seed,
        scene.max_bounces,
        if scene.polarized {
            "polarization traced (Stokes vectors, exact Fresnel)"
        } else {
            "unpolarized (averaged Fresnel)"
        }
    );
    for w in &scene.warnings {
        say!("warning    {w}");
    }
    say!("ok");
    Ok(())
}
