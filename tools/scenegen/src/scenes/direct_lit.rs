//! `direct-lit`: a direct-lit (bottom-lit) backlight: a row of CCFLs in a white reflective
//! box behind a diffuser plate. Lamp count, spacing, height and the back reflector's
//! shape are parameters ([`DirectLit`]), so an optimizer can generate and trace variants;
//! the bundled `direct-lit` scene and the test variants `test/direct-lit-3` and
//! `test/direct-lit-8` are instances.
//!
//! ```no_run
//! use scenegen::scenes::direct_lit::{DirectLit, Reflector};
//! let variant = DirectLit { lamps: 4, pitch: 90.0, reflector: Reflector::Ridges { height: 6.0 }, ..DirectLit::bundled() };
//! for f in variant.files("my-variant") {
//!     std::fs::write(&f.path, &f.bytes).unwrap(); // paths start with the folder name
//! }
//! ```

use super::GENERATED;
use crate::shapes::solid_box;
use crate::templates::{
    Beads, Ccfl, Detector, MtlNote, WHITE_PET_ALBEDO, dielectric, geometry, medium, obj_and_mtl,
    preamble, rough_dielectric, scene_file, trace_table, white_pet_lambert,
};
use crate::{GenFile, P3, Part, dim, num, triangle_count};

/// Inner box length along x, across the lamps (mm).
pub const BOX_X: f64 = 400.0;
/// Inner box width along y, along the lamps (mm).
pub const BOX_Y: f64 = 250.0;
/// Box depth: from the back reflector's lowest point (z = 0) to the diffuser plate (mm).
pub const DEPTH: f64 = 25.0;
/// Diffuser plate thickness (mm); the plate spans z = DEPTH..DEPTH + this.
pub const PLATE_T: f64 = 2.0;
/// Diffuser plate refractive index (polycarbonate).
pub const N_PLATE: f64 = 1.585;
/// Diffuser plate absorption (1/mm).
pub const PLATE_ABSORPTION: f64 = 0.001;
/// CCFL radius (mm).
pub const LAMP_R: f64 = 1.5;
/// Clearance between each lamp's ends and the box's end walls (mm).
pub const LAMP_END_CLEARANCE: f64 = 5.0;
/// Radiant power per lamp (W).
pub const LAMP_POWER_W: f64 = 1.0;
/// Albedo of the white box walls and back reflector (Lambertian).
pub const WALL_ALBEDO: f64 = WHITE_PET_ALBEDO;
/// Detector height above the diffuser plate's top face (mm).
pub const DETECTOR_GAP: f64 = 0.5;
/// Default GGX roughness (alpha) of the diffuser plate's two large faces (rough plate).
pub const DIFFUSER_ROUGHNESS: f64 = 0.6;
/// Bulk plate: radius of the diffusing beads (um): Momentive TSR9000 (polymethyl-
/// silsesquioxane spheres, the Tospearl family), mean diameter 2.0 um.
pub const BEAD_RADIUS_UM: f64 = 1.0;
/// Bulk plate: the beads' refractive index (TSR9000: 1.42).
pub const BEAD_N: f64 = 1.42;
/// Bulk plate: the beads' volume fraction, a design choice: 1 % by volume is 1.1 % by
/// weight at the beads' specific gravity (TSR9000: 1.32) in PC (1.20).
pub const BEAD_VOLUME_FRACTION: f64 = 0.01;
/// The geometry file's name in every variant's folder (its display-material library is
/// `direct-lit.mtl`).
pub const OBJ: &str = "direct-lit.obj";

/// The back reflector's shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reflector {
    /// A flat back at z = 0.
    Flat,
    /// Triangular ridges: valleys (z = 0) under the lamps, straight slopes up to ridges of
    /// `height` midway between neighbouring lamps and at the side walls.
    Ridges {
        /// Ridge height above the valleys (mm).
        height: f64,
    },
}

/// The diffuser plate's model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Plate {
    /// A bulk diffuser: PC filled with beads ([`BEAD_RADIUS_UM`], [`BEAD_N`],
    /// [`BEAD_VOLUME_FRACTION`]), mu_s and g from Mie theory, smooth faces.
    Bulk,
    /// A clear PC plate whose two large faces are rough (model `diffuser`, GGX roughness
    /// `roughness`; 0 is a clear plate): a surface-scattering stand-in for a bulk plate.
    Rough {
        /// GGX alpha.
        roughness: f64,
    },
}

/// The parameters of a direct-lit box.
#[derive(Clone, Debug, PartialEq)]
pub struct DirectLit {
    /// Scene name.
    pub name: String,
    /// Number of lamps (at least 1).
    pub lamps: usize,
    /// Lamp spacing, centre to centre (mm); the row is centred in the box.
    pub pitch: f64,
    /// Lamp axis height above z = 0 (mm).
    pub lamp_height: f64,
    /// Back reflector shape.
    pub reflector: Reflector,
    /// The diffuser plate's model.
    pub plate: Plate,
    /// Flux bins (x, y).
    pub bins: [usize; 2],
    /// Default photon count.
    pub photons: u64,
}

impl DirectLit {
    /// The bundled `direct-lit` scene: 6 lamps at the box's natural pitch (`BOX_X / 6`),
    /// 8 mm up, over 6 mm ridges, under a bulk diffuser plate.
    pub fn bundled() -> Self {
        Self {
            plate: Plate::Bulk,
            ..Self::evenly_spaced("direct-lit", 6)
        }
    }

    /// `lamps` lamps spaced `BOX_X / lamps` (each owns an equal strip of the box), 8 mm
    /// up, over 6 mm ridges, under a rough plate of roughness [`DIFFUSER_ROUGHNESS`];
    /// 80 x 50 bins of 5 mm.
    pub fn evenly_spaced(name: &str, lamps: usize) -> Self {
        Self {
            name: name.to_string(),
            lamps,
            pitch: BOX_X / lamps as f64,
            lamp_height: 8.0,
            reflector: Reflector::Ridges { height: 6.0 },
            plate: Plate::Rough {
                roughness: DIFFUSER_ROUGHNESS,
            },
            bins: [80, 50],
            photons: 400_000,
        }
    }

    /// Lamp axis x positions.
    pub fn lamp_x(&self) -> Vec<f64> {
        let n = self.lamps as f64;
        (0..self.lamps)
            .map(|i| 0.5 * BOX_X + (i as f64 - 0.5 * (n - 1.0)) * self.pitch)
            .collect()
    }

    /// Lamp centres (the lamps run along y).
    pub fn lamp_centres(&self) -> Vec<P3> {
        self.lamp_x()
            .into_iter()
            .map(|x| [x, 0.5 * BOX_Y, self.lamp_height])
            .collect()
    }

    /// Lamp length: the box width less the end clearances.
    pub fn lamp_length(&self) -> f64 {
        BOX_Y - 2.0 * LAMP_END_CLEARANCE
    }

    /// The back reflector's profile (x, z), from x = 0 to `BOX_X`.
    pub fn back_profile(&self) -> Vec<[f64; 2]> {
        match self.reflector {
            Reflector::Flat => vec![[0.0, 0.0], [BOX_X, 0.0]],
            Reflector::Ridges { height } => {
                let xs = self.lamp_x();
                let mut p = vec![[0.0, height]];
                for (i, &x) in xs.iter().enumerate() {
                    if i > 0 {
                        p.push([0.5 * (xs[i - 1] + x), height]);
                    }
                    p.push([x, 0.0]);
                }
                p.push([BOX_X, height]);
                p
            }
        }
    }

    /// Check the parameters: the lamps fit in the box, clear of the walls, the ridges and
    /// each other, below the plate.
    pub fn validate(&self) -> Result<(), String> {
        if self.lamps == 0 {
            return Err("needs at least one lamp".into());
        }
        if let Plate::Rough { roughness } = self.plate
            && !(roughness >= 0.0 && roughness.is_finite())
        {
            return Err(format!("diffuser roughness {roughness}: must be >= 0"));
        }
        let pitch_ok = self.pitch.is_finite() && self.pitch > 2.0 * LAMP_R + 1.0;
        if self.lamps > 1 && !pitch_ok {
            return Err(format!("pitch {} mm: lamps would touch", self.pitch));
        }
        let xs = self.lamp_x();
        if xs[0] - LAMP_R < 1.0 || xs[xs.len() - 1] + LAMP_R > BOX_X - 1.0 {
            return Err(format!(
                "{} lamps at {} mm pitch do not fit in the {BOX_X} mm box",
                self.lamps, self.pitch
            ));
        }
        if self.lamp_height + LAMP_R > DEPTH - 1.0 {
            return Err(format!(
                "lamp height {} mm: too close to the plate",
                self.lamp_height
            ));
        }
        if let Reflector::Ridges { height } = self.reflector
            && !(0.0..DEPTH - 1.0).contains(&height)
        {
            return Err(format!(
                "ridge height {height} mm: must be within 0..{}",
                DEPTH - 1.0
            ));
        }
        // Clearance from every lamp to every back profile segment.
        let prof = self.back_profile();
        for &x in &xs {
            for w in prof.windows(2) {
                let d = point_segment([x, self.lamp_height], w[0], w[1]);
                if d < LAMP_R + 1.0 {
                    return Err(format!(
                        "the lamp at x = {x} mm comes within {:.2} mm of the back reflector",
                        d - LAMP_R
                    ));
                }
            }
        }
        Ok(())
    }

    /// The parts: white box (back reflector and four walls) and diffuser plate.
    pub fn parts(&self) -> Vec<Part> {
        let prof = self.back_profile();
        let (y1, top) = (BOX_Y, DEPTH);
        let t = "box_reflector";
        let mut bx = Part::new("box");
        // Back: one strip per profile segment, normals up (into the box).
        for w in prof.windows(2) {
            let ([xa, za], [xb, zb]) = (w[0], w[1]);
            bx.quad(t, [xa, 0.0, za], [xb, 0.0, zb], [xb, y1, zb], [xa, y1, za]);
        }
        // Side walls x = 0 and x = BOX_X, from the profile's ends up to the plate.
        let (z0, z1) = (prof[0][1], prof[prof.len() - 1][1]);
        bx.quad(
            t,
            [0.0, 0.0, z0],
            [0.0, y1, z0],
            [0.0, y1, top],
            [0.0, 0.0, top],
        );
        bx.quad(
            t,
            [BOX_X, 0.0, z1],
            [BOX_X, 0.0, top],
            [BOX_X, y1, top],
            [BOX_X, y1, z1],
        );
        // End walls y = 0 and y = BOX_Y: a trapezoid over each profile segment.
        for w in prof.windows(2) {
            let ([xa, za], [xb, zb]) = (w[0], w[1]);
            bx.quad(
                t,
                [xa, 0.0, za],
                [xa, 0.0, top],
                [xb, 0.0, top],
                [xb, 0.0, zb],
            );
            bx.quad(t, [xa, y1, za], [xb, y1, zb], [xb, y1, top], [xa, y1, top]);
        }
        vec![bx, diffuser_plate()]
    }

    fn scene_toml(&self, triangles: usize) -> String {
        let reflector = match self.reflector {
            Reflector::Flat => "flat, at z = 0".to_string(),
            Reflector::Ridges { height } => format!(
                "triangular ridges {} high: valleys (z = 0) under the lamps,
  ridges midway between neighbouring lamps and at the x walls",
                dim(height)
            ),
        };
        let xs: Vec<String> = self.lamp_x().iter().map(|&x| dim(x)).collect();
        let header = format!(
            "{name}: a direct-lit backlight: {n} CCFLs in a white reflective box behind a diffuser plate.
{GENERATED}
Made by tools/scenegen's DirectLit (lamp count, spacing, height and back reflector shape
are parameters).

Axes (mm): x across the lamps, y along them, z towards the viewer.

- Box (tag box_reflector, Lambertian, albedo {WALL_ALBEDO}, like white PET): inner
  {BOX_X} x {BOX_Y}, {DEPTH} deep from z = 0 to the diffuser plate; four side walls up to
  the plate.
- Back reflector (same tag): {reflector}.
- Lamps: {n} CCFLs along y, radius {LAMP_R}, length {len} ({LAMP_END_CLEARANCE} clear of each
  end wall), {LAMP_POWER_W} W each, axes at z = {h}, pitch {pitch}, at
  x = {xs}.
- Diffuser plate: polycarbonate (n = {N_PLATE}, absorption {PLATE_ABSORPTION} /mm), {BOX_X} x {BOX_Y} x {PLATE_T}
  at z = {DEPTH}..{ztop}, resting on the walls. Tags diffuser_top (the front face),
  diffuser_back, diffuser_edge (smooth). {plate}
- Detector: {DETECTOR_GAP} above the plate (z = {zd}), covering it, {bx} x {by} bins.

Geometry: {obj} (tags are its usemtl names), {triangles} triangles.
",
            name = self.name,
            n = self.lamps,
            len = dim(self.lamp_length()),
            h = dim(self.lamp_height),
            xs = xs.join(", "),
            pitch = dim(self.pitch),
            ztop = dim(DEPTH + PLATE_T),
            plate = self.plate_note(),
            zd = dim(DEPTH + PLATE_T + DETECTOR_GAP),
            bx = self.bins[0],
            by = self.bins[1],
            obj = OBJ,
        );
        let description = format!(
            "Direct-lit BLU: {} CCFLs at {} mm pitch in a {BOX_X} x {BOX_Y} x {DEPTH} mm white box behind a {PLATE_T} mm plate",
            self.lamps,
            dim(self.pitch)
        );
        let mut tables = vec![preamble(&self.name, &description), geometry(OBJ)];
        tables.extend(self.plate_and_walls());
        for (i, c) in self.lamp_centres().iter().enumerate() {
            let name = format!("lamp{}", i + 1);
            let lamp = Ccfl {
                power_w: LAMP_POWER_W,
                ..Ccfl::new(&name, *c, LAMP_R, self.lamp_length())
            };
            tables.push(lamp.toml());
        }
        tables.push(self.detector().toml());
        tables.push(trace_table(self.photons, 100_000));
        scene_file(&header, &tables)
    }

    /// The plate's medium and the surfaces of the box and the plate.
    pub(crate) fn plate_and_walls(&self) -> Vec<String> {
        let (beads, top_and_back) = match self.plate {
            Plate::Bulk => {
                let beads = Beads {
                    radius_um: BEAD_RADIUS_UM,
                    n: BEAD_N,
                    volume_fraction: BEAD_VOLUME_FRACTION,
                };
                (
                    Some(beads),
                    ["diffuser_top", "diffuser_back"].map(|t| dielectric(t, "pc")),
                )
            }
            Plate::Rough { roughness } => (
                None,
                ["diffuser_top", "diffuser_back"].map(|t| rough_dielectric(t, "pc", roughness)),
            ),
        };
        let [top, back] = top_and_back;
        vec![
            medium("pc", N_PLATE, PLATE_ABSORPTION, beads.as_ref()),
            white_pet_lambert("box_reflector"),
            top,
            back,
            dielectric("diffuser_edge", "pc"),
        ]
    }

    /// The detector, [`DETECTOR_GAP`] above the plate, covering it.
    pub(crate) fn detector(&self) -> Detector {
        Detector::new(
            [0.0, 0.0, DEPTH + PLATE_T + DETECTOR_GAP],
            [BOX_X, BOX_Y],
            self.bins,
        )
    }

    /// The plate's paragraph in the scene file's header.
    pub(crate) fn plate_note(&self) -> String {
        match self.plate {
            Plate::Bulk => format!(
                "A bulk diffuser
  (volume scattering, smooth faces): spheres of radius {r} um and index {nb}
  (Momentive TSR9000 polymethylsilsesquioxane beads: mean diameter 2.0 um, refractive
  index 1.42, specific gravity 1.32, ChemPoint product page \"Momentive TSR9000 for
  Light Diffusion\") at {fv} by volume (a design choice: {wt:.1} % by weight in PC of
  specific gravity 1.20). blutrace computes mu_s and g from Mie theory at 550 nm
  (blutrace check shows them: about 20.4 /mm and 0.978). Stand-in limits: one bead
  size (real beads have a size spread), the Henyey-Greenstein phase function with the
  Mie g (not the full Mie phase function), independent scattering, one wavelength.
  The rough-surface model (diffuser, GGX) stays available: see the scenegen parameters.",
                r = num(BEAD_RADIUS_UM),
                nb = num(BEAD_N),
                fv = num(BEAD_VOLUME_FRACTION),
                wt = 100.0 * (BEAD_VOLUME_FRACTION * 1.32)
                    / (BEAD_VOLUME_FRACTION * 1.32 + (1.0 - BEAD_VOLUME_FRACTION) * 1.20),
            ),
            Plate::Rough { roughness } => format!(
                "Its two large faces are rough
  dielectric interfaces (model diffuser, GGX roughness {}): a surface-scattering
  stand-in for a bulk-diffusing plate (the bundled direct-lit scene has the bulk one).",
                num(roughness)
            ),
        }
    }

    /// The scene's files below `folder` (e.g. `direct-lit` or `test/direct-lit-3`):
    /// `scene.toml`, [`OBJ`] and its `.mtl`.
    /// Panics if [`DirectLit::validate`] fails.
    pub fn files(&self, folder: &str) -> Vec<GenFile> {
        if let Err(e) = self.validate() {
            panic!("{}: {e}", self.name);
        }
        let parts = self.parts();
        let header = format!(
            "{}: direct-lit backlight, {} lamps (see scene.toml). Units mm.\n{GENERATED}",
            self.name, self.lamps
        );
        let [obj, mtl] = obj_and_mtl(folder, OBJ, &header, &parts, MtlNote::DisplayOnly);
        vec![
            GenFile::text(
                &format!("{folder}/scene.toml"),
                self.scene_toml(triangle_count(&parts)),
            ),
            obj,
            mtl,
        ]
    }
}

/// The diffuser plate resting on the box's walls.
pub fn diffuser_plate() -> Part {
    solid_box(
        "diffuser",
        [0.0, 0.0, DEPTH],
        [BOX_X, BOX_Y, DEPTH + PLATE_T],
        ["diffuser_top", "diffuser_back", "diffuser_edge"],
    )
}

/// Distance from point `p` to segment `a b` in the xz plane.
fn point_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dz) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dz * dz;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dz) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dz)
}

/// The bundled scene and the test variants (3 and 8 lamps) used by
/// `tests/variants.rs` to check that more lamps make the light more uniform.
pub fn files() -> Vec<GenFile> {
    let mut f = DirectLit::bundled().files("direct-lit");
    let mut three = DirectLit::evenly_spaced("test-direct-lit-3", 3);
    let mut eight = DirectLit::evenly_spaced("test-direct-lit-8", 8);
    for v in [&mut three, &mut eight] {
        v.photons = 100_000;
    }
    f.extend(three.files("test/direct-lit-3"));
    f.extend(eight.files("test/direct-lit-8"));
    f
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bundled_and_test_variants_validate() {
        for n in 1..=12 {
            DirectLit::evenly_spaced("x", n).validate().unwrap();
        }
        let crowded = DirectLit {
            pitch: 2.0,
            ..DirectLit::bundled()
        };
        assert!(crowded.validate().is_err());
        let wide = DirectLit {
            pitch: 100.0,
            ..DirectLit::bundled()
        };
        assert!(wide.validate().unwrap_err().contains("do not fit"));
    }

    #[test]
    fn ridges_peak_between_lamps() {
        let d = DirectLit::evenly_spaced("x", 4);
        let p = d.back_profile();
        assert_eq!(p.len(), 2 * 4 + 1);
        assert_eq!(p[0], [0.0, 6.0]);
        assert_eq!(p[1], [50.0, 0.0]);
        assert_eq!(p[2], [100.0, 6.0]);
        assert_eq!(p[8], [BOX_X, 6.0]);
        let flat = DirectLit {
            reflector: Reflector::Flat,
            ..d
        };
        assert_eq!(flat.parts()[0].triangle_count(), 2 + 4 + 4);
    }
}
