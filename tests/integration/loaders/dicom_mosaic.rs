//! A Siemens mosaic (nibabel's own diffusion test file, its zeroed pixels replaced by a pattern
//! naming each tile and place: `scripts/python/nibabel_mosaic.py`) opens as the volume nibabel
//! unpacks: 48 slices of 128 x 128, each voxel nibabel's, the first slice where nibabel's affine
//! puts it, the slices along its third axis.

use leapview::volume::{LoadOptions, load_volume};
use serde_json::Value;

use crate::common::{self, run_python};

#[test]
fn a_siemens_mosaic_opens_as_the_volume_nibabel_unpacks() {
    let out = common::TempDir::new("mosaic");
    run_python("nibabel_mosaic.py", &[out.path()]);
    let facts: Value =
        serde_json::from_slice(&std::fs::read(out.path().join("mosaic.json")).expect("facts"))
            .expect("JSON");
    let reference: Vec<f64> = std::fs::read(out.path().join("mosaic.f64"))
        .expect("nibabel's volume")
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
        .collect();
    let v = load_volume(&out.path().join("mosaic.dcm"), &LoadOptions::default()).expect("mosaic");
    assert_eq!(v.dims(), [128, 128, 48]);
    let affine: Vec<Vec<f64>> = serde_json::from_value(facts["affine"].clone()).expect("affine");
    // Spacing: the affine's column lengths.
    for (a, s) in v.spacing_mm().iter().enumerate() {
        let length = (0..3).map(|r| affine[r][a].powi(2)).sum::<f64>().sqrt();
        assert!((s - length).abs() < 1e-3, "axis {a}: {s} vs {length}");
    }
    // The slices run along nibabel's third axis (or against it, stored reversed): match each of
    // ours to nibabel's by its pattern, then check the order and the first one's place.
    let plane = 128 * 128;
    let slice_of = |k: u32| -> usize {
        (0..48)
            .find(|&n| {
                (0..plane).all(|i| {
                    let (x, y) = (i as u32 % 128, i as u32 / 128);
                    v.value(x, y, k) == reference[n * plane + i]
                })
            })
            .unwrap_or_else(|| panic!("slice {k} equals none of nibabel's"))
    };
    let order: Vec<usize> = (0..48).map(slice_of).collect();
    let ascending = order.iter().enumerate().all(|(k, &n)| n == k);
    let descending = order.iter().enumerate().all(|(k, &n)| n == 47 - k);
    assert!(ascending || descending, "{order:?}");
    let origin = v.provenance().origin_lps.expect("an origin");
    let first = order[0] as f64;
    for r in 0..3 {
        let expected = affine[r][3] + affine[r][2] * first;
        assert!(
            (origin[r] - expected).abs() < 1e-3,
            "origin {origin:?}, nibabel's {expected} on axis {r}"
        );
    }
}
