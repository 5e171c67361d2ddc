//! MetaImage files (`.mha`, `.mhd` with a data file or a LIST of slices, raw or zlib, either byte
//! order) holding a shared scan's samples load equal to the scan; bad headers fail clearly.

use leapview::volume::{LoadOptions, Volume, load_volume};
use std::io::Write;

use crate::common::{self, data_dir, load_ok, to_bytes};

fn header(v: &Volume, element_type: &str, extra: &str, data_file: &str) -> String {
    let [x, y, z] = v.dims();
    let [sx, sy, sz] = v.spacing_mm();
    format!(
        "ObjectType = Image\nNDims = 3\nBinaryData = True\n{extra}\
         TransformMatrix = -1 0 0 0 -1 0 0 0 1\nOffset = 10 20 30\n\
         ElementSpacing = {sx} {sy} {sz}\nDimSize = {x} {y} {z}\nElementType = {element_type}\n\
         ElementDataFile = {data_file}\n"
    )
}

fn zlib(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(bytes).expect("compress");
    e.finish().expect("compress")
}

fn assert_equal(a: &Volume, b: &Volume) {
    assert_eq!(a.dims(), b.dims());
    assert_eq!(a.spacing_mm(), b.spacing_mm());
    assert!(a.samples() == b.samples(), "the samples differ");
}

#[test]
fn metaimage_files_of_a_shared_scan_equal_it() {
    let scan = load_ok(&data_dir().join("ct_head_cthead_256x256x113_uint16.nrrd"));
    let dir = common::TempDir::new("metaimage");
    let little = to_bytes(scan.samples().expect("in memory"), false);
    let big = to_bytes(scan.samples().expect("in memory"), true);

    // .mha, samples inline, little endian.
    let mut mha = header(
        &scan,
        "MET_USHORT",
        "BinaryDataByteOrderMSB = False\n",
        "LOCAL",
    )
    .into_bytes();
    mha.extend_from_slice(&little);
    let v = load_ok(&dir.write("head.mha", &mha));
    assert_equal(&v, &scan);
    assert_eq!(v.orientation().map(|o| o.code()), Some("RAS".into()));
    assert_eq!(v.provenance().origin_lps, Some([10.0, 20.0, 30.0]));

    // .mha, zlib-compressed, big endian.
    let mut mha = header(
        &scan,
        "MET_USHORT",
        "BinaryDataByteOrderMSB = True\nCompressedData = True\n",
        "LOCAL",
    )
    .into_bytes();
    mha.extend_from_slice(&zlib(&big));
    assert_equal(&load_ok(&dir.write("head-z.mha", &mha)), &scan);

    // .mhd naming a raw file.
    dir.write("head.raw", &little);
    let mhd = header(&scan, "MET_USHORT", "", "head.raw");
    assert_equal(&load_ok(&dir.write("head.mhd", mhd.as_bytes())), &scan);

    // .mhd with a LIST of slice files.
    let slice = 256 * 256 * 2;
    let mut names = String::new();
    for (k, chunk) in little.chunks(slice).enumerate() {
        let name = format!("slice{k:03}.raw");
        dir.write(&name, chunk);
        names.push_str(&name);
        names.push('\n');
    }
    let list = header(&scan, "MET_USHORT", "", "LIST") + &names;
    assert_equal(&load_ok(&dir.write("list.mhd", list.as_bytes())), &scan);
}

fn fails(dir: &common::TempDir, name: &str, bytes: &[u8]) -> String {
    let path = dir.write(name, bytes);
    let e = load_volume(&path, &LoadOptions::default()).expect_err("must fail");
    let text = e.to_string();
    assert!(text.ends_with(&*path.to_string_lossy()), "{text}");
    text
}

#[test]
fn bad_metaimage_files_fail_clearly() {
    let dir = common::TempDir::new("metaimage-bad");
    let v = Volume::new(
        "t",
        [4, 3, 2],
        [1.0; 3],
        leapview::volume::Samples::U8(vec![7; 24]),
        leapview::volume::ValueMapping::IDENTITY,
    )
    .expect("volume");
    let ok = header(&v, "MET_UCHAR", "", "LOCAL");
    // Data shorter than DimSize calls for.
    let mut short = ok.clone().into_bytes();
    short.extend_from_slice(&[7; 20]);
    assert!(fails(&dir, "short.mha", &short).contains("24"));
    // A lying DimSize: refused before allocating.
    let huge = ok.replace("DimSize = 4 3 2", "DimSize = 65536 65536 65536");
    let mut bytes = huge.into_bytes();
    bytes.extend_from_slice(&[7; 24]);
    fails(&dir, "huge.mha", &bytes);
    // A corrupt zlib stream.
    let mut bytes = ok
        .replace(
            "BinaryData = True\n",
            "BinaryData = True\nCompressedData = True\n",
        )
        .into_bytes();
    bytes.extend_from_slice(b"not zlib at all, not at all");
    assert!(fails(&dir, "corrupt.mha", &bytes).contains("zlib"));
    // A data file that is not there.
    let missing = ok.replace("ElementDataFile = LOCAL", "ElementDataFile = nowhere.raw");
    assert!(fails(&dir, "missing.mhd", missing.as_bytes()).contains("nowhere.raw"));
    // Not text, and no ElementDataFile.
    fails(&dir, "binary.mha", &[0xFF; 64]);
    fails(&dir, "nodata.mhd", b"ObjectType = Image\nNDims = 3\n");
    // The messages the first-hour campaign found wrong: NaN spacing ("must be 1 finite
    // numbers"), a negative size ("must be whole numbers"), samples without the
    // ElementDataFile line before them ("bytes that are not text"), a data file that is a
    // folder (which named the header).
    let nan = ok.replace("ElementSpacing = 1 1 1", "ElementSpacing = nan 1 1");
    assert!(nan.contains("nan 1 1"), "{nan}");
    let text = fails(&dir, "nan.mha", nan.as_bytes());
    assert!(text.contains("a finite number for each axis"), "{text}");
    let negative = ok.replace("DimSize = 4 3 2", "DimSize = 4 -3 2");
    let text = fails(&dir, "negative.mha", negative.as_bytes());
    assert!(text.contains("must be 1 or more"), "{text}");
    let mut unlabelled = ok.replace("ElementDataFile = LOCAL\n", "").into_bytes();
    unlabelled.extend_from_slice(&[0xFF, 0xFE, 0, 1, 2, 3]);
    let text = fails(&dir, "unlabelled.mha", &unlabelled);
    assert!(text.contains("without an ElementDataFile line"), "{text}");
    std::fs::create_dir_all(dir.path().join("folder.raw")).expect("a folder");
    let folder = ok.replace("ElementDataFile = LOCAL", "ElementDataFile = folder.raw");
    let text = fails(&dir, "folder.mhd", folder.as_bytes());
    assert!(
        text.contains("'folder.raw' that the header names is a folder"),
        "{text}"
    );
}
