//! Ray files as sources (issue 34): a ray file written from the LED model traces like the
//! LED model; wavelengths and flux weights reach the photons; placement; errors; `check`.
//!
//! The LED comparison: a ray file of N rays drawn from the LED model is itself a random
//! sample of it, so a fate's fraction p differs between the two scenes by the photons'
//! noise (p (1 - p) / n per run) plus the ray set's (at most p (1 - p) / N): the test
//! allows 3 standard errors of that sum. `cargo test --release --test rayfile -- --ignored`
//! runs it with 1M photons and 1M rays.

mod support;

use blutrace::rng::PhotonRng;
use blutrace::scene::Scene;
use blutrace::sources::Emitter;
use blutrace::sources::rayfile::{FileSpectrum, FluxUnit, RaySet, StoredRay, check_ray, tm25};
use blutrace::sources::spectrum::cmf_at;
use glam::DVec3;
use std::path::Path;
use support::{assert_balanced, assert_warns, check_output, load, temp_folder, trace, write_scene};

/// The bundled phone-led scene with cos^3 LEDs (no intensity table) copied into `dir`.
fn cos_led_scene(dir: &Path) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/phone-led");
    for f in ["phone-led.obj", "phone-led.mtl"] {
        std::fs::copy(root.join(f), dir.join(f)).unwrap();
    }
    let text = std::fs::read_to_string(root.join("scene.toml")).unwrap();
    let text = text.replace("intensity_file = \"led.ies\"", "cos_exponent = 3.0");
    std::fs::write(dir.join("scene.toml"), &text).unwrap();
    text
}

/// `n` rays drawn from the LED model of `scene`'s first source, in the LED's own frame
/// (x along its width, y along normal x u, z along its normal, origin at its centre).
fn led_rays(scene: &Scene, n: usize) -> RaySet {
    let Emitter::Led(led) = &scene.sources.list[0].emitter else {
        panic!("the first source is not an LED")
    };
    let (u, v, w) = (led.u, led.normal.cross(led.u), led.normal);
    let power = scene.sources.list[0].power_w;
    let rays = (0..n)
        .map(|i| {
            let (ray, _) = led.emit(&mut PhotonRng::new(7, i as u64));
            let p = ray.origin - led.center;
            let local = |x: DVec3| [x.dot(u), x.dot(v), x.dot(w)].map(|c| c as f32);
            check_ray(local(p), local(ray.dir), (power / n as f64) as f32, None).unwrap()
        })
        .collect();
    RaySet {
        text: std::array::from_fn(|k| {
            if k == 0 {
                "cos^3 LED 3 x 0.4 mm".into()
            } else {
                String::new()
            }
        }),
        rays,
        nm: Vec::new(),
        table: Vec::new(),
        spectrum: FileSpectrum::None,
        unit: FluxUnit::Watt,
        stokes: Vec::new(),
        header_flux: [f64::NAN; 2],
    }
}

/// `text` with every LED entry replaced by a ray file entry at the same place: odd LEDs
/// placed by `rotate_deg`, even ones by `matrix` (both turn the file's x, y, z to the
/// LED's u = +y, +z and normal = +x).
fn with_ray_files(text: &str) -> String {
    let mut out = String::new();
    for (k, part) in text.split("[[sources]]").enumerate() {
        if k == 0 {
            out += part;
            continue;
        }
        let center = part.lines().find(|l| l.starts_with("center = ")).unwrap();
        let c: Vec<f64> = center["center = [".len()..center.len() - 1]
            .split(", ")
            .map(|x| x.parse().unwrap())
            .collect();
        let place = if k % 2 == 1 {
            format!(
                "rotate_deg = [90.0, 0.0, 90.0]\ntranslate = [{}, {}, {}]\n",
                c[0], c[1], c[2]
            )
        } else {
            format!(
                "matrix = [[0.0, 0.0, 1.0, {}], [1.0, 0.0, 0.0, {}], [0.0, 1.0, 0.0, {}], [0.0, 0.0, 0.0, 1.0]]\n",
                c[0], c[1], c[2]
            )
        };
        let tail = &part[part.find("\n[detector]").unwrap_or(part.len())..];
        out += &format!(
            "[[sources]]\ntype = \"rayfile\"\nname = \"led{k}\"\nfile = \"led.TM25RAY\"\n{place}\
             power_w = 0.03\nlumens = 9.18\nbody = {{ model = \"lambert\", albedo = 0.8 }}\n{tail}"
        );
    }
    out
}

/// Fractions of the emitted power by fate: detected, each surface's absorption, the
/// medium's, the lamp bodies' and escaped.
fn fates(scene: &Scene, photons: u64) -> Vec<(String, f64)> {
    let r = trace(scene, photons, 11, 2);
    assert_balanced(&r);
    let l = &r.tally.ledger;
    let n = l.photons as f64;
    let mut v = vec![("detected".to_string(), l.detected.sum.value() / n)];
    for (t, a) in scene.tags.iter().zip(&l.absorbed_by_surface) {
        v.push((format!("absorbed by {t}"), a.value() / n));
    }
    let sum = |x: &[blutrace::tally::ExactSum]| x.iter().map(|a| a.value()).sum::<f64>() / n;
    v.push(("absorbed in media".into(), sum(&l.absorbed_in_medium)));
    v.push(("absorbed by bodies".into(), sum(&l.absorbed_by_source)));
    v.push(("escaped".into(), l.escaped.value() / n));
    v
}

fn led_and_ray_file_agree(photons: u64, rays: usize) {
    let dir = temp_folder("rayfile-led");
    let text = cos_led_scene(dir.path());
    let led_scene = load(&dir.path().join("scene.toml"));
    tm25::write(&dir.path().join("led.TM25RAY"), &led_rays(&led_scene, rays)).unwrap();
    let rays_path = dir.path().join("rays.toml");
    std::fs::write(&rays_path, with_ray_files(&text)).unwrap();
    let ray_scene = load(&rays_path);
    assert_eq!(ray_scene.sources.list.len(), 6);
    let (a, b) = (fates(&led_scene, photons), fates(&ray_scene, photons));
    for ((name, p), (_, q)) in a.iter().zip(&b) {
        let var = |x: f64| x * (1.0 - x);
        let se =
            (var(*p) / photons as f64 + var(*q) / photons as f64 + var(*p) / rays as f64).sqrt();
        eprintln!(
            "{name:<28} LED {p:.5}  ray file {q:.5}  diff {:+.2} se",
            (q - p) / se.max(1e-300)
        );
        assert!(
            (p - q).abs() <= 3.0 * se + 1e-12,
            "{name}: LED {p}, ray file {q}, se {se}"
        );
    }
    assert!(a[0].1 > 0.3, "the scene detects light: {a:?}");
}

#[test]
fn a_ray_file_of_the_led_model_traces_like_it() {
    led_and_ray_file_agree(100_000, 200_000);
}

#[test]
#[ignore = "slow statistical test (about 20 s on 2 idle cores)"]
fn a_ray_file_of_the_led_model_traces_like_it_at_1m_photons() {
    led_and_ray_file_agree(1_000_000, 1_000_000);
}

/// A mirror below (z = -1) that reflects only beyond 550 nm, the target above (z = 1), and
/// a ray file `rays` (text) in between.
fn two_colour_scene(name: &str, rays: &str, extra: &str) -> Scene {
    load(&write_scene(
        name,
        &two_colour_toml("two.rays", extra),
        &[("mirror.obj", MIRROR), ("two.rays", rays)],
    ))
}

/// The scene of [`two_colour_scene`] with the ray file `file`.
fn two_colour_toml(file: &str, extra: &str) -> String {
    format!(
        "version = 1\n[[geometry]]\nfile = \"mirror.obj\"\n\
         [surfaces.mirror]\nmodel = \"mirror\"\nreflectance = {{ table = [[360, 0.0], [549, 0.0], [551, 1.0], [830, 1.0]] }}\n\
         [[sources]]\ntype = \"rayfile\"\nfile = \"{file}\"\nbody = \"transparent\"\n{extra}\
         [detector]\norigin = [-5.0, -5.0, 1.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [10.0, 10.0]\nbins = [2, 2]\n"
    )
}

#[test]
fn wavelengths_and_flux_weights_reach_the_photons() {
    // 450 nm down onto the mirror (absorbed), 650 nm straight up to the target.
    let rays = "# x y z kx ky kz flux nm\n0 0 0  0 0 -1  0.25 450\n0.5 0 0  0 0 1  0.75 650\n";
    let scene = two_colour_scene("two-colours", rays, "");
    let s = &scene.sources.list[0];
    assert_eq!(s.power_w, 1.0, "power_w defaults to the file's total flux");
    let efficacy = s.luminous_flux().unwrap();
    assert!(efficacy > 20.0 && efficacy < 200.0, "{efficacy} lm");
    // The 650 nm flux share.
    assert_detects(&scene, 3, 0.75);
    // Half the photons per ray (flux ignored) would detect 0.5; every photon at 555 nm
    // (wavelengths ignored) 1; wavelengths drawn from the file's spectrum instead of
    // going with their rays 0.75 + 0.25 x 0.75 = 0.9375.
}

#[test]
fn spectra_mix_only_with_spectra() {
    let rays = "0 0 0 0 0 -1 1\n";
    let e = Scene::load(&write_scene(
        "mono",
        &scene_two_sources(rays, ""),
        &[("mirror.obj", MIRROR), ("two.rays", rays)],
    ))
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("sources[1].spectrum: missing: sources[0] has a spectrum"),
        "{e}"
    );
    let with_nm = "0 0 0 0 0 -1 1 500\n";
    let e = Scene::load(&write_scene(
        "twice",
        &scene_two_sources(with_nm, "spectrum = \"cie-d65\"\n"),
        &[("mirror.obj", MIRROR), ("two.rays", with_nm)],
    ))
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("sources[1].spectrum: the ray file gives the rays' wavelengths"),
        "{e}"
    );
    let ok = write_scene(
        "both",
        &scene_two_sources(with_nm, ""),
        &[("mirror.obj", MIRROR), ("two.rays", with_nm)],
    );
    assert!(load(&ok).sources.spectral());
}

const MIRROR: &str =
    "v -5 -5 -1\nv 5 -5 -1\nv 5 5 -1\nv -5 5 -1\nusemtl mirror\nf 1 2 3\nf 1 3 4\n";

/// An LED with a D65 spectrum and a ray file (`extra`: its further keys).
fn scene_two_sources(_rays: &str, extra: &str) -> String {
    format!(
        "version = 1\n[[geometry]]\nfile = \"mirror.obj\"\n[surfaces.mirror]\nmodel = \"absorber\"\n\
         [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, -1.0]\nu = [1.0, 0.0, 0.0]\n\
         width_mm = 1.0\nheight_mm = 1.0\npower_w = 1.0\nspectrum = \"cie-d65\"\n\
         [[sources]]\ntype = \"rayfile\"\nfile = \"two.rays\"\n{extra}\
         [detector]\norigin = [-5.0, -5.0, 1.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [10.0, 10.0]\nbins = [2, 2]\n"
    )
}

#[test]
fn a_ray_lands_where_its_placement_puts_it() {
    let rays = "1 2 3  1 0 0  1.0\n";
    let extra = "units = \"cm\"\nrotate_deg = [0.0, 0.0, 90.0]\ntranslate = [100.0, 0.0, 0.0]\npower_w = 2.0\n";
    let scene = two_colour_scene("placed", rays, extra);
    let e = scene.sources.sample(&mut PhotonRng::new(1, 0));
    // (10, 20, 30) mm turned 90 degrees about z: (-20, 10, 30), then moved.
    let at = e.ray.origin + scene.offset; // the loader centres the scene
    assert!((at - DVec3::new(80.0, 10.0, 30.0)).length() < 1e-9, "{at}");
    assert!((e.ray.dir - DVec3::Y).length() < 1e-12, "{}", e.ray.dir);
    assert_eq!(scene.sources.list[0].power_w, 2.0);
    let bad = "matrix = [[2.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]\n";
    let dir = temp_folder("rayfile-matrix");
    std::fs::write(dir.path().join("two.rays"), rays).unwrap();
    std::fs::write(dir.path().join("mirror.obj"), MIRROR).unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(
        &path,
        scene_two_sources(rays, bad).replace("spectrum = \"cie-d65\"\n", ""),
    )
    .unwrap();
    let e = Scene::load(&path).unwrap_err().to_string();
    assert!(e.contains("sources[1].matrix: must be a rotation"), "{e}");
}

#[test]
fn scene_errors_name_the_entry_the_file_and_the_byte() {
    let dir = temp_folder("rayfile-errors");
    let set = RaySet {
        text: Default::default(),
        rays: vec![StoredRay {
            pos: [0.0; 3],
            dir: [0.0, 0.0, -1.0],
            flux: 1.0,
        }],
        nm: Vec::new(),
        table: Vec::new(),
        spectrum: FileSpectrum::None,
        unit: FluxUnit::Watt,
        stokes: Vec::new(),
        header_flux: [f64::NAN; 2],
    };
    let file = dir.path().join("x.TM25RAY");
    tm25::write(&file, &set).unwrap();
    let mut bytes = std::fs::read(&file).unwrap();
    bytes.truncate(bytes.len() - 3);
    std::fs::write(&file, bytes).unwrap();
    std::fs::write(dir.path().join("mirror.obj"), MIRROR).unwrap();
    let path = dir.path().join("scene.toml");
    let toml = scene_two_sources("", "")
        .replace("two.rays", "x.TM25RAY")
        .replace("spectrum = \"cie-d65\"\n", "");
    std::fs::write(&path, toml).unwrap();
    let e = Scene::load(&path).unwrap_err().to_string();
    assert!(
        e.contains("scene.toml: sources[1].file:")
            && e.contains("x.TM25RAY: byte 20: number of rays (4.7.1.6): 1 rays of 28 bytes"),
        "{e}"
    );
}

#[test]
fn check_prints_the_ray_file() {
    let dir = temp_folder("rayfile-check");
    let mut set = RaySet {
        text: std::array::from_fn(|k| match k {
            0 => "LED-1".into(),
            1 => "Maker GmbH".into(),
            _ => String::new(),
        }),
        rays: vec![
            StoredRay {
                pos: [-1.0, 0.0, 0.0],
                dir: [0.0, 0.0, 1.0],
                flux: 0.5,
            },
            StoredRay {
                pos: [1.0, 0.5, 0.25],
                dir: [0.0, 0.0, 1.0],
                flux: 1.5,
            },
        ],
        nm: Vec::new(),
        table: Vec::new(),
        spectrum: FileSpectrum::Table(vec![[440.0, 0.0], [450.0, 1.0], [460.0, 0.0]]),
        unit: FluxUnit::Watt,
        stokes: Vec::new(),
        header_flux: [f64::NAN; 2],
    };
    tm25::write(&dir.path().join("x.TM25RAY"), &set).unwrap();
    std::fs::write(dir.path().join("mirror.obj"), MIRROR).unwrap();
    let toml = scene_two_sources("", "").replace("two.rays", "x.TM25RAY");
    std::fs::write(dir.path().join("scene.toml"), toml).unwrap();
    let run = |json: bool| check_output(&dir.path().join("scene.toml"), json);
    let text = run(false);
    for want in [
        "ray file x.TM25RAY: 2 rays, total 2.000000 W",
        "light source",
        "LED-1",
        "Maker GmbH",
        "one table of 3 rows for every ray, 440-460 nm",
        "from [-1.0000, 0.0000, 0.0000] to [1.0000, 0.5000, 0.2500]",
    ] {
        assert!(text.contains(want), "want '{want}' in:\n{text}");
    }
    let json: serde_json::Value = serde_json::from_str(&run(true)).unwrap();
    let r = &json["sources"][1]["rayfile"];
    assert_eq!(r["rays"], 2);
    assert_eq!(r["total_flux"], 2.0);
    assert_eq!(r["text"][1][1], "Maker GmbH");
    set.rays.clear();
    assert!(json["sources"][0]["rayfile"].is_null());
}

/// A white LED's ray file with spectral tables per ray: a blue table and a broad yellow
/// one, 0.6 W of rays on the blue, 0.4 W on the yellow (two rays: weighting the tables by
/// ray count instead of flux would give 1:2).
fn two_table_set() -> RaySet {
    let ray = |x: f32, flux: f32| StoredRay {
        pos: [x, 0.0, 0.0],
        dir: [0.0, 0.0, 1.0],
        flux,
    };
    RaySet {
        text: Default::default(),
        rays: vec![ray(-1.0, 0.1), ray(0.0, 0.6), ray(1.0, 0.3)],
        nm: Vec::new(),
        table: vec![1, 0, 1],
        spectrum: FileSpectrum::Tables(vec![
            vec![[440.0, 0.0], [455.0, 1.0], [470.0, 0.0]],
            vec![[480.0, 0.5], [560.0, 1.0], [650.0, 0.25], [700.0, 0.0]],
        ]),
        unit: FluxUnit::Watt,
        stokes: Vec::new(),
        header_flux: [f64::NAN; 2],
    }
}

/// Luminous efficacy (lm/W) of the piecewise-linear table `rows`: 683 lm/W times
/// ∫ S ȳ / ∫ S, by the midpoint rule at 0.001 nm.
fn efficacy(rows: &[[f64; 2]]) -> f64 {
    let at = |x: f64| {
        let i = rows.iter().position(|r| r[0] >= x).unwrap().max(1);
        let (p, q) = (rows[i - 1], rows[i]);
        p[1] + (x - p[0]) / (q[0] - p[0]) * (q[1] - p[1])
    };
    let (lo, hi) = (rows[0][0], rows[rows.len() - 1][0]);
    let n = ((hi - lo) / 1e-3) as usize;
    let h = (hi - lo) / n as f64;
    let (mut s, mut sy) = (0.0, 0.0);
    for k in 0..n {
        let x = lo + (k as f64 + 0.5) * h;
        s += at(x) * h;
        sy += at(x) * cmf_at(x)[1] * h;
    }
    683.0 * sy / s
}

#[test]
fn spectral_tables_per_ray_mix_their_colour_by_flux() {
    let dir = temp_folder("rayfile-tables");
    let set = two_table_set();
    tm25::write(&dir.path().join("x.TM25RAY"), &set).unwrap();
    std::fs::write(dir.path().join("mirror.obj"), MIRROR).unwrap();
    let toml = scene_two_sources("", "").replace("two.rays", "x.TM25RAY");
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, toml).unwrap();
    let scene = load(&path);
    let s = &scene.sources.list[1];
    assert!((s.power_w - 1.0).abs() < 1e-7, "{}", s.power_w);
    let FileSpectrum::Tables(tables) = &set.spectrum else {
        unreachable!()
    };
    let (blue, yellow) = (efficacy(&tables[0]), efficacy(&tables[1]));
    let want = s.power_w * (0.6 * blue + 0.4 * yellow);
    let lm = s.luminous_flux().unwrap();
    assert!(
        (lm - want).abs() < 1e-6 * want,
        "{lm} lm, expected {want} (blue {blue} lm/W, yellow {yellow} lm/W)"
    );
    let range = s.spectrum.as_ref().unwrap().range_nm();
    assert_eq!(range, (440.0, 700.0));
    let text = check_output(&path, false);
    let want = "2 spectral tables, one per ray by index, 440-700 nm";
    assert!(text.contains(want), "want '{want}' in:\n{text}");
}

#[test]
fn photons_trace_with_their_rays_tables() {
    // Two rays down onto the mirror that reflects only beyond 550 nm, one with the red
    // table (0.2 W, reflected to the target), one with the blue (0.4 W, absorbed), and a
    // blue ray straight up (0.4 W): 0.6 of the power is detected. Tables swapped: 0.8;
    // wavelengths drawn from the mixture whatever the ray: 0.4 + 0.6 x 0.2 = 0.52.
    let ray = |kz: f32, flux: f32| StoredRay {
        pos: [0.0; 3],
        dir: [0.0, 0.0, kz],
        flux,
    };
    let set = RaySet {
        text: Default::default(),
        rays: vec![ray(-1.0, 0.2), ray(-1.0, 0.4), ray(1.0, 0.4)],
        nm: Vec::new(),
        table: vec![1, 0, 0],
        spectrum: FileSpectrum::Tables(vec![
            vec![[440.0, 0.0], [460.0, 1.0], [480.0, 0.0]],
            vec![[600.0, 1.0], [650.0, 1.0]],
        ]),
        unit: FluxUnit::Watt,
        stokes: Vec::new(),
        header_flux: [f64::NAN; 2],
    };
    let dir = write_scene(
        "tables-trace",
        &two_colour_toml("x.TM25RAY", ""),
        &[("mirror.obj", MIRROR)],
    );
    tm25::write(&dir.parent().unwrap().join("x.TM25RAY"), &set).unwrap();
    assert_detects(&load(&dir), 5, 0.6);
}

/// 40,000 photons of `scene` (seed `seed`), balanced, detect the fraction `p` within 4
/// standard errors.
fn assert_detects(scene: &Scene, seed: u64, p: f64) {
    let n = 40_000;
    let r = trace(scene, n, seed, 2);
    assert_balanced(&r);
    let detected = r.tally.ledger.detected.sum.value() / n as f64;
    let se = (p * (1.0 - p) / n as f64).sqrt();
    assert!(
        (detected - p).abs() < 4.0 * se,
        "detected {detected}, expected {p}"
    );
}

/// The files of `fuzz/seeds/<target>`: (name, path), sorted.
fn fuzz_seeds(target: &str) -> Vec<(String, std::path::PathBuf)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/seeds")
        .join(target);
    let mut out: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), p))
        .collect();
    out.sort();
    out
}

#[test]
fn the_fuzz_seeds_read_and_the_bad_ones_fail() {
    for target in ["tm25", "rayfile_text"] {
        let seeds = fuzz_seeds(target);
        assert!(seeds.len() >= 4, "{target}: {seeds:?}");
        for (name, path) in seeds {
            let read = RaySet::read(&path);
            match (name.starts_with("bad-"), read) {
                (false, Ok(set)) => assert!(set.total_flux() > 0.0, "{name}"),
                (true, Err(e)) => assert!(format!("{e:#}").contains(&name), "{name}: {e:#}"),
                (false, Err(e)) => panic!("{target}/{name} should read: {e:#}"),
                (true, Ok(set)) => panic!("{target}/{name} should fail: {set:?}"),
            }
        }
    }
}

#[test]
fn a_ray_file_with_wavelengths_makes_the_media_spectral() {
    // No `spectrum` key anywhere: the file's nm column alone makes the scene spectral, so
    // the particles are tabulated over wavelength (found by the fuzz target `rayfile_text`,
    // whose debug build asserted the scene's two views of it agree).
    let rays = "0 0 0  0 0 1  0.5 450\n0.5 0 0  0 0 1  0.5 650\n";
    let medium = "[media.milk]\nn = 1.49\n\
        particles = { radius_um = 1.0, n = 1.42, volume_fraction = 0.01, wavelength_nm = 480.0 }\n";
    let scene = two_colour_scene("spectral-media", rays, medium);
    assert!(scene.sources.spectral());
    let milk = scene.media.iter().find(|m| m.name == "milk").unwrap();
    assert!(
        milk.scattering.per_mm.is_spectral(),
        "{:?}",
        milk.scattering
    );
    assert_warns(
        &scene,
        "media.milk.particles.wavelength_nm = 480 is not used",
    );
}
