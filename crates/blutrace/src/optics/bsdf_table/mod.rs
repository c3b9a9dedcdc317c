//! Measured BSDF tables: a face that scatters as an IS BSDF file (Zemax/Radiant BSDF Data
//! Interchange format, [`mod@format`]) says, as scatterometers measure films, sheets and inks
//! and `blutrace bsdf` characterises a part of a scene.
//!
//! ```toml
//! [surfaces.diffuser_film]
//! model = "bsdf_table"
//! file = "film.bsdf"       # or a list: file = ["film_r.bsdf", "film_t.bsdf"]
//! back_file = "film_back.bsdf" # optional: measured with light arriving on the back
//! inside = "air"           # with a BTDF: the medium behind the face (as dielectric's)
//! outside = "air"          # default "air"
//! u_axis = [1.0, 0.0, 0.0] # optional: the direction of sample rotation 0 on the face
//! tristimulus = "Y"        # XYZ files: the channel to trace (X, Y or Z)
//! ```
//!
//! The files hold at most one BRDF and one BTDF section. A photon arriving at the
//! angle of incidence `theta` (to the face's normal on its side) is reflected back into
//! its medium with probability
//! `TIS_R(theta)`, transmitted into the medium on the other side with probability
//! `TIS_T(theta)` (a table with a BTDF is an interface and needs `inside`), else absorbed
//! (analog roulette, or the weight `TIS_R + TIS_T` when absorption is weighted). The
//! direction is drawn from the table ([`sample`]): exactly the BSDF times the cosine, as
//! the cells give it; the TIS gives the power (the table's values, as other tracers read
//! them, set the shape only).
//!
//! Between the table's angles of incidence the BSDF is interpolated linearly at each
//! outgoing direction (one of the two neighbouring blocks is drawn with the weight of its
//! share, and scatters as at its own AOI); outside them the nearest block is used. A
//! sharp (glossy) peak therefore does not move between two AOIs but fades from one
//! node's place to the next: such tables need a fine AOI grid. Sample rotations (the orientation of the plane of incidence on
//! the face, measured from `u_axis` towards `normal x u_axis`) take the nearest block;
//! `u_axis` defaults to the world x axis projected onto the face (the y axis where the
//! face's normal is within 26 degrees of x).
//!
//! Monochrome and XYZ (tristimulus) files. An XYZ file holds the BSDF weighted by x̄, ȳ
//! and z̄; `tristimulus` picks the one to trace at every wavelength (as OpticStudio's
//! table model does): `"Y"` is the photopic table, what a luminance meter sees. A stand-in
//! for a spectral BSDF: three weighted means cannot give the table at each wavelength,
//! so a film's colour (a yellowish sheet's lower Z) is not traced; trace the channels in
//! turn to see how much it matters.
//!
//! The two sides: `file` holds the tables measured with light arriving on the front (the
//! side the triangles' normals point to, `outside`), `back_file` those measured with light
//! arriving on the back (`inside`), as a scatterometer measures a film turned over about
//! `u_axis`: sample rotations on the back are read from `u_axis` the same way, seen from
//! the back. Without `back_file` the part is taken as the same seen from both sides, which
//! a prism film or a film coated on one side is not. The two sides' tables are checked
//! each on its own: the TIS sums at most 1 wherever a photon reads them (at every sample
//! rotation and AOI, the BRDF and the BTDF on different grids too); nothing ties the
//! sides together (reciprocity between a front BTDF and a back BTDF is the measurement's
//! business). A block whose values lie (almost) all below the surface is refused.
//!
//! What a table leaves out: where the light leaves (a part's lateral spread: light
//! enters and leaves at one point), polarisation and coherence.

pub mod format;
pub mod sample;

use super::medium::{Interface, Medium, air};
use super::model::{Arrival, Face, Feature, Outcome, Surface, SurfaceSpecOf};
use crate::rng::PhotonRng;
use crate::spec_check::{Ctx, short};
use anyhow::{Result, bail};
use format::{Channel, ScatterType, Section};
use glam::DVec3;
use sample::{BlockSampler, Frame, Grid, Incidence};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The largest |cos| between `u_axis` and a face's normal: an axis closer to the normal
/// (within 2.6 degrees) leaves sample rotation 0 to rounding.
pub const MAX_U_AXIS_COS: f64 = 0.999;

/// One file or several.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(untagged)]
pub enum Files {
    /// One file.
    One(PathBuf),
    /// Several files (e.g. a BRDF and a BTDF file).
    Many(Vec<PathBuf>),
}

impl Files {
    fn list(&self) -> Vec<PathBuf> {
        match self {
            Files::One(f) => vec![f.clone()],
            Files::Many(v) => v.clone(),
        }
    }
}

/// `[surfaces.TAG]` with `model = "bsdf_table"`.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BsdfTableSpec {
    /// The IS BSDF file(s), relative to the scene file: light arriving on the front.
    pub file: Files,
    /// The file(s) measured with light arriving on the back (`None`: as the front).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub back_file: Option<Files>,
    /// Medium behind the face (needed with a BTDF).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inside: Option<String>,
    /// Medium in front of the face.
    #[serde(default = "air")]
    pub outside: String,
    /// The direction of sample rotation 0 on the face.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub u_axis: Option<[f64; 3]>,
    /// XYZ files: the tristimulus channel to trace, "X", "Y" or "Z" (read as text and
    /// checked in `build`, so an error names `surfaces.TAG.tristimulus`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tristimulus: Option<String>,
}

/// One scatter type's table, ready to sample.
#[derive(Debug, PartialEq)]
pub struct Table {
    /// BRDF or BTDF.
    pub kind: ScatterType,
    /// Sample rotations (radians).
    rotations: Vec<f64>,
    /// Angles of incidence (radians).
    aoi: Vec<f64>,
    /// The cells.
    grid: Grid,
    /// Rotation-major blocks (`None`: TIS 0 and no values above the surface).
    blocks: Vec<Option<BlockSampler>>,
}

impl Table {
    /// Build the table of `sec`, read from `file` (named in errors).
    pub fn new(sec: &Section, file: &Path) -> Result<Table> {
        let grid = Grid::new(&sec.radial, &sec.azimuth, sec.plane_symmetric);
        let aoi: Vec<f64> = sec.aoi.iter().map(|a| a.to_radians()).collect();
        let mut blocks = Vec::with_capacity(sec.blocks.len());
        for (k, b) in sec.blocks.iter().enumerate() {
            let s = BlockSampler::new(&grid, aoi[k % aoi.len()], b.tis, &b.values);
            let here = || {
                format!(
                    "{}: line {}: TIS {} of the {} block at AOI {} deg, rotation {} deg",
                    file.display(),
                    b.line,
                    b.tis,
                    sec.scatter.keyword(),
                    sec.aoi[k % aoi.len()],
                    sec.rotations[k / aoi.len()]
                )
            };
            match &s {
                None if b.tis > 0.0 => {
                    bail!("{}, but no value of it lies above the surface", here())
                }
                Some(s) if b.tis > 0.0 && s.kept < sample::MIN_KEPT => bail!(
                    "{}, but its values lie (almost) all below the surface: {:.2} % of the directions drawn from them lie above it, less than the {} % a table must give",
                    here(),
                    100.0 * s.kept,
                    100.0 * sample::MIN_KEPT
                ),
                _ => {}
            }
            blocks.push(s);
        }
        Ok(Table {
            kind: sec.scatter,
            rotations: sec.rotations.iter().map(|a| a.to_radians()).collect(),
            aoi,
            grid,
            blocks,
        })
    }

    /// The nearest sample rotation's index to `rot` (radians, periodic; a tie takes the
    /// lower index): one of the two nodes about it, the rotations being increasing.
    fn rotation(&self, rot: f64) -> usize {
        let n = self.rotations.len();
        let rot = rot.rem_euclid(TAU);
        let dist = |i: usize| {
            let d = (self.rotations[i] - rot).rem_euclid(TAU);
            d.min(TAU - d)
        };
        let k = self.rotations.partition_point(|&r| r < rot);
        let (a, b) = ((k + n - 1) % n, k % n);
        match dist(a).total_cmp(&dist(b)) {
            std::cmp::Ordering::Less => a,
            std::cmp::Ordering::Greater => b,
            std::cmp::Ordering::Equal => a.min(b),
        }
    }

    /// The largest TIS over the angles of incidence of each sample rotation.
    fn max_tis(&self) -> Vec<f64> {
        let n = self.aoi.len();
        (0..self.rotations.len())
            .map(|ri| (0..n).map(|k| self.tis_of(ri * n + k)).fold(0.0, f64::max))
            .collect()
    }

    /// The two blocks about `theta` in rotation `ri` and the weight of the second.
    fn bracket(&self, ri: usize, theta: f64) -> (usize, usize, f64) {
        let n = self.aoi.len();
        let base = ri * n;
        let k = self.aoi.partition_point(|&a| a <= theta);
        if k == 0 {
            (base, base, 0.0)
        } else if k == n {
            (base + n - 1, base + n - 1, 0.0)
        } else {
            let t = (theta - self.aoi[k - 1]) / (self.aoi[k] - self.aoi[k - 1]);
            (base + k - 1, base + k, t)
        }
    }

    fn tis_of(&self, k: usize) -> f64 {
        self.blocks[k].as_ref().map_or(0.0, |b| b.tis)
    }

    /// The TIS at sample rotation `rot` and angle of incidence `theta` (radians).
    pub fn tis(&self, rot: f64, theta: f64) -> f64 {
        let (a, b, t) = self.bracket(self.rotation(rot), theta);
        (1.0 - t) * self.tis_of(a) + t * self.tis_of(b)
    }

    /// A scattered direction for a photon meeting the face as `inc` says (`None`: the
    /// table holds no scatter there): one of the two blocks about its AOI, drawn in
    /// proportion to its share of the interpolated TIS, sampled in the frame of that
    /// block's own AOI, so that the BSDF at each outgoing direction is interpolated
    /// linearly in the angle of incidence.
    pub fn sample(&self, inc: &Incidence, rng: &mut PhotonRng) -> Option<DVec3> {
        let (a, b, t) = self.bracket(self.rotation(inc.rotation), inc.theta);
        let (ta, tb) = ((1.0 - t) * self.tis_of(a), t * self.tis_of(b));
        let k = if rng.uniform() * (ta + tb) < tb { b } else { a };
        let own = self.aoi[k % self.aoi.len()];
        let frame = Frame::new(self.kind, &inc.at_angle(own));
        self.blocks[k].as_ref()?.sample(&self.grid, &frame, rng)
    }
}

/// The tables of light arriving on one side of a face.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Side {
    /// The reflection table.
    pub brdf: Option<Arc<Table>>,
    /// The transmission table.
    pub btdf: Option<Arc<Table>>,
}

impl Side {
    /// The TIS of reflection and transmission for a photon of `inc`.
    fn tis(&self, inc: &Incidence) -> (f64, f64) {
        let of =
            |t: &Option<Arc<Table>>| t.as_ref().map_or(0.0, |t| t.tis(inc.rotation, inc.theta));
        (of(&self.brdf), of(&self.btdf))
    }
}

/// A face that scatters as measured tables say.
#[derive(Clone, Debug, PartialEq)]
pub struct BsdfTable {
    /// Light arriving on the front (the side the normals point to).
    pub front: Side,
    /// Light arriving on the back (`None`: as on the front).
    pub back: Option<Side>,
    /// The two media (with a BTDF; `None`: opaque).
    pub interface: Option<Interface>,
    /// The direction of sample rotation 0 (`None`: world x, or y on faces facing x).
    pub u_axis: Option<DVec3>,
}

impl BsdfTable {
    /// The unit tangent of sample rotation 0 on a face of unit normal `n`.
    fn u_on(&self, n: DVec3) -> DVec3 {
        let u = self
            .u_axis
            .unwrap_or(if n.x.abs() > 0.9 { DVec3::Y } else { DVec3::X });
        (u - u.dot(n) * n).normalize()
    }
}

impl Surface for BsdfTable {
    fn interact(&self, at: &Arrival, rng: &mut PhotonRng) -> (Outcome, Feature) {
        let n = at.facing();
        let inc = sample::incidence(at.dir, n, self.u_on(n));
        let on_front = at.dir.dot(at.hit.normal) < 0.0;
        let side = match &self.back {
            Some(back) if !on_front => back,
            _ => &self.front,
        };
        let (r, t) = side.tis(&inc);
        let Some(weight) = at.est.survive(r + t, rng) else {
            return (Outcome::Absorbed, Feature::Plain);
        };
        let reflect = rng.uniform() * (r + t) < r;
        let (table, medium) = match (reflect, self.interface) {
            (true, _) => (&side.brdf, at.medium),
            (false, Some(i)) => (&side.btdf, if on_front { i.inside } else { i.outside }),
            (false, None) => return (Outcome::Absorbed, Feature::Plain),
        };
        let dir = table.as_ref().and_then(|tab| tab.sample(&inc, rng));
        let out = match dir {
            Some(dir) => Outcome::Scattered {
                dir,
                medium,
                weight,
            },
            None => Outcome::Absorbed,
        };
        (out, Feature::Plain)
    }

    fn interface(&self) -> Option<Interface> {
        self.interface
    }

    fn fit_to_face(&mut self, ctx: &Ctx, at: &str, face: &Face) -> Result<()> {
        let Some(u) = self.u_axis else {
            return Ok(());
        };
        if face.normals().any(|n| n.dot(u).abs() > MAX_U_AXIS_COS) {
            return Err(ctx.err(
                &format!("{at}.u_axis"),
                "is (nearly) along a normal of the face: it must lie in the face",
            ));
        }
        Ok(())
    }
}

impl SurfaceSpecOf for BsdfTableSpec {
    type Model = BsdfTable;

    fn build(&self, ctx: &Ctx, at: &str, media: &[Medium]) -> Result<BsdfTable> {
        let channel = tristimulus(ctx, at, self.tristimulus.as_deref())?;
        let read = |key: &str, files: &Files| {
            let field = format!("{at}.{key}");
            read_side(ctx, (&field, at), &files.list(), channel)
        };
        let (front, front_btdf) = read("file", &self.file)?;
        let back = self
            .back_file
            .as_ref()
            .map(|f| read("back_file", f))
            .transpose()?;
        let btdf = front_btdf.or_else(|| back.as_ref().and_then(|b| b.1.clone()));
        let interface = match (&self.inside, &btdf) {
            (Some(inside), _) => Some(Interface::build(ctx, at, inside, &self.outside, media)?),
            (None, Some(p)) => {
                return Err(ctx.err(
                    &format!("{at}.inside"),
                    format!(
                        "{} has a BTDF: light crosses the face, so give the medium behind it (inside = \"...\")",
                        p.display()
                    ),
                ));
            }
            (None, None) => None,
        };
        let u_axis = self
            .u_axis
            .map(|u| ctx.direction(&format!("{at}.u_axis"), u))
            .transpose()?;
        Ok(BsdfTable {
            front,
            back: back.map(|b| b.0),
            interface,
            u_axis,
        })
    }

    fn files(&self) -> Vec<PathBuf> {
        let back = self.back_file.as_ref().map(Files::list);
        self.file
            .list()
            .into_iter()
            .chain(back.into_iter().flatten())
            .collect()
    }
}

/// A table and the file it came from.
type Loaded = Option<(PathBuf, Arc<Table>)>;

/// Read one side's `files` (relative to the scene file; `field` names them in errors, `at`
/// the surface) and check its TIS sums: its tables, and the file of its BTDF if any.
fn read_side(
    ctx: &Ctx,
    (field, at): (&str, &str),
    files: &[PathBuf],
    channel: Option<Channel>,
) -> Result<(Side, Option<PathBuf>)> {
    if files.is_empty() {
        return Err(ctx.err(field, "names no file"));
    }
    let dir = ctx.0.parent().unwrap_or(Path::new("."));
    let (brdf, btdf) = read_tables(ctx, (field, at), dir, files, channel)?;
    check_sum(ctx, field, brdf.as_ref(), btdf.as_ref())?;
    let btdf_file = btdf.as_ref().map(|b| b.0.clone());
    let side = Side {
        brdf: brdf.map(|b| b.1),
        btdf: btdf.map(|b| b.1),
    };
    Ok((side, btdf_file))
}

/// Read `files` (relative to `dir`; `field` names them in errors, `at` the surface): the
/// BRDF and the BTDF, of channel `channel` in XYZ files.
fn read_tables(
    ctx: &Ctx,
    (field, at): (&str, &str),
    dir: &Path,
    files: &[PathBuf],
    channel: Option<Channel>,
) -> Result<(Loaded, Loaded)> {
    let (mut brdf, mut btdf): (Loaded, Loaded) = (None, None);
    for f in files {
        let path = dir.join(f);
        let in_field = |e: anyhow::Error| ctx.err(field, format!("{e:#}"));
        let text = crate::input_file::read_text(&path, "BSDF table").map_err(in_field)?;
        for sec in format::parse(&text, &path).map_err(in_field)? {
            if !traced_channel(ctx, at, &path, sec.channel, channel)? {
                continue;
            }
            let slot = match sec.scatter {
                ScatterType::Brdf => &mut brdf,
                ScatterType::Btdf => &mut btdf,
            };
            if let Some((first, _)) = slot {
                return Err(ctx.err(
                    field,
                    format!(
                        "{} holds a second {} section (the first is in {}): give one of each at most",
                        path.display(),
                        sec.scatter.keyword(),
                        first.display()
                    ),
                ));
            }
            let table = Table::new(&sec, &path).map_err(in_field)?;
            *slot = Some((path.clone(), Arc::new(table)));
        }
    }
    Ok((brdf, btdf))
}

/// The channel `tristimulus = name` of the surface at `at` names.
fn tristimulus(ctx: &Ctx, at: &str, name: Option<&str>) -> Result<Option<Channel>> {
    let Some(name) = name else {
        return Ok(None);
    };
    match name {
        "X" => Ok(Some(Channel::X)),
        "Y" => Ok(Some(Channel::Y)),
        "Z" => Ok(Some(Channel::Z)),
        other => Err(ctx.err(
            &format!("{at}.tristimulus"),
            format!("unknown channel '{other}': expected \"X\", \"Y\" (photopic) or \"Z\""),
        )),
    }
}

/// Whether a section of `path` holding `found` (`None`: Monochrome) is traced when the
/// scene asks for `wanted`; an error when the two do not go together.
fn traced_channel(
    ctx: &Ctx,
    at: &str,
    path: &Path,
    found: Option<Channel>,
    wanted: Option<Channel>,
) -> Result<bool> {
    match (found, wanted) {
        (None, None) => Ok(true),
        (Some(f), Some(w)) => Ok(f == w),
        (Some(_), None) => Err(ctx.err(
            &format!("{at}.tristimulus"),
            format!(
                "{} holds XYZ (tristimulus) tables: say which to trace, tristimulus = \"X\", \"Y\" (photopic) or \"Z\"",
                path.display()
            ),
        )),
        (None, Some(_)) => Err(ctx.err(
            &format!("{at}.tristimulus"),
            format!(
                "is for XYZ files, and {} is Monochrome",
                path.display()
            ),
        )),
    }
}

/// The reflected and transmitted TIS may not add up to more than 1 where a photon reads
/// them: at any sample rotation (each table takes its nearest node, so the pair of nodes
/// read changes at either table's half-way rotations) and any angle of incidence (each
/// interpolates linearly between its nodes, so the sum is largest at a node of either).
fn check_sum(
    ctx: &Ctx,
    field: &str,
    brdf: Option<&(PathBuf, Arc<Table>)>,
    btdf: Option<&(PathBuf, Arc<Table>)>,
) -> Result<()> {
    let (Some((pr, r)), Some((pt, t))) = (brdf, btdf) else {
        return Ok(());
    };
    let (max_r, max_t) = (r.max_tis(), t.max_tis());
    let mut aois: Vec<f64> = r.aoi.iter().chain(&t.aoi).copied().collect();
    aois.sort_by(f64::total_cmp);
    aois.dedup();
    for rot in rotation_probes(r, t) {
        let (ri, ti) = (r.rotation(rot), t.rotation(rot));
        if max_r[ri] + max_t[ti] <= 1.0 + TIS_SUM_TOLERANCE {
            continue;
        }
        for &aoi in &aois {
            let (a, b) = (r.tis(rot, aoi), t.tis(rot, aoi));
            if a + b > 1.0 + TIS_SUM_TOLERANCE {
                return Err(ctx.err(
                    field,
                    format!(
                        "at AOI {} deg, sample rotation {} deg the BRDF's TIS {a} ({}, its rotation {} deg) and the BTDF's {b} ({}, its rotation {} deg) add up to {}, more than 1",
                        short(aoi.to_degrees()),
                        short(rot.to_degrees()),
                        pr.display(),
                        short(r.rotations[ri].to_degrees()),
                        pt.display(),
                        short(t.rotations[ti].to_degrees()),
                        short(a + b)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// How far above 1 the reflected and transmitted TIS may add up (rounding in the files).
const TIS_SUM_TOLERANCE: f64 = 1e-9;

/// Sample rotations (radians) that meet every pair of nodes two tables read together:
/// both tables' nodes and the rotations where either's nearest node changes (half-way
/// between its nodes), and the middle of each interval between these (the pair is the
/// same across an interval).
fn rotation_probes(a: &Table, b: &Table) -> Vec<f64> {
    let mut edges: Vec<f64> = a
        .rotations
        .iter()
        .chain(&b.rotations)
        .copied()
        .chain(half_way_round(&a.rotations))
        .chain(half_way_round(&b.rotations))
        .collect();
    edges.sort_by(f64::total_cmp);
    edges.dedup();
    let middles: Vec<f64> = half_way_round(&edges).collect();
    edges.extend(middles);
    edges.sort_by(f64::total_cmp);
    edges
}

/// The angles half-way between neighbours of the increasing angles `v` (radians, in
/// [0, 2 pi)), round the circle: the last one's is half-way to the first plus 2 pi.
fn half_way_round(v: &[f64]) -> impl Iterator<Item = f64> + '_ {
    let n = v.len();
    (0..n).map(move |i| {
        let next = if i + 1 < n { v[i + 1] } else { v[0] + TAU };
        (0.5 * (v[i] + next)).rem_euclid(TAU)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A table of no scatter on `rotations` (degrees), for its rotation lookup.
    fn on_rotations(rotations: &[f64]) -> Table {
        Table {
            kind: ScatterType::Brdf,
            rotations: rotations.iter().map(|r| r.to_radians()).collect(),
            aoi: vec![0.0],
            grid: Grid::new(&[0.0], &[0.0], false),
            blocks: vec![None; rotations.len()],
        }
    }

    #[test]
    fn the_nearest_rotation_is_the_nearest_of_all_round_the_circle() {
        for rotations in [
            &[0.0][..],
            &[10.0, 100.0, 350.0],
            &[0.0, 90.0, 180.0, 270.0],
            &[5.0, 6.0, 7.0, 200.0],
        ] {
            let t = on_rotations(rotations);
            let dist = |i: usize, rot: f64| {
                let d = (t.rotations[i] - rot).rem_euclid(TAU);
                d.min(TAU - d)
            };
            for step in 0..7200 {
                let rot = (step as f64 * 0.05).to_radians();
                let all = (0..rotations.len())
                    .min_by(|&a, &b| dist(a, rot).total_cmp(&dist(b, rot)))
                    .unwrap();
                assert_eq!(t.rotation(rot), all, "{rotations:?} at {rot}");
                let wrapped = t.rotation(rot - TAU);
                assert!(
                    dist(wrapped, rot) <= dist(all, rot) + 1e-12,
                    "{rotations:?} at {rot} - 2 pi"
                );
            }
        }
    }
}
