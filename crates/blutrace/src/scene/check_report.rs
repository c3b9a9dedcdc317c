//! What `blutrace check --json` prints: the geometry report, tallies, sources, media and
//! warnings of a loaded scene, as one JSON document (the Python package's
//! `Scene.check()` returns the same).

use super::Scene;
use crate::optics::medium::Medium;
use crate::optics::two_sided;
use crate::sources::Emitter;
use anyhow::Result;
use std::path::Path;

/// The `check --json` report of `scene`, loaded from `scene_file` (as the user named it);
/// an error when its tallies exceed [`crate::run::TALLY_BUDGET_BYTES`].
pub fn check_json(scene: &Scene, scene_file: &Path) -> Result<serde_json::Value> {
    let tally_bytes = crate::run::check_tally_budget(scene)?;
    Ok(serde_json::json!({
        "scene": scene.name,
        "scene_file": scene_file.display().to_string(),
        "geometry": scene.geometry,
        "tally_bytes": tally_bytes,
        "sources": scene.sources.list.iter().map(|s| serde_json::json!({
            "name": s.name,
            "power_w": s.power_w,
            "medium": scene.media[s.medium as usize].name,
            "body": s.body.as_ref().map_or("transparent".to_string(), |b| b.describe()),
            "spectrum": s.spectrum.as_ref().map(|sp| sp.report()),
            "rayfile": match &s.emitter {
                Emitter::RayFile(r) => serde_json::to_value(r.summary()).ok(),
                _ => None,
            },
        })).collect::<Vec<_>>(),
        "surfaces": surfaces_json(scene),
        "media": scene.media.iter().map(medium_json).collect::<Vec<_>>(),
        "warnings": scene.warnings,
    }))
}

/// Each tag's model, its back's and which way its triangles face, for `check --json`.
fn surfaces_json(scene: &Scene) -> Vec<serde_json::Value> {
    let counts = scene.triangles_per_tag();
    (0..scene.tags.len())
        .map(|t| {
            let facing: serde_json::Map<String, serde_json::Value> =
                two_sided::facing(&scene.mesh, t as u32)
                    .into_iter()
                    .map(|(way, n)| (way.to_string(), n.into()))
                    .collect();
            serde_json::json!({
                "tag": scene.tags[t],
                "model": scene.surfaces[t].kind(),
                "back": two_sided::back_kind(&scene.surfaces[t], scene.backs[t].as_ref()),
                "triangles": counts[t],
                "facing": facing,
            })
        })
        .collect()
}

/// One medium for `check --json`.
fn medium_json(m: &Medium) -> serde_json::Value {
    serde_json::json!({
        "name": m.name,
        "n": m.n,
        "absorption_per_mm": m.absorption_per_mm,
        "scattering_per_mm": m.scattering.per_mm,
        "anisotropy": m.scattering.anisotropy,
        "phase_table": m.scattering.table.is_some(),
        "particles": m.particles,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_report_names_the_scene_its_sources_and_media() {
        let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("scenes/bench-box/scene.toml");
        let scene = Scene::load(&path).unwrap();
        let r = check_json(&scene, &path).unwrap();
        assert_eq!(r["scene"], scene.name.as_str());
        assert_eq!(r["scene_file"], path.display().to_string().as_str());
        assert_eq!(
            r["sources"].as_array().unwrap().len(),
            scene.sources.list.len()
        );
        assert_eq!(r["media"].as_array().unwrap().len(), scene.media.len());
        assert_eq!(r["media"][0]["name"], scene.media[0].name.as_str());
        assert_eq!(r["tally_bytes"], crate::run::tally_bytes(&scene));
    }
}
