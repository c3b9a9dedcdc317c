use super::*;

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
        spectrum: FileSpectrum::PerRay,
        unit: FluxUnit::Watt,
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
    let (_dir, path) = written(&sample_set());
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
            "byte 60: spectral data identifier (4.7.1.9): per-ray spectral tables",
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
