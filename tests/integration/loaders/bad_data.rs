//! Bad data, as opposed to bad headers: truncated, too long, absurdly large, zero-sized, corrupt
//! gzip, and non-finite floats. Every failure is a clear error of the right kind naming the file
//! last; sizes are refused before anything is allocated.

use leapview::volume::error::VolumeError;
use leapview::volume::{Samples, ScalarType};

use crate::common::{
    NiftiSpec, TempDir, fails, gzip, load_err, load_ok, nrrd_file, nrrd_lines, raw_options,
    samples_of, to_bytes,
};

/// A 16×16×8 uint16 volume: 4096 bytes of samples.
fn u16_nrrd(dir: &TempDir, name: &str, encoding: &str, data: &[u8]) -> std::path::PathBuf {
    let lines = nrrd_lines(ScalarType::U16, [16, 16, 8], encoding, false);
    let lines: Vec<&str> = lines.iter().map(String::as_str).collect();
    dir.write(name, &nrrd_file(&lines, data))
}

fn u16_data() -> Vec<u8> {
    to_bytes(&samples_of(ScalarType::U16, 16 * 16 * 8), false)
}
#[test]
fn truncated_data_is_reported_with_both_sizes() {
    let dir = TempDir::new("truncated");
    let data = u16_data();
    let path = u16_nrrd(&dir, "short.nrrd", "raw", &data[..1000]);
    let e = fails(&path);
    assert!(
        matches!(
            e,
            VolumeError::DataTooShort {
                declared_bytes: 4096,
                found_bytes: 1000,
                ..
            }
        ),
        "{e}"
    );
    assert!(
        e.to_string()
            .contains("16×16×8 uint16 samples (4.1 kB) but the data holds only 1.0 kB"),
        "{e}"
    );

    let packed = gzip(&data[..1000]);
    let path = u16_nrrd(&dir, "short-gz.nrrd", "gzip", &packed);
    let e = fails(&path);
    assert!(
        matches!(
            e,
            VolumeError::DataTooShort {
                found_bytes: 1000,
                ..
            }
        ),
        "{e}"
    );

    // A gzip stream cut in the middle: the data end early.
    let packed = gzip(&data);
    let path = u16_nrrd(&dir, "cut-gz.nrrd", "gzip", &packed[..packed.len() / 2]);
    let e = fails(&path);
    assert!(matches!(e, VolumeError::DataTooShort { .. }), "{e}");

    let spec = NiftiSpec::new(ScalarType::U16, [16, 16, 8], [1.0; 3]);
    let path = dir.write("short.nii", &spec.file(&data[..4000]));
    assert!(matches!(
        fails(&path),
        VolumeError::DataTooShort {
            found_bytes: 4000,
            ..
        }
    ));
    let path = dir.write("cut.nii.gz", &gzip(&spec.file(&data))[..2000]);
    assert!(matches!(fails(&path), VolumeError::DataTooShort { .. }));

    let path = dir.write("short.raw", &data[..4095]);
    let e = load_err(&path, &raw_options([16, 16, 8], ScalarType::U16)).problem;
    assert!(
        matches!(
            e,
            VolumeError::RawSizeMismatch {
                expected_bytes: 4096,
                found_bytes: 4095,
                ..
            }
        ),
        "{e}"
    );
    assert!(
        e.to_string().contains("4096 bytes") && e.to_string().contains("4095 bytes"),
        "{e}"
    );
}
#[test]
fn more_data_than_declared_is_reported() {
    let dir = TempDir::new("long");
    let mut data = u16_data();
    data.extend_from_slice(&[0; 10]);
    let path = u16_nrrd(&dir, "long.nrrd", "raw", &data);
    let e = fails(&path);
    assert!(
        matches!(
            e,
            VolumeError::DataTooLong {
                found_bytes: 4106,
                exact: true,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("holds more"), "{e}");
    let path = u16_nrrd(&dir, "long-gz.nrrd", "gzip", &gzip(&data));
    assert!(matches!(
        fails(&path),
        VolumeError::DataTooLong { exact: false, .. }
    ));

    let spec = NiftiSpec::new(ScalarType::U16, [16, 16, 8], [1.0; 3]);
    let path = dir.write("long.nii", &spec.file(&data));
    assert!(matches!(fails(&path), VolumeError::DataTooLong { .. }));
    let path = dir.write("long.nii.gz", &gzip(&spec.file(&data)));
    assert!(matches!(fails(&path), VolumeError::DataTooLong { .. }));

    let path = dir.write("long.raw", &data);
    let e = load_err(&path, &raw_options([16, 16, 8], ScalarType::U16)).problem;
    assert!(
        matches!(
            e,
            VolumeError::RawSizeMismatch {
                found_bytes: 4106,
                ..
            }
        ),
        "{e}"
    );
}
#[test]
fn absurd_sizes_are_refused_before_allocating() {
    let dir = TempDir::new("absurd");
    let nrrd = |name: &str, sizes: &str, encoding: &str, data: &[u8]| {
        let sizes = format!("sizes: {sizes}");
        let encoding = format!("encoding: {encoding}");
        let lines = [
            "type: uint8",
            "dimension: 3",
            sizes.as_str(),
            encoding.as_str(),
        ];
        dir.write(name, &nrrd_file(&lines, data))
    };
    // Every error below comes from the limit checks, which run before any sample is allocated.
    let path = nrrd("huge.nrrd", "100000 100000 100000", "raw", &[0; 64]);
    assert!(matches!(
        fails(&path),
        VolumeError::DimensionTooLarge { .. }
    ));
    // 16384² × 4096 bytes = 1 TiB: every axis is allowed, the total is more than this machine
    // holds.
    let path = nrrd("1tib.nrrd", "16384 16384 4096", "raw", &[0; 64]);
    let e = fails(&path);
    assert!(matches!(e, VolumeError::TooLarge { .. }), "{e}");
    assert!(e.to_string().contains("1.1 TB"), "{e}");
    // 2000³ bytes = 8 GB is under the cap, but 64 raw bytes cannot hold it…
    let path = nrrd("8gb.nrrd", "2000 2000 2000", "raw", &[0; 64]);
    assert!(matches!(
        fails(&path),
        VolumeError::DataTooShort {
            found_bytes: 64,
            ..
        }
    ));
    // …and 64 bytes of gzip cannot expand to it (at most 1032 × 64 bytes).
    let path = nrrd("8gb-gz.nrrd", "2000 2000 2000", "gzip", &gzip(&[0; 64]));
    let e = fails(&path);
    assert!(
        matches!(e, VolumeError::CompressedDataTooSmall { .. }),
        "{e}"
    );

    let mut spec = NiftiSpec::new(ScalarType::F64, [30000, 30000, 30000], [1.0; 3]);
    let path = dir.write("huge.nii", &spec.file(&[0; 64]));
    assert!(matches!(fails(&path), VolumeError::TooLarge { .. }));
    spec = NiftiSpec::new(ScalarType::U8, [2000, 2000, 2000], [1.0; 3]);
    let path = dir.write("8gb.nii.gz", &gzip(&spec.file(&[0; 64])));
    assert!(matches!(
        fails(&path),
        VolumeError::CompressedDataTooSmall { .. }
    ));

    let path = dir.write("huge.raw", &[0; 64]);
    let e = load_err(&path, &raw_options([100_000, 1, 1], ScalarType::U8)).problem;
    assert!(matches!(e, VolumeError::DimensionTooLarge { .. }), "{e}");
}
#[test]
fn zero_or_negative_dimensions_are_refused() {
    let dir = TempDir::new("zero");
    for sizes in ["0 4 4", "4 -4 4", "4 4 x", "4 4"] {
        let sizes = format!("sizes: {sizes}");
        let lines = [
            "type: uint8",
            "dimension: 3",
            sizes.as_str(),
            "encoding: raw",
        ];
        let path = dir.write("zero.nrrd", &nrrd_file(&lines, &[0; 64]));
        let e = fails(&path);
        assert!(
            matches!(&e, VolumeError::BadField { field, .. } if field == "sizes"),
            "{e}"
        );
    }
    for (axis, value) in [(1, 0), (3, -3)] {
        let mut spec = NiftiSpec::new(ScalarType::U8, [4, 4, 4], [1.0; 3]);
        spec.dim[axis] = value;
        let path = dir.write("zero.nii", &spec.file(&[0; 64]));
        let e = fails(&path);
        assert!(
            matches!(&e, VolumeError::BadField { field, .. } if field == "dim"),
            "{e}"
        );
    }
    let path = dir.write("zero.raw", &[0; 64]);
    let e = load_err(&path, &raw_options([0, 8, 8], ScalarType::U8)).problem;
    assert!(matches!(e, VolumeError::ZeroDimension { .. }), "{e}");
}
#[test]
fn corrupt_gzip_is_reported() {
    let dir = TempDir::new("corrupt");
    let data = u16_data();
    let mut packed = gzip(&data);
    let middle = packed.len() / 2;
    packed[middle..middle + 16]
        .iter_mut()
        .for_each(|b| *b ^= 0x5a);
    let path = u16_nrrd(&dir, "corrupt.nrrd", "gzip", &packed);
    assert!(matches!(fails(&path), VolumeError::CorruptGzip { .. }));
    // Not gzip at all.
    let path = u16_nrrd(&dir, "plain.nrrd", "gzip", &data);
    assert!(matches!(fails(&path), VolumeError::CorruptGzip { .. }));
    // A damaged checksum: every sample decodes, the trailer does not match.
    let mut packed = gzip(&data);
    let crc = packed.len() - 8;
    packed[crc] ^= 1;
    let path = u16_nrrd(&dir, "crc.nrrd", "gzip", &packed);
    assert!(matches!(fails(&path), VolumeError::CorruptGzip { .. }));
    let spec = NiftiSpec::new(ScalarType::U16, [16, 16, 8], [1.0; 3]);
    let mut packed = gzip(&spec.file(&data));
    let middle = packed.len() / 2;
    packed[middle..middle + 16]
        .iter_mut()
        .for_each(|b| *b ^= 0x5a);
    let path = dir.write("corrupt.nii.gz", &packed);
    assert!(matches!(fails(&path), VolumeError::CorruptGzip { .. }));
}
#[test]
fn non_finite_floats_load_and_stay_out_of_the_range() {
    let dir = TempDir::new("nonfinite");
    let values = [
        1.5f32,
        f32::NAN,
        -2.0,
        f32::INFINITY,
        4.0,
        f32::NEG_INFINITY,
        0.0,
        3.0,
    ];
    let data = to_bytes(&Samples::F32(values.to_vec()), true);
    let lines = nrrd_lines(ScalarType::F32, [2, 2, 2], "gzip", true);
    let lines: Vec<&str> = lines.iter().map(String::as_str).collect();
    let v = load_ok(&dir.write("nan.nrrd", &nrrd_file(&lines, &gzip(&data))));
    let range = v.value_range().expect("some samples are finite");
    assert_eq!((range.min, range.max), (-2.0, 4.0));
    assert_eq!(v.non_finite_count(), 3);
    assert!(v.value(1, 0, 0).is_nan());

    let values = [f64::NAN, 7.0, f64::INFINITY, f64::NEG_INFINITY];
    let spec = NiftiSpec::new(ScalarType::F64, [4, 1, 1], [1.0; 3]);
    let data = to_bytes(&Samples::F64(values.to_vec()), false);
    let v = load_ok(&dir.write("nan.nii", &spec.file(&data)));
    let range = v.value_range().expect("one sample is finite");
    assert_eq!((range.min, range.max), (7.0, 7.0));
    assert_eq!(v.non_finite_count(), 3);
}
