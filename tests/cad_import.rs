//! CAD geometry as CAD tools write it: one part written as Z-up OBJ in millimetres, Y-up
//! glTF in metres, STL (ASCII and binary) and PLY (ASCII and binary) loads to the same
//! triangles and traces to the same tallies; bad files and placements give errors that
//! name the file and the field.

mod support;

use blutrace::scene::Scene;
use std::fmt::Write;
use support::*;

/// The part: a box guide 125 x 62.5 x 3.90625 mm (numbers exact in f32, in millimetres
/// and in metres), as 12 triangles wound outward, in millimetres, z up.
fn part() -> Vec<[[f64; 3]; 3]> {
    let (x, y, z) = (125.0, 62.5, 3.906_25);
    let c = |i: usize| {
        [
            if i & 1 == 0 { 0.0 } else { x },
            if i & 2 == 0 { 0.0 } else { y },
            if i & 4 == 0 { 0.0 } else { z },
        ]
    };
    let quads = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ];
    quads
        .iter()
        .flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]])
        .collect()
}

/// glTF's frame: metres, y up (blutrace (x, y, z) is glTF (x, z, -y)).
fn to_gltf(p: [f64; 3]) -> [f32; 3] {
    [p[0] / 1000.0, p[2] / 1000.0, -p[1] / 1000.0].map(|v| v as f32)
}

fn obj(tris: &[[[f64; 3]; 3]]) -> String {
    let mut s = String::from("usemtl lgp\n");
    for (k, t) in tris.iter().enumerate() {
        for p in t {
            writeln!(s, "v {} {} {}", p[0], p[1], p[2]).unwrap();
        }
        writeln!(s, "f {} {} {}", 3 * k + 1, 3 * k + 2, 3 * k + 3).unwrap();
    }
    s
}

fn stl_ascii(tris: &[[[f64; 3]; 3]]) -> String {
    let mut s = String::from("solid part\n");
    for t in tris {
        s += "facet normal 0 0 0\nouter loop\n";
        for p in t {
            writeln!(s, "vertex {} {} {}", p[0], p[1], p[2]).unwrap();
        }
        s += "endloop\nendfacet\n";
    }
    s + "endsolid part\n"
}

fn stl_binary(tris: &[[[f64; 3]; 3]]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend((tris.len() as u32).to_le_bytes());
    for t in tris {
        b.extend([0u8; 12]);
        for p in t {
            p.iter().for_each(|v| b.extend((*v as f32).to_le_bytes()));
        }
        b.extend([0u8; 2]);
    }
    b
}

fn ply_header(format: &str, tris: usize) -> String {
    format!(
        "ply\nformat {format} 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nelement face {tris}\nproperty list uchar int vertex_indices\nend_header\n",
        3 * tris
    )
}

fn ply_ascii(tris: &[[[f64; 3]; 3]]) -> String {
    let mut s = ply_header("ascii", tris.len());
    for p in tris.iter().flatten() {
        writeln!(s, "{} {} {}", p[0], p[1], p[2]).unwrap();
    }
    for k in 0..tris.len() {
        writeln!(s, "3 {} {} {}", 3 * k, 3 * k + 1, 3 * k + 2).unwrap();
    }
    s
}

fn ply_binary(tris: &[[[f64; 3]; 3]]) -> Vec<u8> {
    let mut b = ply_header("binary_little_endian", tris.len()).into_bytes();
    for p in tris.iter().flatten() {
        p.iter().for_each(|v| b.extend((*v as f32).to_le_bytes()));
    }
    for k in 0..tris.len() as i32 {
        b.push(3);
        [3 * k, 3 * k + 1, 3 * k + 2]
            .iter()
            .for_each(|i| b.extend(i.to_le_bytes()));
    }
    b
}

/// A glTF file with one mesh, one primitive, material "lgp", and its .bin buffer.
fn gltf(tris: &[[[f64; 3]; 3]]) -> (String, Vec<u8>) {
    let pts: Vec<[f32; 3]> = tris.iter().flatten().map(|p| to_gltf(*p)).collect();
    let bin: Vec<u8> = pts.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    let (lo, hi) = pts
        .iter()
        .fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), p| {
            (
                std::array::from_fn(|i| lo[i].min(p[i])),
                std::array::from_fn(|i| hi[i].max(p[i])),
            )
        });
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"material":0}}]}}],"materials":[{{"name":"lgp"}}],
"buffers":[{{"uri":"part.bin","byteLength":{}}}],"bufferViews":[{{"buffer":0,"byteLength":{}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":{},"type":"VEC3","min":{lo:?},"max":{hi:?}}}]}}"#,
        bin.len(),
        bin.len(),
        pts.len()
    );
    (json, bin)
}

/// A scene around one geometry file (`geometry` is its `[[geometry]]` body).
fn scene_toml(geometry: &str) -> String {
    format!(
        "version = 1\n[[geometry]]\n{geometry}\n[media.pmma]\nn = 1.49\n\
         [surfaces.lgp]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [[sources]]\ntype = \"led\"\ncenter = [-0.01, 31.25, 1.953125]\nnormal = [1.0, 0.0, 0.0]\n\
         u = [0.0, 1.0, 0.0]\nwidth_mm = 60.0\nheight_mm = 3.0\npower_w = 1.0\n\
         [detector]\norigin = [0.0, 0.0, 4.5]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [125.0, 62.5]\nbins = [10, 5]\n"
    )
}

/// Load a scene whose geometry is one file with these bytes.
fn load_one(name: &str, file: &str, bytes: &[u8], extra: &str) -> Scene {
    let geometry = format!("file = \"{file}\"\n{extra}");
    let path = write_scene(name, &scene_toml(&geometry), &[]);
    std::fs::write(path.parent().unwrap().join(file), bytes).unwrap();
    load(&path)
}

/// The scene's triangles in file coordinates (the loader recentres the scene).
fn triangles(s: &Scene) -> Vec<[[f64; 3]; 3]> {
    (0..s.mesh.len() as u32)
        .map(|p| s.mesh.corners(p).map(|c| (c + s.offset).to_array()))
        .collect()
}

/// Equal to rounding: the recentring offset is subtracted and added back.
fn assert_close(got: &[[[f64; 3]; 3]], want: &[[[f64; 3]; 3]], what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: triangle count");
    for (g, w) in got.iter().flatten().zip(want.iter().flatten()) {
        for (a, b) in g.iter().zip(w) {
            assert!(
                (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
                "{what}: {g:?} vs {w:?}"
            );
        }
    }
}

#[test]
fn every_format_gives_the_same_triangles_and_tallies() {
    let tris = part();
    let (json, bin) = gltf(&tris);
    let gltf_path = write_scene("cad-gltf", &scene_toml("file = \"part.gltf\""), &[]);
    let dir = gltf_path.parent().unwrap();
    std::fs::write(dir.join("part.gltf"), json).unwrap();
    std::fs::write(dir.join("part.bin"), bin).unwrap();
    let tag = "tag = \"lgp\"";
    let scenes = [
        (
            "obj",
            load_one("cad-obj", "part.obj", obj(&tris).as_bytes(), ""),
        ),
        ("gltf", load(&gltf_path)),
        (
            "stl",
            load_one("cad-stl", "part.stl", stl_ascii(&tris).as_bytes(), tag),
        ),
        (
            "binary stl",
            load_one("cad-stlb", "part.stl", &stl_binary(&tris), tag),
        ),
        (
            "ply",
            load_one("cad-ply", "part.ply", ply_ascii(&tris).as_bytes(), tag),
        ),
        (
            "binary ply",
            load_one("cad-plyb", "part.ply", &ply_binary(&tris), tag),
        ),
    ];
    let reference = trace(&scenes[0].1, 50_000, 3, 2).tally.clone();
    assert_close(&triangles(&scenes[0].1), &tris, "obj");
    for (name, s) in &scenes {
        assert_eq!(
            triangles(s),
            triangles(&scenes[0].1),
            "{name}: triangles differ"
        );
        assert!(s.warnings.is_empty(), "{name}: {:?}", s.warnings);
        assert_eq!(
            trace(s, 50_000, 3, 2).tally,
            reference,
            "{name}: tallies differ"
        );
    }
}

#[test]
fn units_up_axis_and_rotation_place_the_part() {
    let tris = part();
    // The part in metres, y up, turned by -90 degrees about z in the file's frame: the
    // placement undoes each step.
    let metres_y_up: Vec<[[f64; 3]; 3]> = tris
        .iter()
        .map(|t| t.map(|p| to_gltf(p).map(f64::from)))
        .collect();
    let s = load_one(
        "cad-units",
        "part.obj",
        obj(&metres_y_up).as_bytes(),
        "units = \"m\"\nup = \"y\"",
    );
    assert_close(&triangles(&s), &tris, "metres, y up");
    // A quarter turn about z, then back with a matrix: exact, not to 1e-17.
    let turned: Vec<[[f64; 3]; 3]> = tris
        .iter()
        .map(|t| t.map(|p| [-p[1], p[0], p[2]]))
        .collect();
    let s = load_one(
        "cad-turn",
        "part.obj",
        obj(&turned).as_bytes(),
        "rotate_deg = [0.0, 0.0, -90.0]",
    );
    let reference = load_one("cad-plain", "part.obj", obj(&tris).as_bytes(), "");
    assert_eq!(triangles(&s), triangles(&reference));
    let s = load_one(
        "cad-matrix",
        "part.obj",
        obj(&turned).as_bytes(),
        "matrix = [[0.0, 1.0, 0.0, 0.0], [-1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]",
    );
    assert_eq!(triangles(&s), triangles(&reference));
}

#[test]
fn a_mirroring_matrix_keeps_the_solid_outward() {
    let tris = part();
    // The mirror image of the part, wound outward as a CAD tool writes it.
    let mirrored: Vec<[[f64; 3]; 3]> = tris
        .iter()
        .map(|t| [t[0], t[2], t[1]].map(|p| [-p[0], p[1], p[2]]))
        .collect();
    let s = load_one(
        "cad-mirror",
        "part.obj",
        obj(&mirrored).as_bytes(),
        "matrix = [[-1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]",
    );
    // No re-winding warning: the loader kept the faces outward.
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    // Mirrored back, with windings reversed back: the original triangles.
    assert_close(&triangles(&s), &tris, "mirrored");
}

fn load_err(name: &str, file: &str, bytes: &[u8], extra: &str) -> String {
    let geometry = format!("file = \"{file}\"\n{extra}");
    let path = write_scene(name, &scene_toml(&geometry), &[]);
    std::fs::write(path.parent().unwrap().join(file), bytes).unwrap();
    match Scene::load(&path) {
        Ok(_) => panic!("{name}: loaded"),
        Err(e) => format!("{e:#}"),
    }
}

/// A bad input: name, file, its bytes, extra geometry keys, what the error must say.
type BadCase<'a> = (&'a str, &'a str, Vec<u8>, &'a str, &'a [&'a str]);

#[test]
fn bad_cad_input_names_the_file_and_field() {
    let tris = part();
    let text = obj(&tris);
    let cases: [BadCase; 10] = [
        (
            "unit",
            "part.obj",
            text.clone().into(),
            "units = \"furlong\"",
            &["unknown variant `furlong`"],
        ),
        (
            "up",
            "part.obj",
            text.clone().into(),
            "up = \"x\"",
            &["unknown variant `x`"],
        ),
        (
            "nan",
            "part.obj",
            text.clone().into(),
            "rotate_deg = [0.0, nan, 0.0]",
            &["geometry[0].rotate_deg[1]", "finite"],
        ),
        (
            "both",
            "part.obj",
            text.clone().into(),
            "rotate_deg = [0.0, 0.0, 0.0]\nmatrix = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]",
            &["geometry[0].matrix", "not both"],
        ),
        (
            "notag",
            "part.stl",
            stl_binary(&tris),
            "",
            &["geometry[0].tag", "part.stl"],
        ),
        (
            "empty",
            "part.stl",
            stl_binary(&[]),
            "tag = \"lgp\"",
            &["part.stl", "no triangles"],
        ),
        (
            "truncated",
            "part.stl",
            stl_binary(&tris)[..300].to_vec(),
            "tag = \"lgp\"",
            &["part.stl", "header says 12 triangles"],
        ),
        (
            "plyneg",
            "part.ply",
            (ply_header("ascii", 1) + "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n").into_bytes(),
            "tag = \"lgp\"",
            &["part.ply", "face 0", "vertex index -1", "negative"],
        ),
        (
            "turns",
            "part.obj",
            text.clone().into(),
            "rotate_deg = [1e300, 0.0, 0.0]",
            &["geometry[0].rotate_deg[0]", "degrees", "got 1e300"],
        ),
        (
            "plyjunk",
            "part.ply",
            b"ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n".to_vec(),
            "tag = \"lgp\"",
            &["part.ply", "not a valid PLY"],
        ),
    ];
    for (name, file, bytes, extra, wants) in cases {
        let e = load_err(&format!("cad-bad-{name}"), file, &bytes, extra);
        for w in wants {
            assert!(e.contains(w), "{name}: {e}");
        }
        // Parse errors quote the offending line; the loader's errors name the field.
        let placed = e.contains("geometry[0]") || e.contains("unknown variant");
        assert!(e.contains("scene.toml") && placed, "{name}: {e}");
        // Numbers in short form: never a 301-digit bound.
        let longest = e.split(|c: char| !c.is_ascii_digit()).map(str::len).max();
        assert!(longest < Some(20), "{name}: {e}");
    }
}

#[test]
fn tag_overrides_the_file_materials_with_a_warning() {
    let s = load_one(
        "cad-override",
        "part.obj",
        obj(&part()).as_bytes(),
        "tag = \"lgp\"",
    );
    assert!(
        s.warnings.is_empty(),
        "same name, nothing replaced: {:?}",
        s.warnings
    );
    let other = obj(&part()).replace("usemtl lgp", "usemtl acrylic");
    let s = load_one(
        "cad-override2",
        "part.obj",
        other.as_bytes(),
        "tag = \"lgp\"",
    );
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("replaces") && w.contains("acrylic")),
        "{:?}",
        s.warnings
    );
}

/// Two boxes, `a` of PMMA and `b` (4 x 4 x 1 mm) of `inside` with `outside` in front of
/// its faces, shifted by `dx` along x: loaded, or the error.
fn two_solids(name: &str, dx: f64, inside: &str, outside: &str) -> Result<Scene, String> {
    let a = box_obj([0.0, 0.0, 0.0], [10.0, 10.0, 2.0], ["a"; 6]);
    let b = box_obj([dx, 2.0, 0.5], [dx + 4.0, 6.0, 1.5], ["b"; 6]);
    let toml = format!(
        "version = 1\n[[geometry]]\nfile = \"a.obj\"\n[[geometry]]\nfile = \"b.obj\"\n\
         [media.pmma]\nn = 1.49\n[media.pc]\nn = 1.58\n[media.glass]\nn = 1.52\n\
         [media.black]\nn = 1.58\nabsorption_per_mm = 1e9\n\
         [media.grey]\nn = 1.58\nabsorption_per_mm = 1e3\n\
         [surfaces.a]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.b]\nmodel = \"dielectric\"\ninside = \"{inside}\"\noutside = \"{outside}\"\n\
         [[sources]]\ntype = \"led\"\ncenter = [-0.5, 5.0, 1.0]\nnormal = [1.0, 0.0, 0.0]\n\
         u = [0.0, 1.0, 0.0]\nwidth_mm = 4.0\nheight_mm = 1.0\npower_w = 1.0\n\
         [detector]\norigin = [0.0, 0.0, 2.5]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [10.0, 10.0]\n"
    );
    let dir = write_scene(name, &toml, &[("a.obj", &a), ("b.obj", &b)]);
    Scene::load(&dir).map_err(|e| format!("{e:#}"))
}

/// Where media meet, every point has one medium and every face names the medium in front
/// of it: crossing solids, solids of one medium overlapping, a face naming its own medium
/// outside, or one naming a medium that is not there, are errors naming the field.
#[test]
fn overlapping_solids_and_wrong_outside_media_are_errors() {
    let err = |r: Result<Scene, String>| r.map(|_| ()).expect_err("loaded");
    let crossing = err(two_solids("cad-overlap", 8.0, "pc", "air"));
    assert!(
        crossing.contains("overlap: their surfaces cross"),
        "{crossing}"
    );
    // Wholly inside, with the outer medium named outside: a legitimate nesting.
    let nested = two_solids("cad-nested", 3.0, "pc", "pmma").unwrap();
    assert!(nested.warnings.is_empty(), "{:?}", nested.warnings);
    // Wholly inside, but its faces say air outside.
    let wrong = err(two_solids("cad-nested-air", 3.0, "pc", "air"));
    assert!(
        wrong.contains("surfaces.b.outside") && wrong.contains("have 'pmma' in front"),
        "{wrong}"
    );
    // Side by side, touching along x = 10: air on the touching face is a gap between parts
    // in contact (its other faces are in air anyway); PMMA is wrong for those others.
    let apart = two_solids("cad-apart", 10.0, "pc", "air").unwrap();
    assert!(apart.warnings.is_empty(), "{:?}", apart.warnings);
    let pmma = err(two_solids("cad-apart-pmma", 10.0, "pc", "pmma"));
    assert!(pmma.contains("have 'air' in front"), "{pmma}");
    let glass = err(two_solids("cad-apart-glass", 12.0, "pc", "glass"));
    assert!(
        glass.contains("surfaces.b.outside")
            && glass.contains("is 'glass'")
            && glass.contains("no closed solid encloses 'glass'"),
        "{glass}"
    );
    // A black backing (absorbing whatever enters within nanometres) needs no solid; a
    // medium that lets light travel on does.
    two_solids("cad-backing", 12.0, "pc", "black").unwrap();
    let grey = err(two_solids("cad-grey", 12.0, "pc", "grey"));
    assert!(grey.contains("no closed solid encloses 'grey'"), "{grey}");
    // A face between a medium and itself.
    let same = err(two_solids("cad-same", 12.0, "pc", "pc"));
    assert!(
        same.contains("surfaces.b.outside") && same.contains("the medium inside too"),
        "{same}"
    );
    // Two PMMA guides overlapping: one medium, two shells.
    let guides = err(two_solids("cad-two-guides", 8.0, "pmma", "air"));
    assert!(
        guides.contains("two closed solids of medium 'pmma' overlap"),
        "{guides}"
    );
    let inner = err(two_solids("cad-guide-in-guide", 3.0, "pmma", "air"));
    assert!(
        inner.contains("two closed solids of medium 'pmma' overlap"),
        "{inner}"
    );
}

#[test]
fn placement_mistakes_are_warned() {
    let tris = part();
    // A part in metres read as millimetres: 0.125 mm across is fine, 0.004 mm is not.
    let tiny: Vec<[[f64; 3]; 3]> = tris.iter().map(|t| t.map(|p| p.map(|c| c / 1e5))).collect();
    let s = load_one("cad-tiny", "part.obj", obj(&tiny).as_bytes(), "");
    assert_warns(&s, "check units");
    // The same part 1000 x too large (mm read as metres), moved clear of the LED (which
    // it would otherwise swallow: an error, tested below).
    let s = load_one(
        "cad-huge",
        "part.obj",
        obj(&tris).as_bytes(),
        "units = \"m\"\ntranslate = [0.0, 0.0, 1000000.0]",
    );
    assert_warns(&s, "check units");
    // Lifted by 2 mm, the part is cut by the detector plane (z = 4.5).
    let s = load_one(
        "cad-cut",
        "part.obj",
        obj(&tris).as_bytes(),
        "translate = [0.0, 0.0, 2.0]",
    );
    assert_warns(&s, "detector plane cuts tag 'lgp'");
    // Moved 1 mm towards the LED and lifted 1 mm, the PMMA part's bottom face crosses
    // the LED's emitting rectangle: the lamp lies half in the PMMA, half in air.
    let dir = write_scene(
        "cad-led",
        &scene_toml("file = \"part.obj\"\ntranslate = [-1.0, 0.0, 1.0]"),
        &[],
    );
    std::fs::write(dir.parent().unwrap().join("part.obj"), obj(&tris)).unwrap();
    let e = format!(
        "{:#}",
        Scene::load(&dir).expect_err("a lamp across a solid's face")
    );
    assert!(
        e.contains("sources[0].center") && e.contains("crosses the boundary"),
        "{e}"
    );
}

#[test]
fn check_prints_sizes_and_json() {
    let tris = part();
    let geometry = "file = \"part.stl\"\ntag = \"lgp\"\nunits = \"cm\"\nscale = 0.1";
    let dir = write_scene("cad-check", &scene_toml(geometry), &[]);
    std::fs::write(dir.parent().unwrap().join("part.stl"), stl_binary(&tris)).unwrap();
    let run = |json: bool| check_output(&dir, json);
    let text = run(false);
    assert!(
        text.contains("file part.stl") && text.contains("125.000 x 62.500 x 3.906 mm"),
        "{text}"
    );
    let v: serde_json::Value = serde_json::from_str(&run(true)).unwrap();
    let g = &v["geometry"][0];
    assert_eq!(g["triangles"], 12);
    assert_eq!(g["tags"]["lgp"]["bounds_mm"]["max"][0], 125.0);
}

/// A glTF node that is its own ancestor is an error naming the node, not a stack
/// overflow; so is a chain of nodes deeper than any CAD export nests.
#[test]
fn gltf_node_cycles_and_runaway_depth_are_errors() {
    let (json, bin) = gltf(&part());
    let scene_dir = |name: &str, json: &str| {
        let path = write_scene(name, &scene_toml("file = \"part.gltf\""), &[]);
        let dir = path.parent().unwrap().to_path_buf();
        std::fs::write(dir.join("part.gltf"), json).unwrap();
        std::fs::write(dir.join("part.bin"), &bin).unwrap();
        path
    };
    let cycle = json.replace(
        r#""nodes":[{"mesh":0}]"#,
        r#""nodes":[{"mesh":0,"children":[1]},{"children":[0]}]"#,
    );
    assert_ne!(cycle, json);
    let path = scene_dir("gltf-cycle", &cycle);
    let err = format!("{:#}", Scene::load(&path).expect_err("a cycle loaded"));
    assert!(
        err.contains("part.gltf") && err.contains("own ancestor"),
        "{err}"
    );

    let chain: Vec<String> = (0..400)
        .map(|i| match i {
            399 => r#"{"mesh":0}"#.to_string(),
            _ => format!(r#"{{"children":[{}]}}"#, i + 1),
        })
        .collect();
    let deep = json.replace(
        r#""nodes":[{"mesh":0}]"#,
        &format!(r#""nodes":[{}]"#, chain.join(",")),
    );
    let path = scene_dir("gltf-deep", &deep);
    let err = format!(
        "{:#}",
        Scene::load(&path).expect_err("a 400-deep chain loaded")
    );
    assert!(err.contains("deeper than 256"), "{err}");
}

/// An accessor whose `count` is more than its buffer view holds is an error naming the
/// accessor, not a mesh loaded in part.
#[test]
fn gltf_accessor_counts_past_their_buffer_view_are_errors() {
    let tris = part();
    let (json, bin) = gltf(&tris);
    let declared = format!(r#""count":{}"#, 3 * tris.len());
    assert!(json.contains(&declared));
    let bad = json.replace(&declared, r#""count":99999999"#);
    let path = write_scene("gltf-count", &scene_toml("file = \"part.gltf\""), &[]);
    let dir = path.parent().unwrap().to_path_buf();
    std::fs::write(dir.join("part.gltf"), bad).unwrap();
    std::fs::write(dir.join("part.bin"), &bin).unwrap();
    let err = format!(
        "{:#}",
        Scene::load(&path).expect_err("a short accessor loaded")
    );
    assert!(
        err.contains("part.gltf") && err.contains("POSITION accessor") && err.contains("99999999"),
        "{err}"
    );
}

/// A glTF primitive without a material is tagged by its mesh's name, else its node's,
/// with a warning naming where it sits; with neither the error names node, mesh and
/// primitive indices.
#[test]
fn gltf_primitives_without_materials_take_their_mesh_or_node_name() {
    let (json, bin) = gltf(&part());
    let no_material = json.replace(r#","material":0"#, "");
    assert_ne!(no_material, json);
    let scene_dir = |name: &str, json: &str| {
        let path = write_scene(name, &scene_toml("file = \"part.gltf\""), &[]);
        let dir = path.parent().unwrap().to_path_buf();
        std::fs::write(dir.join("part.gltf"), json).unwrap();
        std::fs::write(dir.join("part.bin"), &bin).unwrap();
        path
    };
    let by_mesh = no_material.replace(r#""meshes":[{"#, r#""meshes":[{"name":"lgp","#);
    let s = load(&scene_dir("gltf-mesh-name", &by_mesh));
    assert_eq!(s.tags, ["lgp"]);
    assert_warns(
        &s,
        "nodes[0] meshes[0] 'lgp' primitives[0]: no material name, tagged 'lgp' by its mesh's name",
    );
    let by_node = no_material.replace(
        r#""nodes":[{"mesh":0}]"#,
        r#""nodes":[{"mesh":0,"name":"lgp"}]"#,
    );
    let s = load(&scene_dir("gltf-node-name", &by_node));
    assert_eq!(s.tags, ["lgp"]);
    assert_warns(&s, "by its node's name");
    let err = format!(
        "{:#}",
        Scene::load(&scene_dir("gltf-no-name", &no_material)).expect_err("an untagged primitive")
    );
    assert!(
        err.contains("part.gltf") && err.contains("nodes[0] meshes[0] primitives[0]"),
        "{err}"
    );
    // The scene's tag needs no name from the file.
    let path = write_scene(
        "gltf-no-name-tagged",
        &scene_toml("file = \"part.gltf\"\ntag = \"lgp\""),
        &[],
    );
    let dir = path.parent().unwrap();
    std::fs::write(dir.join("part.gltf"), &no_material).unwrap();
    std::fs::write(dir.join("part.bin"), &bin).unwrap();
    let s = load(&path);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

/// A part whose size is the scene's (here: the detector's, 125 x 62.5 mm) times 1/25.4 or
/// 1/1000 was exported in other units than it is read in: a warning suggests the units.
/// Read right, or as a small part of another shape, it gives none.
#[test]
fn parts_off_by_a_unit_factor_are_warned() {
    let inches: Vec<[[f64; 3]; 3]> = part()
        .iter()
        .map(|t| t.map(|p| p.map(|c| c / 25.4)))
        .collect();
    let unit_warnings = |s: &Scene| -> Vec<String> {
        s.warnings
            .iter()
            .filter(|w| w.contains("units = "))
            .cloned()
            .collect()
    };
    // The part sits in the lamp's reach only at full size: move the lamp with it.
    let stl = stl_ascii(&inches);
    let s = load_units(
        "units-in",
        "part.stl",
        stl.as_bytes(),
        "tag = \"lgp\"",
        1.0 / 25.4,
    );
    let w = unit_warnings(&s);
    assert!(
        w.len() == 1 && w[0].contains("1/25.4") && w[0].contains("units = \"in\"?"),
        "{w:?}"
    );
    // `check`, as a user runs it, prints the warning.
    let path = write_scene(
        "units-in-check",
        &scene_toml_lamp("file = \"part.stl\"\ntag = \"lgp\"", 1.0 / 25.4),
        &[],
    );
    std::fs::write(path.parent().unwrap().join("part.stl"), &stl).unwrap();
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .arg("check")
        .arg(&*path)
        .output()
        .unwrap();
    let printed =
        String::from_utf8_lossy(&run.stdout).to_string() + &String::from_utf8_lossy(&run.stderr);
    assert!(
        run.status.success() && printed.contains("units = \"in\"?"),
        "{printed}"
    );
    // Declared in inches, it is right: no warning.
    let s = load_one(
        "units-in-ok",
        "part.stl",
        stl.as_bytes(),
        "tag = \"lgp\"\nunits = \"in\"",
    );
    assert!(unit_warnings(&s).is_empty(), "{:?}", s.warnings);
    // A glTF (metres) declared in millimetres: 1000x small.
    let (json, bin) = gltf(&part());
    let path = write_scene(
        "units-m",
        &scene_toml_lamp("file = \"part.gltf\"\nunits = \"mm\"\nup = \"y\"", 1e-3),
        &[],
    );
    let dir = path.parent().unwrap();
    std::fs::write(dir.join("part.gltf"), &json).unwrap();
    std::fs::write(dir.join("part.bin"), &bin).unwrap();
    let s = load(&path);
    let w = unit_warnings(&s);
    assert!(
        w.len() == 1 && w[0].contains("1/1000") && w[0].contains("units = \"m\"?"),
        "{w:?}"
    );
    // The part at its true size gives none.
    let s = load_one("units-mm", "part.obj", obj(&part()).as_bytes(), "");
    assert!(unit_warnings(&s).is_empty(), "{:?}", s.warnings);
}

/// scene_toml with the LED's centre scaled by `k` about the origin (so it stays on the
/// part's edge when the part is read at the wrong scale).
fn scene_toml_lamp(geometry: &str, k: f64) -> String {
    scene_toml(geometry)
        .replace(
            "center = [-0.01, 31.25, 1.953125]",
            &format!(
                "center = [{:?}, {:?}, {:?}]\nwidth_mm = {:?}\nheight_mm = {:?}",
                -0.01 * k,
                31.25 * k,
                1.953125 * k,
                60.0 * k,
                3.0 * k
            ),
        )
        .replace("width_mm = 60.0\nheight_mm = 3.0\n", "")
}

/// load_one with the lamp scaled by `k` (scene_toml_lamp).
fn load_units(name: &str, file: &str, bytes: &[u8], extra: &str, k: f64) -> Scene {
    let geometry = format!("file = \"{file}\"\n{extra}");
    let path = write_scene(name, &scene_toml_lamp(&geometry, k), &[]);
    std::fs::write(path.parent().unwrap().join(file), bytes).unwrap();
    load(&path)
}

/// Every tag without a surface table is reported in one error, with the files using it.
#[test]
fn every_missing_surface_table_is_reported_at_once() {
    let tris = part();
    let mut text = String::from("mtllib none.mtl\n");
    for t in &tris {
        for p in t {
            text += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
    }
    for (k, tag) in ["lgp", "back", "edge"].iter().enumerate() {
        text += &format!("usemtl {tag}\n");
        for f in (4 * k..4 * k + 4).filter(|f| *f < tris.len()) {
            text += &format!("f {} {} {}\n", 3 * f + 1, 3 * f + 2, 3 * f + 3);
        }
    }
    let err = load_err("missing-tables", "part.obj", text.as_bytes(), "");
    assert!(
        err.contains("[surfaces.back]")
            && err.contains("[surfaces.edge]")
            && err.contains("part.obj"),
        "{err}"
    );
    assert!(!err.contains("[surfaces.lgp]"), "{err}");
}
