//! The IS BSDF ASCII format (Radiant Imaging's BSDF Data Interchange format, read by
//! OpticStudio, Speos and LightTools): reading it, with errors naming the file and the
//! line, and writing it.
//!
//! ```text
//! # comment lines start with '#'
//! Source  Measured
//! Symmetry  PlaneSymmetrical        # or Asymmetrical (Asymmetrical4D reads the same)
//! SpectralContent  Monochrome
//! ScatterType  BRDF                 # or BTDF
//! SampleRotation  1
//! 0
//! AngleOfIncidence  3
//! 0 30 60
//! ScatterAzimuth  2
//! 0 180
//! ScatterRadial  3
//! 0 45 90
//!
//! Monochrome
//! DataBegin
//! TIS 0.9                           # one block per rotation, then per AOI:
//! 0.28 0.28 0.28                    # one row per azimuth, one value per radial
//! 0.28 0.28 0.28
//! TIS 0.9
//! ...
//! DataEnd
//! ```
//!
//! A file may hold several such sections one after the other (blutrace writes a BRDF and
//! a BTDF section in one file; other tools write one section per file). Values may wrap
//! over lines: numbers are read in order, each remembered with its line.
//!
//! `SpectralContent XYZ` sections hold three tables on the one grid, the BSDF weighted by
//! the CIE x̄, ȳ and z̄ functions: after the angles, `TristimulusX`, `TristimulusY` and
//! `TristimulusZ` each followed by its own `DataBegin` ... `DataEnd` (in any order, each
//! once). They are read as three sections, one per [`Channel`].

use anyhow::{Result, bail};
use std::fmt::Write as _;
use std::path::Path;

/// Reflection or transmission data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScatterType {
    /// Reflected light (back into the medium the light came from).
    Brdf,
    /// Transmitted light (into the medium on the other side).
    Btdf,
}

impl ScatterType {
    /// The keyword in the file.
    pub fn keyword(self) -> &'static str {
        match self {
            ScatterType::Brdf => "BRDF",
            ScatterType::Btdf => "BTDF",
        }
    }
}

/// The largest BSDF value read (1/sr). A specular peak holding all of the power in a cell
/// of 0.01 degrees reaches about 1e7; far larger values are a damaged file, and would
/// overflow the sampler's running sums of value times solid angle.
pub const MAX_BSDF: f64 = 1e12;

/// A tristimulus channel of an XYZ table.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize, schemars::JsonSchema,
)]
pub enum Channel {
    /// The x̄-weighted table.
    X,
    /// The ȳ-weighted (photopic) table.
    Y,
    /// The z̄-weighted table.
    Z,
}

impl Channel {
    const ALL: [Channel; 3] = [Channel::X, Channel::Y, Channel::Z];

    /// The data's indicator in the file.
    pub fn indicator(self) -> &'static str {
        match self {
            Channel::X => "TristimulusX",
            Channel::Y => "TristimulusY",
            Channel::Z => "TristimulusZ",
        }
    }
}

/// One section of a file: one scatter type on one grid, all angles in degrees.
#[derive(Clone, Debug, PartialEq)]
pub struct Section {
    /// BRDF or BTDF.
    pub scatter: ScatterType,
    /// The tristimulus channel of an XYZ file (`None`: Monochrome).
    pub channel: Option<Channel>,
    /// `PlaneSymmetrical`: the azimuths cover 0..=180 and the other half mirrors them.
    pub plane_symmetric: bool,
    /// Sample rotations (degrees).
    pub rotations: Vec<f64>,
    /// Angles of incidence (degrees, increasing, within [0, 90)).
    pub aoi: Vec<f64>,
    /// Scatter azimuths about the specular direction (degrees, increasing).
    pub azimuth: Vec<f64>,
    /// Scatter radial angles from the specular direction (degrees, increasing).
    pub radial: Vec<f64>,
    /// One block per (rotation, AOI), rotation-major.
    pub blocks: Vec<Block>,
}

/// The data of one (rotation, AOI).
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// Total integrated scatter: the fraction of the incident power this type scatters.
    pub tis: f64,
    /// The line of its `TIS` (for messages; 0 when written, not read).
    pub line: usize,
    /// BSDF (1/sr), `values[azimuth][radial]`.
    pub values: Vec<Vec<f64>>,
}

/// A whitespace-separated word and its 1-based line.
#[derive(Clone, Copy, Debug)]
struct Word<'a> {
    text: &'a str,
    line: usize,
}

/// The words of a file, comments (`#` to the end of a line) left out.
struct Words<'a> {
    file: String,
    words: Vec<Word<'a>>,
    next: usize,
    last_line: usize,
}

impl<'a> Words<'a> {
    fn new(text: &'a str, path: &Path) -> Words<'a> {
        let mut words = Vec::new();
        let mut last_line = 1;
        for (i, raw) in text.lines().enumerate() {
            last_line = i + 1;
            let code = raw.split('#').next().unwrap_or("");
            words.extend(
                code.split_whitespace()
                    .map(|text| Word { text, line: i + 1 }),
            );
        }
        Words {
            file: path.display().to_string(),
            words,
            next: 0,
            last_line,
        }
    }

    fn err_at(&self, line: usize, msg: impl std::fmt::Display) -> anyhow::Error {
        anyhow::anyhow!("{}: line {line}: {msg}", self.file)
    }

    fn at_end(&self) -> bool {
        self.next >= self.words.len()
    }

    /// The words not read yet: no declared count can ask for more numbers than these.
    fn left(&self) -> usize {
        self.words.len().saturating_sub(self.next)
    }

    fn word(&mut self, what: &str) -> Result<Word<'a>> {
        match self.words.get(self.next) {
            Some(w) => {
                self.next += 1;
                Ok(*w)
            }
            None => Err(self.err_at(
                self.last_line,
                format!("the file ends where {what} was expected"),
            )),
        }
    }

    /// The keyword `key` (any case).
    fn keyword(&mut self, key: &str) -> Result<usize> {
        let w = self.word(key)?;
        if !w.text.eq_ignore_ascii_case(key) {
            return Err(self.err_at(w.line, format!("expected {key}, found {:?}", w.text)));
        }
        Ok(w.line)
    }

    /// `key VALUE`: the value, as written.
    fn keyed(&mut self, key: &str) -> Result<Word<'a>> {
        self.keyword(key)?;
        self.word(&format!("the value of {key}"))
    }

    fn number(&mut self, what: &str) -> Result<(f64, usize)> {
        let w = self.word(what)?;
        match w.text.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok((x, w.line)),
            _ => Err(self.err_at(
                w.line,
                format!("{what}: expected a number, found {:?}", w.text),
            )),
        }
    }

    /// `key N` then N numbers: an angle list, increasing and within `[lo, hi]` (or below
    /// `hi` when `open`).
    fn angles(&mut self, key: &str, (lo, hi, open): (f64, f64, bool)) -> Result<Vec<f64>> {
        let w = self.keyed(key)?;
        let n: usize = match w.text.parse() {
            Ok(n) if (1..=100_000).contains(&n) => n,
            _ => {
                return Err(self.err_at(
                    w.line,
                    format!(
                        "{key}: expected a count from 1 to 100000, found {:?}",
                        w.text
                    ),
                ));
            }
        };
        if n > self.left() {
            return Err(self.err_at(
                w.line,
                format!(
                    "{key}: declares {n} angles, but only {} numbers follow in the file",
                    self.left()
                ),
            ));
        }
        let mut out: Vec<f64> = Vec::with_capacity(n);
        for _ in 0..n {
            let (a, line) = self.number(&format!("{key} angle"))?;
            let inside = a >= lo && (if open { a < hi } else { a <= hi });
            if !inside {
                let bound = if open { ")" } else { "]" };
                return Err(self.err_at(
                    line,
                    format!("{key} angle {a} is outside [{lo}, {hi}{bound} degrees"),
                ));
            }
            if out.last().is_some_and(|&p| a <= p) {
                return Err(self.err_at(
                    line,
                    format!(
                        "{key} angles must increase: {a} follows {}",
                        out[out.len() - 1]
                    ),
                ));
            }
            out.push(a);
        }
        Ok(out)
    }
}

/// Read every section of the IS BSDF text `text` (from `path`, named in errors).
pub fn parse(text: &str, path: &Path) -> Result<Vec<Section>> {
    let mut words = Words::new(text, path);
    let mut sections = Vec::new();
    while !words.at_end() {
        sections.extend(section(&mut words)?);
    }
    if sections.is_empty() {
        bail!("{}: holds no BSDF data (no Source line)", path.display());
    }
    Ok(sections)
}

/// One section of the file: one table, or three for an XYZ file.
fn section(w: &mut Words) -> Result<Vec<Section>> {
    w.keyword("Source")?;
    w.word("the value of Source")?;
    let sym = w.keyed("Symmetry")?;
    let plane_symmetric = match sym.text.to_ascii_lowercase().as_str() {
        "planesymmetrical" => true,
        "asymmetrical" | "asymmetrical4d" => false,
        _ => {
            return Err(w.err_at(
                sym.line,
                format!(
                    "Symmetry: expected PlaneSymmetrical or Asymmetrical, found {:?}",
                    sym.text
                ),
            ));
        }
    };
    let content = w.keyed("SpectralContent")?;
    let xyz = match content.text.to_ascii_lowercase().as_str() {
        "monochrome" => false,
        "xyz" => true,
        _ => {
            return Err(w.err_at(
                content.line,
                format!(
                    "SpectralContent: expected Monochrome or XYZ, found {:?}",
                    content.text
                ),
            ));
        }
    };
    let st = w.keyed("ScatterType")?;
    let scatter = match st.text.to_ascii_uppercase().as_str() {
        "BRDF" => ScatterType::Brdf,
        "BTDF" => ScatterType::Btdf,
        _ => {
            return Err(w.err_at(
                st.line,
                format!("ScatterType: expected BRDF or BTDF, found {:?}", st.text),
            ));
        }
    };
    let rotations = w.angles("SampleRotation", (0.0, 360.0, true))?;
    let aoi = w.angles("AngleOfIncidence", (0.0, 90.0, true))?;
    let az_max = if plane_symmetric { 180.0 } else { 360.0 };
    let azimuth = w.angles("ScatterAzimuth", (0.0, az_max, !plane_symmetric))?;
    let radial = w.angles("ScatterRadial", (0.0, 180.0, false))?;
    let grid = Section {
        scatter,
        channel: None,
        plane_symmetric,
        rotations,
        aoi,
        azimuth,
        radial,
        blocks: Vec::new(),
    };
    if !xyz {
        let indicator = w.word("the spectral content indicator (Monochrome)")?;
        if !indicator.text.eq_ignore_ascii_case("Monochrome") {
            return Err(w.err_at(
                indicator.line,
                format!(
                    "expected Monochrome (the SpectralContent), found {:?}",
                    indicator.text
                ),
            ));
        }
        return Ok(vec![data(w, grid)?]);
    }
    let mut out: Vec<Section> = Vec::with_capacity(3);
    for _ in 0..3 {
        let indicator = w.word("TristimulusX, TristimulusY or TristimulusZ")?;
        let channel = Channel::ALL
            .into_iter()
            .find(|c| indicator.text.eq_ignore_ascii_case(c.indicator()))
            .filter(|c| out.iter().all(|s| s.channel != Some(*c)))
            .ok_or_else(|| {
                w.err_at(
                    indicator.line,
                    format!(
                        "an XYZ table needs TristimulusX, TristimulusY and TristimulusZ data, each once; found {:?}",
                        indicator.text
                    ),
                )
            })?;
        let table = Section {
            channel: Some(channel),
            ..grid.clone()
        };
        out.push(data(w, table)?);
    }
    Ok(out)
}

/// The `DataBegin` ... `DataEnd` of `sec`'s grid: its blocks.
fn data(w: &mut Words, mut sec: Section) -> Result<Section> {
    let line = w.keyword("DataBegin")?;
    fits(w, line, &sec)?;
    let n = sec.rotations.len() * sec.aoi.len();
    for r in &sec.rotations {
        for a in &sec.aoi {
            let b = block(w, (*r, *a), sec.azimuth.len(), sec.radial.len())?;
            sec.blocks.push(b);
        }
    }
    let end = w.word("DataEnd")?;
    if !end.text.eq_ignore_ascii_case("DataEnd") {
        return Err(w.err_at(
            end.line,
            format!(
                "expected DataEnd after {n} blocks of {} x {} values, found {:?}",
                sec.azimuth.len(),
                sec.radial.len(),
                end.text
            ),
        ));
    }
    Ok(sec)
}

/// Check that the words left in the file hold at least one block of `sec`'s grid (its
/// `TIS`, the value and the BSDF values) before one is allocated: a count only a damaged
/// file declares is refused, not allocated (a shorter file ends with its own message).
fn fits(w: &Words, line: usize, sec: &Section) -> Result<()> {
    let needed = (sec.azimuth.len() as u128) * (sec.radial.len() as u128) + 2;
    if needed > w.left() as u128 {
        return Err(w.err_at(
            line,
            format!(
                "a block of ScatterAzimuth {} x ScatterRadial {} values needs {needed} numbers, but the file holds only {} more: a count is wrong",
                sec.azimuth.len(),
                sec.radial.len(),
                w.left()
            ),
        ));
    }
    Ok(())
}

fn block(w: &mut Words, (rot, aoi): (f64, f64), n_az: usize, n_rad: usize) -> Result<Block> {
    let here = format!("rotation {rot}, AOI {aoi}");
    let key = w.word(&format!("TIS of {here}"))?;
    if !key.text.eq_ignore_ascii_case("TIS") {
        return Err(w.err_at(
            key.line,
            format!("expected TIS (the block of {here}), found {:?}", key.text),
        ));
    }
    let (tis, line) = w.number(&format!("TIS of {here}"))?;
    if !(0.0..=1.0).contains(&tis) {
        return Err(w.err_at(
            line,
            format!("TIS of {here} is {tis}; it must be within [0, 1]"),
        ));
    }
    let mut values = vec![vec![0.0; n_rad]; n_az];
    for row in values.iter_mut() {
        for v in row.iter_mut() {
            let (x, line) = w.number(&format!("BSDF value of {here}"))?;
            if !(0.0..=MAX_BSDF).contains(&x) {
                return Err(w.err_at(
                    line,
                    format!("BSDF value {x:e} of {here} is outside [0, {MAX_BSDF:e}] (1/sr)"),
                ));
            }
            *v = x;
        }
    }
    Ok(Block { tis, line, values })
}

/// The text of `sections` in the IS BSDF format, after `comments` (one `#` line each),
/// each section as a Monochrome table (a channel of an XYZ file as the table it is).
pub fn write(sections: &[Section], comments: &[String]) -> String {
    let mut s = String::new();
    let list = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    for c in comments {
        let _ = writeln!(s, "# {c}");
    }
    for sec in sections {
        let sym = if sec.plane_symmetric {
            "PlaneSymmetrical"
        } else {
            "Asymmetrical"
        };
        let _ = writeln!(
            s,
            "Source  Measured\nSymmetry  {sym}\nSpectralContent  Monochrome"
        );
        let _ = writeln!(s, "ScatterType  {}", sec.scatter.keyword());
        for (key, v) in [
            ("SampleRotation", &sec.rotations),
            ("AngleOfIncidence", &sec.aoi),
            ("ScatterAzimuth", &sec.azimuth),
            ("ScatterRadial", &sec.radial),
        ] {
            let _ = writeln!(s, "{key}  {}\n{}", v.len(), list(v));
        }
        s.push_str("\nMonochrome\nDataBegin\n");
        for b in &sec.blocks {
            let _ = writeln!(s, "TIS {}", b.tis);
            for row in &b.values {
                let r: Vec<String> = row.iter().map(|x| format!("{x:.5e}")).collect();
                let _ = writeln!(s, "{}", r.join(" "));
            }
        }
        s.push_str("DataEnd\n");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = "# a Lambertian reflector\nSource  Measured\nSymmetry  PlaneSymmetrical\n\
        SpectralContent  Monochrome\nScatterType  BRDF\nSampleRotation  1\n0\n\
        AngleOfIncidence  2\n0 60\nScatterAzimuth  2\n0 180\nScatterRadial  3\n0 45 90\n\n\
        Monochrome\nDataBegin\nTIS 0.5\n0.1 0.1 0.1\n0.1 0.1 0.1\nTIS 0.4\n0.1 0.1 0.1\n\
        0.1 0.1 0.1\nDataEnd\n";

    fn err(text: &str) -> String {
        format!("{:#}", parse(text, Path::new("t.bsdf")).unwrap_err())
    }

    #[test]
    fn a_table_reads_and_writes_back_the_same() {
        let s = parse(GOOD, Path::new("t.bsdf")).unwrap();
        assert_eq!(s.len(), 1);
        assert_eq!(s[0].aoi, vec![0.0, 60.0]);
        assert_eq!(s[0].blocks[1].tis, 0.4);
        assert!(s[0].plane_symmetric);
        let again = parse(&write(&s, &["x".into()]), Path::new("w.bsdf")).unwrap();
        let values = |s: &[Section]| {
            s[0].blocks
                .iter()
                .map(|b| (b.tis, b.values.clone()))
                .collect::<Vec<_>>()
        };
        assert_eq!(values(&again), values(&s));
        assert_eq!(
            (&again[0].aoi, &again[0].radial, &again[0].azimuth),
            (&s[0].aoi, &s[0].radial, &s[0].azimuth)
        );
    }

    /// `GOOD` as an XYZ file: its data three times, X's values scaled by `kx`.
    fn xyz(kx: f64, order: [&str; 3]) -> String {
        let (head, data) = GOOD.split_once("\nMonochrome\n").unwrap();
        let head = head.replace("SpectralContent  Monochrome", "SpectralContent  XYZ");
        let x = data.replace("TIS 0.5", &format!("TIS {}", 0.5 * kx));
        let mut s = head + "\n";
        for c in order {
            s.push_str(&format!(
                "{c}\n{}",
                if c == "TristimulusX" { &x } else { data }
            ));
        }
        s
    }

    #[test]
    fn an_xyz_table_reads_as_three_channels() {
        let s = parse(
            &xyz(0.5, ["TristimulusZ", "TristimulusX", "TristimulusY"]),
            Path::new("t.bsdf"),
        )
        .unwrap();
        let got: Vec<(Option<Channel>, f64)> =
            s.iter().map(|c| (c.channel, c.blocks[0].tis)).collect();
        assert_eq!(
            got,
            [
                (Some(Channel::Z), 0.5),
                (Some(Channel::X), 0.25),
                (Some(Channel::Y), 0.5)
            ]
        );
        assert!(
            s.iter()
                .all(|c| c.aoi == [0.0, 60.0] && c.blocks.len() == 2)
        );
        let twice = xyz(1.0, ["TristimulusX", "TristimulusX", "TristimulusY"]);
        let e = err(&twice);
        assert!(e.contains("line 24:") && e.contains("each once"), "{e}");
    }

    /// `GOOD` with `n` azimuths and `n` radials (increasing, within range) but its two
    /// blocks of 2 x 3 values: the counts claim `n * n` values a block.
    fn huge_grid(n: usize) -> String {
        let list = |max: f64| {
            (0..n)
                .map(|i| format!("{}", max * i as f64 / n as f64))
                .collect::<Vec<_>>()
                .join(" ")
        };
        GOOD.replace(
            "ScatterAzimuth  2\n0 180",
            &format!("ScatterAzimuth  {n}\n{}", list(180.0)),
        )
        .replace(
            "ScatterRadial  3\n0 45 90",
            &format!("ScatterRadial  {n}\n{}", list(90.0)),
        )
    }

    #[test]
    fn counts_the_file_cannot_hold_are_refused_before_allocating() {
        // 3000 x 3000 values a block declared in a 50 KB file: an error naming the counts
        // before the block is allocated (at 100000 x 100000, 80 GB, the allocation
        // aborted; this size fails safely without the check, at the end of the file).
        let e = err(&huge_grid(3000));
        assert!(
            e.starts_with("t.bsdf: line 16: a block of ScatterAzimuth 3000 x ScatterRadial 3000 values needs 9000002 numbers, but the file holds only 17 more"),
            "{e}"
        );
        // A list longer than the file.
        let e = err(&GOOD.replace("ScatterRadial  3", "ScatterRadial  99999"));
        assert!(
            e.starts_with(
                "t.bsdf: line 12: ScatterRadial: declares 99999 angles, but only 22 numbers follow"
            ),
            "{e}"
        );
    }

    #[test]
    fn every_error_names_the_file_and_the_line() {
        let cases = [
            (
                GOOD.replace("TIS 0.4", "TIS 1.2"),
                "line 20: TIS of rotation 0, AOI 60 is 1.2",
            ),
            (
                GOOD.replace("Symmetry  PlaneSymmetrical", "Symmetry  Round"),
                "line 3: Symmetry",
            ),
            (
                GOOD.replace("SpectralContent  Monochrome", "SpectralContent  RGB"),
                "line 4: SpectralContent: expected Monochrome or XYZ",
            ),
            (
                GOOD.replace("SpectralContent  Monochrome", "SpectralContent  XYZ"),
                "line 15: an XYZ table needs TristimulusX, TristimulusY and TristimulusZ",
            ),
            (
                GOOD.replace("ScatterType  BRDF", "ScatterType  BXDF"),
                "line 5: ScatterType",
            ),
            (
                GOOD.replace("0 60\n", "60 0\n"),
                "line 9: AngleOfIncidence angles must increase",
            ),
            (
                GOOD.replace("0 60\n", "0 90\n"),
                "line 9: AngleOfIncidence angle 90 is outside",
            ),
            (
                GOOD.replace("0 45 90", "0 45 190"),
                "line 13: ScatterRadial angle 190",
            ),
            (
                GOOD.replace("0 180\n", "0 270\n"),
                "line 11: ScatterAzimuth angle 270",
            ),
            (
                GOOD.replace("0.1 0.1 0.1\nDataEnd", "0.1 -0.1 0.1\nDataEnd"),
                "line 22: BSDF value -1e-1 of rotation 0, AOI 60 is outside [0, 1e12]",
            ),
            (
                GOOD.replace("0.1 0.1 0.1\nDataEnd", "0.1 1e300 0.1\nDataEnd"),
                "line 22: BSDF value 1e300",
            ),
            (
                GOOD.replace("0.1 0.1 0.1\nDataEnd", "0.1 x 0.1\nDataEnd"),
                "line 22: BSDF value",
            ),
            (
                GOOD.replace("DataEnd\n", ""),
                "line 22: the file ends where DataEnd",
            ),
            (GOOD.replace("TIS 0.4\n", ""), "line 20: expected TIS"),
            (
                GOOD.replace("0.1 0.1 0.1\nDataEnd", "0.1 0.1 0.1 0.1\nDataEnd"),
                "line 22: expected DataEnd",
            ),
            (
                GOOD.replace("DataBegin\n", ""),
                "line 16: expected DataBegin",
            ),
            (
                GOOD.replace("Source  Measured\n", ""),
                "line 2: expected Source",
            ),
            (
                GOOD.replace("AngleOfIncidence  2", "AngleOfIncidence  0"),
                "line 8: AngleOfIncidence: expected a count",
            ),
            ("# nothing\n".to_string(), "holds no BSDF data"),
        ];
        for (text, want) in cases {
            let e = err(&text);
            assert!(
                e.starts_with("t.bsdf: ") && e.contains(want),
                "want {want:?}, got {e}"
            );
        }
    }
}
