//! Generated NRRD and raw files read back exactly: every type, both encodings, both byte orders,
//! attached and detached headers with skips, spacings and space directions, value scaling.

use leapview::volume::load::{LoadOptions, load_volume};
use leapview::volume::raw::RawParams;
use leapview::volume::{ScalarType, ValueMapping};

use crate::common::{
    ALL_TYPES, TempDir, gzip, load_ok, nrrd_file, nrrd_lines, samples_of, to_bytes,
};

const DIMS: [u32; 3] = [5, 4, 3];
const COUNT: usize = 60;

fn lines_with(t: ScalarType, encoding: &str, big_endian: bool, extra: &[&str]) -> Vec<String> {
    let mut lines = nrrd_lines(t, DIMS, encoding, big_endian);
    lines.extend(extra.iter().map(|s| s.to_string()));
    lines
}

fn file(lines: &[String], data: &[u8]) -> Vec<u8> {
    let lines: Vec<&str> = lines.iter().map(String::as_str).collect();
    nrrd_file(&lines, data)
}

#[test]
fn every_type_encoding_and_byte_order_round_trips() {
    let dir = TempDir::new("nrrd-types");
    for t in ALL_TYPES {
        for gz in [false, true] {
            for big_endian in [false, true] {
                let samples = samples_of(t, COUNT);
                let raw = to_bytes(&samples, big_endian);
                let (encoding, data) = if gz {
                    ("gzip", gzip(&raw))
                } else {
                    ("raw", raw)
                };
                let lines = lines_with(t, encoding, big_endian, &["spacings: 0.5 0.75 2"]);
                let name = format!("{t}-{encoding}-{big_endian}.nrrd");
                let v = load_ok(&dir.write(&name, &file(&lines, &data)));
                assert_eq!(v.name(), name);
                assert_eq!(v.dims(), DIMS, "{name}");
                assert_eq!(v.spacing_mm(), [0.5, 0.75, 2.0], "{name}");
                assert_eq!(v.samples().expect("in memory"), &samples, "{name}");
                assert_eq!(v.mapping(), ValueMapping::IDENTITY, "{name}");
            }
        }
    }
}

#[test]
fn gz_is_gzip_and_single_byte_types_need_no_endian() {
    let dir = TempDir::new("nrrd-gz");
    let samples = samples_of(ScalarType::I8, COUNT);
    let data = gzip(&to_bytes(&samples, false));
    let lines = [
        "type: signed char",
        "dimension: 3",
        "sizes: 5 4 3",
        "encoding: gz",
    ];
    let v = load_ok(&dir.write("gz.nrrd", &nrrd_file(&lines, &data)));
    assert_eq!(v.samples().expect("in memory"), &samples);
    assert_eq!(v.spacing_mm(), [1.0; 3], "no spacing given: 1 mm");
}

#[test]
fn detached_headers_with_line_and_byte_skips_round_trip() {
    let dir = TempDir::new("nrrd-detached");
    std::fs::create_dir(dir.path().join("sub")).expect("create a sub-folder");
    let samples = samples_of(ScalarType::I16, COUNT);
    let raw = to_bytes(&samples, true);

    // Raw: two text lines, then 7 bytes, then the samples.
    let mut data = b"a text line\nanother\n\x01\x02\x03\x04\x05\x06\x07".to_vec();
    data.extend_from_slice(&raw);
    dir.write("sub/data.bin", &data);
    let skips = ["data file: sub/data.bin", "line skip: 2", "byte skip: 7"];
    let lines = lines_with(ScalarType::I16, "raw", true, &skips);
    let v = load_ok(&dir.write("raw.nhdr", &file(&lines, b"")));
    assert_eq!(v.samples().expect("in memory"), &samples);

    // Gzip: the line skip counts stored lines, the byte skip decompressed bytes.
    let mut data = b"stored line\n".to_vec();
    data.extend_from_slice(&gzip(&[b"12345".as_slice(), &raw].concat()));
    let data_path = dir.write("data.gz", &data);
    let absolute = format!("datafile: {}", data_path.display());
    let skips = [absolute.as_str(), "line skip: 1", "byte skip: 5"];
    let lines = lines_with(ScalarType::I16, "gzip", true, &skips);
    let v = load_ok(&dir.write("gz.nhdr", &file(&lines, b"")));
    assert_eq!(v.samples().expect("in memory"), &samples);

    // `byte skip: -1`: the samples are the last bytes, after a prefix of any length.
    let mut data = vec![0xee; 123];
    data.extend_from_slice(&raw);
    dir.write("tail.raw", &data);
    let skips = ["data file: tail.raw", "byte skip: -1"];
    let lines = lines_with(ScalarType::I16, "raw", true, &skips);
    let v = load_ok(&dir.write("tail.nhdr", &file(&lines, b"")));
    assert_eq!(v.samples().expect("in memory"), &samples);

    // An attached header with a byte skip.
    let lines = lines_with(ScalarType::I16, "raw", true, &["byte skip: 3"]);
    let v = load_ok(&dir.write(
        "skip.nrrd",
        &file(&lines, &[&[9, 9, 9], raw.as_slice()].concat()),
    ));
    assert_eq!(v.samples().expect("in memory"), &samples);
}

#[test]
fn spacings_and_space_directions_give_the_same_spacing() {
    let dir = TempDir::new("nrrd-spacing");
    let samples = samples_of(ScalarType::F32, COUNT);
    let data = to_bytes(&samples, false);
    let cases: [(&[&str], [f64; 3]); 4] = [
        (&["spacings: 0.5 0.75 2"], [0.5, 0.75, 2.0]),
        (
            &[
                "space: left-posterior-superior",
                "space directions: (0.5,0,0) (0,0.75,0) (0,0,2)",
            ],
            [0.5, 0.75, 2.0],
        ),
        // An oblique grid: the spacing is each direction's length (3-4-5 triangles).
        (
            &["space directions: (0,0.3,0.4) (-0.6,0,0.8) (0,0,-2)"],
            [0.5, 1.0, 2.0],
        ),
        (&["spacings: nan 2 nan"], [1.0, 2.0, 1.0]),
    ];
    for (i, (extra, spacing)) in cases.iter().enumerate() {
        let lines = lines_with(ScalarType::F32, "raw", false, extra);
        let v = load_ok(&dir.write(&format!("{i}.nrrd"), &file(&lines, &data)));
        // 0.3² + 0.4² and 0.6² + 0.8² are not exact in binary: a few ulps.
        for (got, want) in v.spacing_mm().iter().zip(spacing) {
            assert!(
                (got - want).abs() < 1e-12,
                "{extra:?}: {:?}",
                v.spacing_mm()
            );
        }
        assert_eq!(v.samples().expect("in memory"), &samples);
    }

    // A 4-D file whose first axis has one sample is a volume.
    let lines = [
        "type: float",
        "dimension: 4",
        "sizes: 1 5 4 3",
        "encoding: raw",
        "endian: little",
        "space directions: none (0.5,0,0) (0,0.75,0) (0,0,2)",
        "kinds: list domain domain domain",
    ];
    let v = load_ok(&dir.write("4d.nrrd", &nrrd_file(&lines, &data)));
    assert_eq!((v.dims(), v.spacing_mm()), (DIMS, [0.5, 0.75, 2.0]));
    assert_eq!(v.samples().expect("in memory"), &samples);
}

#[test]
fn value_scaling_keys_give_data_units() {
    let dir = TempDir::new("nrrd-scaling");
    let samples = samples_of(ScalarType::U8, COUNT);
    let data = to_bytes(&samples, false);
    let cases: [(&[&str], ValueMapping); 3] = [
        (
            &["nifti_scl_slope:=2.5", "nifti_scl_inter:=-10"],
            ValueMapping {
                slope: 2.5,
                intercept: -10.0,
            },
        ),
        (
            &["rescale_slope:=1", "rescale_intercept:=-1024"],
            ValueMapping {
                slope: 1.0,
                intercept: -1024.0,
            },
        ),
        // NIfTI's rule: a slope of 0 means no scaling at all.
        (
            &["nifti_scl_slope:=0", "nifti_scl_inter:=7"],
            ValueMapping::IDENTITY,
        ),
    ];
    for (i, (extra, mapping)) in cases.iter().enumerate() {
        let lines = lines_with(ScalarType::U8, "raw", false, extra);
        let v = load_ok(&dir.write(&format!("{i}.nrrd"), &file(&lines, &data)));
        assert_eq!(v.mapping(), *mapping, "{extra:?}");
        let stored = v.samples().expect("in memory").get_f64(v.index(1, 2, 0));
        assert_eq!(v.value(1, 2, 0), stored * mapping.slope + mapping.intercept);
        let range = v.value_range().expect("finite");
        // samples_of puts 0 and 255 first: the stored range is the whole of u8.
        assert_eq!(
            (range.min, range.max),
            (mapping.apply(0.0), mapping.apply(255.0))
        );
    }
}

#[test]
fn raw_files_round_trip_in_every_type_and_byte_order() {
    let dir = TempDir::new("raw");
    for t in ALL_TYPES {
        for big_endian in [false, true] {
            let samples = samples_of(t, COUNT);
            let name = format!("{t}-{big_endian}.img");
            let path = dir.write(&name, &to_bytes(&samples, big_endian));
            let options = LoadOptions {
                raw: Some(RawParams {
                    dims: DIMS,
                    scalar_type: t,
                    spacing_mm: [0.25, 0.5, 3.0],
                    big_endian,
                }),
                ..LoadOptions::default()
            };
            let v = load_volume(&path, &options).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(
                (v.name(), v.dims(), v.spacing_mm()),
                (name.as_str(), DIMS, [0.25, 0.5, 3.0])
            );
            assert_eq!(v.samples().expect("in memory"), &samples, "{name}");
        }
    }
}
