use blutrace::run::metrics::Uniformity;
use blutrace::run::{self, RunOptions};
use blutrace::scene::Scene;
fn main() -> anyhow::Result<()> {
    let a: Vec<String> = std::env::args().collect();
    let mut scene = Scene::load(std::path::Path::new(&a[1]))?;
    if a.len() > 3 {
        let c: Vec<f64> = a[3].split(',').map(|v| v.parse().unwrap()).collect();
        for s in &mut scene.surfaces {
            if let blutrace::optics::surface::SurfaceModel::Dots { pattern, .. } = s {
                pattern.density = blutrace::optics::dots::Density::Polynomial(c.clone());
            }
        }
    }
    let n: u64 = a[2].parse()?;
    if let Ok(t) = std::env::var("ABSORB_TAG") {
        let i = scene.tags.iter().position(|x| *x == t).unwrap();
        scene.surfaces[i] = blutrace::optics::surface::SurfaceModel::Absorber;
    }
    let r = run::trace(
        &scene,
        &RunOptions {
            photons: n,
            seed: 7,
            ..Default::default()
        },
        &|_| {},
    )?;
    let m = r.flux_map();
    let s = r.summary();
    println!(
        "cv {:.4} deb {:.4} floor {:.4} 13pt {:.3} t {:.1}",
        s.uniformity.cv,
        s.cv_debiased,
        s.cv_noise_floor,
        s.uniformity.thirteen_point_min_over_max,
        r.runtime_s
    );
    let u = Uniformity::of(&m);
    println!("abs mean {:.4e}", u.mean);
    let mut px = vec![0.0; m.nx];
    for y in 0..m.ny {
        for x in 0..m.nx {
            px[x] += m.value[y * m.nx + x] / m.ny as f64 / u.mean;
        }
    }
    println!(
        "x-profile: {}",
        px.iter()
            .map(|v| format!("{v:.3}"))
            .collect::<Vec<_>>()
            .join(" ")
    );
    let mut py = vec![0.0; m.ny];
    for y in 0..m.ny {
        for x in 0..m.nx {
            py[y] += m.value[y * m.nx + x] / m.nx as f64 / u.mean;
        }
    }
    println!(
        "y-profile: {}",
        py.iter()
            .map(|v| format!("{v:.3}"))
            .collect::<Vec<_>>()
            .join(" ")
    );
    Ok(())
}
