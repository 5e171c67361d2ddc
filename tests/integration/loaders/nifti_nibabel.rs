//! NIfTI files written by nibabel (`scripts/python/nibabel_files.py`): 4-D time series (any
//! volume of them), NIfTI-2 (64-bit sizes, double fields), big-endian, scaled samples, each read
//! with nibabel's values, spacing and origin; and an MR-like volume with negative values and no
//! modality, which is not taken for CT.

use leapview::transfer::fit::DataKind;
use leapview::volume::{LoadOptions, VolumeIndex, load_volume};
use serde_json::Value;

use crate::common::{self, run_python};

#[test]
fn nibabels_files_open_with_nibabels_values() {
    let out = common::TempDir::new("nibabel");
    run_python("nibabel_files.py", &[out.path()]);
    let cases: Vec<Value> =
        serde_json::from_slice(&std::fs::read(out.path().join("cases.json")).expect("the cases"))
            .expect("JSON");
    assert!(cases.len() >= 7);
    for case in &cases {
        let name = case["name"].as_str().expect("a name");
        let volume = case["volume"].as_u64().expect("a volume") as u32;
        let count = case["volumes"].as_u64().expect("a count") as u32;
        let path = out.path().join(case["file"].as_str().expect("a file"));
        // The first volume by default; any other when asked for.
        let options = LoadOptions {
            volume: (volume > 0).then_some(volume),
            ..LoadOptions::default()
        };
        let v = load_volume(&path, &options).unwrap_or_else(|e| panic!("{name}: {e}"));
        let dims: Vec<u32> = case["dims"]
            .as_array()
            .expect("dims")
            .iter()
            .map(|d| d.as_u64().expect("a size") as u32)
            .collect();
        assert_eq!(v.dims().to_vec(), dims, "{name}");
        // NIfTI-1 holds pixdim as f32.
        let spacing = v.spacing_mm();
        assert!(
            spacing
                .iter()
                .zip([0.9, 1.1, 2.5])
                .all(|(a, b)| (a - b).abs() < 1e-6),
            "{name}: {spacing:?}"
        );
        assert_eq!(
            v.orientation().map(|o| o.code()),
            Some("RAS".to_string()),
            "{name}"
        );
        let origin = v.provenance().origin_lps.expect("an origin");
        assert!(
            (origin[0] - 10.0).abs() < 1e-5
                && (origin[1] + 20.0).abs() < 1e-5
                && (origin[2] - 5.5).abs() < 1e-5,
            "{name}: origin {origin:?}"
        );
        let expected_index = (count > 1).then_some(VolumeIndex {
            chosen: volume,
            count,
        });
        assert_eq!(v.provenance().volumes, expected_index, "{name}");
        let reference: Vec<f64> = std::fs::read(out.path().join(format!("{name}.f64")))
            .expect("nibabel's data")
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
            .collect();
        assert_eq!(reference.len() as u64, v.sample_count(), "{name}");
        let [nx, ny, _] = v.dims();
        for (i, &want) in reference.iter().enumerate() {
            let (x, y, z) = (i as u32 % nx, (i as u32 / nx) % ny, i as u32 / (nx * ny));
            let got = v.value(x, y, z);
            // f32 samples: nibabel's float64 of the same f32.
            assert!(
                (got - want).abs() <= 1e-9 * want.abs().max(1.0),
                "{name} ({x}, {y}, {z}): {got} vs {want}"
            );
        }
    }
    // Negative values are not evidence of Hounsfield units without air and soft tissue where
    // CT has them.
    let mr = load_volume(
        &out.path().join("mr_negative.nii.gz"),
        &LoadOptions::default(),
    )
    .expect("MR");
    assert!(!DataKind::of(&mr).is_ct(), "{:?}", DataKind::of(&mr));
}
