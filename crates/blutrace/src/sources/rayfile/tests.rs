use super::*;
use crate::rng::PhotonRng;

fn ray(pos: [f32; 3], dir: [f32; 3], flux: f32) -> StoredRay {
    check_ray(pos, dir, flux, None).unwrap()
}

/// Three rays with wavelengths and text fields (one of them not ASCII).
fn sample_set() -> RaySet {
    let mut text: [String; TEXT_FIELDS] = Default::default();
    text[0] = "side-view LED Ø 0.6 mm".into();
    text[1] = "blutrace tests".into();
    text[8] = "µ-data 𝛌".into();
    RaySet {
        text,
        rays: vec![
            ray([0.1, -0.2, 0.0], [0.0, 0.6, 0.8], 0.5),
            ray([1.5, 0.25, -0.125], [1.0, 0.0, 0.0], 0.25),
            ray([-1e-3, 3.0, 0.5], [0.3, -0.4, 0.866], 1.25),
        ],
        nm: vec![450.5, 555.0, 650.25],
        table: Vec::new(),
        spectrum: FileSpectrum::PerRay,
        unit: FluxUnit::Watt,
        stokes: Vec::new(),
        header_flux: [f64::NAN; 2],
    }
}

fn written(set: &RaySet) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("led.TM25RAY");
    tm25::write(&path, set).unwrap();
    (dir, path)
}

fn same_content(a: &RaySet, b: &RaySet) {
    assert_eq!(a.text, b.text);
    assert_eq!(a.rays, b.rays);
    assert_eq!(a.nm, b.nm);
    assert_eq!(a.table, b.table);
    assert_eq!(a.spectrum, b.spectrum);
    assert_eq!(a.unit, b.unit);
}

#[test]
fn tm25_round_trip_keeps_rays_text_and_wavelengths() {
    let set = sample_set();
    let (_dir, path) = written(&set);
    let back = tm25::read(&path).unwrap();
    same_content(&set, &back);
    assert_eq!(back.header_flux[0], set.total_flux() as f32 as f64);
    assert!(back.header_flux[1].is_nan());
    // 36288 header bytes and 8 f32 columns per ray (radiant flux and wavelength).
    assert_eq!(std::fs::metadata(&path).unwrap().len(), 36288 + 3 * 32);
}

#[test]
fn tm25_round_trip_of_a_table_a_single_wavelength_and_lumens() {
    let mut set = sample_set();
    set.nm.clear();
    set.spectrum =
        FileSpectrum::Table(vec![[400.0, 0.0], [450.0, 1.0], [600.0, 0.5], [700.0, 0.0]]);
    let (_d, path) = written(&set);
    same_content(&set, &tm25::read(&path).unwrap());
    // Three table rows pad the 4 + 32 byte block to 64.
    assert_eq!(std::fs::metadata(&path).unwrap().len(), 36288 + 64 + 3 * 28);
    set.spectrum = FileSpectrum::Single(589.0);
    set.unit = FluxUnit::Lumen;
    let (_d, path) = written(&set);
    let back = tm25::read(&path).unwrap();
    same_content(&set, &back);
    assert_eq!(back.header_flux[1], set.total_flux() as f32 as f64);
}

/// The file's bytes, changed by `edit`, read back: the error's text.
fn error_after(edit: impl FnOnce(&mut Vec<u8>)) -> String {
    error_after_in(&sample_set(), edit)
}

/// [`error_after`] for the file of `set`.
fn error_after_in(set: &RaySet, edit: impl FnOnce(&mut Vec<u8>)) -> String {
    let (_dir, path) = written(set);
    let mut bytes = std::fs::read(&path).unwrap();
    edit(&mut bytes);
    std::fs::write(&path, &bytes).unwrap();
    let e = format!("{:#}", tm25::read(&path).unwrap_err());
    assert!(e.contains(&path.display().to_string()), "{e}");
    e
}

/// A change to a file's bytes.
type Edit = Box<dyn FnOnce(&mut Vec<u8>)>;

fn put_f32(b: &mut [u8], at: usize, x: f32) {
    b[at..at + 4].copy_from_slice(&x.to_le_bytes());
}

#[test]
fn tm25_errors_name_the_byte_and_the_field() {
    let ray0 = 36288;
    let cases: Vec<(Edit, &str)> = vec![
        (
            Box::new(|b| b.truncate(b.len() - 1)),
            "byte 20: number of rays (4.7.1.6): 3 rays of 32 bytes",
        ),
        (
            Box::new(|b| b.truncate(1000)),
            "byte 0: header (4.7.1 to 4.7.3): the file ends at byte 1000 (truncated)",
        ),
        (
            Box::new(|b| b[20] = 4),
            "byte 20: number of rays (4.7.1.6): 4 rays",
        ),
        (
            Box::new(|b| b[27] = 0x80),
            "byte 20: number of rays (4.7.1.6)",
        ),
        (Box::new(|b| b[0] = b'X'), "byte 0: file type (4.7.1.1)"),
        (Box::new(|b| b[4] = 0), "byte 4: version (4.7.1.2)"),
        (
            Box::new(|b| b[256] = 0),
            "byte 256: position flag (4.7.2.1): must be 1",
        ),
        (
            Box::new(|b| b[264] = 2),
            "byte 264: radiant flux flag (4.7.2.3): must be 0 or 1, got 2",
        ),
        (
            Box::new(|b| b[264] = 0),
            "byte 264: radiant flux flag (4.7.2.3): the radiant and luminous flux flags are both 0",
        ),
        (
            Box::new(|b| b[284] = 1),
            "byte 284: spectrum index flag (4.7.2.8): must be 0 unless the spectral data identifier is 4",
        ),
        (
            Box::new(|b| b[60] = 9),
            "byte 60: spectral data identifier (4.7.1.9): must be 0..4, got 9",
        ),
        (
            Box::new(|b| b[288 + 4000 + 2] = 0x20),
            "byte 4288: text field 4.7.3.2: U+200062 is not a Unicode code point",
        ),
        (
            Box::new(move |b| put_f32(b, ray0 + 32 + 16, f32::NAN)),
            "byte 36336: ray 1 ky: must be a finite number, got NaN",
        ),
        (
            Box::new(move |b| put_f32(b, ray0 + 64 + 24, -0.5)),
            "byte 36376: ray 2 radiant flux: must be finite and >= 0, got -0.5",
        ),
        (
            Box::new(move |b| put_f32(b, ray0 + 28, 1000.0)),
            "byte 36316: ray 0 wavelength: must be within 360-830 nm, got 1000",
        ),
        (
            Box::new(move |b| (12..24).for_each(|k| put_f32(b, ray0 + 32 + k / 4 * 4, 0.0))),
            "byte 36332: ray 1 kx: the direction (0, 0, 0) has no length",
        ),
    ];
    for (edit, want) in cases {
        let e = error_after(edit);
        assert!(e.contains(want), "want '{want}' in: {e}");
    }
}

#[test]
fn text_rays_read_with_comments_and_wavelengths() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("two.rays");
    std::fs::write(
        &path,
        "# two colours\n0 0 0 0 0 2 0.25 450\n\n1,0,0, 0,0,1, 0.75, 650 # red\n",
    )
    .unwrap();
    let set = RaySet::read(&path).unwrap();
    assert_eq!(set.rays.len(), 2);
    assert_eq!(set.rays[0].dir, [0.0, 0.0, 1.0]);
    assert_eq!(set.nm, vec![450.0, 650.0]);
    assert_eq!(set.total_flux(), 1.0);
    let spectrum = set.emission_spectrum().unwrap().unwrap();
    let below = (0..1000)
        .filter(|k| spectrum.sample((*k as f64 + 0.5) / 1000.0) < 550.0)
        .count();
    assert_eq!(below, 250, "the histogram splits as the flux does");
}

#[test]
fn text_errors_name_the_line_and_column() {
    let cases = [
        (
            "0 0 0 0 0 1 1\n0 0 0 0 0 1 1 500\n",
            "line 2: expected 7 numbers",
        ),
        ("0 0 0 0 0 1\n", "line 1: expected 7 numbers"),
        (
            "# c\n0 0 0 0 nan 1 1\n",
            "line 2: ky: must be a finite number, got NaN",
        ),
        (
            "0 0 0 0 0 1 -1\n",
            "line 1: flux: must be finite and >= 0, got -1",
        ),
        (
            "0 0 0 0 0 1 1 300\n",
            "line 1: nm: must be within 360-830 nm, got 300",
        ),
        ("0 0 zero 0 0 1 1\n", "line 1: z: not a number: 'zero'"),
        ("# nothing\n", "no rays"),
    ];
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.txt");
    for (text, want) in cases {
        std::fs::write(&path, text).unwrap();
        let e = format!("{:#}", RaySet::read(&path).unwrap_err());
        assert!(
            e.contains(want) && e.contains("bad.txt"),
            "want '{want}' in: {e}"
        );
    }
}

#[test]
fn the_alias_table_draws_in_proportion_to_flux() {
    let w = [1.0, 0.0, 3.0, 0.5, 2.5, 1e-3];
    let alias = Alias::new(w.iter().copied());
    let total: f64 = w.iter().sum();
    for (i, &x) in w.iter().enumerate() {
        assert!(
            (alias.probability(i) - x / total).abs() < 1e-7,
            "{i}: {}",
            alias.probability(i)
        );
    }
    let n = 200_000;
    let mut counts = [0usize; 6];
    for k in 0..n {
        counts[alias.sample((k as f64 + 0.5) / n as f64)] += 1;
    }
    for (i, &x) in w.iter().enumerate() {
        let p = x / total;
        let sigma = (p * (1.0 - p) * n as f64).sqrt() + 1.0;
        assert!(
            (counts[i] as f64 - p * n as f64).abs() < 4.0 * sigma,
            "{i}: {counts:?}"
        );
    }
}

#[test]
fn text_rays_stop_at_the_cap_naming_the_line() {
    let text = "# three rays\n0 0 0 0 0 1 1\n\n0 0 0 0 0 1 1\n0 0 0 0 0 1 1\n";
    let read = |cap| text::read_rows(text.as_bytes(), "big.txt", cap);
    assert_eq!(read(3).unwrap().rays.len(), 3);
    let e = format!("{:#}", read(2).unwrap_err());
    assert!(
        e.contains("big.txt: line 5: more than 2 rays"),
        "want the file, the line and the cap in: {e}"
    );
    assert_eq!(text::MAX_RAYS, 76_694_548);
    let long = format!("0 0 0 0 0 1 1 #{}\n", "x".repeat(text::MAX_LINE_BYTES));
    let e = format!(
        "{:#}",
        text::read_rows(long.as_bytes(), "long.txt", 9).unwrap_err()
    );
    assert!(
        e.contains("long.txt: line 1: longer than 65536 bytes"),
        "{e}"
    );
}

/// A blue table (a triangle 440-460-480 nm) and a broad yellow one.
fn blue_and_yellow() -> Vec<Vec<[f64; 2]>> {
    vec![
        vec![[440.0, 0.0], [460.0, 1.0], [480.0, 0.0]],
        vec![[500.0, 0.25], [560.0, 1.0], [600.0, 0.75], [650.0, 0.0]],
    ]
}

/// Four rays: the yellow table (index 2 in the file), the blue one (1), yellow, blue,
/// along +z, +x, +y and -x; and a third table no ray uses.
fn tables_set() -> RaySet {
    let mut tables = blue_and_yellow();
    tables.push(vec![[400.0, 1.0], [700.0, 1.0]]);
    RaySet {
        text: Default::default(),
        rays: vec![
            ray([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 0.5),
            ray([0.1, 0.0, 0.0], [1.0, 0.0, 0.0], 0.25),
            ray([0.0, 0.2, 0.0], [0.0, 1.0, 0.0], 1.0),
            ray([0.0, 0.0, 0.3], [-1.0, 0.0, 0.0], 0.125),
        ],
        nm: Vec::new(),
        table: vec![1, 0, 1, 0],
        spectrum: FileSpectrum::Tables(tables),
        unit: FluxUnit::Watt,
        stokes: Vec::new(),
        header_flux: [f64::NAN; 2],
    }
}

/// Where the first ray of [`tables_set`]'s file starts: the tables' block is 3 counts and
/// 3 + 4 + 2 rows, 84 bytes, padded to 96.
const TABLES_RAY0: usize = 36288 + 96;

#[test]
fn tm25_round_trip_of_spectral_tables_per_ray() {
    let set = tables_set();
    let (_d, path) = written(&set);
    let back = tm25::read(&path).unwrap();
    same_content(&set, &back);
    // 8 f32 columns per ray: radiant flux, then the spectrum index.
    assert_eq!(
        std::fs::metadata(&path).unwrap().len(),
        TABLES_RAY0 as u64 + 4 * 32
    );
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(i32::from_le_bytes(bytes[60..64].try_into().unwrap()), 4);
    assert_eq!(i32::from_le_bytes(bytes[76..80].try_into().unwrap()), 3);
    assert_eq!(i32::from_le_bytes(bytes[284..288].try_into().unwrap()), 1);
    // The file numbers the tables from 1: ray 0 uses the second.
    let index =
        |i: usize| f32::from_le_bytes(bytes[TABLES_RAY0 + 32 * i + 28..][..4].try_into().unwrap());
    assert_eq!(
        [index(0), index(1), index(2), index(3)],
        [2.0, 1.0, 2.0, 1.0]
    );
    // Written again, the file is the same byte for byte.
    let (_d2, again) = written(&back);
    assert_eq!(std::fs::read(&again).unwrap(), bytes);
    same_content(&set, &tm25::read(&again).unwrap());
    let range = back.wavelength_range().unwrap();
    assert_eq!(range, (400.0, 700.0));
}

#[test]
fn tm25_spectral_table_errors_name_the_byte_and_the_field() {
    let index_at = |i: usize| TABLES_RAY0 + 32 * i + 28;
    let cases: Vec<(Edit, String)> = vec![
        (
            Box::new(move |b| put_f32(b, index_at(2), 4.0)),
            format!(
                "byte {}: ray 2 spectrum index (4.7.2.8): must be 1 to 3 (the file's spectral tables, numbered from 1), got 4",
                index_at(2)
            ),
        ),
        (
            Box::new(move |b| put_f32(b, index_at(1), 0.0)),
            format!(
                "byte {}: ray 1 spectrum index (4.7.2.8): must be 1 to 3",
                index_at(1)
            ),
        ),
        (
            Box::new(move |b| put_f32(b, index_at(3), 1.5)),
            format!(
                "byte {}: ray 3 spectrum index (4.7.2.8): must be a whole number (a spectral table, numbered from 1), got 1.5",
                index_at(3)
            ),
        ),
        (
            Box::new(move |b| put_f32(b, index_at(0), f32::NAN)),
            format!(
                "byte {}: ray 0 spectrum index (4.7.2.8): must be a whole number",
                index_at(0)
            ),
        ),
        (
            Box::new(|b| b[284] = 0),
            "byte 284: spectrum index flag (4.7.2.8): must be 1 when the spectral data identifier is 4".into(),
        ),
        (
            Box::new(|b| b[76] = 0),
            "byte 76: number of spectral tables (4.7.1.13): got 0 (identifier 4 needs 1 to 65536)".into(),
        ),
        (
            Box::new(|b| {
                b[264] = 0;
                b[272] = 1;
            }),
            "byte 264: radiant flux flag (4.7.2.3): must be 1 when the spectral data identifier is 4".into(),
        ),
        (
            // The second table's second wavelength (560 nm) turned to 100 nm: the first
            // table takes 28 bytes, the second's count 4, its first row 8.
            Box::new(|b| put_f32(b, 36288 + 28 + 4 + 8, 100.0)),
            "byte 36328: spectral table 2 (4.7.4): row 1: [100 nm, 1]: wavelengths must be positive and increasing".into(),
        ),
    ];
    for (edit, want) in cases {
        let e = error_after_in(&tables_set(), edit);
        assert!(e.contains(&want), "want '{want}' in: {e}");
    }
    // A table without power within 360-830 nm is named by its byte.
    let mut set = tables_set();
    if let FileSpectrum::Tables(t) = &mut set.spectrum {
        t[2] = vec![[900.0, 1.0], [950.0, 1.0]];
    }
    let e = error_after_in(&set, |_| {});
    let want = "byte 36352: spectral table 3 (4.7.4): the table has no power within 360-830 nm";
    assert!(e.contains(want), "want '{want}' in: {e}");
}

#[test]
fn the_writer_refuses_table_indices_that_do_not_fit() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.TM25RAY");
    let mut set = tables_set();
    set.table[3] = 3;
    let e = format!("{:#}", tm25::write(&path, &set).unwrap_err());
    assert!(e.contains("x.TM25RAY: ray 3: spectral table 4 of 3"), "{e}");
    set.table.pop();
    let e = format!("{:#}", tm25::write(&path, &set).unwrap_err());
    assert!(e.contains("4 rays but 3 spectral table indices"), "{e}");
    let mut set = tables_set();
    set.unit = FluxUnit::Lumen;
    let e = format!("{:#}", tm25::write(&path, &set).unwrap_err());
    assert!(
        e.contains("spectral tables per ray need radiant flux"),
        "{e}"
    );
}

/// The integral of `f(nm) x table(nm)` over `[a, b]` for the piecewise-linear table
/// `rows`, by the midpoint rule at 0.001 nm (independent of the code under test).
fn table_integral(rows: &[[f64; 2]], a: f64, b: f64, f: impl Fn(f64) -> f64) -> f64 {
    let at = |x: f64| {
        if x < rows[0][0] || x > rows[rows.len() - 1][0] {
            return 0.0;
        }
        let i = rows.iter().position(|r| r[0] >= x).unwrap().max(1);
        let (p, q) = (rows[i - 1], rows[i]);
        p[1] + (x - p[0]) / (q[0] - p[0]) * (q[1] - p[1])
    };
    let n = ((b - a) / 1e-3).ceil().max(1.0) as usize;
    let h = (b - a) / n as f64;
    (0..n)
        .map(|k| a + (k as f64 + 0.5) * h)
        .map(|x| f(x) * at(x) * h)
        .sum()
}

/// The probability of `[a, b]` under the table `rows`.
fn table_mass(rows: &[[f64; 2]], a: f64, b: f64) -> f64 {
    let (lo, hi) = (rows[0][0], rows[rows.len() - 1][0]);
    table_integral(rows, a, b, |_| 1.0) / table_integral(rows, lo, hi, |_| 1.0)
}

#[test]
fn photons_take_their_wavelengths_from_their_rays_tables() {
    let set = Arc::new(tables_set());
    let tables = blue_and_yellow();
    let e = RayFileEmitter::new(
        PathBuf::from("x.TM25RAY"),
        set.clone(),
        DMat3::IDENTITY,
        1.0,
        DVec3::ZERO,
    )
    .unwrap();
    // By table: the wavelengths of the photons of its rays (told apart by direction).
    let mut nm: [Vec<f64>; 2] = Default::default();
    let n = 200_000;
    for k in 0..n {
        let (ray, _, w) = e.emit(&mut PhotonRng::new(17, k));
        let i = set
            .rays
            .iter()
            .position(|r| (DVec3::from_array(r.dir.map(f64::from)) - ray.dir).length() < 1e-6)
            .unwrap();
        nm[set.table[i] as usize].push(w.unwrap());
    }
    // Flux shares: blue 0.375 / 1.875, yellow 1.5 / 1.875.
    let blue = nm[0].len() as f64 / n as f64;
    let se = (0.2 * 0.8 / n as f64).sqrt();
    assert!((blue - 0.2).abs() < 4.0 * se, "blue share {blue}");
    for (t, rows) in tables.iter().enumerate() {
        let (lo, hi) = (rows[0][0], rows[rows.len() - 1][0]);
        let bins = 12;
        let mut count = vec![0usize; bins];
        for &w in &nm[t] {
            assert!(
                (lo..=hi).contains(&w),
                "table {t}: {w} nm outside {lo}-{hi}"
            );
            count[(((w - lo) / (hi - lo) * bins as f64) as usize).min(bins - 1)] += 1;
        }
        let m = nm[t].len() as f64;
        for (b, &c) in count.iter().enumerate() {
            let edge = |k: usize| lo + (hi - lo) * k as f64 / bins as f64;
            let p = table_mass(rows, edge(b), edge(b + 1));
            let sigma = (m * p * (1.0 - p)).sqrt() + 1.0;
            assert!(
                (c as f64 - m * p).abs() < 4.5 * sigma,
                "table {t} bin {b}: {c} photons, expected {:.0} (+- {sigma:.0}): {count:?}",
                m * p
            );
        }
    }
    // The mean wavelengths: each its table's within 4 standard errors, so the blue rays'
    // photons are some 100 nm bluer than the yellow ones'.
    let mut means = [0.0; 2];
    for (t, rows) in tables.iter().enumerate() {
        let (lo, hi) = (rows[0][0], rows[rows.len() - 1][0]);
        let want = table_integral(rows, lo, hi, |x| x) / table_integral(rows, lo, hi, |_| 1.0);
        let m = nm[t].len() as f64;
        let mean = nm[t].iter().sum::<f64>() / m;
        let sd = (nm[t].iter().map(|w| (w - mean).powi(2)).sum::<f64>() / (m - 1.0)).sqrt();
        assert!(
            (mean - want).abs() < 4.0 * sd / m.sqrt(),
            "table {t}: mean {mean} nm, expected {want} (sd {sd})"
        );
        means[t] = mean;
    }
    assert!(means[1] - means[0] > 90.0, "{means:?}");
}

#[test]
fn the_summary_names_the_tables_per_ray() {
    let e = RayFileEmitter::new(
        PathBuf::from("x.TM25RAY"),
        Arc::new(tables_set()),
        DMat3::IDENTITY,
        1.0,
        DVec3::ZERO,
    )
    .unwrap();
    assert_eq!(
        e.summary().spectrum,
        "3 spectral tables, one per ray by index, 400-700 nm"
    );
    let mut bad = tables_set();
    bad.table[1] = 7;
    let e = RayFileEmitter::new(
        PathBuf::from("x.TM25RAY"),
        Arc::new(bad),
        DMat3::IDENTITY,
        1.0,
        DVec3::ZERO,
    )
    .unwrap_err();
    assert!(
        format!("{e}").contains("ray 1: spectral table 8 of 3"),
        "{e}"
    );
}

/// A spectral table's scale is free (TM-25-13 4.7.4: relative power): the file's table,
/// and its tables per ray, at 1e300 or 1e-300 give the colour and the draws of the same
/// tables at 1.
#[test]
fn spectral_tables_at_any_scale_draw_the_same_wavelengths() {
    let scaled = |rows: &[[f64; 2]], s: f64| -> Vec<[f64; 2]> {
        rows.iter().map(|&[nm, v]| [nm, v * s]).collect()
    };
    let looks = |set: &RaySet| {
        let e = set.emission_spectrum().unwrap().unwrap();
        let mut draws = vec![e.xyz_per_w().xy().unwrap().x, e.efficacy_lm_per_w()];
        for t in set.table_spectra().unwrap() {
            draws.extend((0..100).map(|k| t.sample((k as f64 + 0.5) / 100.0)));
        }
        draws
    };
    let at = |s: f64| {
        let mut one = sample_set();
        one.nm.clear();
        one.spectrum = FileSpectrum::Table(scaled(&blue_and_yellow()[1], s));
        let mut many = tables_set();
        if let FileSpectrum::Tables(t) = &mut many.spectrum {
            t.iter_mut().for_each(|rows| *rows = scaled(rows, s));
        }
        [looks(&one), looks(&many)]
    };
    let want = at(1.0);
    for s in [1e300, 1e-300] {
        for (got, want) in at(s).iter().zip(&want) {
            for (g, w) in got.iter().zip(want) {
                assert!(
                    (g - w).abs() <= 1e-12 * w.abs(),
                    "scale {s:e}: {g} against {w}"
                );
            }
        }
    }
}

/// Rays whose flux sums to 3.4e39 W, with no `power_w`, would be the source's power: the
/// error names the entry's file field and the file, and says the rays' flux is too large
/// (not a `power_w` the scene never set). Given `power_w`, the flux only weighs the rays.
#[test]
fn rays_too_bright_for_a_source_are_named_at_the_file() {
    let mut set = sample_set();
    set.nm.clear();
    set.spectrum = FileSpectrum::None;
    set.rays = (0..11)
        .map(|_| ray([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 3.1e38))
        .collect();
    let (dir, _) = written(&set);
    let scene = dir.path().join("scene.toml");
    let spec = |extra: &str| -> RayFileSpec {
        toml::from_str(&format!("file = \"led.TM25RAY\"\n{extra}")).unwrap()
    };
    let e = format!(
        "{:#}",
        spec("").emitter(&Ctx(&scene), "sources[1]").unwrap_err()
    );
    assert!(
        e.contains(
            "scene.toml: sources[1].file: led.TM25RAY: the rays' total flux is 3.41e39 W, too large"
        ),
        "{e}"
    );
    let e = spec("power_w = 0.5")
        .emitter(&Ctx(&scene), "sources[1]")
        .unwrap();
    assert!((e.probability(3) - 1.0 / 11.0).abs() < 1e-6);
}
