//! Extreme scenes (issue 6): blutrace at the edges of a backlight's numerical range.
//! One file per family of cases (`fresnel_cases`, `thin_plate`, `scale`, `enclosures`,
//! `meshes`, `dots`, `tallies`); this one holds the rows, the doc and shared helpers.
//!
//! Every case is a function returning one row of `docs/book/src/stability-cases.md`: what could go wrong,
//! what blutrace does, the expected answer and the measured one. Each case is also a test
//! (the slow ones `#[ignore]`d), and each test checks that the doc's row for it carries the
//! verdict and the measured numbers the case gets now (the numbers where Embree is
//! available, as it was for the doc's run), so the doc cannot silently go stale.
//!
//! ```text
//! cargo test --release --test stability                      # the fast cases + doc check
//! cargo test --release --test stability -- --ignored         # the slow cases
//! cargo test --release --test stability -- --ignored regenerate_stability_doc
//!                                                            # all cases, rewrites the doc
//! ```
//!
//! Monte Carlo tolerances are stated in standard errors (4 SE: a correct tracer fails one
//! seed in 16,000); floating-point checks in units of the rounding error they allow. Every
//! run is seeded, so the numbers in the doc are reproducible bit for bit.

#[path = "../support/mod.rs"]
mod support;

mod dots;
mod enclosures;
mod fresnel_cases;
mod meshes;
mod scale;
mod tallies;
mod thin_plate;

use dots::*;
use enclosures::*;
use fresnel_cases::*;
use meshes::*;
use scale::*;
use tallies::*;
use thin_plate::*;

use blutrace::accel::{self, BackendChoice};
use blutrace::geometry::{Mesh, Ray, SurfaceHit, intersect_triangle};
use blutrace::optics::dots::{Density, DotPattern, Gradation, Lattice, Placement, XUnit};
use blutrace::optics::fresnel;
use blutrace::optics::surface::{Estimator, Interface, Medium, Outcome, SurfaceModel};
use blutrace::rng::PhotonRng;
use blutrace::run::{RunOptions, RunResult};
use blutrace::scene::Scene;
use blutrace::tally::ExactSum;
use blutrace::tally::Ledger;
use glam::{DMat3, DVec3};
use std::f64::consts::FRAC_PI_2;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use support::{trace_opts, write_scene};

// =======================================================================================
// Rows, verdicts and the doc

/// How a case came out.
#[derive(Clone, Debug, PartialEq)]
enum Verdict {
    /// Measured agrees with expected.
    Pass,
    /// A known, quantified deviation with a proposed fix (named in the doc); the case
    /// checks that the deviation is exactly the explained one.
    Open(String),
    /// Anything else.
    Fail(String),
}

impl Verdict {
    fn word(&self) -> &'static str {
        match self {
            Verdict::Pass => "pass",
            Verdict::Open(_) => "open",
            Verdict::Fail(_) => "FAIL",
        }
    }
}

/// One row of the doc.
struct Row {
    id: &'static str,
    /// What could go wrong.
    risk: &'static str,
    /// What blutrace does about it.
    does: &'static str,
    expected: String,
    measured: String,
    verdict: Verdict,
}

/// Pass when `ok`, else fail saying `why`.
fn verdict(ok: bool, why: impl FnOnce() -> String) -> Verdict {
    if ok {
        Verdict::Pass
    } else {
        Verdict::Fail(why())
    }
}

/// A case: id, slow (ignored in the default run), and the function running it.
type Case = (&'static str, bool, fn() -> Row);

/// Every case, in doc order.
const CASES: &[Case] = &[
    ("fresnel-normal", false, fresnel_normal),
    ("fresnel-grazing", false, fresnel_grazing),
    ("fresnel-critical", false, fresnel_critical),
    ("fresnel-no-interface", false, fresnel_no_interface),
    ("fresnel-diamond", false, fresnel_diamond),
    ("fresnel-energy", false, fresnel_energy),
    ("fresnel-roulette", false, fresnel_roulette),
    ("thin-plate-leak", false, thin_plate_leak),
    ("thin-plate-bounces", false, thin_plate_bounces),
    ("tv-guide-20um-dots", false, tv_guide_dots),
    ("phone-guide-5um-dots", false, phone_guide_dots),
    ("translate-10m", false, translate_10m),
    ("scale-phone-tv", false, scale_phone_tv),
    ("furnace-lambert", false, furnace_lambert),
    ("furnace-albedo-1", false, furnace_albedo_one),
    ("furnace-weighted", false, furnace_weighted),
    ("recycling-cavity", false, recycling_cavity),
    ("recycling-esr-0.999", true, recycling_esr_slow),
    ("mesh-seams", false, mesh_seams),
    ("mesh-zero-area", false, mesh_zero_area),
    ("mesh-duplicate-vertices", false, mesh_duplicate_vertices),
    ("mesh-slivers", false, mesh_slivers),
    ("mesh-inverted-normals", false, mesh_inverted_normals),
    ("mesh-open", false, mesh_open),
    ("mesh-non-finite", false, mesh_non_finite),
    ("dots-density-extremes", false, dots_density_extremes),
    ("dots-polynomial-range", false, dots_polynomial_range),
    ("exact-sum-1e8", false, exact_sum_1e8),
    ("exact-sum-1e9", true, exact_sum_1e9),
];

const DOC: &str = "docs/book/src/stability-cases.md";
const REGENERATE: &str =
    "cargo test --release --test stability -- --ignored regenerate_stability_doc";

fn doc_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(DOC)
}

/// Table cell text: no pipes, no newlines.
fn cell(s: &str) -> String {
    s.replace('|', "/").replace('\n', " ")
}

fn render(rows: &[(Row, bool, f64)]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# blutrace at the edges: the extreme-scene suite\n\n\
         <!-- Generated by `{REGENERATE}`: do not edit by hand. -->\n\n\
         One row per case of `tests/stability/` (issue 6). **Regenerate** this file with\n\n\
         ```text\n{REGENERATE}\n```\n\n\
         (all cases, including the slow ones; about a minute in release on 2 cores). `cargo test --release \
         --test stability` runs the fast cases and checks that each has a row here with the \
         verdict and the measured numbers it gets now (the numbers on a machine with Embree, \
         as this run had; the run times vary); `-- --ignored` runs the slow ones. Every run is seeded, so the \
         measured numbers are reproducible; Monte Carlo tolerances are in standard errors \
         (SE), floating-point ones in units of the rounding error (eps = 2^-52).\n\n\
         Verdicts: **pass** (measured agrees with expected), **open** (a known deviation, \
         measured exactly as explained, fix proposed below), **FAIL**.\n"
    );
    let _ = writeln!(
        s,
        "| Case | What could go wrong | What blutrace does | Expected | Measured | Verdict |\n\
         |---|---|---|---|---|---|"
    );
    for (r, slow, secs) in rows {
        let _ = writeln!(
            s,
            "| `{}`{} | {} | {} | {} | {} | **{}** |",
            r.id,
            if *slow { " (slow)" } else { "" },
            cell(r.risk),
            cell(r.does),
            cell(&r.expected),
            cell(&format!("{} ({secs:.1} s)", r.measured)),
            r.verdict.word()
        );
    }
    let open: Vec<&Row> = rows
        .iter()
        .map(|(r, _, _)| r)
        .filter(|r| !matches!(r.verdict, Verdict::Pass))
        .collect();
    if !open.is_empty() {
        let _ = writeln!(s, "\n## Open and failing cases\n");
        for r in open {
            let why = match &r.verdict {
                Verdict::Open(w) | Verdict::Fail(w) => w.as_str(),
                Verdict::Pass => "",
            };
            let _ = writeln!(s, "- `{}` ({}): {}\n", r.id, r.verdict.word(), why);
        }
    }
    s
}

/// The committed doc's row for case `id`: its measured cell without the run time that
/// `render` appends, and its verdict word.
fn doc_row(id: &str) -> Option<(String, String)> {
    let text = std::fs::read_to_string(doc_path()).ok()?;
    let key = format!("| `{id}`");
    let line = text.lines().find(|l| l.starts_with(&key))?;
    let cells: Vec<&str> = line.split('|').map(str::trim).collect();
    let [_, _, _, _, _, measured, verdict, _] = cells[..] else {
        return None;
    };
    let measured = measured.rsplit_once(" (").map_or(measured, |(m, _)| m);
    Some((measured.to_string(), verdict.trim_matches('*').to_string()))
}

/// Run case `id` as a test: it must not fail, and the doc's row must carry its verdict
/// and, where this machine has Embree (as the doc's run had), its measured numbers: every
/// case is seeded, so a row that differs is a stale row.
fn run_case(id: &str) {
    let (_, _, f) = CASES
        .iter()
        .find(|c| c.0 == id)
        .expect("case listed in CASES");
    let r = f();
    eprintln!(
        "{id}: expected {} | measured {} | {}",
        r.expected,
        r.measured,
        r.verdict.word()
    );
    if let Verdict::Fail(why) = &r.verdict {
        panic!(
            "{id} failed: {why}\n  expected: {}\n  measured: {}",
            r.expected, r.measured
        );
    }
    let documented = doc_row(id);
    assert_eq!(
        documented.as_ref().map(|d| d.1.as_str()),
        Some(r.verdict.word()),
        "{DOC} is stale for `{id}` (it says {documented:?}, the case gives '{}'): run `{REGENERATE}`",
        r.verdict.word()
    );
    if accel::embree::info().is_ok() {
        assert_eq!(
            documented.map(|d| d.0),
            Some(cell(&r.measured)),
            "{DOC}'s measured numbers for `{id}` are stale: run `{REGENERATE}`"
        );
    }
}

macro_rules! case_tests {
    ($($name:ident = $id:literal),* $(,)?) => {
        $( #[test] fn $name() { run_case($id); } )*
    };
}
macro_rules! slow_case_tests {
    ($($name:ident = $id:literal),* $(,)?) => {
        $( #[test] #[ignore = "slow: cargo test --release --test stability -- --ignored"] fn $name() { run_case($id); } )*
    };
}

case_tests! {
    case_fresnel_normal = "fresnel-normal",
    case_fresnel_grazing = "fresnel-grazing",
    case_fresnel_critical = "fresnel-critical",
    case_fresnel_no_interface = "fresnel-no-interface",
    case_fresnel_diamond = "fresnel-diamond",
    case_fresnel_energy = "fresnel-energy",
    case_fresnel_roulette = "fresnel-roulette",
    case_thin_plate_leak = "thin-plate-leak",
    case_thin_plate_bounces = "thin-plate-bounces",
    case_tv_guide_dots = "tv-guide-20um-dots",
    case_phone_guide_dots = "phone-guide-5um-dots",
    case_translate_10m = "translate-10m",
    case_scale_phone_tv = "scale-phone-tv",
    case_furnace_lambert = "furnace-lambert",
    case_furnace_albedo_one = "furnace-albedo-1",
    case_furnace_weighted = "furnace-weighted",
    case_recycling_cavity = "recycling-cavity",
    case_mesh_seams = "mesh-seams",
    case_mesh_zero_area = "mesh-zero-area",
    case_mesh_duplicate_vertices = "mesh-duplicate-vertices",
    case_mesh_slivers = "mesh-slivers",
    case_mesh_inverted_normals = "mesh-inverted-normals",
    case_mesh_open = "mesh-open",
    case_mesh_non_finite = "mesh-non-finite",
    case_dots_density_extremes = "dots-density-extremes",
    case_dots_polynomial_range = "dots-polynomial-range",
    case_exact_sum_1e8 = "exact-sum-1e8",
}

slow_case_tests! {
    case_recycling_esr_slow = "recycling-esr-0.999",
    case_exact_sum_1e9 = "exact-sum-1e9",
}

/// Runs every case and rewrites `docs/book/src/stability-cases.md`.
#[test]
#[ignore = "rewrites docs/book/src/stability-cases.md: cargo test --release --test stability -- --ignored regenerate_stability_doc"]
fn regenerate_stability_doc() {
    let mut rows = Vec::new();
    for (id, slow, f) in CASES {
        let start = std::time::Instant::now();
        let r = f();
        assert_eq!(r.id, *id, "case function and CASES disagree on the id");
        let secs = start.elapsed().as_secs_f64();
        eprintln!("{id}: {} ({secs:.1} s)", r.verdict.word());
        rows.push((r, *slow, secs));
    }
    let path = doc_path();
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    // Write aside and rename: case tests running alongside read the doc.
    let tmp = path.with_extension("md.tmp");
    std::fs::write(&tmp, render(&rows)).unwrap();
    std::fs::rename(&tmp, &path).unwrap();
    let failed: Vec<&str> = rows
        .iter()
        .filter(|(r, _, _)| matches!(r.verdict, Verdict::Fail(_)))
        .map(|(r, _, _)| r.id)
        .collect();
    assert!(
        failed.is_empty(),
        "failing cases (written to {DOC}): {failed:?}"
    );
}

/// The doc lists exactly the cases of this file, in order, and names its command.
#[test]
fn stability_doc_lists_every_case() {
    let text = std::fs::read_to_string(doc_path())
        .unwrap_or_else(|e| panic!("{DOC}: {e}: run `{REGENERATE}`"));
    assert!(text.contains(REGENERATE), "{DOC} does not name its command");
    let ids: Vec<&str> = text
        .lines()
        .filter_map(|l| l.strip_prefix("| `"))
        .filter_map(|l| l.split('`').next())
        .collect();
    let cases: Vec<&str> = CASES.iter().map(|c| c.0).collect();
    assert_eq!(
        ids, cases,
        "{DOC} rows differ from the cases: run `{REGENERATE}`"
    );
    let mut seen = std::collections::HashSet::new();
    assert!(cases.iter().all(|c| seen.insert(c)), "duplicate case ids");
}

// =======================================================================================
// Shared helpers

const PMMA: f64 = 1.49;
const EPS: f64 = f64::EPSILON;

fn v3(p: DVec3) -> String {
    format!("[{:?}, {:?}, {:?}]", p.x, p.y, p.z)
}

/// A unit vector perpendicular to unit `n`.
fn perp(n: DVec3) -> DVec3 {
    let a = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    (a - n * a.dot(n)).normalize()
}

/// A `[[sources]]` LED.
fn led(center: DVec3, normal: DVec3, w: f64, h: f64, cos_exponent: f64, medium: &str) -> String {
    let n = normal.normalize();
    format!(
        "[[sources]]\ntype = \"led\"\ncenter = {}\nnormal = {}\nu = {}\nwidth_mm = {w:?}\nheight_mm = {h:?}\n\
         power_w = 1.0\ncos_exponent = {cos_exponent:?}\nmedium = \"{medium}\"\n",
        v3(center),
        v3(n),
        v3(perp(n))
    )
}

/// An isotropic point-like source: two back-to-back cos^0 hemispheres.
fn isotropic(center: DVec3, medium: &str) -> String {
    let tilt = DVec3::new(0.3, -0.2, 1.0).normalize();
    led(center, tilt, 1e-3, 1e-3, 0.0, medium) + &led(center, -tilt, 1e-3, 1e-3, 0.0, medium)
}

/// A `[detector]` table.
fn detector(origin: DVec3, u: DVec3, v: DVec3, size: [f64; 2], bins: [usize; 2]) -> String {
    format!(
        "[detector]\norigin = {}\nu = {}\nv = {}\nsize_mm = [{:?}, {:?}]\nbins = [{}, {}]\nangular_bins = [3, 4]\n",
        v3(origin),
        v3(u),
        v3(v),
        size[0],
        size[1],
        bins[0],
        bins[1]
    )
}

/// A triangle soup for OBJ files (vertices written at full precision).
#[derive(Default, Clone)]
struct Obj {
    tris: Vec<(String, [DVec3; 3])>,
}

impl Obj {
    fn tri(&mut self, tag: &str, a: DVec3, b: DVec3, c: DVec3) {
        self.tris.push((tag.to_string(), [a, b, c]));
    }

    fn quad(&mut self, tag: &str, a: DVec3, b: DVec3, c: DVec3, d: DVec3) {
        self.tri(tag, a, b, c);
        self.tri(tag, a, c, d);
    }

    /// An axis-aligned box, faces wound outward, tagged -x, +x, -y, +y, -z, +z.
    fn cuboid(&mut self, min: DVec3, max: DVec3, tags: [&str; 6]) {
        let p = |i: usize| {
            DVec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            )
        };
        let faces = [
            [0, 4, 6, 2],
            [1, 3, 7, 5],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 2, 3, 1],
            [4, 5, 7, 6],
        ];
        for (f, tag) in faces.iter().zip(tags) {
            self.quad(tag, p(f[0]), p(f[1]), p(f[2]), p(f[3]));
        }
    }

    /// Every point mapped by `f`.
    fn mapped(&self, f: impl Fn(DVec3) -> DVec3) -> Obj {
        Obj {
            tris: self
                .tris
                .iter()
                .map(|(t, c)| (t.clone(), c.map(&f)))
                .collect(),
        }
    }

    /// OBJ text, one `v` line per distinct position (bit-exact), `usemtl` tags.
    fn text(&self) -> String {
        let mut index = std::collections::HashMap::new();
        let mut s = String::new();
        let mut faces = String::new();
        let mut tag = "";
        for (t, corners) in &self.tris {
            let ids = corners.map(|p| {
                let key = p.to_array().map(f64::to_bits);
                let next = index.len() + 1;
                *index.entry(key).or_insert_with(|| {
                    let _ = writeln!(s, "v {:?} {:?} {:?}", p.x, p.y, p.z);
                    next
                })
            });
            if t != tag {
                let _ = writeln!(faces, "usemtl {t}");
                tag = t;
            }
            let _ = writeln!(faces, "f {} {} {}", ids[0], ids[1], ids[2]);
        }
        s + &faces
    }
}

/// Write and load a scene; the error text when it does not load.
fn try_scene(name: &str, toml: &str, objs: &[(&str, &str)]) -> Result<Scene, String> {
    let path = write_scene(&format!("stab-{name}"), toml, objs);
    Scene::load(&path).map_err(|e| format!("{e:#}"))
}

fn scene(name: &str, toml: &str, objs: &[(&str, &str)]) -> Scene {
    try_scene(name, toml, objs).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Trace with the BVH backend on 2 threads (convex fast path as the default says).
fn run(scene: &Scene, photons: u64, seed: u64) -> RunResult {
    run_with(scene, photons, seed, |_| {})
}

fn run_with(
    scene: &Scene,
    photons: u64,
    seed: u64,
    tweak: impl FnOnce(&mut RunOptions),
) -> RunResult {
    let mut o = RunOptions {
        photons,
        seed,
        threads: Some(2),
        backend: BackendChoice::Bvh,
        ..RunOptions::default()
    };
    tweak(&mut o);
    trace_opts(scene, &o)
}

/// Ledger readings (one place to adapt when the ledger changes).
fn detected(l: &Ledger) -> f64 {
    l.detected.sum.value()
}

fn balanced(l: &Ledger) -> bool {
    l.accounted() == l.emitted && l.emitted.value() == l.photons as f64
}

fn medium_absorbed(r: &RunResult, name: &str) -> f64 {
    let m = r.scene.media.iter().position(|m| m.name == name).unwrap();
    r.tally.ledger.absorbed_in_medium[m].value()
}

fn surface_absorbed(r: &RunResult, tag: &str) -> f64 {
    let t = r.scene.tags.iter().position(|t| t == tag).unwrap();
    r.tally.ledger.absorbed_by_surface[t].value()
}

/// Every finite number in the run's outputs (maps and ledger) is finite: no NaN anywhere.
fn all_finite(r: &RunResult) -> bool {
    let l = &r.tally.ledger;
    let maps = [r.flux_map(), r.angular_map()];
    maps.iter()
        .all(|m| m.value.iter().chain(&m.stderr).all(|x| x.is_finite()))
        && [detected(l), l.escaped.value(), l.killed.value()]
            .iter()
            .all(|x| x.is_finite())
}

/// The scene's load warnings, with temporary folders cut from the file names.
fn warnings(s: &Scene) -> Vec<String> {
    s.warnings
        .iter()
        .map(|w| match w.split_once(": ") {
            Some((path, rest)) if path.contains('/') => {
                format!("{}: {rest}", path.rsplit('/').next().unwrap_or(path))
            }
            _ => w.clone(),
        })
        .collect()
}

/// Standard error of a binomial fraction `p` over `n`.
fn se_binomial(p: f64, n: f64) -> f64 {
    (p * (1.0 - p) / n).sqrt()
}

/// `|a - b|` in units of `se` (0 when both are equal, even for se = 0).
fn z(a: f64, b: f64, se: f64) -> f64 {
    if a == b { 0.0 } else { (a - b).abs() / se }
}
