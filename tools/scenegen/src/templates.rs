//! The text every generated scene file shares: its TOML tables (media, surfaces,
//! sources, the detector, the trace settings) and the `.obj` + `.mtl` pair of its
//! geometry. Each table function returns the table's lines, every line ending in a
//! newline and no blank line; [`scene_file`] puts one blank line before each table:
//!
//! ```toml
//! # header comment
//!
//! version = 1
//! name = "example"
//! description = "..."
//!
//! [[sources]]
//! type = "ccfl"
//! name = "lamp"
//! center = [-2.0, 30.0, 1.5]
//! axis = [0.0, 1.0, 0.0]
//! radius_mm = 1.0
//! length_mm = 59.0
//! power_w = 1.0
//! # ... (CCFL_BODY: where the albedo comes from)
//! body = { model = "lambert", albedo = 0.5 }
//!
//! [detector]
//! origin = [0.0, 0.0, 3.5]
//! u = [1.0, 0.0, 0.0]
//! v = [0.0, 1.0, 0.0]
//! size_mm = [100.0, 60.0]
//! bins = [100, 60]
//! angular_bins = [18, 36]
//!
//! [trace]
//! photons = 400000
//! seed = 1
//! max_bounces = 100000
//! ```

use crate::shapes::LGP_TAGS;
use crate::{GenFile, ObjTags, P3, Part, arr, comment, num, tags_of, write_mtl, write_obj};

/// A scene file: `header` as `#` comments, then `tables`, each after a blank line.
pub fn scene_file(header: &str, tables: &[String]) -> String {
    let mut s = comment(header);
    for t in tables {
        s.push('\n');
        s += t;
    }
    s
}

/// The lines that open every scene file, before its first table.
pub fn preamble(name: &str, description: &str) -> String {
    format!("version = 1\nname = \"{name}\"\ndescription = \"{description}\"\n")
}

/// A `[[geometry]]` table loading `file`.
pub fn geometry(file: &str) -> String {
    format!("[[geometry]]\nfile = \"{file}\"\n")
}

/// The `[trace]` table: `photons` photons from seed 1, at most `max_bounces` each.
pub fn trace_table(photons: u64, max_bounces: u32) -> String {
    format!("[trace]\nphotons = {photons}\nseed = 1\nmax_bounces = {max_bounces}\n")
}

// ---------------------------------------------------------------------------------------
// Media and surfaces

/// Scattering beads dispersed in a medium (a `particles` entry, Mie theory at 550 nm).
#[derive(Clone, Copy, Debug)]
pub struct Beads {
    /// Bead radius (um).
    pub radius_um: f64,
    /// Bead refractive index.
    pub n: f64,
    /// Volume fraction of the beads.
    pub volume_fraction: f64,
}

/// A `[media.NAME]` table: refractive index, absorption (1/mm), optional beads.
pub fn medium(name: &str, n: f64, absorption_per_mm: f64, beads: Option<&Beads>) -> String {
    let mut s = format!(
        "[media.{name}]\nn = {}\nabsorption_per_mm = {}\n",
        num(n),
        num(absorption_per_mm)
    );
    if let Some(b) = beads {
        s += &format!(
            "particles = {{ radius_um = {}, n = {}, volume_fraction = {}, wavelength_nm = 550.0 }}\n",
            num(b.radius_um),
            num(b.n),
            num(b.volume_fraction)
        );
    }
    s
}

/// A smooth dielectric interface `[surfaces.TAG]` with medium `inside` behind it.
pub fn dielectric(tag: &str, inside: &str) -> String {
    format!("[surfaces.{tag}]\nmodel = \"dielectric\"\ninside = \"{inside}\"\n")
}

/// A rough dielectric interface `[surfaces.TAG]` (model `diffuser`: GGX microfacets of
/// roughness alpha `roughness`) with medium `inside` behind it.
pub fn rough_dielectric(tag: &str, inside: &str, roughness: f64) -> String {
    format!(
        "[surfaces.{tag}]\nmodel = \"diffuser\"\ninside = \"{inside}\"\nroughness = {}\n",
        num(roughness)
    )
}

/// The three smooth faces of a dot-free light guide of medium `inside`, in the order of
/// [`LGP_TAGS`]: front, back, edge.
pub fn bare_guide_faces(inside: &str) -> [String; 3] {
    LGP_TAGS.map(|tag| dielectric(tag, inside))
}

/// The faces of a light guide with printed dots on its back, in the order front, edge
/// (both smooth), back.
pub fn dotted_guide_faces(dots: &Dots) -> [String; 3] {
    [
        dielectric("lgp_front", dots.inside),
        dielectric("lgp_edge", dots.inside),
        dots.toml("lgp_back"),
    ]
}

/// A Lambertian `[surfaces.TAG]` of albedo `albedo`.
pub fn lambert(tag: &str, albedo: f64) -> String {
    format!(
        "[surfaces.{tag}]\nmodel = \"lambert\"\nalbedo = {}\n",
        num(albedo)
    )
}

/// A Phong `[surfaces.TAG]`: total reflectance, its specular share and the lobe exponent.
pub fn phong(tag: &str, reflectance: f64, specular: f64, exponent: f64) -> String {
    format!(
        "[surfaces.{tag}]\nmodel = \"phong\"\nreflectance = {}\nspecular = {}\nexponent = {}\n",
        num(reflectance),
        num(specular),
        num(exponent)
    )
}

/// The white reflector sheet under the bundled CCFL and LED guides, with its comment: a
/// `[surfaces.reflector_sheet]` Phong table.
pub fn reflector_sheet() -> String {
    "# White polyester (PET) reflector film. Reflectance 0.95: a round value just under the
# over 96 % LCD reflector films are required to reflect (lcdpartscn.com, \"Reflector
# film, reflective film\"). Its weak gloss (specular 0.1, exponent 10) is an assumption,
# not a measurement.
"
    .to_string()
        + &phong("reflector_sheet", 0.95, 0.1, 10.0)
}

/// Albedo of the bundled scenes' white PET films taken as Lambertian (see
/// [`white_pet_lambert`]).
pub const WHITE_PET_ALBEDO: f64 = 0.95;

/// A white polyester (PET) film or white wall as a Lambertian `[surfaces.TAG]` of albedo
/// [`WHITE_PET_ALBEDO`], with the source of that number.
pub fn white_pet_lambert(tag: &str) -> String {
    "# White polyester (PET) film, fully diffuse. Albedo 0.95: a round value just under the
# over 96 % LCD reflector films are required to reflect (lcdpartscn.com, \"Reflector
# film, reflective film\"); real white PET has a weak gloss this leaves out.
"
    .to_string()
        + &lambert(tag, WHITE_PET_ALBEDO)
}

/// A silver-coated lamp reflector as a mirror `[surfaces.TAG]` of reflectance 0.95, with
/// the source of that number.
pub fn silver_mirror(tag: &str) -> String {
    "# Silver-coated reflector film as a perfect mirror. Reflectance 0.95: an assumption
# below the over 97 % of silver-coated LCD reflector films (lcdpartscn.com, \"Reflector
# film, reflective film\"), for a film bent round the lamp.
"
    .to_string()
        + &mirror(tag, 0.95)
}

/// The curved lamp reflector round the bundled CCFLs, with its comment: a
/// `[surfaces.lamp_reflector]` Phong table.
pub fn lamp_reflector() -> String {
    "# Silver-coated lamp reflector film. Reflectance 0.95: an assumption below the over
# 97 % of silver-coated LCD reflector films (lcdpartscn.com, \"Reflector film,
# reflective film\"), for a film bent round the lamp; mostly specular (specular 0.8,
# exponent 100), also an assumption.
"
    .to_string()
        + &phong("lamp_reflector", 0.95, 0.8, 100.0)
}

/// A specular `[surfaces.TAG]` of reflectance `reflectance`.
pub fn mirror(tag: &str, reflectance: f64) -> String {
    format!(
        "[surfaces.{tag}]\nmodel = \"mirror\"\nreflectance = {}\n",
        num(reflectance)
    )
}

/// A black `[surfaces.TAG]`.
pub fn absorber(tag: &str) -> String {
    format!("[surfaces.{tag}]\nmodel = \"absorber\"\n")
}

/// Printed ink dots on a guide's face (`model = "dots"`, src/optics/dots.rs), the pattern
/// starting at the world origin (every bundled guide's lamp-edge corner), the dots at
/// their cell centres.
#[derive(Clone, Copy, Debug)]
pub struct Dots<'a> {
    /// The guide's medium.
    pub inside: &'a str,
    /// Ink albedo (Lambertian).
    pub ink_albedo: f64,
    /// `"hex"` or `"square"`.
    pub lattice: &'a str,
    /// Lattice pitch (mm).
    pub pitch: f64,
    /// Direction along which the density is graded. Written at full precision, so a
    /// unit vector in a sloping face stays unit and in the face.
    pub axis: P3,
    /// Length of the pattern along `axis` (mm).
    pub length: f64,
    /// Density polynomial, lowest degree first.
    pub density: &'a [f64],
    /// Whether the polynomial's variable is the position over `length` (`x_unit =
    /// "normalized"`) rather than millimetres (the default).
    pub normalized: bool,
    /// Whether x is measured from the nearer end of `length` (lamps on both edges);
    /// written only when set.
    pub mirror: Option<bool>,
}

impl Dots<'_> {
    /// The `[surfaces.TAG]` table.
    pub fn toml(&self, tag: &str) -> String {
        let a = self.axis;
        let mut s = format!(
            "[surfaces.{tag}]\nmodel = \"dots\"\ninside = \"{}\"\nink_albedo = {}\nlattice = \"{}\"\npitch_mm = {}\norigin = [0.0, 0.0, 0.0]\naxis = [{:?}, {:?}, {:?}]\nlength_mm = {}\ndensity = {}\n",
            self.inside,
            num(self.ink_albedo),
            self.lattice,
            num(self.pitch),
            a[0],
            a[1],
            a[2],
            num(self.length),
            arr(self.density),
        );
        if self.normalized {
            s += "x_unit = \"normalized\"\n";
        }
        if let Some(m) = self.mirror {
            s += &format!("mirror = {m}\n");
        }
        s
    }
}

// ---------------------------------------------------------------------------------------
// Sources, detector

/// The body of every bundled CCFL (a `[[sources]]` line with its comment).
pub const CCFL_BODY: &str =
    "# The tube's phosphor coat as a diffuse (Lambertian) reflector of albedo 0.5: a
# modelling assumption, not a measurement. Backlight models commonly take 0.3 to 0.6;
# no published measured value was found. The README (\"Lamp bodies\") gives the
# efficiency for 0.3, 0.5 and 0.9. Left out: light that enters the tube and crosses it.
body = { model = \"lambert\", albedo = 0.5 }
";

/// The body of every bundled LED (a `[[sources]]` line with its comment).
pub const LED_BODY: &str =
    "# The package front (phosphor-in-silicone window over the die in a white cup) as a
# diffuse reflector of albedo 0.8: an assumption below the white cup's 0.95 (Panasonic
# Full Bright CE6000/CV1800 LED reflector compounds, initial reflectance 95 %, EDN Japan,
# 2 March 2012) for the darker die and phosphor it surrounds. The back absorbs.
body = { model = \"lambert\", albedo = 0.8 }
";

/// A row of identical sources (a source's `array` entry).
#[derive(Clone, Copy, Debug)]
pub struct Row {
    /// Number of sources.
    pub count: usize,
    /// Centre-to-centre spacing (mm).
    pub pitch: f64,
    /// Direction of the row.
    pub direction: P3,
}

/// A CCFL `[[sources]]` table: a tube along +y.
#[derive(Clone, Copy, Debug)]
pub struct Ccfl<'a> {
    /// Source name.
    pub name: &'a str,
    /// Tube centre (mm).
    pub center: P3,
    /// Tube radius (mm).
    pub radius: f64,
    /// Tube length (mm).
    pub length: f64,
    /// Radiant power (W).
    pub power_w: f64,
    /// Luminous flux (lm), when the scene gives one.
    pub lumens: Option<f64>,
    /// A row of tubes instead of one.
    pub row: Option<Row>,
    /// Whether the tube has a body ([`CCFL_BODY`]): light returning to it is reflected.
    pub body: bool,
}

impl<'a> Ccfl<'a> {
    /// A 1 W tube with the bundled CCFL body.
    pub fn new(name: &'a str, center: P3, radius: f64, length: f64) -> Self {
        Self {
            name,
            center,
            radius,
            length,
            power_w: 1.0,
            lumens: None,
            row: None,
            body: true,
        }
    }

    /// The `[[sources]]` table.
    pub fn toml(&self) -> String {
        let mut s = format!(
            "[[sources]]\ntype = \"ccfl\"\nname = \"{}\"\ncenter = {}\naxis = [0.0, 1.0, 0.0]\nradius_mm = {}\nlength_mm = {}\npower_w = {}\n",
            self.name,
            arr(&self.center),
            num(self.radius),
            num(self.length),
            num(self.power_w)
        );
        if let Some(lm) = self.lumens {
            s += &format!("lumens = {}\n", num(lm));
        }
        if let Some(r) = self.row {
            s += &format!(
                "array = {{ count = {}, pitch_mm = {}, direction = {} }}\n",
                r.count,
                num(r.pitch),
                arr(&r.direction)
            );
        }
        if self.body {
            s += CCFL_BODY;
        }
        s
    }
}

/// An LED `[[sources]]` table: a flat emitting rectangle.
#[derive(Clone, Copy, Debug)]
pub struct Led<'a> {
    /// Source name.
    pub name: &'a str,
    /// Centre of the emitting rectangle (mm).
    pub center: P3,
    /// Emitting direction.
    pub normal: P3,
    /// The rectangle's width direction.
    pub u: P3,
    /// Width (along `u`) and height (mm).
    pub size: [f64; 2],
    /// How `size` is written: [`num`], or [`crate::dim`] for whole numbers without `.0`.
    pub size_format: fn(f64) -> String,
    /// Radiant power (W).
    pub power_w: f64,
    /// Luminous flux (lm), when the scene gives one.
    pub lumens: Option<f64>,
    /// Tabulated intensity profile file, when not Lambertian.
    pub intensity_file: Option<&'a str>,
    /// Exponent of the cos^n profile, when written.
    pub cos_exponent: Option<f64>,
    /// Medium the LED emits into, when not air.
    pub medium: Option<&'a str>,
    /// Whether the LED has a body ([`LED_BODY`]): light returning to it is reflected.
    pub body: bool,
}

impl<'a> Led<'a> {
    /// A 1 W Lambertian LED of `size` (width along `u`, height) facing `normal`, with
    /// the bundled LED body.
    pub fn new(name: &'a str, center: P3, normal: P3, u: P3, size: [f64; 2]) -> Self {
        Self {
            name,
            center,
            normal,
            u,
            size,
            size_format: num,
            power_w: 1.0,
            lumens: None,
            intensity_file: None,
            cos_exponent: None,
            medium: None,
            body: true,
        }
    }

    /// [`Led::new`] facing +x, its width along y: an LED on a guide's x = 0 edge.
    pub fn facing_x(name: &'a str, center: P3, size: [f64; 2]) -> Self {
        Self::new(name, center, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], size)
    }

    /// The `[[sources]]` table.
    pub fn toml(&self) -> String {
        let f = self.size_format;
        let mut s = format!(
            "[[sources]]\ntype = \"led\"\nname = \"{}\"\ncenter = {}\nnormal = {}\nu = {}\nwidth_mm = {}\nheight_mm = {}\npower_w = {}\n",
            self.name,
            arr(&self.center),
            arr(&self.normal),
            arr(&self.u),
            f(self.size[0]),
            f(self.size[1]),
            num(self.power_w)
        );
        if let Some(lm) = self.lumens {
            s += &format!("lumens = {}\n", num(lm));
        }
        if let Some(file) = self.intensity_file {
            s += &format!("intensity_file = \"{file}\"\n");
        }
        if let Some(e) = self.cos_exponent {
            s += &format!("cos_exponent = {}\n", num(e));
        }
        if let Some(m) = self.medium {
            s += &format!("medium = \"{m}\"\n");
        }
        if self.body {
            s += LED_BODY;
        }
        s
    }
}

/// The `[detector]` table: a rectangle parallel to the xy plane.
#[derive(Clone, Copy, Debug)]
pub struct Detector {
    /// Its low corner (mm).
    pub origin: P3,
    /// Its size along x and y (mm).
    pub size: [f64; 2],
    /// Flux bins along x and y.
    pub bins: [usize; 2],
    /// Angular bins (polar, azimuthal).
    pub angular_bins: [usize; 2],
}

impl Detector {
    /// Covering `size` from `origin`, with 5 deg polar and 10 deg azimuthal bins.
    pub fn new(origin: P3, size: [f64; 2], bins: [usize; 2]) -> Self {
        Self {
            origin,
            size,
            bins,
            angular_bins: [18, 36],
        }
    }

    /// The `[detector]` table.
    pub fn toml(&self) -> String {
        let ([bx, by], [bt, bp]) = (self.bins, self.angular_bins);
        format!(
            "[detector]\norigin = {}\nu = [1.0, 0.0, 0.0]\nv = [0.0, 1.0, 0.0]\nsize_mm = {}\nbins = [{bx}, {by}]\nangular_bins = [{bt}, {bp}]\n",
            arr(&self.origin),
            arr(&self.size)
        )
    }
}

// ---------------------------------------------------------------------------------------
// Geometry files

/// What the `.mtl` file's header adds to the `.obj` file's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MtlNote {
    /// Nothing: the same header.
    Plain,
    /// A line saying the colours are for display only.
    DisplayOnly,
}

/// `folder/NAME.obj` (`obj`; its `usemtl` names are the tags) and `folder/NAME.mtl`, the
/// display materials of its tags, both headed by `header`.
pub fn obj_and_mtl(
    folder: &str,
    obj: &str,
    header: &str,
    parts: &[Part],
    note: MtlNote,
) -> [GenFile; 2] {
    let stem = obj
        .strip_suffix(".obj")
        .expect("an OBJ file name ends in .obj");
    let mtl = format!("{stem}.mtl");
    let mtl_header = match note {
        MtlNote::Plain => header.to_string(),
        MtlNote::DisplayOnly => {
            format!("{header}\nDisplay colours only: blutrace reads the usemtl names as tags.")
        }
    };
    [
        GenFile::text(
            &format!("{folder}/{obj}"),
            write_obj(header, parts, ObjTags::Usemtl(&mtl)),
        ),
        GenFile::text(
            &format!("{folder}/{mtl}"),
            write_mtl(&mtl_header, &tags_of(parts)),
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::guide_box;

    #[test]
    fn tables_follow_the_header_after_one_blank_line_each() {
        let s = scene_file("title\n\nmore", &[preamble("x", "y"), trace_table(10, 5)]);
        assert_eq!(
            s,
            "# title\n#\n# more\n\nversion = 1\nname = \"x\"\ndescription = \"y\"\n\n\
             [trace]\nphotons = 10\nseed = 1\nmax_bounces = 5\n"
        );
    }

    #[test]
    fn optional_source_keys_are_written_only_when_set() {
        let bare = Led {
            body: false,
            ..Led::facing_x("led", [0.0; 3], [1.0, 0.5])
        }
        .toml();
        for key in ["lumens", "intensity_file", "cos_exponent", "medium", "body"] {
            assert!(!bare.contains(key), "{key} in {bare}");
        }
        let full = Ccfl {
            lumens: Some(300.0),
            row: Some(Row {
                count: 3,
                pitch: 10.0,
                direction: [1.0, 0.0, 0.0],
            }),
            ..Ccfl::new("lamp", [0.0; 3], 1.0, 20.0)
        }
        .toml();
        let at = |k: &str| full.find(k).unwrap_or_else(|| panic!("{k} missing"));
        assert!(at("power_w") < at("lumens") && at("lumens") < at("array"));
        assert!(at("array") < at("body = "));
    }

    #[test]
    fn the_obj_names_its_mtl_and_the_mtl_lists_its_tags() {
        let parts = [guide_box("guide", [1.0, 1.0, 1.0])];
        let [obj, mtl] = obj_and_mtl("f", "g.obj", "head", &parts, MtlNote::DisplayOnly);
        assert_eq!(
            (obj.path.as_str(), mtl.path.as_str()),
            ("f/g.obj", "f/g.mtl")
        );
        let (obj, mtl) = (
            String::from_utf8(obj.bytes).unwrap(),
            String::from_utf8(mtl.bytes).unwrap(),
        );
        assert!(obj.starts_with("# head\nmtllib g.mtl\n"), "{obj}");
        assert!(mtl.starts_with("# head\n# Display colours only"), "{mtl}");
        for tag in LGP_TAGS {
            assert!(mtl.contains(&format!("newmtl {tag}\n")), "{tag}");
        }
    }
}
