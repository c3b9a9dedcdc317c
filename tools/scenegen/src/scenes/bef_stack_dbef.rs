//! `bef-stack-dbef`: bef-stack with a reflective polarizer sheet (DBEF-like) above its
//! prism films and the panel's rear polarizer as the detector's analyzer. Its scene file is
//! bef-stack's with the sheet's geometry file and surface added, the analyzer set and the
//! name changed; bef-stack's mesh is reused byte for byte. Dropping the `dbef.obj`
//! geometry gives the same stack under the absorbing polarizer alone: the ratio of the two
//! is the sheet's gain.

use super::GENERATED;
use super::bef_stack::{self, DETECTOR_Z, GUIDE};
use crate::shapes::sheet_up;
use crate::{GenFile, ObjTags, dim, tags_of, write_mtl, write_obj};

/// Height (z, mm) of the reflective polarizer sheet: above bef2's prism tips (1.325 mm),
/// below the detector.
pub const DBEF_Z: f64 = 1.36;

/// The rear polarizer's transmission axis and the sheet's pass axis (degrees from x).
pub const AXIS_DEG: f64 = 0.0;

/// What this scene says of itself, before bef-stack's own header.
fn header() -> String {
    format!(
        "\
# bef-stack-dbef: bef-stack (below) with a reflective polarizer sheet (DBEF-like, tag
# dbef, in dbef.obj at z = {z} mm, above bef2's prism tips) and the panel's rear
# polarizer as [detector] analyzer_deg, its axis along the sheet's pass axis (x).
# {GENERATED}
# Dropping dbef.obj gives the stack under the absorbing rear polarizer alone; the ratio
# of the two extraction efficiencies is the reflective polarizer's gain (README, Polarization).
#
# The sheet's model (\"polarizer\") is a stand-in for a birefringent multilayer (DBEF,
# APF): its transmittances and reflectances are the same at every angle of incidence (a
# real stack's block reflectance and pass transmittance change beyond about 60 degrees),
# it does not retard (the birefringent layers turn the phase of oblique light), it has
# no colour (the stack's reflection band shifts with angle), and it reflects specularly.
#
",
        z = dim(DBEF_Z)
    )
}

/// The sheet's surface: the numbers and their sources.
const DBEF_SURFACE: &str = "\
# A reflective polarizer (3M DBEF-like). The gain it is bought for: displays with DBEF
# measured 32 % brighter than without (3M, in K. Werner, \"3M wants to expand market for
# DBEF reflective polarizer\", HDTV Magazine, January 2012). Its sheet values are assumed
# (no maker's number for the film alone at hand): pass_transmittance 0.90, below 1 by the
# Fresnel reflection of the film's two polymer faces in air (n about 1.6: about 5 % each,
# of which pass_reflectance keeps 0.08) and a little absorption; block_reflectance 0.95 as
# for the multilayer polymer mirrors of Weber et al., Science 287, 2451 (2000) \"Giant
# birefringent optics in multilayer polymer mirrors\" (broadband reflectance above 0.9,
# the polarizer's block state alike); block_transmittance 0.02, the rest absorbed.
[surfaces.dbef]
model = \"polarizer\"
axis = [1.0, 0.0, 0.0]
pass_transmittance = 0.9
pass_reflectance = 0.08
block_transmittance = 0.02
block_reflectance = 0.95

";

/// bef-stack's scene file turned into this one.
fn scene_toml(bef_stack: &str) -> String {
    let films = "[[geometry]]\nfile = \"bef-films.obj\"\n";
    let detector = format!("[detector]\norigin = [0.0, 0.0, {}]\n", dim(DETECTOR_Z));
    let trace = "[[sources]]\n";
    for (what, part) in [
        ("films", films),
        ("detector", detector.as_str()),
        ("sources", trace),
    ] {
        assert!(bef_stack.contains(part), "bef-stack's {what} changed");
    }
    let text = bef_stack
        .replace("name = \"bef-stack\"", "name = \"bef-stack-dbef\"")
        .replace(
            "description = \"Edge-lit guide",
            "description = \"bef-stack under a reflective polarizer (DBEF-like) and the panel's rear polarizer: edge-lit guide",
        )
        .replace(films, &format!("{films}\n[[geometry]]\nfile = \"dbef.obj\"\n"))
        .replace(trace, &format!("{DBEF_SURFACE}{trace}"))
        .replace(
            "angular_bins = [18, 36]\n",
            &format!(
                "angular_bins = [18, 36]\n# The panel's rear polarizer (an ideal absorbing polarizer), along the sheet's pass axis.\nanalyzer_deg = {}\n",
                dim(AXIS_DEG)
            ),
        );
    format!("{}{text}", header())
}

/// The scene's files: its scene.toml, bef-stack's mesh, and the sheet's.
pub fn files() -> Vec<GenFile> {
    let [gx, gy, _] = GUIDE;
    let sheet = vec![sheet_up("dbef", "dbef", [0.0, 0.0], [gx, gy], DBEF_Z)];
    let obj_header = format!(
        "bef-stack-dbef: the reflective polarizer sheet over bef-stack (see scene.toml). Units mm.\n{GENERATED}"
    );
    let mut files: Vec<GenFile> = bef_stack::files()
        .into_iter()
        .map(|f| {
            let path = f.path.replacen("bef-stack/", "bef-stack-dbef/", 1);
            if path.ends_with("scene.toml") {
                let text = String::from_utf8(f.bytes).expect("UTF-8");
                GenFile::text(&path, scene_toml(&text))
            } else {
                GenFile {
                    path,
                    bytes: f.bytes,
                }
            }
        })
        .collect();
    files.push(GenFile::text(
        "bef-stack-dbef/dbef.obj",
        write_obj(&obj_header, &sheet, ObjTags::Usemtl("dbef.mtl")),
    ));
    files.push(GenFile::text(
        "bef-stack-dbef/dbef.mtl",
        write_mtl(&obj_header, &tags_of(&sheet)),
    ));
    files
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sheet_lies_between_the_prism_tips_and_the_detector() {
        let tips = bef_stack::BEF_Z[1] + bef_stack::BEF_T + 0.5 * bef_stack::PRISM[0];
        assert!(tips < DBEF_Z && DBEF_Z < DETECTOR_Z);
    }
}
