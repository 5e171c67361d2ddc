//! Bad input of every kind gives a clear error of the right kind whose message names the file
//! last: never a panic, and never an allocation beyond what the file can hold.

use std::path::Path;

use leapview::volume::error::{LoadError, VolumeError};
use leapview::volume::load::{LoadOptions, load_volume};
use leapview::volume::raw::RawParams;
use leapview::volume::{Samples, ScalarType};

use crate::common::{
    NiftiSpec, TempDir, gzip, load_ok, nrrd_file, nrrd_lines, samples_of, to_bytes,
};

/// Loads a file that must fail; checks that the message is one line ending with the path.
fn load_err(path: &Path, options: &LoadOptions) -> LoadError {
    let err = match load_volume(path, options) {
        Ok(v) => panic!(
            "{} should not load, but gave {:?}",
            path.display(),
            v.dims()
        ),
        Err(e) => e,
    };
    let message = err.to_string();
    assert_eq!(err.path, path);
    assert!(
        message.ends_with(&format!(": {}", path.display())),
        "the message should name the file last: {message}"
    );
    assert!(!message.contains('\n'), "one line: {message}");
    err
}

fn fails(path: &Path) -> VolumeError {
    load_err(path, &LoadOptions::default()).problem
}

fn raw_options(dims: [u32; 3], scalar_type: ScalarType) -> LoadOptions {
    LoadOptions {
        raw: Some(RawParams {
            dims,
            scalar_type,
            spacing_mm: [1.0; 3],
            big_endian: false,
        }),
    }
}

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
    // 4096³ bytes = 64 GiB: every axis is allowed, the total is not.
    let path = nrrd("64gib.nrrd", "4096 4096 4096", "raw", &[0; 64]);
    let e = fails(&path);
    assert!(matches!(e, VolumeError::TooLarge { .. }), "{e}");
    assert!(e.to_string().contains("68.7 GB"), "{e}");
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
fn unknown_and_unsupported_types_are_named() {
    let dir = TempDir::new("types");
    for t in ["quaternion", "int64", "unsigned long long", "block"] {
        let t_line = format!("type: {t}");
        let lines = [
            t_line.as_str(),
            "dimension: 3",
            "sizes: 2 2 2",
            "encoding: raw",
        ];
        let path = dir.write("t.nrrd", &nrrd_file(&lines, &[0; 64]));
        let e = fails(&path);
        assert!(
            matches!(&e, VolumeError::UnsupportedType { name } if name == t),
            "{e}"
        );
        assert!(e.to_string().contains(t), "{e}");
    }
    for (code, name) in [
        (128, "Rgb24"),
        (1024, "Int64"),
        (32, "Complex64"),
        (9999, "9999"),
    ] {
        let mut spec = NiftiSpec::new(ScalarType::U8, [2, 2, 2], [1.0; 3]);
        spec.datatype = code;
        let path = dir.write("t.nii", &spec.file(&[0; 8]));
        let e = fails(&path);
        assert!(matches!(e, VolumeError::UnsupportedType { .. }), "{e}");
        assert!(e.to_string().contains(name), "{e}");
    }
}

#[test]
fn unknown_and_unsupported_encodings_are_named() {
    let dir = TempDir::new("encodings");
    for encoding in ["bzip2", "ascii", "text", "hex", "wavelet"] {
        let line = format!("encoding: {encoding}");
        let lines = ["type: uint8", "dimension: 3", "sizes: 2 2 2", line.as_str()];
        let path = dir.write("e.nrrd", &nrrd_file(&lines, &[0; 8]));
        let e = fails(&path);
        assert!(
            matches!(&e, VolumeError::UnsupportedEncoding { name } if name == encoding),
            "{e}"
        );
    }
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
fn empty_files_folders_and_missing_files_are_told_apart() {
    let dir = TempDir::new("files");
    for name in ["empty.nrrd", "empty.nhdr", "empty.nii", "empty.nii.gz"] {
        assert!(matches!(
            fails(&dir.write(name, b"")),
            VolumeError::EmptyFile
        ));
    }
    let path = dir.write("empty.raw", b"");
    let e = load_err(&path, &raw_options([1, 1, 1], ScalarType::U8)).problem;
    assert!(matches!(e, VolumeError::EmptyFile), "{e}");

    let folder = dir.path().join("folder.nrrd");
    std::fs::create_dir(&folder).expect("create a folder");
    assert!(matches!(fails(&folder), VolumeError::IsDirectory));
    assert!(matches!(fails(dir.path()), VolumeError::IsDirectory));

    assert!(matches!(
        fails(&dir.path().join("missing.nrrd")),
        VolumeError::NotFound
    ));
    assert!(matches!(
        fails(&dir.path().join("missing.nii.gz")),
        VolumeError::NotFound
    ));

    let lines = [
        "type: uint8",
        "dimension: 3",
        "sizes: 2 2 2",
        "encoding: raw",
        "data file: gone.raw",
    ];
    let path = dir.write("detached.nhdr", &nrrd_file(&lines, b""));
    let e = fails(&path);
    assert!(
        matches!(&e, VolumeError::DataFileUnreadable { name, .. } if name == "gone.raw"),
        "{e}"
    );
}

#[test]
fn unknown_file_types_and_raw_files_without_a_layout_say_what_to_do() {
    let dir = TempDir::new("formats");
    let path = dir.write("scan.mha", b"ObjectType = Image\n");
    let e = fails(&path);
    assert!(matches!(e, VolumeError::UnknownFormat { .. }), "{e}");
    assert!(e.to_string().contains(".nrrd, .nhdr, .nii, .nii.gz"), "{e}");
    let path = dir.write("scan.raw", &[0; 8]);
    let e = fails(&path);
    assert!(matches!(e, VolumeError::RawNeedsParams), "{e}");
    assert!(e.to_string().contains("--dims X,Y,Z --type T"), "{e}");
}

#[test]
fn broken_headers_are_refused() {
    let dir = TempDir::new("headers");
    // No blank line and no data file: the header never ends.
    let path = dir.write(
        "noblank.nrrd",
        b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n",
    );
    assert!(matches!(fails(&path), VolumeError::BadHeader { .. }));
    // Binary data right after the fields, without the blank line.
    let path = dir.write(
        "binary.nrrd",
        b"NRRD0004\ntype: uint8\nencoding: raw\n\x00\x9f\xff\x01\n",
    );
    assert!(matches!(fails(&path), VolumeError::BadHeader { .. }));
    // Garbage from the first byte.
    let garbage: Vec<u8> = (0..5000u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    for name in ["garbage.nrrd", "garbage.nii", "garbage.nii.gz"] {
        assert!(matches!(
            fails(&dir.write(name, &garbage)),
            VolumeError::BadHeader { .. }
        ));
    }
    let path = dir.write("tiny.nii", b"n+1");
    assert!(matches!(fails(&path), VolumeError::BadHeader { .. }));
    // Required fields, byte order, dimension.
    let path = dir.write(
        "nosizes.nrrd",
        &nrrd_file(&["type: uint8", "dimension: 3", "encoding: raw"], &[0; 8]),
    );
    assert!(matches!(
        fails(&path),
        VolumeError::MissingField { field: "sizes", .. }
    ));
    let path = dir.write(
        "noendian.nrrd",
        &nrrd_file(
            &[
                "type: float",
                "dimension: 3",
                "sizes: 2 1 1",
                "encoding: raw",
            ],
            &[0; 8],
        ),
    );
    assert!(matches!(
        fails(&path),
        VolumeError::MissingField {
            field: "endian",
            ..
        }
    ));
    let path = dir.write(
        "2d.nrrd",
        &nrrd_file(
            &["type: uint8", "dimension: 2", "sizes: 2 4", "encoding: raw"],
            &[0; 8],
        ),
    );
    assert!(matches!(
        fails(&path),
        VolumeError::UnsupportedDimension { .. }
    ));
    let mut spec = NiftiSpec::new(ScalarType::U8, [2, 2, 2], [1.0; 3]);
    spec.dim[0] = 4;
    spec.dim[4] = 3;
    assert!(matches!(
        fails(&dir.write("4d.nii", &spec.file(&[0; 24]))),
        VolumeError::UnsupportedDimension { .. }
    ));
    let mut spec = NiftiSpec::new(ScalarType::U8, [2, 2, 2], [1.0; 3]);
    spec.magic = *b"ni1\0";
    assert!(matches!(
        fails(&dir.write("pair.nii", &spec.file(&[0; 8]))),
        VolumeError::BadHeader { .. }
    ));
    let mut spec = NiftiSpec::new(ScalarType::U8, [2, 2, 2], [1.0; 3]);
    spec.vox_offset = 100.0;
    assert!(matches!(
        fails(&dir.write("offset.nii", &spec.file(&[0; 8]))),
        VolumeError::BadField { .. }
    ));
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
