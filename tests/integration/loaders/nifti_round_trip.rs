//! Generated NIfTI-1 files (header written field by field) read back exactly: every type, both
//! byte orders, plain and gzip, extensions before the samples, scaling and spacing rules.

use leapview::volume::{ScalarType, ValueMapping};

use crate::common::{ALL_TYPES, NiftiSpec, TempDir, gzip, load_ok, samples_of, to_bytes};

const DIMS: [u32; 3] = [5, 4, 3];
const COUNT: usize = 60;

#[test]
fn every_type_byte_order_and_compression_round_trips() {
    let dir = TempDir::new("nifti-types");
    for t in ALL_TYPES {
        for big_endian in [false, true] {
            for gz in [false, true] {
                let samples = samples_of(t, COUNT);
                let mut spec = NiftiSpec::new(t, DIMS, [0.5, 0.75, 2.0]);
                spec.big_endian = big_endian;
                let bytes = spec.file(&to_bytes(&samples, big_endian));
                let name = format!("{t}-{big_endian}.nii{}", if gz { ".gz" } else { "" });
                let bytes = if gz { gzip(&bytes) } else { bytes };
                let v = load_ok(&dir.write(&name, &bytes));
                assert_eq!(v.name(), name);
                assert_eq!(v.dims(), DIMS, "{name}");
                // 0.5, 0.75 and 2 are exact in f32.
                assert_eq!(v.spacing_mm(), [0.5, 0.75, 2.0], "{name}");
                assert_eq!(v.samples().expect("in memory"), &samples, "{name}");
                assert_eq!(v.mapping(), ValueMapping::IDENTITY, "{name}: scl_slope 0");
            }
        }
    }
}

#[test]
fn extensions_before_the_samples_are_skipped() {
    let dir = TempDir::new("nifti-extensions");
    let samples = samples_of(ScalarType::I16, COUNT);
    let mut spec = NiftiSpec::new(ScalarType::I16, DIMS, [1.0; 3]);
    spec.vox_offset = 400.0;
    let mut bytes = spec.header_bytes();
    // Extension flag set, then an extension block of junk up to byte 400.
    bytes.extend_from_slice(&[1, 0, 0, 0]);
    bytes.extend((352..400).map(|i| i as u8));
    bytes.extend_from_slice(&to_bytes(&samples, false));
    for (name, bytes) in [("ext.nii", bytes.clone()), ("ext.nii.gz", gzip(&bytes))] {
        let v = load_ok(&dir.write(name, &bytes));
        assert_eq!(v.samples().expect("in memory"), &samples, "{name}");
    }
}

#[test]
fn scaling_follows_the_standard() {
    let dir = TempDir::new("nifti-scaling");
    let samples = samples_of(ScalarType::U8, COUNT);
    let data = to_bytes(&samples, false);
    // (scl_slope, scl_inter) → mapping. A zero or non-finite slope means no scaling.
    let cases = [
        (
            2.0,
            -1.0,
            ValueMapping {
                slope: 2.0,
                intercept: -1.0,
            },
        ),
        (0.0, 5.0, ValueMapping::IDENTITY),
        (f32::NAN, 5.0, ValueMapping::IDENTITY),
        (
            -0.5,
            0.0,
            ValueMapping {
                slope: -0.5,
                intercept: 0.0,
            },
        ),
    ];
    for (i, (slope, inter, mapping)) in cases.into_iter().enumerate() {
        let mut spec = NiftiSpec::new(ScalarType::U8, DIMS, [1.0; 3]);
        (spec.scl_slope, spec.scl_inter) = (slope, inter);
        let v = load_ok(&dir.write(&format!("{i}.nii"), &spec.file(&data)));
        assert_eq!(v.mapping(), mapping, "slope {slope}, inter {inter}");
        let range = v.value_range().expect("finite");
        // samples_of puts 0 and 255 first; a negative slope swaps the ends.
        let ends = (mapping.apply(0.0), mapping.apply(255.0));
        assert_eq!(
            (range.min, range.max),
            (ends.0.min(ends.1), ends.0.max(ends.1))
        );
    }
}

#[test]
fn spacing_is_the_magnitude_of_pixdim_and_unusable_ones_become_1_mm() {
    let dir = TempDir::new("nifti-spacing");
    let samples = samples_of(ScalarType::U8, COUNT);
    let data = to_bytes(&samples, false);
    let cases = [
        ([-0.5, 0.75, 2.0], [0.5, 0.75, 2.0]),
        // The chosen rule (see nifti.rs): zero or non-finite pixdim → 1 mm, with a warning.
        ([0.0, f32::NAN, f32::INFINITY], [1.0, 1.0, 1.0]),
    ];
    for (i, (pixdim, spacing)) in cases.into_iter().enumerate() {
        let spec = NiftiSpec::new(ScalarType::U8, DIMS, pixdim);
        let v = load_ok(&dir.write(&format!("{i}.nii"), &spec.file(&data)));
        assert_eq!(v.spacing_mm(), spacing, "pixdim {pixdim:?}");
    }
    // A 4-D file with a single time point is a volume.
    let mut spec = NiftiSpec::new(ScalarType::U8, DIMS, [1.0, 2.0, 3.0]);
    spec.dim[0] = 4;
    spec.pixdim[4] = 2.5;
    let v = load_ok(&dir.write("4d.nii", &spec.file(&data)));
    assert_eq!((v.dims(), v.spacing_mm()), (DIMS, [1.0, 2.0, 3.0]));
    assert_eq!(v.samples().expect("in memory"), &samples);
}
