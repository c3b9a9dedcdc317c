//! The input is a shard file, `shard.json`, read by `shard::read_shard`, then checked
//! (`shard::check`) against the fixed small scene of fuzz/fixtures/shard and, as
//! `blutrace merge --partial` would, merged (`shard::merge`) and summarised.
//!
//! The scene's content hash is first checked as the file gives it, then replaced by the
//! scene's own, so that the corpus reaches `merge` even after a change to the hash or the
//! fixture scene.
#![no_main]

mod common;

use blutrace::scene::Scene;
use blutrace::shard;
use std::sync::OnceLock;

static SCENE: OnceLock<Scene> = OnceLock::new();

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let dir = common::workdir("shard", &["shard"], &[]);
    let scene = SCENE.get_or_init(|| Scene::load(&dir.join("scene.toml")).expect("fixture scene"));
    let path = common::put(dir, "shard.json", data);
    let read = shard::read_shard(&path);
    common::report("read_shard", &read);
    let Ok(mut file) = read else {
        return;
    };
    common::report(
        "check",
        &shard::check(&[(path.clone(), file.clone())], scene),
    );
    file.scene_hash = format!("{:016x}", scene.content_hash());
    let shards = [(path, file)];
    let checked = shard::check(&shards, scene);
    common::report("check (scene's hash)", &checked);
    if checked.is_err() {
        return;
    }
    let merged = shard::merge(&shards, scene);
    common::report("merge", &merged);
    if let Ok(result) = merged {
        let _ = result.summary();
    }
});
