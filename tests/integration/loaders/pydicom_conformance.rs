//! Every DICOM image among pydicom's own test files (shipped with the pydicom wheel: real files
//! from scanners, DCMTK, GDCM and pydicom, in every common codec and byte order), and the team's
//! vendor files, read by LeapView and by pydicom (with its pylibjpeg decoders): where pydicom
//! decodes a file, LeapView opens it with the same values (exactly for lossless syntaxes, within
//! a codec's rounding for lossy ones); where pydicom cannot, LeapView refuses it with a message
//! naming the file, or opens it. Each file is read from a folder of its own, as a user opening
//! one file would.

use std::path::{Path, PathBuf};

use leapview::volume::{LoadOptions, Volume, load_volume};
use serde_json::Value;

use crate::common::{self, data_dir, run_python};

/// What pydicom made of one file.
struct Reference {
    file: PathBuf,
    entry: Value,
    samples: Option<Vec<f64>>,
}

fn references(out: &Path) -> Vec<Reference> {
    let vendor: Vec<PathBuf> = std::fs::read_dir(data_dir().join("dicom/vendor"))
        .expect("the team's vendor files")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "dcm"))
        .collect();
    let mut args: Vec<&Path> = vec![out];
    args.extend(vendor.iter().map(PathBuf::as_path));
    run_python("pydicom_reference.py", &args);
    let manifest: Vec<Value> = serde_json::from_slice(
        &std::fs::read(out.join("manifest.json")).expect("the reference's manifest"),
    )
    .expect("JSON");
    manifest
        .into_iter()
        .map(|entry| {
            let samples = entry["samples"].as_str().map(|name| {
                std::fs::read(out.join(name))
                    .expect("the reference's samples")
                    .chunks_exact(8)
                    .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
                    .collect()
            });
            Reference {
                file: PathBuf::from(entry["file"].as_str().expect("a path")),
                entry,
                samples,
            }
        })
        .collect()
}

/// The largest difference between LeapView's stored samples of slice `k` and pydicom's frame
/// `f` (grey, or each of red, green and blue for colour), reading LeapView's column i where the
/// file's was (undoing an unmirroring).
fn frame_difference(v: &Volume, k: u32, reference: &[f64], f: usize) -> f64 {
    let [nx, ny, _] = v.dims();
    let plane = nx as usize * ny as usize;
    let channels = if v.colour().is_some() { 3 } else { 1 };
    let mut worst = 0.0f64;
    for y in 0..ny {
        for x in 0..nx {
            let file_x = if v.reversed_i() { nx - 1 - x } else { x };
            let at = (f * plane + (y * nx + file_x) as usize) * channels;
            let index = v.index(x, y, k);
            for c in 0..channels {
                let ours = match v.colour() {
                    Some(colour) => colour.channels()[c].get_f64(index),
                    None => v.samples().expect("in memory").get_f64(index),
                };
                worst = worst.max((ours - reference[at + c]).abs());
            }
        }
    }
    worst
}

#[test]
fn every_image_pydicom_decodes_opens_with_pydicoms_values() {
    let out = common::TempDir::new("pydicom-reference");
    let references = references(out.path());
    let mut report = Vec::new();
    let mut failures = Vec::new();
    for r in &references {
        let name = r
            .file
            .file_name()
            .expect("a name")
            .to_string_lossy()
            .into_owned();
        if r.entry["image"] != Value::Bool(true) {
            continue;
        }
        let dir = common::TempDir::new("pydicom-file");
        std::fs::copy(&r.file, dir.path().join(&name)).expect("copy");
        let loaded = load_volume(&dir.path().join(&name), &LoadOptions::default());
        let decoded = r.entry["decoded"] == Value::Bool(true);
        // Segmentations are not images to show as they are (the issue "Segmentations" reads
        // them as labels over an image); a refusal must say what the file is.
        let segmentation = loaded
            .as_ref()
            .err()
            .is_some_and(|e| e.to_string().contains("DICOM segmentation (SEG)"));
        let outcome = match (&loaded, &r.samples) {
            (Err(e), _) if segmentation => format!("a segmentation, not an image: {e}"),
            (Err(e), _) if !decoded => {
                let text = e.to_string();
                if !text.contains(&name) {
                    failures.push(format!(
                        "{name}: the refusal does not name the file: {text}"
                    ));
                }
                format!("refused, as pydicom: {text}")
            }
            (Ok(_), _) if !decoded => "opens; pydicom cannot decode it".to_string(),
            (Err(e), _) => {
                failures.push(format!("{name}: pydicom decodes it, LeapView refuses: {e}"));
                format!("REFUSED: {e}")
            }
            (Ok(v), Some(samples)) => {
                let frames = r.entry["frames"].as_u64().unwrap_or(1) as usize;
                let [nx, ny, nz] = v.dims();
                let shape_ok = (nx as u64, ny as u64)
                    == (
                        r.entry["columns"].as_u64().unwrap_or(0),
                        r.entry["rows"].as_u64().unwrap_or(0),
                    )
                    && nz as usize == frames;
                let colour = r.entry["colour"] == Value::Bool(true);
                if colour != v.colour().is_some() {
                    failures.push(format!(
                        "{name}: colour {} where pydicom says {colour}",
                        v.colour().is_some()
                    ));
                    "COLOUR DIFFERS".to_string()
                } else if !shape_ok {
                    failures.push(format!(
                        "{name}: {nx} x {ny} x {nz}, pydicom {} x {} x {frames}",
                        r.entry["columns"], r.entry["rows"]
                    ));
                    "SHAPE DIFFERS".to_string()
                } else {
                    // Slices may be reordered by position: each must equal some frame.
                    let lossy = r.entry["lossy"] == Value::Bool(true);
                    let worst = (0..nz)
                        .map(|k| {
                            (0..frames)
                                .map(|f| frame_difference(v, k, samples, f))
                                .fold(f64::INFINITY, f64::min)
                        })
                        .fold(0.0f64, f64::max);
                    // Lossy codecs: two decoders' IDCT or wavelet rounding (libjpeg-turbo against
                    // libjpeg, hayro against OpenJPEG) differ by a level or two, and their
                    // upsampling of subsampled chroma by one more.
                    let tolerance = match (lossy, colour) {
                        (false, _) => 0.0,
                        (true, false) => 2.0,
                        (true, true) => 3.0,
                    };
                    if worst > tolerance {
                        failures.push(format!(
                            "{name}: values differ from pydicom's by up to {worst}"
                        ));
                    }
                    format!(
                        "same {} (largest difference {worst}{})",
                        if colour { "colours" } else { "values" },
                        if lossy { ", lossy" } else { "" }
                    )
                }
            }
            (Ok(_), None) => "opens".to_string(),
        };
        report.push(format!("{name}: {outcome}"));
    }
    println!("{}", report.join("\n"));
    assert!(
        report.len() >= 90,
        "{} images: pydicom's test files are missing",
        report.len()
    );
    assert!(
        failures.is_empty(),
        "{} of {} files:\n{}",
        failures.len(),
        report.len(),
        failures.join("\n")
    );
}
