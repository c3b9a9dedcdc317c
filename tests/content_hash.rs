//! The scene content hash (shards of one run must agree on it) is over canonical data:
//! formatting, key order, comments, name and defaults do not change it; physics does.

mod support;

use support::*;

const OBJ_TAGS: [&str; 6] = ["edge", "edge", "edge", "edge", "face", "face"];
const SHEET: &str =
    "v -12 -12 -0.7\nv 12 -12 -0.7\nv 12 12 -0.7\nv -12 12 -0.7\nusemtl back\nf 1 2 3\nf 1 3 4\n";

fn scene_toml(name: &str, albedo: &str, comment: bool, photons: u64) -> String {
    let note = if comment { "# a comment\n" } else { "" };
    format!(
        "version = 1\nname = \"{name}\"\n{note}[[geometry]]\nfile = \"plate.obj\"\n[[geometry]]\nfile = \"sheet.obj\"\n\
         [media.pmma]\nn = 1.49\nabsorption_per_mm = 0.01\n\
         [surfaces.face]\nmodel = \"dielectric\"\ninside = \"pmma\"\n\
         [surfaces.edge]\ninside = \"pmma\"\nmodel = \"dielectric\"\n\
         [surfaces.back]\nmodel = \"lambert\"\nalbedo = {albedo}\n\
         [[sources]]\ntype = \"led\"\ncenter = [-10.001, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\n\
         u = [0.0, 1.0, 0.0]\nwidth_mm = 10.0\nheight_mm = 0.5\npower_w = 2.0\n\
         [detector]\norigin = [-10.0, -10.0, 0.6]\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\n\
         size_mm = [20.0, 20.0]\nbins = [10, 10]\nangular_bins = [6, 8]\n\
         [trace]\nphotons = {photons}\n"
    )
}

fn hash(name: &str, toml: &str) -> u64 {
    let obj = box_obj([-10.0, -10.0, -0.5], [10.0, 10.0, 0.5], OBJ_TAGS);
    load(&write_scene(
        name,
        toml,
        &[("plate.obj", &obj), ("sheet.obj", SHEET)],
    ))
    .content_hash()
}

#[test]
fn content_hash_ignores_form_and_names_but_not_physics() {
    let base = hash("hash-base", &scene_toml("a", "0.8", false, 1000));
    assert_eq!(
        base,
        hash("hash-again", &scene_toml("a", "0.8", false, 1000))
    );
    // Another name, a comment, another default photon count, 0.80 for 0.8, keys reordered.
    let same = scene_toml("b", "0.80", true, 5000).replace(
        "n = 1.49\nabsorption_per_mm = 0.01\n",
        "absorption_per_mm = 0.01\nn = 1.49\n",
    );
    assert_eq!(base, hash("hash-same", &same));
    assert_ne!(
        base,
        hash("hash-albedo", &scene_toml("a", "0.7", false, 1000))
    );
}
