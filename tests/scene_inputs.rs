//! `Scene::inputs` lists exactly the files loading reads, so that no output can delete
//! one (`output::atomic::check_apart`). The oracle is the loader itself: in a copy of a
//! scene's folder, removing any listed file makes loading fail, and removing every file
//! not listed leaves it loading.

mod support;

use blutrace::scene::Scene;
use std::path::{Path, PathBuf};
use support::bsdf::lambert_table;
use support::{bundled_scene_files, temp_folder};

/// Copy the files of `scene`'s folder (not its subfolders) into `into`.
fn copy_folder(scene: &Path, into: &Path) {
    for e in std::fs::read_dir(scene.parent().unwrap()).unwrap() {
        let p = e.unwrap().path();
        if p.is_file() {
            std::fs::copy(&p, into.join(p.file_name().unwrap())).unwrap();
        }
    }
}

/// The oracle of the module header, on the scene `scene.toml` in the folder `dir`.
fn assert_inputs_are_what_loading_reads(dir: &Path) {
    let scene_file = dir.join("scene.toml");
    let scene = Scene::load(&scene_file).unwrap_or_else(|e| panic!("{e:#}"));
    let listed: Vec<PathBuf> = scene
        .inputs
        .iter()
        .map(|p| p.canonicalize().unwrap())
        .collect();
    assert!(listed.contains(&scene_file.canonicalize().unwrap()));
    let present: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path().canonicalize().unwrap())
        .collect();
    for f in listed
        .iter()
        .filter(|f| **f != scene_file.canonicalize().unwrap())
    {
        let keep = std::fs::read(f).unwrap();
        std::fs::remove_file(f).unwrap();
        assert!(
            Scene::load(&scene_file).is_err(),
            "{}: loads without {}, which it lists as an input",
            scene_file.display(),
            f.display()
        );
        std::fs::write(f, keep).unwrap();
    }
    for f in present.iter().filter(|f| !listed.contains(f)) {
        std::fs::remove_file(f).unwrap();
    }
    Scene::load(&scene_file)
        .unwrap_or_else(|e| panic!("loads only with a file it does not list as an input: {e:#}"));
}

#[test]
fn every_bundled_scene_lists_the_files_it_reads() {
    for scene in bundled_scene_files() {
        let dir = temp_folder("inputs-bundled");
        copy_folder(&scene, dir.path());
        assert_inputs_are_what_loading_reads(dir.path());
    }
}

/// A sheet with a measured table and its back, an LED with an intensity file, a spectrum
/// file and a lamp body's table, and a ray file: every kind of file a scene names.
#[test]
fn every_kind_of_file_a_scene_names_is_an_input() {
    let dir = temp_folder("inputs-kinds");
    let toml = r#"version = 1
[[geometry]]
file = "sheet.obj"
[surfaces.sheet]
model = "bsdf_table"
file = "front.bsdf"
back_file = "back.bsdf"
[[sources]]
type = "led"
center = [0.0, 0.0, 5.0]
normal = [0.0, 0.0, -1.0]
u = [1.0, 0.0, 0.0]
width_mm = 2.0
height_mm = 2.0
power_w = 1.0
intensity_file = "led.csv"
spectrum = { file = "led-spectrum.csv" }
body = { model = "bsdf_table", file = "body.bsdf" }
[[sources]]
type = "rayfile"
file = "rays.txt"
[detector]
origin = [-100.0, -100.0, 10.0]
u = [1.0, 0.0, 0.0]
v = [0.0, 1.0, 0.0]
size_mm = [200.0, 200.0]
bins = [4, 4]
angular_bins = [3, 4]
"#;
    let files = [
        ("scene.toml", toml.to_string()),
        (
            "sheet.obj",
            "v -100 -100 0\nv 100 -100 0\nv 100 100 0\nv -100 100 0\nusemtl sheet\nf 1 2 3\nf 1 3 4\n"
                .to_string(),
        ),
        ("front.bsdf", lambert_table(0.5)),
        ("back.bsdf", lambert_table(0.7)),
        ("body.bsdf", lambert_table(0.3)),
        ("led.csv", "theta_deg,relative_intensity\n0,1\n45,0.7\n90,0\n".to_string()),
        ("led-spectrum.csv", "450, 1.0\n550, 0.5\n650, 0.8\n".to_string()),
        ("rays.txt", "0 0 3  0 0 -1  0.5  550\n1 0 3  0 0 -1  0.5  600\n".to_string()),
        ("unrelated.txt", "not read".to_string()),
    ];
    for (name, text) in &files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let scene = Scene::load(&dir.path().join("scene.toml")).unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!(scene.inputs.len(), files.len() - 1, "{:?}", scene.inputs);
    assert_inputs_are_what_loading_reads(dir.path());
}
