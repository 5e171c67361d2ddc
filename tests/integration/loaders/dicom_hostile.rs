//! DICOM that lies or hides: codestreams that disagree with their headers (refused naming both
//! values, or read as they are with a note), sequences nested thousands deep (the parser would
//! overflow its stack), a corrupt copy of a slice beside a good one, series many folders down,
//! a named file that is not DICOM, a slice shifted impossibly far. Files are written here with
//! dicom-rs and libjpeg-turbo, or taken from pydicom's and the team's vendor files and edited.

use std::path::Path;

use dicom_core::{DataElement, PrimitiveValue, VR};
use dicom_dictionary_std::tags;
use leapview::volume::{LoadOptions, load_volume};

use super::dicom_written::{axial, libjpeg_turbo, write, write_sized};
use crate::common::{self, data_dir, load_ok};

/// A grey frame of `columns` x `rows` 8-bit samples as a lossless JPEG codestream (process 14,
/// predictor 1) written by libjpeg-turbo.
fn libjpeg_turbo_8_bit(samples: &[u8], columns: u32, rows: u32) -> Vec<u8> {
    let wide: Vec<u16> = samples.iter().map(|&s| u16::from(s)).collect();
    libjpeg_turbo(&wide, columns, rows, 8, true)
}

/// Two slices whose pixel data is `stream` (JPEG lossless) under a header of `columns` x `rows`
/// with `bits_allocated` / `bits_stored`.
fn jpeg_series(dir: &Path, stream: &[u8], columns: u16, rows: u16, bits: (u16, u16)) {
    for k in 0..2 {
        let mut s = axial("lying", f64::from(k), 0);
        s.bits_allocated = bits.0;
        s.bits_stored = bits.1;
        s.transfer_syntax = "1.2.840.10008.1.2.4.70";
        s.fragment = Some(stream.to_vec());
        write_sized(dir, &format!("IM{k}.dcm"), &s, rows, columns);
    }
}

fn ramp(columns: u32, rows: u32) -> Vec<u8> {
    (0..columns * rows).map(|i| (i % 251) as u8).collect()
}

#[test]
fn a_jpeg_stream_of_another_size_than_its_header_is_refused_naming_both() {
    // 64 x 64 in the stream, 128 x 128 in the header: decoded into the header's buffer it was a
    // squashed copy; one column more than the header made dicom-rs's adapter panic.
    for (columns, rows, size) in [(64u32, 64u32, "64 x 64"), (65, 64, "65 x 64")] {
        let dir = common::TempDir::new("dicom-jpeg-size");
        let header = if columns == 65 { (64, 64) } else { (128, 128) };
        jpeg_series(
            dir.path(),
            &libjpeg_turbo_8_bit(&ramp(columns, rows), columns, rows),
            header.0,
            header.1,
            (8, 8),
        );
        let e = load_volume(dir.path(), &LoadOptions::default()).expect_err("a lying header");
        let text = e.to_string();
        let header_size = format!("{} x {} (Columns x Rows)", header.0, header.1);
        assert!(text.contains(size) && text.contains(&header_size), "{text}");
        assert!(
            text.contains("IM0.dcm") || text.contains("IM1.dcm"),
            "{text}"
        );
    }
}

#[test]
fn an_8_bit_stream_under_a_16_bit_header_is_read_as_the_stream_holds_it_and_said() {
    let dir = common::TempDir::new("dicom-jpeg-depth");
    let samples = ramp(16, 8);
    jpeg_series(
        dir.path(),
        &libjpeg_turbo_8_bit(&samples, 16, 8),
        16,
        8,
        (16, 12),
    );
    let v = load_ok(dir.path());
    assert_eq!(v.dims(), [16, 8, 2]);
    for (i, &s) in samples.iter().enumerate() {
        assert_eq!(
            v.value(i as u32 % 16, i as u32 / 16, 1),
            f64::from(s),
            "sample {i}"
        );
    }
    let notes = &v.provenance().notes;
    assert!(
        notes
            .iter()
            .any(|n| n.contains("8-bit samples where BitsStored says 12")),
        "{notes:?}"
    );
}

/// pydicom's 16-bit JPEG 2000 MR slice, its header edited to say 8 bits.
#[test]
fn a_16_bit_jpeg_2000_stream_under_an_8_bit_header_is_refused_naming_both_depths() {
    let dir = common::TempDir::new("dicom-j2k-depth");
    let mut obj =
        dicom_object::open_file(data_dir().join("dicom/vendor/MR_small_jp2klossless.dcm"))
            .expect("the vendor file");
    for (tag, value) in [
        (tags::BITS_ALLOCATED, 8u16),
        (tags::BITS_STORED, 8),
        (tags::HIGH_BIT, 7),
    ] {
        obj.put(DataElement::new(tag, VR::US, PrimitiveValue::from(value)));
    }
    obj.write_to_file(dir.path().join("mr.dcm")).expect("write");
    let e = load_volume(&dir.path().join("mr.dcm"), &LoadOptions::default()).expect_err("16 in 8");
    let text = e.to_string();
    assert!(
        text.contains("16-bit samples") && text.contains("BitsAllocated 8"),
        "{text}"
    );
}

/// A slice whose data set nests sequences `depth` deep before its pixel data: bytes as dicom-rs
/// reads them (undefined lengths), spliced into a slice dicom-rs wrote.
fn deeply_nested(dir: &Path, name: &str, depth: usize) {
    write(dir, name, &axial("deep", 99.0, 7));
    let path = dir.join(name);
    let bytes = std::fs::read(&path).expect("written");
    let pixel_data = [0xE0u8, 0x7F, 0x10, 0x00];
    let at = bytes
        .windows(4)
        .rposition(|w| w == pixel_data)
        .expect("PixelData");
    let mut nested = Vec::new();
    for _ in 0..depth {
        // (0040,A730) SQ, undefined length; an item of undefined length.
        nested.extend([
            0x40, 0x00, 0x30, 0xA7, b'S', b'Q', 0, 0, 0xFF, 0xFF, 0xFF, 0xFF,
        ]);
        nested.extend([0xFE, 0xFF, 0x00, 0xE0, 0xFF, 0xFF, 0xFF, 0xFF]);
    }
    for _ in 0..depth {
        nested.extend([0xFE, 0xFF, 0x0D, 0xE0, 0, 0, 0, 0]);
        nested.extend([0xFE, 0xFF, 0xDD, 0xE0, 0, 0, 0, 0]);
    }
    let mut out = bytes[..at].to_vec();
    out.extend(nested);
    out.extend(&bytes[at..]);
    std::fs::write(&path, out).expect("rewrite");
}

/// Sequences nested 3000 deep made dicom-rs's recursive reader overflow the stack and abort the
/// process (exit 134), in the window too; a folder of good slices with one such file beside them
/// did not open.
#[test]
fn sequences_nested_thousands_deep_are_refused_and_the_good_slices_beside_them_open() {
    let dir = common::TempDir::new("dicom-deep");
    for z in 0..3 {
        write(
            dir.path(),
            &format!("s{z}.dcm"),
            &axial("deep", f64::from(z), 100),
        );
    }
    deeply_nested(dir.path(), "deep.dcm", 3000);
    let v = load_ok(dir.path());
    assert_eq!(v.dims(), [4, 3, 3]);
    let skipped = v.provenance().skipped.clone().unwrap_or_default();
    assert!(
        skipped.contains("deep.dcm") && skipped.contains("nest"),
        "{skipped}"
    );
    let e = load_volume(&dir.path().join("deep.dcm"), &LoadOptions::default()).expect_err("deep");
    assert!(e.to_string().contains("nest more than 64 deep"), "{e}");
    // Nesting real objects use still reads.
    let shallow = common::TempDir::new("dicom-shallow");
    deeply_nested(shallow.path(), "nested.dcm", 20);
    assert_eq!(
        load_ok(&shallow.path().join("nested.dcm")).dims(),
        [4, 3, 1]
    );
}

/// Two copies of one slice (the same SOPInstanceUID): the one kept, first by name, has a corrupt
/// codestream; the other is read in its place, and a note says so.
#[test]
fn a_corrupt_copy_of_a_slice_gives_way_to_a_copy_that_decodes() {
    let dir = common::TempDir::new("dicom-copies");
    let samples = ramp(4, 3);
    let good = libjpeg_turbo_8_bit(&samples, 4, 3);
    let mut broken = good.clone();
    let middle = broken.len() / 2;
    broken[middle..middle + 2].copy_from_slice(&[0xFF, 0xD9]);
    for (name, z, stream) in [
        ("b.dcm", 0.0, &good),
        ("c.dcm", 1.0, &good),
        ("a.dcm", 0.0, &broken),
    ] {
        let mut s = axial("copies", z, 0);
        s.bits_allocated = 8;
        s.bits_stored = 8;
        s.transfer_syntax = "1.2.840.10008.1.2.4.70";
        s.fragment = Some(stream.clone());
        write(dir.path(), name, &s);
    }
    let v = load_ok(dir.path());
    assert_eq!(v.dims(), [4, 3, 2]);
    assert_eq!(v.value(3, 2, 0), f64::from(samples[11]));
    let notes = &v.provenance().notes;
    assert!(
        notes
            .iter()
            .any(|n| n.contains("a.dcm") && n.contains("b.dcm") && n.contains("was read instead")),
        "{notes:?}"
    );
}

#[test]
fn a_series_many_folders_down_opens_and_one_too_deep_is_named() {
    let dir = common::TempDir::new("dicom-folders");
    let mut deep = dir.path().to_path_buf();
    for level in 0..20 {
        deep.push(format!("level{level}"));
    }
    std::fs::create_dir_all(&deep).expect("folders");
    for z in 0..2 {
        write(
            &deep,
            &format!("s{z}.dcm"),
            &axial("deep folders", f64::from(z), 5),
        );
    }
    assert_eq!(load_ok(dir.path()).dims(), [4, 3, 2]);

    let too_deep = common::TempDir::new("dicom-too-deep");
    let mut path = too_deep.path().to_path_buf();
    for level in 0..40 {
        path.push(format!("{level}"));
    }
    std::fs::create_dir_all(&path).expect("folders");
    write(&path, "s.dcm", &axial("too deep", 0.0, 5));
    let e = load_volume(too_deep.path(), &LoadOptions::default()).expect_err("too deep");
    assert!(e.to_string().contains("more than 32 levels down"), "{e}");
}

/// A file named by the user that is not DICOM, beside a series that is: an error naming it,
/// not the series beside it opened in its place.
#[test]
fn a_named_file_that_is_not_dicom_is_named_not_passed_over() {
    let dir = common::TempDir::new("dicom-named");
    for z in 0..2 {
        write(
            dir.path(),
            &format!("s{z}.dcm"),
            &axial("beside", f64::from(z), 5),
        );
    }
    let named = dir.write("scan.dcm", b"not a DICOM file at all, but named like one");
    let e = load_volume(&named, &LoadOptions::default()).expect_err("not DICOM");
    let text = e.to_string();
    assert!(
        text.contains("scan.dcm") && text.contains("not a DICOM file"),
        "{text}"
    );
}

/// A gantry tilt's in-plane shift past anything a frame holds (a position of -1e308 mm across the
/// normal: an infinite shift in pixels): the resampler's indices overflowed (a panic in debug
/// builds, a wrapped index in release); now such a slice is refused, naming it.
#[test]
fn a_slice_shifted_impossibly_far_in_its_plane_does_not_overflow() {
    let dir = common::TempDir::new("dicom-far-shift");
    for z in 0..3 {
        let mut s = axial("far", f64::from(z), 10);
        if z == 1 {
            s.position[0] = -1e308;
        }
        write(dir.path(), &format!("s{z}.dcm"), &s);
    }
    let e = load_volume(dir.path(), &LoadOptions::default()).expect_err("a slice far away");
    assert!(
        e.to_string().contains("'s1.dcm' lies") && e.to_string().contains("beyond any gantry tilt"),
        "{e}"
    );
    // The resampler itself reads such a shift as outside the frame (its unit test); a tilt of
    // a few pixels still resamples.
    let tilt = common::TempDir::new("dicom-small-shift");
    for z in 0..3 {
        let mut s = axial("tilt", f64::from(z), 10);
        s.position[1] += 0.5 * f64::from(z);
        write(tilt.path(), &format!("s{z}.dcm"), &s);
    }
    assert_eq!(load_ok(tilt.path()).dims(), [4, 3, 3]);
}

/// A file that cannot be decoded, in a sub-folder of the folder opened: the error names it by its
/// path below that folder, not by a bare file name another sub-folder could hold too.
#[test]
fn an_undecodable_file_is_named_by_its_path_below_the_folder() {
    let dir = common::TempDir::new("dicom-named-path");
    let samples = ramp(4, 3);
    let good = libjpeg_turbo_8_bit(&samples, 4, 3);
    let mut broken = good.clone();
    let middle = broken.len() / 2;
    broken[middle..middle + 2].copy_from_slice(&[0xFF, 0xD9]);
    for (sub, z, stream) in [("a", 0.0, &good), ("b", 1.0, &broken), ("c", 2.0, &good)] {
        let folder = dir.path().join(sub);
        std::fs::create_dir_all(&folder).expect("folder");
        let mut s = axial("paths", z, 0);
        s.bits_allocated = 8;
        s.bits_stored = 8;
        s.transfer_syntax = "1.2.840.10008.1.2.4.70";
        s.fragment = Some(stream.clone());
        write(&folder, "IM.dcm", &s);
    }
    let e = load_volume(dir.path(), &LoadOptions::default()).expect_err("a corrupt stream");
    let text = e.to_string();
    let named = Path::new("b").join("IM.dcm");
    assert!(text.contains(&format!("'{}'", named.display())), "{text}");
}
