//! The EXR images as other tools read them: OpenImageIO (`oiiotool`), OpenEXR's `exrheader`
//! and OpenEXR's Python module. Each part runs only when its tool is installed and prints a
//! note otherwise (Debian: `apt-get install openimageio-tools openexr`; `pip install
//! OpenEXR`).

use blutrace::output::exr::{Attribute, read_channels};
use std::path::Path;
use std::process::Command;

/// A run of phone-led (whose lamps give lumens, so angular.exr has luminance layers) with
/// the largest seed, which a `double` attribute could not hold.
fn run() -> tempfile::TempDir {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let ok = Command::new(env!("CARGO_BIN_EXE_blutrace"))
        .args(["trace", "scenes/phone-led", "--photons", "20000", "--quiet"])
        .args(["--seed", &u64::MAX.to_string(), "--out"])
        .arg(&out)
        .status()
        .unwrap()
        .success();
    assert!(ok);
    tmp
}

/// `program args...`'s stdout, or None (with a note) when the program is not installed.
fn tool(program: &str, args: &[&str]) -> Option<String> {
    match Command::new(program).args(args).output() {
        Ok(o) => {
            assert!(
                o.status.success(),
                "{program} {args:?}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
            Some(String::from_utf8_lossy(&o.stdout).into_owned())
        }
        Err(_) => {
            println!("note: {program} not installed, its part of the test skipped");
            None
        }
    }
}

fn text_attribute(file: &Path, name: &str) -> String {
    let (_, _, _, attrs) = read_channels(file).unwrap();
    match attrs.iter().find(|(n, _)| n == name) {
        Some((_, Attribute::Text(t))) => t.clone(),
        other => panic!("{name}: {other:?}"),
    }
}

#[test]
fn oiiotool_and_exrheader_see_grey_images_with_layers_and_attributes() {
    let tmp = run();
    let flux = tmp.path().join("out/flux.exr");
    let angular = tmp.path().join("out/angular.exr");
    let (f, a) = (flux.to_str().unwrap(), angular.to_str().unwrap());
    let seed = u64::MAX.to_string();
    let hash = text_attribute(&flux, "scene_hash");
    assert_eq!(hash.len(), 16);
    if let Some(info) = tool("oiiotool", &["--info", "-v", f]) {
        for want in [
            "channel list: Y, hits.Y, preview.Y, stderr.Y".to_string(),
            format!("seed: \"{seed}\""),
            "units: \"W/mm^2\"".into(),
            "scene: \"phone-led\"".into(),
            format!("scene_hash: \"{hash}\""),
            format!("software: \"blutrace {}\"", env!("CARGO_PKG_VERSION")),
            "detector_u: \"[1, 0, 0]\"".into(),
            "detector_origin_mm: \"[2, 0, 0.85]\"".into(),
            "size_x_mm: \"138\"".into(),
            "ImageDescription: \"blutrace flux map: Y = irradiance".into(),
        ] {
            assert!(info.contains(&want), "{want} not in\n{info}");
        }
        let info = tool("oiiotool", &["--info", "-v", a]).unwrap();
        for want in [
            "channel list: Y, hits.Y, luminance.Y, luminance_stderr.Y, stderr.Y",
            "units: \"W/sr\"",
            "luminance_units: \"cd/m^2\"",
        ] {
            assert!(info.contains(want), "{want} not in\n{info}");
        }
        // Channel Y alone is the grey irradiance image.
        let grey = tmp.path().join("grey.exr");
        tool("oiiotool", &[f, "--ch", "Y", "-o", grey.to_str().unwrap()]).unwrap();
        let (_, _, ours, _) = read_channels(&flux).unwrap();
        let (_, _, theirs, _) = read_channels(&grey).unwrap();
        assert_eq!(theirs.len(), 1);
        assert_eq!(theirs[0], ours[0], "Y through oiiotool");
        // The README's recipe: the preview layer as a grey PNG, the mean mid-grey.
        let png = tmp.path().join("flux.png");
        tool(
            "oiiotool",
            &[f, "--ch", "Y=preview.Y", "-o", png.to_str().unwrap()],
        )
        .unwrap();
        let stats = tool("oiiotool", &["--stats", png.to_str().unwrap()]).unwrap();
        let avg: f64 = stats
            .lines()
            .find_map(|l| l.trim().strip_prefix("Stats Avg:"))
            .and_then(|l| l.split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("no average in\n{stats}"));
        // 8-bit levels; bins above twice the mean clip to white, pulling the mean down.
        assert!(
            (0.35..0.6).contains(&(avg / 255.0)),
            "PNG mean {avg} of 255 (half is mid-grey)\n{stats}"
        );
        // Counts read as counts (integer channels are normalised to [0, 1] on reading).
        let hits = tmp.path().join("hits.exr");
        tool(
            "oiiotool",
            &[f, "--ch", "hits.Y", "-o", hits.to_str().unwrap()],
        )
        .unwrap();
        let (_, _, theirs, _) = read_channels(&hits).unwrap();
        assert_eq!(theirs[0].1, ours[1].1, "hits through oiiotool");
        assert!(theirs[0].1.iter().any(|&h| h >= 2.0));
    }
    if let Some(header) = tool("exrheader", &[f]) {
        for want in [
            "Y, 32-bit floating-point".to_string(),
            "hits.Y, 32-bit floating-point".into(),
            "stderr.Y, 32-bit floating-point".into(),
            format!("seed (type string): \"{seed}\""),
            "units (type string): \"W/mm^2\"".into(),
            "comments (type string): \"blutrace flux map".into(),
        ] {
            assert!(header.contains(&want), "{want} not in\n{header}");
        }
    }
}

#[test]
fn python_openexr_reads_channels_and_attributes() {
    let tmp = run();
    let flux = tmp.path().join("out/flux.exr");
    let script = r#"
import json, sys
try:
    import OpenEXR
except ImportError:
    print("missing"); sys.exit(0)
out = {}
with OpenEXR.File(sys.argv[1]) as f:
    h = f.header()
    out["attrs"] = {k: h[k] for k in ["seed", "scene", "units", "size_x_mm", "detector_origin_mm"]}
    ch = f.channels()
    out["channels"] = {k: str(v.pixels.dtype) for k, v in ch.items()}
    y = ch["Y"].pixels
    out["top_left"] = float(y[0][0])
    out["shape"] = list(y.shape)
    out["hits"] = float(ch["hits.Y"].pixels.astype("float64").sum())
# The old API (what older scripts use) reads the text attributes too.
old = OpenEXR.InputFile(sys.argv[1]).header()
out["old_seed"] = old["seed"].decode()
out["old_size"] = old["size_x_mm"].decode()
print(json.dumps(out))
"#;
    let Ok(o) = Command::new("python3")
        .arg("-c")
        .arg(script)
        .arg(&flux)
        .output()
    else {
        println!("note: python3 not installed, test skipped");
        return;
    };
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    if text.trim() == "missing" {
        println!("note: Python module OpenEXR not installed, test skipped");
        return;
    }
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let seed = u64::MAX.to_string();
    assert_eq!(v["attrs"]["seed"], seed.as_str());
    assert_eq!(v["old_seed"], seed.as_str());
    assert_eq!(v["attrs"]["scene"], "phone-led");
    assert_eq!(v["attrs"]["units"], "W/mm^2");
    assert_eq!(v["attrs"]["size_x_mm"], "138");
    assert_eq!(v["old_size"], "138");
    assert_eq!(v["channels"]["Y"], "float32");
    assert_eq!(v["channels"]["stderr.Y"], "float32");
    assert_eq!(v["channels"]["hits.Y"], "float32");
    // Python's first row is the image's top row: our grid's highest y.
    let (nx, ny, ours, _) = read_channels(&flux).unwrap();
    assert_eq!(v["shape"], serde_json::json!([ny, nx]));
    assert_eq!(
        v["top_left"].as_f64().unwrap(),
        ours[0].1[(ny - 1) * nx] as f64
    );
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(tmp.path().join("out/summary.json")).unwrap())
            .unwrap();
    let hits: f64 = ours[1].1.iter().map(|&h| h as f64).sum();
    assert_eq!(v["hits"].as_f64().unwrap(), hits);
    assert!(summary["ledger"]["detected_w"].as_f64().unwrap() > 0.0);
}

/// Positions in the outputs are in the scene file's frame: the EXR attribute and
/// summary.json's detector block give the origin as phone-led's scene file writes it
/// (the tracer works in a frame moved to the scene's centre).
#[test]
fn detector_frame_is_the_scene_files() {
    let tmp = run();
    let flux = tmp.path().join("out/flux.exr");
    assert_eq!(text_attribute(&flux, "detector_origin_mm"), "[2, 0, 0.85]");
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(tmp.path().join("out/summary.json")).unwrap())
            .unwrap();
    let d = &summary["detector"];
    assert_eq!(d["origin_mm"], serde_json::json!([2.0, 0.0, 0.85]));
    assert_eq!(d["u"], serde_json::json!([1.0, 0.0, 0.0]));
    assert_eq!(d["v"], serde_json::json!([0.0, 1.0, 0.0]));
    assert_eq!(d["size_mm"], serde_json::json!([138.0, 68.0]));
    assert_eq!(d["bins"], serde_json::json!([138, 68]));
    // hits.Y holds whole photon counts; preview.Y has mean 1/2.
    let (_, _, channels, _) = read_channels(&flux).unwrap();
    let hits = &channels.iter().find(|(n, _)| n == "hits.Y").unwrap().1;
    assert!(hits.iter().all(|h| h.fract() == 0.0 && *h >= 0.0));
    let preview = &channels.iter().find(|(n, _)| n == "preview.Y").unwrap().1;
    let mean = preview.iter().map(|&p| p as f64).sum::<f64>() / preview.len() as f64;
    assert!((mean - 0.5).abs() < 1e-4, "preview mean {mean}");
}
