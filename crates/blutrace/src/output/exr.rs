//! Multi-channel 32-bit float OpenEXR images of 2D grids.
//!
//! [`write_channels`] stores any number of equally sized `f32` or `u32` grids as the
//! channels of a single-part, scan-line EXR file with lossless ZIP compression (16-line
//! blocks), plus header attributes: numbers as EXR `double`, text as EXR `string` (UTF-8
//! bytes, as OpenImageIO and OpenEXR's Python module read them), and the standard
//! `software` and `comments` attributes. [`read_channels`] reads such a file back exactly.
//! The header attributes are stored in name order, so the same image always gives the same
//! bytes.
//!
//! Channel names follow OpenEXR's layer convention: `Y` is a grey image (every viewer shows
//! it as luminance), `stderr.Y` is channel `Y` of layer `stderr`.
//!
//! Orientation: grids are row-major, `x` fastest, grid row 0 is the lowest `y`. EXR (like
//! every image format) stores its top row first, with image `y` pointing down, so the rows
//! are written in reverse order: grid row 0 is the *bottom* row of the image and the file
//! looks right (grid `y` up) in any EXR viewer. [`read_channels`] undoes the flip.

use std::collections::HashSet;
use std::path::Path;

use ::exr::meta::header::standard_names;
use ::exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image, Layer, LayerAttributes,
    ReadChannels, ReadLayers, SmallVec, Text, WritableImage, read,
};
use anyhow::{Context, Result, bail, ensure};

/// The contents of a file read by [`read_channels`]: `(width, height, channels,
/// attributes)`.
pub type ChannelImage = (
    usize,
    usize,
    Vec<(String, Vec<f32>)>,
    Vec<(String, Attribute)>,
);

/// The samples of one channel, row-major with row 0 at the lowest `y`.
#[derive(Clone, Copy, Debug)]
pub enum Samples<'a> {
    /// 32-bit float samples (values).
    F32(&'a [f32]),
    /// 32-bit unsigned integer samples (counts, exact to 2^32 - 1).
    U32(&'a [u32]),
}

impl Samples<'_> {
    fn len(&self) -> usize {
        match self {
            Samples::F32(v) => v.len(),
            Samples::U32(v) => v.len(),
        }
    }

    /// The samples with the rows in reverse order.
    fn flipped(&self, width: usize) -> FlatSamples {
        match self {
            Samples::F32(v) => {
                FlatSamples::F32(v.rchunks_exact(width).flatten().copied().collect())
            }
            Samples::U32(v) => {
                FlatSamples::U32(v.rchunks_exact(width).flatten().copied().collect())
            }
        }
    }
}

/// A header attribute value.
#[derive(Clone, Debug, PartialEq)]
pub enum Attribute {
    /// EXR `double`.
    F64(f64),
    /// EXR `string`.
    Text(String),
}

/// Attribute names written into the standard EXR fields rather than as custom attributes.
const STANDARD_TEXT: [&str; 2] = ["software", "comments"];

/// Write a `width × height` grid with one `f32` channel per entry of `channels` to the
/// OpenEXR file `path` (overwriting it), with the numeric header `attributes`.
///
/// Each channel slice is row-major (`x` fastest) with row 0 at the lowest `y`; it must hold
/// exactly `width * height` values. Row 0 is written as the bottom row of the image (see the
/// module docs). Channel names must be unique, non-empty, Latin-1 and at most 255 bytes;
/// EXR stores channels in alphabetical order. Attribute names must be unique, follow the
/// same rules and must not be a standard EXR attribute name (such as `channels`, `owner`,
/// `dataWindow`) other than `software` and `comments` (text, stored in those standard
/// attributes). Compression is lossless ZIP.
///
/// The same arguments always give the same bytes. The file is written directly to `path`; use
/// [`OutputSet`](crate::output::atomic::OutputSet) for all-or-nothing output.
pub fn write_channels(
    path: &Path,
    width: usize,
    height: usize,
    channels: &[(&str, Samples)],
    attributes: &[(&str, Attribute)],
) -> Result<()> {
    let what = || format!("cannot write EXR image {}", path.display());
    let image = build_image(width, height, channels, attributes).with_context(what)?;
    // Compress on this thread: parallel compression stores blocks in completion order,
    // so the same image would give different bytes from run to run.
    let mut bytes = std::io::Cursor::new(Vec::new());
    image
        .write()
        .non_parallel()
        .to_buffered(&mut bytes)
        .with_context(what)?;
    let mut bytes = bytes.into_inner();
    sort_header_attributes(&mut bytes).with_context(what)?;
    std::fs::write(path, bytes).with_context(what)
}

/// Put the header attributes of a single-part EXR file in name order, in place.
///
/// The exr crate writes the attributes it keeps in a hash map in that map's order, which
/// changes from run to run; sorted, the same image always gives the same bytes. The header
/// keeps its length, so the offset table after it stays valid.
fn sort_header_attributes(bytes: &mut [u8]) -> Result<()> {
    const HEADER_START: usize = 8; // magic number and version field
    let mut attributes: Vec<&[u8]> = Vec::new();
    let mut i = HEADER_START;
    while *bytes.get(i).context("header has no end")? != 0 {
        let start = i;
        let name_end = nul_after(bytes, i)?;
        let type_end = nul_after(bytes, name_end + 1)?;
        let size_bytes = bytes
            .get(type_end + 1..type_end + 5)
            .context("header attribute size is cut off")?;
        let size = u32::from_le_bytes(size_bytes.try_into()?) as usize;
        i = type_end + 5 + size;
        ensure!(i <= bytes.len(), "header attribute value is cut off");
        attributes.push(&bytes[start..i]);
    }
    let name = |a: &&[u8]| a.split(|&b| b == 0).next().unwrap_or_default().to_vec();
    attributes.sort_by_key(name);
    let sorted: Vec<u8> = attributes.concat();
    bytes[HEADER_START..i].copy_from_slice(&sorted);
    Ok(())
}

/// Index of the first NUL byte at or after `from`.
fn nul_after(bytes: &[u8], from: usize) -> Result<usize> {
    let rest = bytes.get(from..).context("header is cut off")?;
    let at = rest
        .iter()
        .position(|&b| b == 0)
        .context("header text has no end")?;
    Ok(from + at)
}

/// Validate the arguments of [`write_channels`] and assemble the EXR image.
fn build_image(
    width: usize,
    height: usize,
    channels: &[(&str, Samples)],
    attributes: &[(&str, Attribute)],
) -> Result<Image<Layer<AnyChannels<FlatSamples>>>> {
    ensure!(width > 0 && height > 0, "empty grid ({width} × {height})");
    // EXR stores the data window in i32 coordinates.
    let max_side = i32::MAX as usize / 2;
    ensure!(
        width <= max_side && height <= max_side,
        "grid {width} × {height} is too large for EXR"
    );
    let count = width
        .checked_mul(height)
        .with_context(|| format!("grid {width} × {height} is too large"))?;
    ensure!(!channels.is_empty(), "no channels to write");

    let mut seen = HashSet::new();
    let mut list = SmallVec::new();
    for &(name, data) in channels {
        let text = exr_name(name).with_context(|| format!("invalid channel name {name:?}"))?;
        ensure!(seen.insert(name), "duplicate channel name {name:?}");
        ensure!(
            data.len() == count,
            "channel {name:?} has {} values, expected {width} × {height} = {count}",
            data.len()
        );
        // Grid row 0 (lowest y) becomes the bottom image row.
        list.push(AnyChannel::new(text, data.flipped(width)));
    }

    let mut layer_attributes = LayerAttributes::default();
    let mut names = HashSet::new();
    for (name, value) in attributes {
        let text = exr_name(name).with_context(|| format!("invalid attribute name {name:?}"))?;
        ensure!(names.insert(*name), "duplicate attribute name {name:?}");
        let value = match value {
            Attribute::F64(v) => AttributeValue::F64(*v),
            Attribute::Text(s) => {
                ensure!(
                    !s.contains('\0'),
                    "attribute {name:?} contains a NUL character"
                );
                AttributeValue::Text(Text::from_slice_unchecked(s.as_bytes()))
            }
        };
        match (*name, value) {
            ("software", AttributeValue::Text(t)) => layer_attributes.software_name = Some(t),
            ("comments", AttributeValue::Text(t)) => layer_attributes.comments = Some(t),
            (n, _) if STANDARD_TEXT.contains(&n) => bail!("attribute {n:?} must be text"),
            (n, _) if standard_names::ALL.contains(&n.as_bytes()) => {
                bail!("attribute name {n:?} is reserved by the EXR format")
            }
            (_, value) => {
                layer_attributes.other.insert(text, value);
            }
        }
    }

    let layer = Layer::new(
        (width, height),
        layer_attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    Ok(Image::from_layer(layer))
}

/// Convert a channel or attribute name to EXR text, checking the format's rules.
fn exr_name(name: &str) -> Result<Text> {
    ensure!(!name.is_empty(), "name is empty");
    ensure!(!name.contains('\0'), "name contains a NUL character");
    let text = Text::new_or_none(name).context("name has characters outside Latin-1")?;
    ensure!(text.bytes().len() <= 255, "name is longer than 255 bytes");
    Ok(text)
}

/// Read an OpenEXR file written by [`write_channels`]: returns `(width, height, channels,
/// attributes)`.
///
/// The rows are flipped back, so each channel is again row-major with row 0 at the lowest
/// `y`, exactly as it was passed to [`write_channels`]. Channels come in the file's
/// (alphabetical) order, samples of any type converted to `f32`. Attributes are the custom
/// `double`, `float` and `string` header attributes (other types are skipped) and the
/// standard `software` and `comments`, sorted by name. Only the first layer and its full
/// resolution level are read.
pub fn read_channels(path: &Path) -> Result<ChannelImage> {
    let what = || format!("cannot read EXR image {}", path.display());
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .with_context(what)?;

    let layer = &image.layer_data;
    let (width, height) = (layer.size.width(), layer.size.height());
    if width == 0 || height == 0 {
        bail!("{}: empty image ({width} × {height})", what());
    }
    let count = width * height;
    let mut channels = Vec::with_capacity(layer.channel_data.list.len());
    for channel in &layer.channel_data.list {
        let samples: Vec<f32> = channel.sample_data.values_as_f32().collect();
        ensure!(
            samples.len() == count,
            "{}: channel {} has {} samples instead of {width} × {height} (subsampled?)",
            what(),
            channel.name,
            samples.len()
        );
        let unflipped = samples.rchunks_exact(width).flatten().copied().collect();
        channels.push((channel.name.to_string(), unflipped));
    }

    let text = |t: &Text| Attribute::Text(String::from_utf8_lossy(t.bytes()).into_owned());
    let la = &layer.attributes;
    let standard = [("software", &la.software_name), ("comments", &la.comments)];
    let mut attributes: Vec<(String, Attribute)> = image
        .attributes
        .other
        .iter()
        .chain(&la.other)
        .filter_map(|(name, value)| match value {
            AttributeValue::F64(v) => Some((name.to_string(), Attribute::F64(*v))),
            AttributeValue::F32(v) => Some((name.to_string(), Attribute::F64(f64::from(*v)))),
            AttributeValue::Text(t) => Some((name.to_string(), text(t))),
            _ => None,
        })
        .chain(
            standard
                .iter()
                .filter_map(|(n, t)| t.as_ref().map(|t| (n.to_string(), text(t)))),
        )
        .collect();
    attributes.sort_by(|a, b| a.0.cmp(&b.0));
    Ok((width, height, channels, attributes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    /// A path (not yet a file) in a fresh temporary folder, removed on drop.
    struct TempFile(PathBuf, #[allow(dead_code)] tempfile::TempDir);

    impl TempFile {
        fn new(tag: &str) -> Self {
            let dir = tempfile::Builder::new()
                .prefix(&format!("blutrace-exr-{tag}-"))
                .tempdir()
                .unwrap();
            Self(dir.path().join("file.exr"), dir)
        }
    }

    #[test]
    fn same_image_gives_same_bytes() {
        // Each write builds a new hash map of attributes, with its own random order.
        let attributes: Vec<(String, f64)> = (0..12)
            .map(|k| (format!("attr_{k:02}"), k as f64))
            .collect();
        let mut attributes: Vec<(&str, Attribute)> = attributes
            .iter()
            .map(|(n, v)| (n.as_str(), Attribute::F64(*v)))
            .collect();
        attributes.push(("scene", Attribute::Text("Prüfstand 測試".into())));
        attributes.push(("software", Attribute::Text("blutrace test".into())));
        let data: Vec<f32> = (0..6).map(|i| i as f32).collect();
        let files: Vec<Vec<u8>> = (0..6)
            .map(|_| {
                let file = TempFile::new("same-bytes");
                let channels = [("Y", Samples::F32(&data))];
                write_channels(&file.0, 3, 2, &channels, &attributes).unwrap();
                std::fs::read(&file.0).unwrap()
            })
            .collect();
        assert!(files.windows(2).all(|w| w[0] == w[1]));
        let file = TempFile::new("same-bytes-read");
        std::fs::write(&file.0, &files[0]).unwrap();
        let (_, _, channels, read) = read_channels(&file.0).unwrap();
        assert_eq!(channels[0].1, data);
        let mut expected: Vec<(String, Attribute)> = attributes
            .iter()
            .map(|(n, v)| (n.to_string(), v.clone()))
            .collect();
        expected.sort_by(|a, b| a.0.cmp(&b.0));
        assert_eq!(read, expected);
    }

    #[test]
    fn round_trip_is_exact() {
        let (w, h) = (7, 5);
        let flux: Vec<f32> = (0..w * h)
            .map(|i| (i as f32 * 0.37).sin() * 1e3 + 1e-7)
            .collect();
        let err: Vec<f32> = (0..w * h)
            .map(|i| if i == 3 { f32::NAN } else { i as f32 / 3.0 })
            .collect();
        let count: Vec<u32> = (0..w * h).map(|i| (i * i) as u32).collect();
        let attrs = [
            ("bin_size_x_mm", Attribute::F64(0.1234567890123)),
            ("bin_size_y_mm", Attribute::F64(2.5)),
            ("seed", Attribute::Text(u64::MAX.to_string())),
        ];
        let f = TempFile::new("rt");
        write_channels(
            &f.0,
            w,
            h,
            &[
                ("Y", Samples::F32(&flux)),
                ("hits.Y", Samples::U32(&count)),
                ("stderr.Y", Samples::F32(&err)),
            ],
            &attrs,
        )
        .unwrap();

        let (rw, rh, channels, attributes) = read_channels(&f.0).unwrap();
        assert_eq!((rw, rh), (w, h));
        let names: Vec<&str> = channels.iter().map(|c| c.0.as_str()).collect();
        assert_eq!(names, ["Y", "hits.Y", "stderr.Y"]);
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let count_f32: Vec<f32> = count.iter().map(|&c| c as f32).collect();
        assert_eq!(bits(&channels[0].1), bits(&flux));
        assert_eq!(bits(&channels[1].1), bits(&count_f32));
        assert_eq!(bits(&channels[2].1), bits(&err));
        let expected: Vec<(String, Attribute)> = attrs
            .iter()
            .map(|(n, v)| (n.to_string(), v.clone()))
            .collect();
        assert_eq!(attributes, expected);
    }

    #[test]
    fn grid_row_zero_is_the_bottom_image_row() {
        let (w, h) = (3, 4);
        let v: Vec<f32> = (0..w * h).map(|i| (i / w) as f32).collect(); // value = grid row
        let f = TempFile::new("flip");
        write_channels(&f.0, w, h, &[("Y", Samples::F32(&v))], &[]).unwrap();
        // Read with the plain exr API: its first stored row is the top of the image.
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_file(&f.0)
            .unwrap();
        let raw: Vec<f32> = image.layer_data.channel_data.list[0]
            .sample_data
            .values_as_f32()
            .collect();
        assert_eq!(&raw[..w], &[3.0; 3]); // top row = highest grid row
        assert_eq!(&raw[raw.len() - w..], &[0.0; 3]); // bottom row = grid row 0
        assert_eq!(read_channels(&f.0).unwrap().2[0].1, v);
    }

    #[test]
    fn compression_is_lossless_zip() {
        let image = build_image(2, 2, &[("a", Samples::F32(&[1.0, 2.0, 3.0, 4.0]))], &[]).unwrap();
        assert_eq!(
            image.layer_data.encoding.compression,
            ::exr::prelude::Compression::ZIP16
        );
    }

    #[test]
    fn invalid_arguments_are_errors() {
        let f = TempFile::new("bad");
        let four = [0.0f32; 4];
        let three = [0.0f32; 3];
        let (four, three) = (Samples::F32(&four), Samples::F32(&three));
        let (one, two) = (Attribute::F64(1.0), Attribute::F64(2.0));
        type Case<'a> = (
            usize,
            usize,
            Vec<(&'a str, Samples<'a>)>,
            Vec<(&'a str, Attribute)>,
            &'a str,
        );
        let cases: Vec<Case> = vec![
            (2, 2, vec![("a", three)], vec![], "3 values"),
            (0, 2, vec![("a", Samples::F32(&[]))], vec![], "empty grid"),
            (2, 2, vec![], vec![], "no channels"),
            (
                2,
                2,
                vec![("a", four), ("a", four)],
                vec![],
                "duplicate channel",
            ),
            (2, 2, vec![("", four)], vec![], "empty"),
            (2, 2, vec![("√", four)], vec![], "Latin-1"),
            (
                2,
                2,
                vec![("a", four)],
                vec![("owner", one.clone())],
                "reserved",
            ),
            (
                2,
                2,
                vec![("a", four)],
                vec![("k", one.clone()), ("k", two)],
                "duplicate attribute",
            ),
            (usize::MAX, 2, vec![("a", four)], vec![], "too large"),
            (
                2,
                2,
                vec![("a", four)],
                vec![("software", one)],
                "must be text",
            ),
        ];
        for (w, h, ch, at, msg) in cases {
            let err = write_channels(&f.0, w, h, &ch, &at).unwrap_err();
            assert!(
                format!("{err:#}").contains(msg),
                "expected {msg:?} in {err:#}"
            );
        }
        assert!(!f.0.exists());
        assert!(read_channels(&f.0).is_err());
    }
}
