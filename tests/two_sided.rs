//! Two-sided surfaces (`back = ...` in a `[surfaces.*]` table): a sheet white on top and
//! black below traces like a white sheet with a black sheet meshed 0.5 um under it (the
//! trick a user needed before), and unlike a sheet white on both sides.

mod support;

use blutrace::run::RunResult;
use support::{assert_balanced, load, trace, write_scene};

/// A 40 x 40 mm sheet at z = 0 wound to face +z, lit from above and from below by two
/// Lambertian LEDs 5 mm away; `sheet` is its table, `extra` more geometry and tables.
fn sheet_scene(name: &str, sheet: &str, extra: &str, files: &[(&str, &str)]) -> RunResult {
    let square = |z: f64, tag: &str| {
        format!(
            "v -20 -20 {z}\nv 20 -20 {z}\nv 20 20 {z}\nv -20 20 {z}\nusemtl {tag}\nf 1 2 3\nf 1 3 4\n"
        )
    };
    let led = |z: f64, nz: f64| {
        format!(
            "[[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, {z}]\nnormal = [0.0, 0.0, {nz}]\n\
             u = [1.0, 0.0, 0.0]\nwidth_mm = 2.0\nheight_mm = 2.0\npower_w = 1.0\n"
        )
    };
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"sheet.obj\"\n{extra}\
         [surfaces.sheet]\n{sheet}\n{}{}\
         [detector]\norigin = [-50.0, -50.0, 10.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [100.0, 100.0]\nbins = [4, 4]\nangular_bins = [3, 4]\n",
        led(5.0, -1.0),
        led(-5.0, 1.0)
    );
    let mut all = vec![("sheet.obj", square(0.0, "sheet"))];
    all.extend(files.iter().map(|(f, t)| (*f, t.to_string())));
    let all: Vec<(&str, &str)> = all.iter().map(|(f, t)| (*f, t.as_str())).collect();
    let scene = load(&write_scene(name, &toml, &all));
    let run = trace(&scene, 200_000, 3, 2);
    assert_balanced(&run);
    run
}

/// Weight absorbed by tag `tag` (0 when the scene has no such tag).
fn absorbed(r: &RunResult, tag: &str) -> f64 {
    r.scene
        .tags
        .iter()
        .position(|t| t == tag)
        .map_or(0.0, |i| r.tally.ledger.absorbed_by_surface[i].value())
}

#[test]
fn a_sheet_black_below_traces_like_a_meshed_black_underside() {
    let white = "model = \"lambert\"\nalbedo = 0.9";
    let two_sided = sheet_scene(
        "two-sided",
        &format!("{white}\nback = \"absorber\""),
        "",
        &[],
    );
    let black_under = "v -20 -20 -0.0005\nv 20 -20 -0.0005\nv 20 20 -0.0005\nv -20 20 -0.0005\n\
                       usemtl black\nf 1 2 3\nf 1 3 4\n";
    let meshed = sheet_scene(
        "meshed-underside",
        white,
        "[[geometry]]\nfile = \"black.obj\"\n[surfaces.black]\nmodel = \"absorber\"\n",
        &[("black.obj", black_under)],
    );
    let both_white = sheet_scene("white-both-sides", white, "", &[]);
    let n = two_sided.tally.ledger.photons as f64;
    let (l2, lm) = (&two_sided.tally.ledger, &meshed.tally.ledger);
    // The same photons, the same random numbers: only rays within 0.5 um of the sheet's
    // rim can tell the two apart.
    let absorbed_2 = absorbed(&two_sided, "sheet");
    let absorbed_m = absorbed(&meshed, "sheet") + absorbed(&meshed, "black");
    assert!(
        (absorbed_2 - absorbed_m).abs() <= 1e-3 * n,
        "{absorbed_2} vs {absorbed_m}"
    );
    let (e2, em) = (l2.escaped.value(), lm.escaped.value());
    assert!((e2 - em).abs() <= 1e-3 * n, "escaped {e2} vs {em}");
    let (d2, dm) = (l2.detected.sum.value(), lm.detected.sum.value());
    assert!((d2 - dm).abs() <= 1e-3 * n, "detected {d2} vs {dm}");
    // Half the light meets the back: black there absorbs about 0.5 of it (the view
    // factor of the sheet from each LED is about 0.9), white there 0.1 of it.
    let absorbed_w = absorbed(&both_white, "sheet");
    assert!(
        absorbed_2 > 0.4 * n,
        "the back absorbed {absorbed_2} of {n}"
    );
    assert!(
        absorbed_w < 0.2 * n,
        "a white back absorbed {absorbed_w} of {n}"
    );
}

#[test]
fn check_says_which_way_a_sheet_faces_and_what_its_back_is() {
    let square =
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nusemtl sheet\nf 1 2 3\nf 1 3 4\nf 1 4 3\n";
    let toml = "version = 1\n[[geometry]]\nfile = \"sheet.obj\"\n\
                [surfaces.sheet]\nmodel = \"mirror\"\nback = { model = \"lambert\", albedo = 0.1 }\n\
                [[sources]]\ntype = \"led\"\ncenter = [0.0, 0.0, 2.0]\nnormal = [0.0, 0.0, -1.0]\n\
                u = [1.0, 0.0, 0.0]\nwidth_mm = 1.0\nheight_mm = 1.0\npower_w = 1.0\n\
                [detector]\norigin = [-5.0, -5.0, 3.0]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = [10.0, 10.0]\n";
    let dir = write_scene("check-two-sided", toml, &[("sheet.obj", square)]);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .args(["check", "--json"])
        .arg(&*dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let sheet = &json["surfaces"][0];
    assert_eq!(sheet["tag"], "sheet");
    assert_eq!(sheet["model"], "mirror");
    assert_eq!(sheet["back"], "lambert");
    assert_eq!(sheet["facing"]["+z"], 2, "{sheet}");
    assert_eq!(sheet["facing"]["-z"], 1, "{sheet}");
}
