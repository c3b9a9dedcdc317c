//! IES TM-25-13 binary ray files (`.TM25RAY`): reader and writer.
//!
//! ```toml
//! [[sources]]
//! type = "rayfile"
//! file = "led.TM25RAY"   # read here; every error names the byte offset and the field
//! ```
//!
//! The layout (little-endian; section numbers of TM-25-13 §4.7, as the public domain
//! reference implementation JuliusMuschaweck/TM25RaySetTools names its fields):
//!
//! | offset | bytes | field |
//! |---|---|---|
//! | 0 | 4 | file type `TM25` (4.7.1.1) |
//! | 4 | i32 | version, 2013 (4.7.1.2) |
//! | 8 | i32 | creation method (4.7.1.3, ignored) |
//! | 12, 16 | f32 | total luminous (lm) and radiant (W) flux (4.7.1.4-5, reported) |
//! | 20 | u64 | number of rays (4.7.1.6) |
//! | 28 | 28 | creation date and time, ASCII (4.7.1.7, ignored) |
//! | 56 | i32 | ray start position (4.7.1.8, ignored) |
//! | 60 | i32 | spectral data identifier (4.7.1.9): 0 none, 1 one wavelength, 2 a wavelength per ray, 3 one spectral table, 4 spectral tables chosen per ray by index; all read |
//! | 64, 68, 72 | f32 | single, minimum, maximum wavelength, nm (4.7.1.10-12) |
//! | 76, 80, 84 | i32 | spectral tables (4.7.1.13: 1 for identifier 3, 1 to 65536 for 4), additional ray items, additional text bytes |
//! | 88 | 168 | reserved |
//! | 256 | 8 x i32 | known data flags (4.7.2): position, direction, radiant flux, wavelength, luminous flux, Stokes, tristimulus, spectrum index |
//! | 288 | 9 x 4000 | nine UTF-32 text fields of 1000 code points, NUL-padded (4.7.3) |
//! | 36288 | | spectral tables (4.7.4), numbered 1, 2, ... in file order: each an i32 count, then (f32 nm, f32 value) pairs; the block is zero-padded to a multiple of 32 bytes |
//! | | 512 each | names of the additional ray items, UTF-32 (4.7.5) |
//! | | | additional text, UTF-32 (4.7.6) |
//! | | | ray records: f32 columns x y z kx ky kz, then radiant flux, wavelength, luminous flux, Stokes S1 S2 S3 and the polarisation ellipse's x y z, tristimulus X Z, spectrum index (a whole number 1..tables, as f32), additional items, each only when its flag is set; the Stokes columns as [`super::stokes`] reads them |
//!
//! Spectral tables per ray (identifier 4), as the reference implementation reads them
//! (TM25RaySetTools `TM25Library/TM25_impl.h`, `ReadHeader`, and `TM25.h`): the tables
//! carry no number of their own in the file, the reader numbers them from 1 in file order
//! (`st.idx_ = i` for `i = 1..=M`; `TSpectralTable::idx_` is commented "base 1, not 0,
//! see 4.7.4", and its sanity check demands `idx_ >= 1`); every ray item, the spectrum
//! index included, is a binary32 float (the ray array is `float`; LarryBoxler's
//! IESTM25RayFiles reads every item with `ReadSingle`). So a ray's index k names the k-th
//! table, 1-based, stored as an f32 holding a whole number. The reference does not check
//! the index; the text of the standard (paywalled) was not seen. Identifier 4 requires the
//! spectrum index flag (and the flag requires identifier 4), radiant flux, and at least one
//! table, as the reference does. Here an index must be a whole number within 1..=tables
//! (else an error naming the ray, its byte and the field), and each table, checked like
//! identifier 3's (wavelengths positive and increasing, values finite and >= 0), must
//! have power within 360-830 nm; tables are kept within 360-830 nm, as identifier 3's is.
//!
//! The ray count must fill the file exactly (a truncated file or a lying header is an
//! error naming both lengths). Rays are read in one pass, in chunks, straight into the
//! compact [`RaySet`]; the file is never held whole in memory.

use super::stokes::{RayStokes, STOKES_COLUMNS};
use super::{
    FileSpectrum, FluxUnit, MAX_TABLES, RaySet, StoredRay, TEXT_FIELDS, check_ray, checked_len,
    table_spectrum,
};
use crate::input_file::MAX_INPUT_BYTES;
use crate::sources::spectrum::VISIBLE_NM;
use anyhow::{Result, bail};
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::Path;

/// Bytes of the file header block (4.7.1).
const HEADER_BYTES: usize = 256;
/// Bytes of one text field (1000 UTF-32 code points).
const TEXT_BYTES: usize = 4000;
/// Where the spectral tables start: header, flags, nine text fields.
const TABLES_AT: u64 = (HEADER_BYTES + 32 + 9 * TEXT_BYTES) as u64;
/// Bytes of one additional item's name.
const COLUMN_NAME_BYTES: u64 = 512;
/// Rays read per chunk.
const CHUNK_RAYS: usize = 1 << 16;
/// Bytes of the smallest ray record: x y z kx ky kz and one flux, f32 each.
const MIN_RECORD_BYTES: u64 = 28;
/// Most rays a TM-25 file read can hold: the ray count must fill the file exactly, and
/// the file may hold at most [`MAX_INPUT_BYTES`] (76,694,548 rays of 28 bytes).
pub const MAX_RAYS: usize = ((MAX_INPUT_BYTES - TABLES_AT) / MIN_RECORD_BYTES) as usize;

/// Names of the known data flags (4.7.2.1 to 4.7.2.8).
const FLAG_NAMES: [&str; 8] = [
    "position",
    "direction",
    "radiant flux",
    "wavelength",
    "luminous flux",
    "Stokes",
    "tristimulus",
    "spectrum index",
];

/// An error at byte `at` of `path`, in `field`.
fn bad(path: &Path, at: u64, field: &str, msg: impl std::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!("{}: byte {at}: {field}: {msg}", path.display())
}

fn i32_at(b: &[u8], at: usize) -> i32 {
    i32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

fn f32_at(b: &[u8], at: usize) -> f32 {
    f32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

/// The header fields the reader uses.
struct Header {
    rays: u64,
    flags: [bool; 8],
    identifier: i32,
    single_nm: f32,
    tables: i32,
    extra_items: i32,
    extra_text: i32,
    luminous_lm: f32,
    radiant_w: f32,
}

impl Header {
    /// f32 columns per ray record.
    fn columns(&self) -> u64 {
        self.index_column() + self.flags[7] as u64 + self.extra_items as u64
    }

    /// The spectrum index's column (when its flag is set): after the position, direction,
    /// fluxes, wavelength, Stokes and tristimulus columns.
    fn index_column(&self) -> u64 {
        let f = |k: usize| self.flags[k] as u64;
        self.stokes_column() + 6 * f(5) + 2 * f(6)
    }

    /// The first Stokes column (when its flag is set): after the position, direction,
    /// fluxes and wavelength.
    fn stokes_column(&self) -> u64 {
        let f = |k: usize| self.flags[k] as u64;
        6 + f(2) + f(3) + f(4)
    }
}

/// Read the file header and known data flags (the first 288 bytes), checked.
fn header(path: &Path, b: &[u8]) -> Result<Header> {
    if &b[0..4] != b"TM25" {
        return Err(bad(
            path,
            0,
            "file type (4.7.1.1)",
            format!(
                "expected \"TM25\", got {:?}",
                String::from_utf8_lossy(&b[0..4])
            ),
        ));
    }
    let version = i32_at(b, 4);
    if version != 2013 {
        return Err(bad(
            path,
            4,
            "version (4.7.1.2)",
            format!("only TM-25-13 (2013) is read, got {version}"),
        ));
    }
    let rays = u64::from_le_bytes(b[20..28].try_into().expect("8 bytes"));
    let identifier = i32_at(b, 60);
    let mut flags = [false; 8];
    for (k, flag) in flags.iter_mut().enumerate() {
        let at = HEADER_BYTES + 4 * k;
        *flag = match i32_at(b, at) {
            0 => false,
            1 => true,
            v => {
                return Err(bad(
                    path,
                    at as u64,
                    &format!("{} flag (4.7.2.{})", FLAG_NAMES[k], k + 1),
                    format!("must be 0 or 1, got {v}"),
                ));
            }
        };
    }
    let h = Header {
        rays,
        flags,
        identifier,
        single_nm: f32_at(b, 64),
        tables: i32_at(b, 76),
        extra_items: i32_at(b, 80),
        extra_text: i32_at(b, 84),
        luminous_lm: f32_at(b, 12),
        radiant_w: f32_at(b, 16),
    };
    check_header(path, &h)?;
    Ok(h)
}

/// The consistency rules of TM-25-13 between the header and the flags.
fn check_header(path: &Path, h: &Header) -> Result<()> {
    let flag = |k: usize, why: &str| {
        bad(
            path,
            (HEADER_BYTES + 4 * k) as u64,
            &format!("{} flag (4.7.2.{})", FLAG_NAMES[k], k + 1),
            why,
        )
    };
    if !h.flags[0] || !h.flags[1] {
        let k = if h.flags[0] { 1 } else { 0 };
        return Err(flag(
            k,
            "must be 1 (every ray has a position and a direction)",
        ));
    }
    if !h.flags[2] && !h.flags[4] {
        return Err(flag(
            2,
            "the radiant and luminous flux flags are both 0: the rays carry no flux",
        ));
    }
    if !(0..=4).contains(&h.identifier) {
        return Err(bad(
            path,
            60,
            "spectral data identifier (4.7.1.9)",
            format!("must be 0..4, got {}", h.identifier),
        ));
    }
    if h.flags[7] != (h.identifier == 4) {
        return Err(flag(
            7,
            if h.flags[7] {
                "must be 0 unless the spectral data identifier is 4 (a spectral table per ray)"
            } else {
                "must be 1 when the spectral data identifier is 4 (a spectral table per ray, by index)"
            },
        ));
    }
    if h.identifier == 4 && !h.flags[2] {
        return Err(flag(
            2,
            "must be 1 when the spectral data identifier is 4 (TM-25-13 4.7.2.5)",
        ));
    }
    if h.identifier == 2 && !h.flags[3] {
        return Err(flag(
            3,
            "must be 1 when the spectral data identifier is 2 (a wavelength per ray)",
        ));
    }
    if h.identifier == 2 && !h.flags[2] {
        return Err(flag(
            2,
            "must be 1 when the spectral data identifier is 2 (TM-25-13 4.7.2.5)",
        ));
    }
    let (lo, hi) = VISIBLE_NM;
    if h.identifier == 1 && !(lo..=hi).contains(&(h.single_nm as f64)) {
        return Err(bad(
            path,
            64,
            "single wavelength (4.7.1.10)",
            format!(
                "must be within {lo}-{hi} nm for spectral data identifier 1, got {}",
                h.single_nm
            ),
        ));
    }
    let (tables_ok, need) = match h.identifier {
        3 => (h.tables == 1, "exactly 1".to_string()),
        4 => (
            h.tables >= 1 && h.tables as usize <= MAX_TABLES,
            format!("1 to {MAX_TABLES}"),
        ),
        _ => (h.tables >= 0, "0 or more".to_string()),
    };
    if !tables_ok {
        return Err(bad(
            path,
            76,
            "number of spectral tables (4.7.1.13)",
            format!(
                "got {} (identifier {} needs {need})",
                h.tables, h.identifier
            ),
        ));
    }
    if h.extra_items < 0 {
        return Err(bad(
            path,
            80,
            "number of additional ray items (4.7.1.14)",
            format!("must be >= 0, got {}", h.extra_items),
        ));
    }
    if h.extra_text < 0 || h.extra_text % 4 != 0 {
        return Err(bad(
            path,
            84,
            "additional text size (4.7.1.15)",
            format!(
                "must be a non-negative multiple of 4 bytes, got {}",
                h.extra_text
            ),
        ));
    }
    Ok(())
}

/// A NUL-padded UTF-32LE text field at byte `at` of `path`.
fn utf32(path: &Path, b: &[u8], at: u64, field: &str) -> Result<String> {
    let mut s = String::new();
    for (k, c) in b.chunks_exact(4).enumerate() {
        let code = u32::from_le_bytes([c[0], c[1], c[2], c[3]]);
        if code == 0 {
            break;
        }
        let ch = char::from_u32(code).ok_or_else(|| {
            bad(
                path,
                at + 4 * k as u64,
                field,
                format!("U+{code:X} is not a Unicode code point"),
            )
        })?;
        s.push(ch);
    }
    Ok(s)
}

/// Reads `n` bytes at a known offset, with errors naming the offset and the field.
struct Cursor<R> {
    inner: R,
    at: u64,
    len: u64,
}

impl<R: Read> Cursor<R> {
    fn take(&mut self, path: &Path, n: u64, field: &str) -> Result<Vec<u8>> {
        if self.at + n > self.len {
            return Err(bad(
                path,
                self.at,
                field,
                format!(
                    "the file ends at byte {} (truncated): {n} bytes needed",
                    self.len
                ),
            ));
        }
        let mut buf = vec![0u8; n as usize];
        self.inner
            .read_exact(&mut buf)
            .map_err(|e| bad(path, self.at, field, e))?;
        self.at += n;
        Ok(buf)
    }
}

/// Read the TM-25 file at `path` into a ray set.
pub fn read(path: &Path) -> Result<RaySet> {
    let len = checked_len(path)?;
    let file = std::fs::File::open(path)
        .map_err(|e| anyhow::anyhow!("{}: cannot read ray file: {e}", path.display()))?;
    let mut c = Cursor {
        inner: BufReader::with_capacity(1 << 20, file),
        at: 0,
        len,
    };
    let head = c.take(path, TABLES_AT, "header (4.7.1 to 4.7.3)")?;
    let h = header(path, &head)?;
    let mut text: [String; TEXT_FIELDS] = Default::default();
    for (k, t) in text.iter_mut().enumerate() {
        let at = HEADER_BYTES + 32 + k * TEXT_BYTES;
        *t = utf32(
            path,
            &head[at..at + TEXT_BYTES],
            at as u64,
            &format!("text field 4.7.3.{}", k + 1),
        )?;
    }
    let mut tables = read_tables(path, &mut c, &h)?;
    c.take(
        path,
        h.extra_items as u64 * COLUMN_NAME_BYTES,
        "additional item names (4.7.5)",
    )?;
    c.take(path, h.extra_text as u64, "additional text (4.7.6)")?;
    let record = 4 * h.columns();
    let expected = h.rays.checked_mul(record).and_then(|r| r.checked_add(c.at));
    if expected != Some(c.len) {
        return Err(bad(
            path,
            20,
            "number of rays (4.7.1.6)",
            format!(
                "{} rays of {record} bytes from byte {} need {} bytes, the file has {}",
                h.rays,
                c.at,
                expected.map_or("more than 2^64".into(), |e| e.to_string()),
                c.len
            ),
        ));
    }
    if h.rays == 0 {
        return Err(bad(
            path,
            20,
            "number of rays (4.7.1.6)",
            "the file holds no rays",
        ));
    }
    let spectrum = match h.identifier {
        1 => FileSpectrum::Single(h.single_nm as f64),
        2 => FileSpectrum::PerRay,
        3 => FileSpectrum::Table(tables.swap_remove(0)),
        4 => FileSpectrum::Tables(tables),
        _ => FileSpectrum::None,
    };
    let (rays, nm, table, stokes) = read_rays(path, &mut c, &h)?;
    Ok(RaySet {
        text,
        rays,
        nm,
        table,
        stokes,
        spectrum,
        unit: if h.flags[2] {
            FluxUnit::Watt
        } else {
            FluxUnit::Lumen
        },
        header_flux: [h.radiant_w as f64, h.luminous_lm as f64],
    })
}

/// The spectral tables block: the tables the identifier uses (3: the first, 4: all, each
/// with power within 360-830 nm; else none).
fn read_tables<R: Read>(path: &Path, c: &mut Cursor<R>, h: &Header) -> Result<Vec<Vec<[f64; 2]>>> {
    let start = c.at;
    let keep = match h.identifier {
        3 => 1,
        4 => h.tables as usize,
        _ => 0,
    };
    let mut tables = Vec::with_capacity(keep);
    for t in 0..h.tables {
        let field = format!("spectral table {} (4.7.4)", t + 1);
        let n = i32_at(&c.take(path, 4, &field)?, 0);
        if n <= 0 || n as u64 * 8 > c.len - c.at {
            return Err(bad(
                path,
                c.at - 4,
                &field,
                format!("{n} rows: must be > 0 and fit in the file"),
            ));
        }
        let bytes = c.take(path, n as u64 * 8, &field)?;
        let mut rows = Vec::with_capacity(n as usize);
        for (k, pair) in bytes.chunks_exact(8).enumerate() {
            let (nm, v) = (f32_at(pair, 0) as f64, f32_at(pair, 4) as f64);
            let ok = nm.is_finite()
                && nm > 0.0
                && v.is_finite()
                && v >= 0.0
                && rows.last().is_none_or(|p: &[f64; 2]| nm > p[0]);
            if !ok {
                return Err(bad(
                    path,
                    c.at - n as u64 * 8 + 8 * k as u64,
                    &field,
                    format!(
                        "row {k}: [{nm} nm, {v}]: wavelengths must be positive and increasing, values finite and >= 0"
                    ),
                ));
            }
            rows.push([nm, v]);
        }
        if h.identifier == 4 {
            table_spectrum(&rows).map_err(|e| bad(path, c.at - n as u64 * 8 - 4, &field, e))?;
        }
        if tables.len() < keep {
            tables.push(rows);
        }
    }
    let pad = (32 - (c.at - start) % 32) % 32;
    c.take(path, pad, "spectral tables' padding (4.7.4)")?;
    Ok(tables)
}

/// The ray records, in chunks: positions, unit directions, flux, wavelengths (identifier
/// 2) and spectrum indices (4, stored 0-based) checked.
fn read_rays<R: Read>(path: &Path, c: &mut Cursor<R>, h: &Header) -> Result<RayColumns> {
    let per_ray_nm = h.identifier == 2;
    let stokes_col = h.flags[5].then(|| h.stokes_column() as usize);
    let index_col = (h.identifier == 4).then(|| h.index_column() as usize);
    let cols = h.columns() as usize;
    let flux_col = if h.flags[2] {
        6
    } else {
        6 + h.flags[3] as usize
    };
    let n = h.rays as usize;
    let mut rays = Vec::with_capacity(n);
    let mut nm = Vec::with_capacity(if per_ray_nm { n } else { 0 });
    let mut table = Vec::with_capacity(if index_col.is_some() { n } else { 0 });
    let mut stokes = Vec::with_capacity(if stokes_col.is_some() { n } else { 0 });
    let mut done = 0;
    while done < n {
        let k = (n - done).min(CHUNK_RAYS);
        let start = c.at;
        let bytes = c.take(path, (k * cols * 4) as u64, "ray records")?;
        for (j, rec) in bytes.chunks_exact(cols * 4).enumerate() {
            let v = |col: usize| f32_at(rec, 4 * col);
            let at = |col: usize| start + (j * cols * 4 + 4 * col) as u64;
            let wl = per_ray_nm.then(|| v(7));
            let ray = check_ray([v(0), v(1), v(2)], [v(3), v(4), v(5)], v(flux_col), wl).map_err(
                |(col, msg)| {
                    let (byte, name) = match col {
                        6 => (
                            flux_col,
                            if h.flags[2] {
                                "radiant flux"
                            } else {
                                "luminous flux"
                            },
                        ),
                        c => (c, COLUMN_NAMES[c]),
                    };
                    bad(path, at(byte), &format!("ray {} {name}", done + j), msg)
                },
            )?;
            if let Some(col) = stokes_col {
                let cols = std::array::from_fn(|k| v(col + k));
                let s = RayStokes::read(cols, ray.dir, ray.flux).map_err(|(k, msg)| {
                    let field = format!("ray {} {} (4.7.2.6)", done + j, STOKES_COLUMNS[k]);
                    bad(path, at(col + k), &field, msg)
                })?;
                stokes.push(s);
            }
            rays.push(ray);
            if let Some(w) = wl {
                nm.push(w);
            }
            if let Some(col) = index_col {
                let field = format!("ray {} spectrum index (4.7.2.8)", done + j);
                let t = spectrum_index(v(col), h.tables as usize)
                    .map_err(|msg| bad(path, at(col), &field, msg))?;
                table.push(t);
            }
        }
        done += k;
    }
    Ok((rays, nm, table, stokes))
}

/// The rays of a file and their optional columns: wavelengths, spectral tables, Stokes
/// vectors (each empty when the file has none).
type RayColumns = (Vec<StoredRay>, Vec<f32>, Vec<u16>, Vec<RayStokes>);

/// A ray's spectrum index: a whole number 1..=`tables` stored as an f32 (TM-25-13 numbers
/// the spectral tables from 1), as the 0-based table.
fn spectrum_index(v: f32, tables: usize) -> Result<u16, String> {
    if !(v.is_finite() && v.fract() == 0.0) {
        return Err(format!(
            "must be a whole number (a spectral table, numbered from 1), got {v}"
        ));
    }
    if !(v >= 1.0 && v as usize <= tables) {
        return Err(format!(
            "must be 1 to {tables} (the file's spectral tables, numbered from 1), got {v}"
        ));
    }
    Ok((v as usize - 1) as u16)
}

/// Names of the first eight columns of a ray record, for errors.
const COLUMN_NAMES: [&str; 8] = ["x", "y", "z", "kx", "ky", "kz", "flux", "wavelength"];

/// Write `set` as a TM-25-13 file: radiant (or luminous) flux per ray, a wavelength per
/// ray, one wavelength, one spectral table, or several with a spectrum index per ray
/// (written from 1), as the set holds.
pub fn write(path: &Path, set: &RaySet) -> Result<()> {
    check_writable(set).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let head = header_bytes(set).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let file = std::fs::File::create(path)
        .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
    let mut w = BufWriter::with_capacity(1 << 20, file);
    w.write_all(&head)?;
    let tables = match &set.spectrum {
        FileSpectrum::Table(rows) => std::slice::from_ref(rows),
        FileSpectrum::Tables(tables) => tables.as_slice(),
        _ => &[],
    };
    if !tables.is_empty() {
        let mut block = Vec::new();
        for rows in tables {
            block.extend((rows.len() as i32).to_le_bytes());
            for r in rows {
                block.extend((r[0] as f32).to_le_bytes());
                block.extend((r[1] as f32).to_le_bytes());
            }
        }
        block.resize(block.len().div_ceil(32) * 32, 0);
        w.write_all(&block)?;
    }
    let per_ray = matches!(set.spectrum, FileSpectrum::PerRay);
    let indexed = matches!(set.spectrum, FileSpectrum::Tables(_));
    for (i, r) in set.rays.iter().enumerate() {
        for x in r.pos.iter().chain(&r.dir).chain([&r.flux]) {
            w.write_all(&x.to_le_bytes())?;
        }
        if per_ray {
            w.write_all(&set.nm[i].to_le_bytes())?;
        }
        if let Some(s) = set.stokes.get(i) {
            for x in s.columns(r.flux) {
                w.write_all(&x.to_le_bytes())?;
            }
        }
        if indexed {
            w.write_all(&((set.table[i] as u32 + 1) as f32).to_le_bytes())?;
        }
    }
    w.flush()
        .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))
}

/// Why `set` cannot be written as it is, if it cannot.
fn check_writable(set: &RaySet) -> Result<()> {
    if !set.stokes.is_empty() && set.stokes.len() != set.rays.len() {
        bail!(
            "{} rays but {} Stokes vectors",
            set.rays.len(),
            set.stokes.len()
        );
    }
    match &set.spectrum {
        FileSpectrum::PerRay if set.unit == FluxUnit::Lumen => {
            bail!("a wavelength per ray needs radiant flux (TM-25-13 4.7.2.5)")
        }
        FileSpectrum::PerRay if set.nm.len() != set.rays.len() => {
            bail!("{} rays but {} wavelengths", set.rays.len(), set.nm.len())
        }
        FileSpectrum::Tables(_) if set.unit == FluxUnit::Lumen => {
            bail!("spectral tables per ray need radiant flux (TM-25-13 4.7.2.5)")
        }
        FileSpectrum::Tables(tables) => {
            if tables.is_empty() || tables.len() > MAX_TABLES {
                bail!("{} spectral tables: 1 to {MAX_TABLES} needed", tables.len());
            }
            if let Some(k) = tables.iter().position(|rows| rows.is_empty()) {
                bail!("spectral table {} has no rows", k + 1);
            }
            set.check_table_indices()?;
        }
        _ => {}
    }
    Ok(())
}

/// The header, flags and text fields of `set` (36288 bytes).
fn header_bytes(set: &RaySet) -> Result<Vec<u8>> {
    let mut b = Vec::with_capacity(TABLES_AT as usize);
    b.extend(b"TM25");
    b.extend(2013i32.to_le_bytes());
    b.extend(0i32.to_le_bytes());
    let total = set.total_flux() as f32;
    let (lm, w) = match set.unit {
        FluxUnit::Watt => (f32::NAN, total),
        FluxUnit::Lumen => (total, f32::NAN),
    };
    b.extend(lm.to_le_bytes());
    b.extend(w.to_le_bytes());
    b.extend((set.rays.len() as u64).to_le_bytes());
    b.extend([0u8; 28]);
    b.extend(0i32.to_le_bytes());
    let (id, single, tables) = match &set.spectrum {
        FileSpectrum::None => (0i32, f32::NAN, 0i32),
        FileSpectrum::Single(nm) => (1, *nm as f32, 0),
        FileSpectrum::PerRay => (2, f32::NAN, 0),
        FileSpectrum::Table(_) => (3, f32::NAN, 1),
        FileSpectrum::Tables(t) => (4, f32::NAN, t.len() as i32),
    };
    let (lo, hi) = set
        .wavelength_range()
        .map_or((f32::NAN, f32::NAN), |(a, b)| (a as f32, b as f32));
    b.extend(id.to_le_bytes());
    for x in [single, lo, hi] {
        b.extend(x.to_le_bytes());
    }
    for x in [tables, 0i32, 0i32] {
        b.extend(x.to_le_bytes());
    }
    b.resize(HEADER_BYTES, 0);
    let watt = set.unit == FluxUnit::Watt;
    let per_ray = matches!(set.spectrum, FileSpectrum::PerRay);
    let indexed = matches!(set.spectrum, FileSpectrum::Tables(_));
    let stokes = !set.stokes.is_empty();
    for f in [true, true, watt, per_ray, !watt, stokes, false, indexed] {
        b.extend((f as i32).to_le_bytes());
    }
    for (k, t) in set.text.iter().enumerate() {
        let codes: Vec<char> = t.chars().collect();
        if codes.len() >= TEXT_BYTES / 4 || codes.contains(&'\0') {
            bail!(
                "text field 4.7.3.{}: at most {} characters and no NUL, got {}",
                k + 1,
                TEXT_BYTES / 4 - 1,
                codes.len()
            );
        }
        let start = b.len();
        codes
            .iter()
            .for_each(|&ch| b.extend((ch as u32).to_le_bytes()));
        b.resize(start + TEXT_BYTES, 0);
    }
    Ok(b)
}
