//! Reading every few slices (`LoadProgress::with_slice_stride`, what `leapview info` does past
//! 1 GiB): every reader keeps exactly slices 0, k, 2k, … of the whole volume, with the spacing
//! between them, in no more memory than they take.

use std::sync::Arc;

use leapview::volume::{LoadOptions, LoadProgress, Volume, load_volume};

use crate::common::{self, data_dir, load_ok};

fn strided(path: &std::path::Path, stride: u32) -> Volume {
    load_volume(
        path,
        &LoadOptions {
            progress: Some(Arc::new(LoadProgress::default().with_slice_stride(stride))),
            ..LoadOptions::default()
        },
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

/// `sampled` holds slices 0, stride, 2 stride… of `full`, `stride` times as far apart.
fn assert_every_strideth_slice(full: &Volume, sampled: &Volume, stride: u32) {
    let [x, y, z] = full.dims();
    assert_eq!(sampled.dims(), [x, y, z.div_ceil(stride)]);
    let (a, b) = (full.spacing_mm(), sampled.spacing_mm());
    assert_eq!([a[0], a[1], a[2] * f64::from(stride)], b);
    for k in 0..sampled.dims()[2] {
        for j in (0..y).step_by(7) {
            for i in (0..x).step_by(5) {
                let (s, f) = (sampled.value(i, j, k), full.value(i, j, k * stride));
                assert!(
                    s == f || (s.is_nan() && f.is_nan()),
                    "({i}, {j}, {k}): {s} vs {f}"
                );
            }
        }
    }
}

#[test]
fn every_reader_keeps_every_strideth_slice() {
    let data = data_dir();
    for (file, stride) in [
        ("ct_head_cthead_256x256x113_uint16.nrrd", 4),
        ("cta_stent_128x128x256_int16.nrrd", 7),
        ("originals/VolumeRenderingData_seg3D_MR.nii.gz", 3),
        ("dicom/ct_head_cthead", 5),
    ] {
        let path = data.join(file);
        let full = load_ok(&path);
        let sampled = strided(&path, stride);
        assert_every_strideth_slice(&full, &sampled, stride);
    }
    // Raw and uncompressed NRRD: the volume LeapView writes itself.
    let dir = common::TempDir::new("sampled");
    let out = dir.path().join("p.nhdr");
    let o = common::leapview(&[
        "generate",
        "phantom",
        "--size",
        "24",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success());
    assert_every_strideth_slice(&load_ok(&out), &strided(&out, 5), 5);
}
