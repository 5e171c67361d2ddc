//! NIfTI files written by nibabel (`scripts/python/nibabel_files.py`): 4-D time series (any
//! volume of them), NIfTI-2 (64-bit sizes, double fields), big-endian, scaled samples, and
//! nibabel's own test files (written by SPM, FSL, AFNI and nibabel, some mirrored, some 4-D),
//! each read with nibabel's values, spacing, orientation and origin; and an MR-like volume with
//! negative values and no modality, which is not taken for CT.

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
    assert!(
        cases.len() >= 12,
        "{} cases: nibabel's test files are missing",
        cases.len()
    );
    for case in &cases {
        let name = case["name"].as_str().expect("a name");
        let volume = case["volume"].as_u64().expect("a volume") as u32;
        let count = case["volumes"].as_u64().expect("a count") as u32;
        // nibabel's own files by their path, the ones written here by name.
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
        // nibabel's affine (RAS): the spacing is its columns' lengths, the orientation their
        // nearest axes, the origin its translation (LPS here). NIfTI-1 holds f32.
        let affine: Vec<Vec<f64>> = serde_json::from_value(case["affine"].clone()).expect("affine");
        let spacing = v.spacing_mm();
        for a in 0..3 {
            let length = (0..3).map(|r| affine[r][a].powi(2)).sum::<f64>().sqrt();
            assert!(
                (spacing[a] - length).abs() < 1e-4 * length,
                "{name}: {spacing:?} axis {a} {length}"
            );
        }
        let columns: [[f64; 3]; 3] = std::array::from_fn(|a| std::array::from_fn(|r| affine[r][a]));
        let expected = leapview::volume::Orientation::from_ras_columns(columns).map(|o| o.code());
        assert_eq!(v.file_orientation().map(|o| o.code()), expected, "{name}");
        let origin = v.provenance().origin_lps.expect("an origin");
        let want = [-affine[0][3], -affine[1][3], affine[2][3]];
        assert!(
            (0..3).all(|a| (origin[a] - want[a]).abs() < 1e-3),
            "{name}: origin {origin:?}, nibabel's {want:?}"
        );
        let expected_index = (count > 1).then_some(VolumeIndex {
            chosen: volume,
            count,
        });
        assert_eq!(v.provenance().volumes, expected_index, "{name}");
        let reference = common::f64_file(&out.path().join(format!("{name}.f64")));
        assert_eq!(reference.len() as u64, v.sample_count(), "{name}");
        let [nx, ny, _] = v.dims();
        for (i, &want) in reference.iter().enumerate() {
            let (x, y, z) = (i as u32 % nx, (i as u32 / nx) % ny, i as u32 / (nx * ny));
            // A mirrored file is read reversed along i.
            let x = if v.reversed_i() { nx - 1 - x } else { x };
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
