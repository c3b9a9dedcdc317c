//! `blutrace bsdf SCENE --tag TAG`: characterise a part of a scene into an IS BSDF file
//! (the library's [`blutrace::characterise`]), to trace it as one `bsdf_table` face.

use anyhow::{Context, Result};
use blutrace::characterise::{Options, characterise};
use blutrace::optics::bsdf_table::format;
use blutrace::scene::Scene;
use clap::Args;
use std::path::PathBuf;

/// `blutrace bsdf`'s options.
#[derive(Args)]
pub struct BsdfArgs {
    /// Scene file (or a folder holding scene.toml).
    scene: PathBuf,
    /// The tag of the flat face the light arrives at (its slab, when it bounds one).
    #[arg(long)]
    tag: String,
    /// The IS BSDF file to write (default: TAG.bsdf).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Photons per angle of incidence (and sample rotation).
    #[arg(long, default_value_t = 1_000_000, value_parser = blutrace::count::parse_photons)]
    photons: u64,
    /// Angles of incidence (degrees).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "0,10,20,30,40,50,60,70,80,85"
    )]
    aoi: Vec<f64>,
    /// Sample rotations (degrees): one gives a plane-symmetric table (an isotropic part),
    /// several an asymmetric one (e.g. 0,45,90,135 for a prism film).
    #[arg(long, value_delimiter = ',', default_value = "0")]
    rotations: Vec<f64>,
    /// Radial step of the table (degrees from the specular direction).
    #[arg(long, default_value_t = 2.0)]
    radial_step: f64,
    /// Azimuth step of the table (degrees).
    #[arg(long, default_value_t = 10.0)]
    azimuth_step: f64,
    /// The direction of sample rotation 0 on the face, as `X,Y,Z` or `X Y Z` (default: x,
    /// or y on faces facing x); a negative X in the first form follows `=`:
    /// `--u-axis=-1,0,0`.
    #[arg(
        long,
        value_delimiter = ',',
        num_args = 1..=3,
        allow_negative_numbers = true,
        value_name = "X,Y,Z"
    )]
    u_axis: Option<Vec<f64>>,
    /// Seed of the random numbers.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

/// The three components of `--u-axis` (given as `X,Y,Z`, `X Y Z` or a mix).
fn u_axis(v: &[f64]) -> Result<[f64; 3]> {
    <[f64; 3]>::try_from(v).map_err(|_| {
        anyhow::anyhow!(
            "--u-axis: expected three numbers, X,Y,Z or X Y Z, got {}",
            v.len()
        )
    })
}

/// Run `blutrace bsdf`.
pub fn bsdf(args: BsdfArgs) -> Result<()> {
    let scene = Scene::load(&super::scene_path(&args.scene))?;
    let opts = Options {
        tag: args.tag.clone(),
        photons: args.photons,
        aoi_deg: args.aoi,
        rotations_deg: args.rotations,
        radial_step_deg: args.radial_step,
        azimuth_step_deg: args.azimuth_step,
        u_axis: args.u_axis.as_deref().map(u_axis).transpose()?,
        seed: args.seed,
    };
    let out = args
        .out
        .unwrap_or_else(|| PathBuf::from(format!("{}.bsdf", args.tag)));
    // Refused before the work, not after it.
    blutrace::output::atomic::check_apart(&out, &scene.inputs)?;
    let start = std::time::Instant::now();
    let c = characterise(&scene, &opts).with_context(|| format!("{}", scene.path.display()))?;
    let comments = [
        format!("blutrace bsdf {} --tag {}", scene.path.display(), args.tag),
        format!("part: {}", c.part),
        format!("{} photons per incidence, seed {}", args.photons, args.seed),
    ];
    let table = format::write(&c.sections, &comments);
    blutrace::output::atomic::write_file(&out, table.as_bytes(), &scene.inputs)?;
    say!("part: {}", c.part);
    say!(
        "{:>8} {:>8} {:>10} {:>10} {:>10}",
        "rot_deg",
        "aoi_deg",
        "reflected",
        "transmit",
        "absorbed"
    );
    let n_aoi = opts.aoi_deg.len();
    for (k, f) in c.fates.iter().enumerate() {
        say!(
            "{:>8} {:>8} {:>10.5} {:>10.5} {:>10.5}{}",
            opts.rotations_deg[k / n_aoi],
            opts.aoi_deg[k % n_aoi],
            f.reflected,
            f.transmitted,
            f.absorbed,
            if f.lost > 0.0 {
                format!(" (lost {:.2e})", f.lost)
            } else {
                String::new()
            }
        );
    }
    say!(
        "wrote {} ({:.1} s)",
        out.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
