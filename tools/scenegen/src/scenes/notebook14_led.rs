//! `notebook14-led`: notebook14's guide and lamp holders lit by two rows of white LEDs,
//! traced in colour (the LEDs have a CIE LED-B5 spectrum, the PMMA a dispersion formula
//! and an absorption spectrum). The scene file is `notebook14_led.toml` beside this
//! module, a hand-written text: it names its sources in comments, which a template would
//! only repeat; the mesh is notebook14's, byte for byte.

use super::notebook14;
use crate::GenFile;

/// The scene file.
const SCENE: &str = include_str!("notebook14_led.toml");

/// The scene's files: its scene.toml and notebook14's mesh.
pub fn files() -> Vec<GenFile> {
    let mut files: Vec<GenFile> = notebook14::files()
        .into_iter()
        .filter(|f| !f.path.ends_with("scene.toml"))
        .map(|f| GenFile {
            path: f.path.replacen("notebook14/", "notebook14-led/", 1),
            bytes: f.bytes,
        })
        .collect();
    files.insert(
        0,
        GenFile::text("notebook14-led/scene.toml", SCENE.to_string()),
    );
    files
}
