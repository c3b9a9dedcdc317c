//! Bad scene files give clear errors that name the file and the field; never a panic.

mod support;

use blutrace::scene::Scene;
use support::*;

const GOOD: &str = r#"
version = 1
[[geometry]]
file = "plate.obj"
[media.pmma]
n = 1.49
[surfaces.face]
model = "dielectric"
inside = "pmma"
[surfaces.dots]
model = "dots"
inside = "pmma"
ink_albedo = 0.9
lattice = "square"
pitch_mm = 0.5
origin = [-10.0, 0.0, -0.5]
axis = [1.0, 0.0, 0.0]
length_mm = 20.0
density = [0.2]
[[sources]]
type = "ccfl"
center = [-12.0, 0.0, 0.0]
axis = [0.0, 1.0, 0.0]
radius_mm = 1.0
length_mm = 20.0
power_w = 1.0
[detector]
origin = [-10.0, -10.0, 0.6]
u = [1.0, 0.0, 0.0]
v = [0.0, 1.0, 0.0]
size_mm = [20.0, 20.0]
"#;

fn plate() -> String {
    box_obj(
        [-10.0, -10.0, -0.5],
        [10.0, 10.0, 0.5],
        ["face", "face", "face", "face", "dots", "face"],
    )
}

/// Load `toml` (with the plate geometry) and return the error message.
fn error_of(name: &str, toml: &str) -> String {
    let obj = plate();
    let path = write_scene(name, toml, &[("plate.obj", &obj)]);
    match Scene::load(&path) {
        Ok(_) => panic!("scene '{name}' loaded but should not have"),
        Err(e) => format!("{e:#}"),
    }
}

fn assert_mentions(msg: &str, words: &[&str]) {
    for w in words {
        assert!(msg.contains(w), "error message lacks '{w}': {msg}");
    }
}

#[test]
fn the_good_scene_loads() {
    let obj = plate();
    let scene = load(&write_scene("good", GOOD, &[("plate.obj", &obj)]));
    assert_eq!(scene.tags.len(), 2);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
}

#[test]
fn missing_geometry_file() {
    let msg = error_of("missing", &GOOD.replace("plate.obj", "nothere.obj"));
    assert_mentions(
        &msg,
        &[
            "scene.toml",
            "geometry[0].file",
            "nothere.obj",
            "does not exist",
        ],
    );
}

#[test]
fn tag_without_surface() {
    let msg = error_of(
        "unknowntag",
        &GOOD.replace("[surfaces.face]", "[surfaces.other]"),
    );
    assert_mentions(&msg, &["plate.obj", "'face'", "[surfaces.face]"]);
}

#[test]
fn unknown_key() {
    let msg = error_of(
        "unknownkey",
        &GOOD.replace("radius_mm = 1.0", "radius_mm = 1.0\nradius = 2.0"),
    );
    assert_mentions(&msg, &["scene.toml", "unknown field `radius`"]);
}

#[test]
fn nan_value() {
    let msg = error_of("nan", &GOOD.replace("power_w = 1.0", "power_w = nan"));
    assert_mentions(&msg, &["scene.toml", "sources[0].power_w", "finite"]);
}

#[test]
fn negative_radius() {
    let msg = error_of(
        "negradius",
        &GOOD.replace("radius_mm = 1.0", "radius_mm = -1.0"),
    );
    assert_mentions(&msg, &["scene.toml", "sources[0].radius_mm", "> 0"]);
}

#[test]
fn density_beyond_packing() {
    let msg = error_of(
        "density",
        &GOOD.replace("density = [0.2]", "density = [1.2]"),
    );
    assert_mentions(&msg, &["scene.toml", "surfaces.dots.density", "packing"]);
    let msg = error_of(
        "density2",
        &GOOD.replace("density = [0.2]", "density = [0.2, -0.5]"),
    );
    assert_mentions(&msg, &["surfaces.dots.density", "outside [0,"]);
}

#[test]
fn wrong_version_and_unknown_medium() {
    let msg = error_of("version", &GOOD.replace("version = 1", "version = 7"));
    assert_mentions(&msg, &["version", "7"]);
    let msg = error_of(
        "medium",
        &GOOD.replace(
            "inside = \"pmma\"\n[surfaces.dots]",
            "inside = \"glass\"\n[surfaces.dots]",
        ),
    );
    assert_mentions(&msg, &["surfaces.face.inside", "unknown medium 'glass'"]);
}

#[test]
fn open_solid_is_refused() {
    let mut obj = plate();
    // Drop the last face (two triangles): the PMMA is no longer enclosed.
    let lines: Vec<&str> = obj.lines().collect();
    obj = lines[..lines.len() - 2].join("\n");
    let path = write_scene("open", GOOD, &[("plate.obj", &obj)]);
    let msg = format!(
        "{:#}",
        Scene::load(&path).expect_err("open solid must not load")
    );
    assert_mentions(&msg, &["medium 'pmma'", "not enclosed", "open"]);
}

#[test]
fn inverted_faces_are_rewound_with_a_warning() {
    // Reverse the winding of every face: the loader re-orients the solid outward.
    let obj: String = plate()
        .lines()
        .map(|l| match l.strip_prefix("f ") {
            Some(rest) => {
                let v: Vec<&str> = rest.split_whitespace().collect();
                format!("f {} {} {}\n", v[0], v[2], v[1])
            }
            None => format!("{l}\n"),
        })
        .collect();
    let scene = load(&write_scene("inverted", GOOD, &[("plate.obj", &obj)]));
    assert_warns(&scene, "re-wound 12 of 12");
    // Outward: the front face (+z) normal points up.
    let front = (0..scene.mesh.len() as u32)
        .find(|&p| scene.mesh.corners(p).iter().all(|c| c.z > 0.0))
        .unwrap();
    assert!(scene.mesh.normal(front).z > 0.99);
}

#[test]
fn garbage_toml_names_the_file() {
    let msg = error_of("garbage", "version = 1\n[[geometry]\n");
    assert_mentions(&msg, &["scene.toml"]);
}

/// Load `toml` with the plate geometry: `Ok` or the error message.
fn load_plate(name: &str, toml: &str) -> Result<(), String> {
    let obj = plate();
    let path = write_scene(name, toml, &[("plate.obj", &obj)]);
    Scene::load(&path).map(|_| ()).map_err(|e| format!("{e:#}"))
}

#[test]
fn lattice_pitch_is_bounded_by_the_face() {
    // The dotted face (z = -0.5, 20 x 20 mm) reaches sqrt(20^2 + 10^2) = 22.36 mm from the
    // pattern's origin (-10, 0, -0.5): the pitch must be within [2.236e-5, 2.236e7] mm.
    let grooves = GOOD.replace(
        "model = \"dots\"\ninside = \"pmma\"\nink_albedo = 0.9\nlattice = \"square\"",
        "model = \"grooves\"\ninside = \"pmma\"\nrelief = \"cut\"\napex_deg = 110.0",
    );
    let grooves = grooves.replace("length_mm = 20.0\ndensity = [0.2]\n", "");
    assert_ne!(grooves, GOOD);
    for (model, toml) in [("dots", GOOD), ("grooves", grooves.as_str())] {
        for (pitch, ok) in [
            ("1e-300", false),
            ("2.2e-5", false),
            ("2.3e-5", true),
            ("0.5", true),
            ("2.2e7", true),
            ("2.3e7", false),
            ("1e300", false),
        ] {
            let name = format!("pitch-{model}-{pitch}");
            let got = load_plate(
                &name,
                &toml.replace("pitch_mm = 0.5", &format!("pitch_mm = {pitch}")),
            );
            match (ok, got) {
                (true, Ok(())) => {}
                (false, Err(msg)) => assert_mentions(
                    &msg,
                    &[
                        "scene.toml",
                        "surfaces.dots.pitch_mm",
                        "22.36",
                        "representable",
                    ],
                ),
                (ok, got) => panic!("{model} pitch {pitch}: expected ok = {ok}, got {got:?}"),
            }
        }
    }
}

#[test]
fn numbers_are_bounded() {
    let two_sources = GOOD.replace("power_w = 1.0", "power_w = 1.7e308")
        + "[[sources]]\ntype = \"ccfl\"\ncenter = [-12.0, 0.0, 0.0]\naxis = [0.0, 1.0, 0.0]\n\
           radius_mm = 1.0\nlength_mm = 20.0\npower_w = 1.7e308\n";
    // The extra source lands inside [detector] as written, so put it before that table.
    let two_sources = two_sources.replacen("[detector]", "[detector_placeholder]", 1);
    let (head, tail) = two_sources.split_once("[detector_placeholder]").unwrap();
    let (det, extra) = tail.split_once("[[sources]]").unwrap();
    let two_sources = format!("{head}[[sources]]{extra}[detector]{det}");
    let msg = error_of("power", &two_sources);
    assert_mentions(&msg, &["scene.toml", "sources", "total power_w"]);
    let msg = error_of(
        "centre",
        &GOOD.replace("center = [-12.0, 0.0, 0.0]", "center = [-12.0, 1e300, 0.0]"),
    );
    assert_mentions(&msg, &["sources[0].center[1]", "1e12"]);
    let msg = error_of(
        "radius",
        &GOOD.replace("radius_mm = 1.0", "radius_mm = 1e300"),
    );
    assert_mentions(&msg, &["sources[0].radius_mm", "at most"]);
    let msg = error_of(
        "detsize",
        &GOOD.replace("size_mm = [20.0, 20.0]", "size_mm = [1e300, 20.0]"),
    );
    assert_mentions(&msg, &["detector.size_mm[0]", "at most"]);
}

#[test]
fn bins_beyond_the_memory_budget_are_refused_before_tracing() {
    let obj = plate();
    let big = GOOD.replace(
        "size_mm = [20.0, 20.0]",
        "size_mm = [20.0, 20.0]\nbins = [20000, 20000]",
    );
    let scene = load(&write_scene("bins", &big, &[("plate.obj", &obj)]));
    let e = blutrace::run::check_tally_budget(&scene).unwrap_err();
    assert!(format!("{e:#}").contains("use fewer bins"), "{e:#}");
    let opts = blutrace::run::RunOptions {
        photons: 10,
        ..Default::default()
    };
    assert!(blutrace::run::trace(&scene, &opts, &|_| {}).is_err());
    let ok = load(&write_scene("bins-ok", GOOD, &[("plate.obj", &obj)]));
    assert!(blutrace::run::check_tally_budget(&ok).unwrap() < 1 << 30);
}

#[test]
fn lamp_body_unknown_model() {
    let msg = error_of(
        "body-model",
        &GOOD.replace(
            "power_w = 1.0",
            "power_w = 1.0\nbody = { model = \"velvet\" }",
        ),
    );
    assert_mentions(&msg, &["scene.toml", "velvet", "lambert"]);
    let msg = error_of(
        "body-word",
        &GOOD.replace("power_w = 1.0", "power_w = 1.0\nbody = \"black\""),
    );
    assert_mentions(
        &msg,
        &["scene.toml", "black", "\"absorber\", \"transparent\""],
    );
}

#[test]
fn lamp_body_albedo_outside_zero_one() {
    for a in ["1.2", "-0.1", "nan"] {
        let msg = error_of(
            "body-albedo",
            &GOOD.replace(
                "power_w = 1.0",
                &format!("power_w = 1.0\nbody = {{ model = \"lambert\", albedo = {a} }}"),
            ),
        );
        assert_mentions(&msg, &["scene.toml", "sources[0].body.albedo"]);
    }
}

#[test]
fn lamp_inside_a_solid_must_name_its_medium() {
    // The CCFL moved into the PMMA plate (z = 0, plate 1 mm thick... tube r = 0.3 mm),
    // its medium left as air.
    let inside = GOOD
        .replace("center = [-12.0, 0.0, 0.0]", "center = [0.0, 0.0, 0.0]")
        .replace("radius_mm = 1.0", "radius_mm = 0.3")
        .replace("length_mm = 20.0\npower_w", "length_mm = 5.0\npower_w");
    let msg = error_of("lamp-in-pmma", &inside);
    assert_mentions(
        &msg,
        &["scene.toml", "sources[0].medium", "'pmma'", "names 'air'"],
    );
    // Named correctly, it loads.
    let ok = inside.replace("power_w = 1.0", "power_w = 1.0\nmedium = \"pmma\"");
    let obj = plate();
    load(&write_scene("lamp-in-pmma-ok", &ok, &[("plate.obj", &obj)]));
    // In air, naming the solid's medium is refused too.
    let msg = error_of(
        "lamp-in-air-named-pmma",
        &GOOD.replace("power_w = 1.0", "power_w = 1.0\nmedium = \"pmma\""),
    );
    assert_mentions(&msg, &["sources[0].medium", "'air'", "names 'pmma'"]);
    // Half in, half out: the surface crosses the boundary.
    let msg = error_of(
        "lamp-across",
        &GOOD.replace("center = [-12.0, 0.0, 0.0]", "center = [-10.0, 0.0, 0.3]"),
    );
    assert_mentions(&msg, &["sources[0].center", "crosses the boundary"]);
}

#[test]
fn led_package_depth_and_duplicate_names() {
    let led = "[[sources]]\ntype = \"led\"\nname = \"a\"\ncenter = [-11.0, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\n\
               u = [0.0, 1.0, 0.0]\nwidth_mm = 2.0\nheight_mm = 0.5\npower_w = 1.0\npackage_depth_mm = -1.0\n";
    let msg = error_of(
        "pkg-depth",
        &GOOD.replace("[detector]", &format!("{led}[detector]")),
    );
    assert_mentions(&msg, &["sources[1].package_depth_mm", "> 0"]);
    let two = GOOD.replace("power_w = 1.0", "power_w = 1.0\nname = \"lamp\"");
    let dup = two.replace(
        "[detector]",
        "[[sources]]\ntype = \"ccfl\"\nname = \"lamp\"\ncenter = [12.0, 0.0, 0.0]\naxis = [0.0, 1.0, 0.0]\n\
         radius_mm = 1.0\nlength_mm = 20.0\npower_w = 1.0\n[detector]",
    );
    let msg = error_of("dup-names", &dup);
    assert_mentions(&msg, &["sources[1].name", "'lamp'", "sources[0]"]);
}

/// A pattern's span is bounded where it matters: beyond 1e12 mm (a typing mistake), past
/// ten times the face's reach (the face would see only the first per cent of a graded
/// density: at `length_mm = 1e20` every groove vanished), and at 2^27 groove cells (the
/// load time). Each error names the field, quickly and with a short number.
#[test]
fn pattern_spans_are_bounded() {
    let graded = GOOD.replace("density = [0.2]", "density = [0.1, 0.2]");
    let grooves = graded.replace(
        "model = \"dots\"\ninside = \"pmma\"\nink_albedo = 0.9\nlattice = \"square\"",
        "model = \"grooves\"\ninside = \"pmma\"\nrelief = \"cut\"\napex_deg = 110.0",
    );
    assert_ne!(grooves, graded);
    let grid = GOOD.replace(
        "density = [0.2]",
        "density_grid = { width_mm = 1e300, values = [[0.1, 0.2], [0.1, 0.3]] }",
    );
    let cases: [(&str, String, &[&str]); 6] = [
        (
            "dots-1e300",
            graded.replacen("length_mm = 20.0", "length_mm = 1e300", 1),
            &["surfaces.dots.length_mm", "at most 1e12 mm", "got 1e300"],
        ),
        (
            "dots-far",
            graded.replacen("length_mm = 20.0", "length_mm = 1000.0", 1),
            &["surfaces.dots.length_mm", "10 times the face's reach"],
        ),
        (
            "grid-1e300",
            grid,
            &[
                "surfaces.dots.density_grid.width_mm",
                "must be at most 1e12 mm",
            ],
        ),
        (
            "grooves-1e20",
            grooves.replacen("length_mm = 20.0", "length_mm = 1e20", 1),
            &["surfaces.dots.length_mm", "at most 1e12 mm"],
        ),
        (
            "grooves-1e12",
            grooves.replacen("length_mm = 20.0", "length_mm = 1e12", 1),
            &["surfaces.dots.length_mm", "cells of pitch_mm"],
        ),
        (
            "grooves-far",
            grooves.replacen("length_mm = 20.0", "length_mm = 1000.0", 1),
            &["surfaces.dots.length_mm", "10 times the face's reach"],
        ),
    ];
    for (name, toml, words) in cases {
        let start = std::time::Instant::now();
        let msg = load_plate(name, &toml).expect_err(name);
        assert_mentions(&msg, words);
        let longest = msg.split(|c: char| !c.is_ascii_digit()).map(str::len).max();
        assert!(longest < Some(20), "{name}: {msg}");
        // Not a timing assertion of speed: a guard against the 10-minute loads of before.
        assert!(
            start.elapsed().as_secs() < 60,
            "{name} took {:?}",
            start.elapsed()
        );
    }
    // Within the bounds, graded dots and grooves load.
    for toml in [&graded, &grooves] {
        load_plate("spans-ok", toml).unwrap();
    }
}

/// Names that end up in file names and EXR attributes are printable text of at most 100
/// bytes, refused when the scene loads, not after tracing.
#[test]
fn names_are_printable_and_short() {
    let long = "n".repeat(300);
    let cases = [
        (
            "name-nul",
            "name = \"a\\u0000b\"".to_string(),
            "name",
            "control character",
        ),
        (
            "name-long",
            format!("name = \"{long}\""),
            "name",
            "300 bytes",
        ),
        (
            "name-path",
            "name = \"a/b\"".to_string(),
            "name",
            "not a path",
        ),
        (
            "name-empty",
            "name = \"\"".to_string(),
            "name",
            "must not be empty",
        ),
    ];
    for (case, line, field, says) in cases {
        let toml = GOOD.replace("version = 1", &format!("version = 1\n{line}"));
        let msg = error_of(case, &toml);
        assert_mentions(&msg, &["scene.toml", &format!("{field}: "), says]);
    }
    let msg = error_of(
        "source-name",
        &GOOD.replace("power_w = 1.0", "power_w = 1.0\nname = \"lamp\\tleft\""),
    );
    assert_mentions(&msg, &["sources[0].name", "control character"]);
}
