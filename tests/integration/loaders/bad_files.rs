//! Bad files and headers: empty files, folders, missing files, unknown formats, types and
//! encodings, broken or garbage headers. Every failure is a clear error of the right kind naming
//! the file last, never a panic.

use leapview::volume::ScalarType;
use leapview::volume::error::VolumeError;

use crate::common::{NiftiSpec, TempDir, fails, load_err, nrrd_file, raw_options};

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
        (128, "RGB24"),
        (1024, "int64"),
        (32, "complex64"),
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
    // A folder is searched for DICOM series, whatever its name: an empty one says so.
    for f in [&folder, &dir.path().to_path_buf()] {
        let e = fails(f);
        assert!(matches!(e, VolumeError::Dicom(_)), "{e}");
        assert!(e.to_string().starts_with("no DICOM image here"), "{e}");
    }

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
    let path = dir.write("scan.img", b"an Analyze image\n");
    let e = fails(&path);
    assert!(matches!(e, VolumeError::UnknownFormat { .. }), "{e}");
    assert!(
        e.to_string().contains(
            ".nrrd, .nhdr, .nii, .nii.gz, .mha, .mhd, .tif/.tiff (stacks, OME-TIFF), DICOM"
        ),
        "{e}"
    );
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
    // A 4-D file opens one volume (tests/integration/loaders/nifti_nibabel.rs); one past its
    // last is refused, naming how many it holds.
    let mut spec = NiftiSpec::new(ScalarType::U8, [2, 2, 2], [1.0; 3]);
    spec.dim[0] = 4;
    spec.dim[4] = 3;
    let path = dir.write("4d.nii", &spec.file(&[0; 24]));
    let e = leapview::volume::load_volume(
        &path,
        &leapview::volume::LoadOptions {
            volume: Some(3),
            ..Default::default()
        },
    )
    .expect_err("volume 4 of 3");
    assert!(
        matches!(e.problem, VolumeError::NoSuchVolume { asked: 4, count: 3 }),
        "{e}"
    );
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
