//! The eight real volumes of `../shared/data` load with the dimensions, type, spacing, value range
//! and empty fraction that its README states; each NIfTI original equals its NRRD twin.

use std::path::PathBuf;

use leapview::volume::stats::quantile;
use leapview::volume::{ScalarType, ValueMapping, Volume};

use crate::common::load_ok;

/// The data folder: `LEAPVIEW_DATA_DIR`, else `../shared/data` beside the repository. A missing
/// folder fails the test, saying where it looked: the real data are never silently skipped.
fn data_dir() -> PathBuf {
    let dir = std::env::var_os("LEAPVIEW_DATA_DIR").map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data"),
        PathBuf::from,
    );
    assert!(
        dir.is_dir(),
        "the real volumes are missing: no folder at {} (set LEAPVIEW_DATA_DIR to the folder \
         holding data/README.md's volumes)",
        dir.display()
    );
    dir
}

/// One row of data/README.md's table.
struct Expected {
    file: &'static str,
    dims: [u32; 3],
    scalar_type: ScalarType,
    spacing_mm: [f64; 3],
    /// Stored value range.
    stored: (f64, f64),
    /// `nifti_scl_slope` as the README rounds it (1 where there is none).
    slope: f64,
    /// "Air %": share of voxels below t, in percent.
    air_percent: f64,
    /// t = min + 0.1 · (P99.9 − min), as the README prints it.
    t: f64,
}

/// data/README.md, "The volumes" table.
#[rustfmt::skip]
const VOLUMES: [Expected; 8] = [
    Expected { file: "ct_head_cthead_256x256x113_uint16.nrrd", dims: [256, 256, 113], scalar_type: ScalarType::U16,
        spacing_mm: [1.0, 1.0, 2.0], stored: (0.0, 3272.0), slope: 1.0, air_percent: 69.8, t: 271.5 },
    Expected { file: "cta_stent_128x128x256_int16.nrrd", dims: [128, 128, 256], scalar_type: ScalarType::I16,
        spacing_mm: [1.0, 1.0, 1.0], stored: (0.0, 2000.0), slope: 1.0, air_percent: 90.0, t: 112.5 },
    Expected { file: "cta_avm_337x319x154_uint8.nrrd", dims: [337, 319, 154], scalar_type: ScalarType::U8,
        spacing_mm: [0.5469, 0.5469, 1.0], stored: (0.0, 255.0), slope: 2.20863, air_percent: 97.6, t: 20.1 },
    Expected { file: "ct_engine_256x256x128_uint8.nrrd", dims: [256, 256, 128], scalar_type: ScalarType::U8,
        spacing_mm: [1.0, 1.0, 1.0], stored: (0.0, 255.0), slope: 1.0, air_percent: 83.1, t: 25.5 },
    Expected { file: "ct_bonsai_256x256x256_uint8.nrrd", dims: [256, 256, 256], scalar_type: ScalarType::U8,
        spacing_mm: [1.0, 1.0, 1.0], stored: (0.0, 255.0), slope: 1.0, air_percent: 87.2, t: 22.0 },
    Expected { file: "mr_head_t1_seg3d_160x232x160_uint8.nrrd", dims: [160, 232, 160], scalar_type: ScalarType::U8,
        spacing_mm: [1.0, 0.898437, 0.898437], stored: (0.0, 255.0), slope: 2.00784, air_percent: 43.1, t: 25.5 },
    Expected { file: "mr_brain_t1_stripped_124x160x140_uint8.nrrd", dims: [124, 160, 140], scalar_type: ScalarType::U8,
        spacing_mm: [1.0, 1.0, 1.0], stored: (0.0, 252.0), slope: 1.0, air_percent: 62.4, t: 21.4 },
    Expected { file: "mra_head_200x256x120_uint8.nrrd", dims: [200, 256, 120], scalar_type: ScalarType::U8,
        spacing_mm: [0.5208329, 0.52083373, 0.65000015], stored: (0.0, 254.0), slope: 1.0, air_percent: 99.1, t: 19.0 },
];

/// data/README.md, "More detail" table: each NIfTI original and its NRRD twin.
#[rustfmt::skip]
const TWINS: [(&str, &str); 6] = [
    ("MRIcroGL_chris_MRA.nii.gz", "mra_head_200x256x120_uint8.nrrd"),
    ("VolumeRenderingData_OpenSciVis_bonsai.nii.gz", "ct_bonsai_256x256x256_uint8.nrrd"),
    ("VolumeRenderingData_OpenSciVis_engine.nii.gz", "ct_engine_256x256x128_uint8.nrrd"),
    ("VolumeRenderingData_Prism_AVM.nii.gz", "cta_avm_337x319x154_uint8.nrrd"),
    ("VolumeRenderingData_seg3D_MR.nii.gz", "mr_head_t1_seg3d_160x232x160_uint8.nrrd"),
    ("VolumeRenderingData_stroke_T1.nii.gz", "mr_brain_t1_stripped_124x160x140_uint8.nrrd"),
];

fn relative_difference(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
}

#[test]
fn real_volumes_load_as_the_readme_states() {
    let dir = data_dir();
    for e in &VOLUMES {
        let v = load_ok(&dir.join(e.file));
        assert_eq!(v.name(), e.file);
        assert_eq!(v.dims(), e.dims, "{}", e.file);
        assert_eq!(v.scalar_type(), e.scalar_type, "{}", e.file);
        // The README prints the header's spacings digit for digit.
        assert_eq!(v.spacing_mm(), e.spacing_mm, "{}", e.file);
        let m = v.mapping();
        assert_eq!(m.intercept, 0.0, "{}", e.file);
        // The README rounds the slope to 6 significant digits: half a unit of the 6th digit.
        assert!(
            relative_difference(m.slope, e.slope) < 5e-6,
            "{}: {m:?}",
            e.file
        );
        let range = v.value_range().expect("integer volumes are finite");
        assert_eq!(
            (range.min, range.max),
            (m.apply(e.stored.0), m.apply(e.stored.1)),
            "{}: the range in data units",
            e.file
        );
        assert_eq!(v.non_finite_count(), 0);
    }
}

/// "Air %" = share of stored values below t = min + 0.1 · (P99.9 − min), all on stored values.
#[test]
fn air_fractions_match_the_readme() {
    let dir = data_dir();
    for e in &VOLUMES {
        let v = load_ok(&dir.join(e.file));
        let stored = ValueMapping::IDENTITY;
        let min = quantile(v.samples().expect("in memory"), stored, 0.0).expect("finite samples");
        let p999 =
            quantile(v.samples().expect("in memory"), stored, 0.999).expect("finite samples");
        let t = min + 0.1 * (p999 - min);
        // The README prints t with one decimal: it must round to that.
        assert!(
            (t - e.t).abs() <= 0.05 + 1e-9,
            "{}: t = {t}, README {}",
            e.file,
            e.t
        );
        let mut below = 0u64;
        v.samples()
            .expect("in memory")
            .for_each_f64(|s| below += u64::from(s < t));
        let air_percent = 100.0 * below as f64 / v.sample_count() as f64;
        // The README prints the percentage with one decimal; ±0.1 point as the brief asks.
        assert!(
            (air_percent - e.air_percent).abs() <= 0.1,
            "{}: air {air_percent:.3} %, README {} %",
            e.file,
            e.air_percent
        );
    }
}

#[test]
fn nifti_originals_equal_their_nrrd_twins() {
    let dir = data_dir();
    for (nifti_name, nrrd_name) in TWINS {
        let nifti: Volume = load_ok(&dir.join("originals").join(nifti_name));
        let nrrd: Volume = load_ok(&dir.join(nrrd_name));
        assert_eq!(nifti.dims(), nrrd.dims(), "{nifti_name}");
        assert!(
            nifti.samples() == nrrd.samples(),
            "{nifti_name}: samples differ"
        );
        // NIfTI stores slope and spacing as f32 (relative rounding ≤ 2^-24 ≈ 6e-8); the NRRD
        // writer printed them with 4 to 9 significant digits of that f32 (0.5469 for
        // 0.54689997…, 5e-8 apart). 1e-6 covers both.
        let (a, b) = (nifti.mapping(), nrrd.mapping());
        assert!(
            relative_difference(a.slope, b.slope) < 1e-6,
            "{nifti_name}: {a:?} {b:?}"
        );
        assert_eq!(a.intercept, b.intercept, "{nifti_name}");
        for axis in 0..3 {
            let (sa, sb) = (nifti.spacing_mm()[axis], nrrd.spacing_mm()[axis]);
            assert!(
                relative_difference(sa, sb) < 1e-6,
                "{nifti_name}: {sa} vs {sb}"
            );
        }
        let (ra, rb) = (
            nifti.value_range().expect("finite"),
            nrrd.value_range().expect("finite"),
        );
        assert!(relative_difference(ra.max, rb.max) < 1e-6, "{nifti_name}");
        assert_eq!(ra.min, rb.min, "{nifti_name}");
    }
}

#[test]
fn a_real_load_reports_progress_and_can_be_cancelled() {
    use leapview::volume::{LoadOptions, LoadProgress, load_volume};
    use std::sync::Arc;
    let path = crate::common::data_dir().join("ct_head_cthead_256x256x113_uint16.nrrd");
    let progress = Arc::new(LoadProgress::default());
    let options = LoadOptions {
        progress: Some(Arc::clone(&progress)),
        ..LoadOptions::default()
    };
    load_volume(&path, &options).expect("loads");
    assert_eq!(progress.fraction(), Some(1.0));
    progress.cancel();
    let err = load_volume(&path, &options).expect_err("cancelled before the first chunk");
    let message = err.to_string();
    assert!(
        message.contains("cancelled") && message.contains("ct_head_cthead"),
        "{message}"
    );
}
