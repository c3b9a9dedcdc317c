//! Generates every bundled blutrace scene (geometry and `scene.toml`) deterministically:
//! the same bytes on every run. Standard library only; OBJ, MTL, glTF JSON and its binary
//! buffer are written by hand.
//!
//! Coordinates are millimetres. Every backlight uses x = lamp-to-far-edge (the direction
//! light propagates in the light guide), y = along the lamps, z = thickness with the front
//! face (towards the viewer) at +z.
//!
//! All vertex coordinates are rounded to 1e-6 mm before they are written, so the text of
//! the files does not depend on the last bit of `sin`/`cos`.
//!
//! Each scene module (`scenes`) builds its files from shared pieces: [`shapes`] (solid
//! boxes, sheets, the lamp box behind an edge) and [`templates`] (the scene file's TOML
//! tables and the `.obj` + `.mtl` pair); this file holds the mesh type and the writers.

use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::io;
use std::path::Path;

pub mod scenes;
pub mod shapes;
pub mod templates;

/// A point (mm).
pub type P3 = [f64; 3];

/// One generated file: its path relative to the output folder and its bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GenFile {
    /// Path relative to the output folder, `/`-separated.
    pub path: String,
    /// File content.
    pub bytes: Vec<u8>,
}

impl GenFile {
    fn text(path: &str, text: String) -> Self {
        Self {
            path: path.to_string(),
            bytes: text.into_bytes(),
        }
    }
}

/// Every file of every bundled scene, in a fixed order.
pub fn all_files() -> Vec<GenFile> {
    let mut files = Vec::new();
    files.extend(scenes::notebook14::files());
    files.extend(scenes::notebook14_led::files());
    files.extend(scenes::notebook14_color::files());
    files.extend(scenes::wedge_ccfl::files());
    files.extend(scenes::edge_holder::files());
    files.extend(scenes::test_slab::files());
    files.extend(scenes::test_slab_edge_lit::files());
    files.extend(scenes::test_two_tags::files());
    files.extend(scenes::phone_led::files());
    files.extend(scenes::direct_lit::files());
    files.extend(scenes::direct_lit_rows::files());
    files.extend(scenes::cad_reflector::files());
    files.extend(scenes::prism_plate::files());
    files.extend(scenes::prism_plate::files_meshed());
    files.extend(scenes::bef_stack::files());
    files.extend(scenes::bef_stack_dbef::files());
    files.extend(scenes::diffusion_lgp::files());
    files.extend(scenes::bench_box::files());
    files
}

/// Write every bundled scene below `out`, creating folders as needed. Returns the files.
pub fn write_all(out: &Path) -> io::Result<Vec<GenFile>> {
    let files = all_files();
    for f in &files {
        let path = out.join(&f.path);
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(&path, &f.bytes)?;
    }
    Ok(files)
}

// ---------------------------------------------------------------------------------------
// Numbers

/// Round to 1e-6 (and turn -0 into 0), the precision every written coordinate has.
pub fn r6(x: f64) -> f64 {
    let y = (x * 1e6).round() / 1e6;
    if y == 0.0 { 0.0 } else { y }
}

/// A number rounded to 1e-6, without trailing zeros but with at least one decimal
/// (`290.0`, `-0.15`), valid in TOML, OBJ and JSON.
pub fn num(x: f64) -> String {
    let s = format!("{:.6}", r6(x));
    let s = s.trim_end_matches('0');
    if s.ends_with('.') {
        format!("{s}0")
    } else {
        s.to_string()
    }
}

/// A length for comments: [`num`] without a trailing `.0` (`290`, `-0.15`).
pub fn dim(x: f64) -> String {
    let s = num(x);
    s.strip_suffix(".0").map(str::to_string).unwrap_or(s)
}

/// `(a, b, c)` with [`dim`], for comments.
pub fn dims(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|&x| dim(x)).collect();
    format!("({})", items.join(", "))
}

/// `[a, b, c]` with [`num`].
pub fn arr(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|&x| num(x)).collect();
    format!("[{}]", items.join(", "))
}

// ---------------------------------------------------------------------------------------
// Meshes

/// A named piece of geometry: welded vertices and triangles grouped by tag.
#[derive(Clone, Debug, Default)]
pub struct Part {
    /// Object name (OBJ `o`, glTF mesh/node name).
    pub name: String,
    /// Vertices, rounded with [`r6`].
    pub verts: Vec<P3>,
    lookup: BTreeMap<[u64; 3], u32>,
    /// Triangles per tag, in order of first use.
    pub groups: Vec<(String, Vec<[u32; 3]>)>,
}

impl Part {
    /// An empty part.
    pub fn new(name: &str) -> Self {
        Self {
            name: name.to_string(),
            ..Default::default()
        }
    }

    fn vert(&mut self, p: P3) -> u32 {
        let p = p.map(r6);
        let key = p.map(f64::to_bits);
        let verts = &mut self.verts;
        *self.lookup.entry(key).or_insert_with(|| {
            verts.push(p);
            (verts.len() - 1) as u32
        })
    }

    fn group(&mut self, tag: &str) -> &mut Vec<[u32; 3]> {
        let i = match self.groups.iter().position(|(t, _)| t == tag) {
            Some(i) => i,
            None => {
                self.groups.push((tag.to_string(), Vec::new()));
                self.groups.len() - 1
            }
        };
        &mut self.groups[i].1
    }

    /// Add triangle `a b c` (counter-clockwise seen from the side its normal points to).
    pub fn tri(&mut self, tag: &str, a: P3, b: P3, c: P3) {
        let t = [self.vert(a), self.vert(b), self.vert(c)];
        assert!(
            t[0] != t[1] && t[1] != t[2] && t[0] != t[2],
            "{}: degenerate triangle {a:?} {b:?} {c:?}",
            self.name
        );
        self.group(tag).push(t);
    }

    /// Add planar quad `a b c d` as triangles `a b c` and `a c d`.
    pub fn quad(&mut self, tag: &str, a: P3, b: P3, c: P3, d: P3) {
        self.tri(tag, a, b, c);
        self.tri(tag, a, c, d);
    }

    /// Add every triangle of `other`, its points mapped by `f`; `flip` reverses the
    /// winding (for mirroring maps).
    pub fn append_mapped(&mut self, other: &Part, f: impl Fn(P3) -> P3, flip: bool) {
        for (tag, tris) in &other.groups {
            for t in tris {
                let [a, b, c] = t.map(|i| f(other.verts[i as usize]));
                if flip {
                    self.tri(tag, a, c, b);
                } else {
                    self.tri(tag, a, b, c);
                }
            }
        }
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.groups.iter().map(|(_, t)| t.len()).sum()
    }

    /// Corner points of every triangle of `tag`.
    pub fn triangles_of(&self, tag: &str) -> Vec<[P3; 3]> {
        self.groups
            .iter()
            .filter(|(t, _)| t == tag)
            .flat_map(|(_, tris)| tris.iter())
            .map(|t| t.map(|i| self.verts[i as usize]))
            .collect()
    }
}

/// Corners of a hexahedron indexed `[x][y][z]` (0 = low side, 1 = high side).
pub type Hexa = [[[P3; 2]; 2]; 2];

/// A closed six-sided solid with outward counter-clockwise winding: the `z = 1` face is
/// tagged `front`, the `z = 0` face `back`, the four others `edge`.
pub fn hexahedron(part: &mut Part, c: &Hexa, front: &str, back: &str, edge: &str) {
    part.quad(front, c[0][0][1], c[1][0][1], c[1][1][1], c[0][1][1]);
    part.quad(back, c[0][0][0], c[0][1][0], c[1][1][0], c[1][0][0]);
    part.quad(edge, c[0][0][0], c[0][0][1], c[0][1][1], c[0][1][0]);
    part.quad(edge, c[1][0][0], c[1][1][0], c[1][1][1], c[1][0][1]);
    part.quad(edge, c[0][0][0], c[1][0][0], c[1][0][1], c[0][0][1]);
    part.quad(edge, c[0][1][0], c[0][1][1], c[1][1][1], c[1][1][0]);
}

/// An axis-aligned box `lo..hi` as a [`Hexa`].
pub fn box_corners(lo: P3, hi: P3) -> Hexa {
    let p = |i: usize, j: usize, k: usize| {
        [
            if i == 0 { lo[0] } else { hi[0] },
            if j == 0 { lo[1] } else { hi[1] },
            if k == 0 { lo[2] } else { hi[2] },
        ]
    };
    [
        [[p(0, 0, 0), p(0, 0, 1)], [p(0, 1, 0), p(0, 1, 1)]],
        [[p(1, 0, 0), p(1, 0, 1)], [p(1, 1, 0), p(1, 1, 1)]],
    ]
}

/// A lamp holder on the light guide's `x = 0` edge (the guide lies at x >= 0), extruded
/// along y from `y0` to `y1`: a circular-arc reflector about `(xc, zc)` whose two lips
/// end at `x = -gap`, at `z_lo` and `z_hi`; a flat strip continuing the upper lip to the
/// guide's edge (`x = 0`, where it meets the front face's edge line); flat end caps at
/// `y0` and `y1` closing the arc and the air gap in front of it. The lower lip meets the
/// reflector sheet, which is at `z_lo` at `x = -gap` and at `z_lo_edge` at `x = 0`.
#[derive(Clone, Copy, Debug)]
pub struct LampHolder {
    /// Air gap between the reflector's lips and the guide's edge face.
    pub gap: f64,
    /// Lower lip height (on the reflector sheet).
    pub z_lo: f64,
    /// Reflector sheet height at the guide's edge.
    pub z_lo_edge: f64,
    /// Upper lip height (the guide's front face).
    pub z_hi: f64,
    /// Arc centre x (the arc's centre z is midway between the lips).
    pub xc: f64,
    /// Extent along the lamps.
    pub y0: f64,
    /// Extent along the lamps.
    pub y1: f64,
    /// Segments along the arc.
    pub segments: usize,
    /// Height of the guide's back edge at `x = 0`. When set, a wall at `x = 0` from the
    /// sheet up to it seals the air gap under the guide (as a lamp reflector taped to the
    /// guide's back does), so lamp light enters the guide only through its edge face.
    pub z_seal: Option<f64>,
}

impl LampHolder {
    /// Arc centre z: midway between the lips.
    pub fn zc(&self) -> f64 {
        0.5 * (self.z_lo + self.z_hi)
    }

    /// Arc radius.
    pub fn radius(&self) -> f64 {
        (-self.gap - self.xc).hypot(0.5 * (self.z_hi - self.z_lo))
    }

    /// The arc's points (x, z), counter-clockwise from the upper lip round the back to the
    /// lower lip; the end points are exactly the lips.
    pub fn arc(&self) -> Vec<[f64; 2]> {
        let (zc, r) = (self.zc(), self.radius());
        let top = (self.z_hi - zc).atan2(-self.gap - self.xc);
        let n = self.segments;
        (0..=n)
            .map(|i| {
                if i == 0 {
                    [-self.gap, self.z_hi]
                } else if i == n {
                    [-self.gap, self.z_lo]
                } else {
                    let t = top + (2.0 * PI - 2.0 * top) * i as f64 / n as f64;
                    [self.xc + r * t.cos(), zc + r * t.sin()]
                }
            })
            .collect()
    }

    /// The holder's triangles, reflective side towards the lamps, all tagged `tag`.
    pub fn part(&self, name: &str, tag: &str) -> Part {
        let mut p = Part::new(name);
        let (y0, y1) = (self.y0, self.y1);
        let arc = self.arc();
        let at = |q: [f64; 2], y: f64| [q[0], y, q[1]];
        // Arc sheet: normals towards the centre.
        for w in arc.windows(2) {
            p.quad(tag, at(w[0], y0), at(w[1], y0), at(w[1], y1), at(w[0], y1));
        }
        // Upper lip strip over the air gap, facing down.
        let (g, zh) = (self.gap, self.z_hi);
        p.quad(
            tag,
            [-g, y0, zh],
            [-g, y1, zh],
            [0.0, y1, zh],
            [0.0, y0, zh],
        );
        // Seal under the guide's edge, facing the lamps (-x).
        if let Some(zs) = self.z_seal {
            let ze = self.z_lo_edge;
            p.quad(
                tag,
                [0.0, y0, ze],
                [0.0, y0, zs],
                [0.0, y1, zs],
                [0.0, y1, ze],
            );
        }
        // End caps: a fan from the arc centre (the region is convex: a disc less a cap)
        // plus the air gap's quad; normals into the holder.
        let c = [self.xc, self.zc()];
        let gap_quad = [
            [-g, self.z_lo],
            [0.0, self.z_lo_edge],
            [0.0, self.z_hi],
            [-g, self.z_hi],
        ];
        for (y, inward_is_ccw) in [(y0, false), (y1, true)] {
            let mut fan = |a: [f64; 2], b: [f64; 2]| {
                if inward_is_ccw {
                    p.tri(tag, at(c, y), at(a, y), at(b, y));
                } else {
                    p.tri(tag, at(c, y), at(b, y), at(a, y));
                }
            };
            for w in arc.windows(2) {
                fan(w[0], w[1]);
            }
            fan(arc[arc.len() - 1], arc[0]);
            let q = gap_quad.map(|v| at(v, y));
            if inward_is_ccw {
                p.quad(tag, q[0], q[1], q[2], q[3]);
            } else {
                p.quad(tag, q[0], q[3], q[2], q[1]);
            }
        }
        p
    }
}

// ---------------------------------------------------------------------------------------
// Writers

/// How an OBJ file names its tags.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ObjTags<'a> {
    /// `usemtl TAG` before each group (with a `mtllib` line naming this file).
    Usemtl(&'a str),
    /// No materials: each part is one tag, named by an `o` line (even parts) or a `g`
    /// line (odd parts).
    ObjectNames,
}

/// Every line of `header` after `# ` (blank lines too, unlike [`comment`]).
fn hash_lines(header: &str) -> String {
    header.lines().map(|l| format!("# {l}\n")).collect()
}

/// An OBJ file of `parts`, each an `o` object; vertex indices are global and 1-based.
pub fn write_obj(header: &str, parts: &[Part], tags: ObjTags) -> String {
    let mut s = hash_lines(header);
    if let ObjTags::Usemtl(mtl) = tags {
        writeln!(s, "mtllib {mtl}").unwrap();
    }
    let mut base = 1;
    for (k, part) in parts.iter().enumerate() {
        match tags {
            ObjTags::Usemtl(_) => writeln!(s, "o {}", part.name).unwrap(),
            ObjTags::ObjectNames => {
                assert!(
                    part.groups.len() == 1 && part.groups[0].0 == part.name,
                    "a part named by `o`/`g` must hold one tag equal to its name"
                );
                let kw = if k % 2 == 0 { "o" } else { "g" };
                writeln!(s, "{kw} {}", part.name).unwrap();
            }
        }
        for v in &part.verts {
            writeln!(s, "v {} {} {}", num(v[0]), num(v[1]), num(v[2])).unwrap();
        }
        for (tag, tris) in &part.groups {
            if let ObjTags::Usemtl(_) = tags {
                writeln!(s, "usemtl {tag}").unwrap();
            }
            for t in tris {
                writeln!(s, "f {} {} {}", t[0] + base, t[1] + base, t[2] + base).unwrap();
            }
        }
        base += part.verts.len() as u32;
    }
    s
}

/// A display colour per tag for `.mtl` files and glTF materials (ignored by blutrace).
pub fn tag_colour(tag: &str) -> [f64; 3] {
    match tag {
        "lgp_front" => [0.6, 0.8, 1.0],
        "lgp_back" => [0.4, 0.6, 0.9],
        "lgp_edge" => [0.5, 0.7, 0.95],
        "lamp_reflector" => [0.85, 0.85, 0.8],
        "reflector_sheet" => [0.95, 0.95, 0.95],
        "absorber" => [0.05, 0.05, 0.05],
        "mirror" => [0.8, 0.8, 0.85],
        _ => [0.7, 0.7, 0.7],
    }
}

/// A `.mtl` file with one display material per tag.
pub fn write_mtl(header: &str, tags: &[&str]) -> String {
    let mut s = hash_lines(header);
    for tag in tags {
        let rgb = tag_colour(tag).map(num).join(" ");
        writeln!(s, "\nnewmtl {tag}\nKd {rgb}").unwrap();
        if tag.starts_with("lgp") {
            writeln!(s, "d 0.4").unwrap();
        }
    }
    s
}

/// Tags of `parts` in order of first use.
pub fn tags_of(parts: &[Part]) -> Vec<&str> {
    let mut tags: Vec<&str> = Vec::new();
    for p in parts {
        for (t, _) in &p.groups {
            if !tags.contains(&t.as_str()) {
                tags.push(t);
            }
        }
    }
    tags
}

/// Number of triangles of all `parts`.
pub fn triangle_count(parts: &[Part]) -> usize {
    parts.iter().map(Part::triangle_count).sum()
}

/// World millimetres, z up, to glTF's metres, y up.
fn gltf_frame(p: P3) -> P3 {
    [p[0] / 1000.0, p[2] / 1000.0, -p[1] / 1000.0]
}

/// A glTF 2.0 file (`.gltf` JSON plus a separate `.bin` buffer named `bin_name`): one
/// root node named `root` with translation `translation`, one child node and mesh per
/// part, one primitive per tag (all primitives of a mesh share its POSITION accessor),
/// one material per tag. Part vertices are in world coordinates (millimetres, z up); the
/// file stores them as the glTF specification says, in metres with +y up (world (x, y, z)
/// is glTF (x, z, -y), as Blender exports), relative to the root node, so the node
/// transform must be applied to read them back.
pub fn write_gltf(
    scene_name: &str,
    root: &str,
    translation: P3,
    parts: &[Part],
    bin_name: &str,
) -> (String, Vec<u8>) {
    let tags = tags_of(parts);
    let mut bin: Vec<u8> = Vec::new();
    let mut views: Vec<String> = Vec::new();
    let mut accessors: Vec<String> = Vec::new();
    let mut meshes: Vec<String> = Vec::new();
    for part in parts {
        let local: Vec<[f32; 3]> = part
            .verts
            .iter()
            .map(|v| gltf_frame([0, 1, 2].map(|k| r6(v[k] - translation[k]))).map(|c| c as f32))
            .collect();
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        let offset = bin.len();
        for v in &local {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
                bin.extend_from_slice(&v[k].to_le_bytes());
            }
        }
        let f32s = |a: [f32; 3]| format!("[{}, {}, {}]", a[0], a[1], a[2]);
        views.push(format!(
            "{{\"buffer\": 0, \"byteOffset\": {offset}, \"byteLength\": {}, \"target\": 34962}}",
            bin.len() - offset
        ));
        let pos_accessor = accessors.len();
        accessors.push(format!(
            "{{\"bufferView\": {}, \"componentType\": 5126, \"count\": {}, \"type\": \"VEC3\", \"min\": {}, \"max\": {}}}",
            views.len() - 1,
            local.len(),
            f32s(lo),
            f32s(hi)
        ));
        let mut prims = Vec::new();
        for (tag, tris) in &part.groups {
            let offset = bin.len();
            for t in tris {
                for i in t {
                    bin.extend_from_slice(&i.to_le_bytes());
                }
            }
            views.push(format!(
                "{{\"buffer\": 0, \"byteOffset\": {offset}, \"byteLength\": {}, \"target\": 34963}}",
                bin.len() - offset
            ));
            accessors.push(format!(
                "{{\"bufferView\": {}, \"componentType\": 5125, \"count\": {}, \"type\": \"SCALAR\"}}",
                views.len() - 1,
                3 * tris.len()
            ));
            let material = tags.iter().position(|t| t == tag).expect("tag listed");
            prims.push(format!(
                "{{\"attributes\": {{\"POSITION\": {pos_accessor}}}, \"indices\": {}, \"material\": {material}, \"mode\": 4}}",
                accessors.len() - 1
            ));
        }
        meshes.push(format!(
            "{{\"name\": \"{}\", \"primitives\": [\n        {}\n      ]}}",
            part.name,
            prims.join(",\n        ")
        ));
    }
    let materials: Vec<String> = tags
        .iter()
        .map(|t| {
            let rgb = tag_colour(t).map(num).join(", ");
            let opaque = !t.starts_with("lgp");
            format!(
                "{{\"name\": \"{t}\", \"doubleSided\": {opaque}, \"pbrMetallicRoughness\": {{\"baseColorFactor\": [{rgb}, 1.0], \"metallicFactor\": 0.0}}}}"
            )
        })
        .collect();
    let children: Vec<String> = (1..=parts.len()).map(|i| i.to_string()).collect();
    let mut nodes = vec![format!(
        "{{\"name\": \"{root}\", \"translation\": {}, \"children\": [{}]}}",
        arr(&gltf_frame(translation)),
        children.join(", ")
    )];
    for (i, part) in parts.iter().enumerate() {
        nodes.push(format!("{{\"name\": \"{}\", \"mesh\": {i}}}", part.name));
    }
    let list = |v: &[String]| format!("[\n    {}\n  ]", v.join(",\n    "));
    let json = format!(
        "{{\n  \"asset\": {{\"version\": \"2.0\", \"generator\": \"blutrace scenegen\"}},\n  \"scene\": 0,\n  \"scenes\": [{{\"name\": \"{scene_name}\", \"nodes\": [0]}}],\n  \"nodes\": {},\n  \"meshes\": {},\n  \"materials\": {},\n  \"accessors\": {},\n  \"bufferViews\": {},\n  \"buffers\": [{{\"uri\": \"{bin_name}\", \"byteLength\": {}}}]\n}}\n",
        list(&nodes),
        list(&meshes),
        list(&materials),
        list(&accessors),
        list(&views),
        bin.len()
    );
    (json, bin)
}

/// `# `-prefix every line of `text` (blank lines become `#`).
pub fn comment(text: &str) -> String {
    text.lines()
        .map(|l| {
            if l.is_empty() {
                "#\n".to_string()
            } else {
                format!("# {l}\n")
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_rounded_and_keep_a_decimal() {
        assert_eq!(num(290.0), "290.0");
        assert_eq!(num(-0.15), "-0.15");
        assert_eq!(num(-1e-9), "0.0");
        assert_eq!(num(2.0 / 3.0), "0.666667");
        assert_eq!(arr(&[1.0, 0.5, -2.25]), "[1.0, 0.5, -2.25]");
    }

    fn signed_volume(part: &Part) -> f64 {
        part.groups
            .iter()
            .flat_map(|(_, t)| t)
            .map(|t| {
                let [a, b, c] = t.map(|i| part.verts[i as usize]);
                let cross = [
                    b[1] * c[2] - b[2] * c[1],
                    b[2] * c[0] - b[0] * c[2],
                    b[0] * c[1] - b[1] * c[0],
                ];
                (a[0] * cross[0] + a[1] * cross[1] + a[2] * cross[2]) / 6.0
            })
            .sum()
    }

    #[test]
    fn hexahedron_winds_outward() {
        let mut p = Part::new("box");
        hexahedron(
            &mut p,
            &box_corners([1.0, 2.0, 3.0], [4.0, 6.0, 8.0]),
            "f",
            "b",
            "e",
        );
        assert_eq!(p.triangle_count(), 12);
        assert_eq!(p.verts.len(), 8);
        assert!((signed_volume(&p) - 60.0).abs() < 1e-9);
    }

    #[test]
    fn lamp_holder_arc_ends_on_the_lips() {
        let h = LampHolder {
            gap: 0.3,
            z_lo: -0.15,
            z_lo_edge: -0.15,
            z_seal: None,
            z_hi: 3.0,
            xc: -2.35,
            y0: 0.0,
            y1: 10.0,
            segments: 64,
        };
        let arc = h.arc();
        assert_eq!(arc.len(), 65);
        let r = h.radius();
        for q in &arc {
            let d = (q[0] - h.xc).hypot(q[1] - h.zc());
            assert!((d - r).abs() < 1e-9, "{q:?}");
            assert!(
                q[0] <= -h.gap + 1e-12,
                "the arc stays behind its lips: {q:?}"
            );
        }
        let p = h.part("holder", "lamp_reflector");
        assert_eq!(p.triangle_count(), 64 * 2 + 2 + 2 * (65 + 2));
    }
}
