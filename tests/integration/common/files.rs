//! Helpers for the loader tests: a self-deleting temporary folder, deterministic samples of every
//! stored type, and small NRRD and NIfTI-1 writers. Test volumes are generated at test time and
//! never committed.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use leapview::volume::error::{LoadError, VolumeError};
use leapview::volume::load::{LoadOptions, load_volume};
use leapview::volume::raw::RawParams;
use leapview::volume::{Samples, ScalarType, Volume};

/// Every stored type, in a fixed order.
pub const ALL_TYPES: [ScalarType; 8] = [
    ScalarType::U8,
    ScalarType::I8,
    ScalarType::U16,
    ScalarType::I16,
    ScalarType::U32,
    ScalarType::I32,
    ScalarType::F32,
    ScalarType::F64,
];

/// A folder under the system's temporary folder, removed with everything in it when dropped.
pub struct TempDir {
    path: PathBuf,
}

impl TempDir {
    /// Creates a fresh, empty folder whose name includes `tag`.
    pub fn new(tag: &str) -> Self {
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let path =
            std::env::temp_dir().join(format!("leapview-test-{tag}-{}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&path);
        std::fs::create_dir_all(&path).expect("create a temporary folder");
        Self { path }
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Writes `bytes` to `name` in the folder and returns the file's path.
    pub fn write(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let path = self.path.join(name);
        std::fs::write(&path, bytes).expect("write a test file");
        path
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.path);
    }
}

/// `n` samples of type `t` that include the type's extremes, negative values where the type has
/// them, and (for floats) fractions, tiny and huge magnitudes; deterministic.
pub fn samples_of(t: ScalarType, n: usize) -> Samples {
    // A simple LCG: enough to make every byte position of every sample vary.
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        state >> 11
    };
    fn fill<T: Copy>(n: usize, extremes: &[T], mut generate: impl FnMut() -> T) -> Vec<T> {
        (0..n)
            .map(|i| extremes.get(i).copied().unwrap_or_else(&mut generate))
            .collect()
    }
    match t {
        ScalarType::U8 => Samples::U8(fill(n, &[0, u8::MAX], || next() as u8)),
        ScalarType::I8 => Samples::I8(fill(n, &[i8::MIN, i8::MAX, 0], || next() as i8)),
        ScalarType::U16 => Samples::U16(fill(n, &[0, u16::MAX], || next() as u16)),
        ScalarType::I16 => Samples::I16(fill(n, &[i16::MIN, i16::MAX], || next() as i16)),
        ScalarType::U32 => Samples::U32(fill(n, &[0, u32::MAX], || next() as u32)),
        ScalarType::I32 => Samples::I32(fill(n, &[i32::MIN, i32::MAX], || next() as i32)),
        ScalarType::F32 => Samples::F32(fill(n, &[f32::MIN, f32::MAX, 1e-30, -0.5], || {
            (next() as i32 as f32) / 1024.0
        })),
        ScalarType::F64 => Samples::F64(fill(n, &[f64::MIN, f64::MAX, 1e-300, -0.5], || {
            (next() as i64 as f64) / 4096.0
        })),
    }
}

/// The samples as bytes in the given byte order.
pub fn to_bytes(samples: &Samples, big_endian: bool) -> Vec<u8> {
    macro_rules! bytes {
        ($v:expr) => {
            $v.iter()
                .flat_map(|x| {
                    if big_endian {
                        x.to_be_bytes().to_vec()
                    } else {
                        x.to_le_bytes().to_vec()
                    }
                })
                .collect()
        };
    }
    match samples {
        Samples::U8(v) => v.clone(),
        Samples::I8(v) => bytes!(v),
        Samples::U16(v) => bytes!(v),
        Samples::I16(v) => bytes!(v),
        Samples::U32(v) => bytes!(v),
        Samples::I32(v) => bytes!(v),
        Samples::F32(v) => bytes!(v),
        Samples::F64(v) => bytes!(v),
    }
}

/// A gzip stream of `bytes`.
pub fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut encoder = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    encoder.write_all(bytes).expect("compress in memory");
    encoder.finish().expect("compress in memory")
}

/// An attached-header NRRD file: magic, the given lines, a blank line, then `data`.
pub fn nrrd_file(lines: &[&str], data: &[u8]) -> Vec<u8> {
    let mut bytes = format!("NRRD0004\n{}\n\n", lines.join("\n")).into_bytes();
    bytes.extend_from_slice(data);
    bytes
}

/// The NRRD header lines of a 3-D volume of `dims` samples of type `t`.
pub fn nrrd_lines(t: ScalarType, dims: [u32; 3], encoding: &str, big_endian: bool) -> Vec<String> {
    vec![
        format!("type: {}", t.name()),
        "dimension: 3".to_string(),
        format!("sizes: {} {} {}", dims[0], dims[1], dims[2]),
        format!("encoding: {encoding}"),
        format!("endian: {}", if big_endian { "big" } else { "little" }),
    ]
}

/// The NIfTI-1 `datatype` code of a stored type.
pub fn nifti_code(t: ScalarType) -> i16 {
    match t {
        ScalarType::U8 => 2,
        ScalarType::I16 => 4,
        ScalarType::I32 => 8,
        ScalarType::F32 => 16,
        ScalarType::F64 => 64,
        ScalarType::I8 => 256,
        ScalarType::U16 => 512,
        ScalarType::U32 => 768,
    }
}

/// The fields of a NIfTI-1 header that the tests vary.
#[derive(Clone, Debug)]
pub struct NiftiSpec {
    /// `dim[0..8]`.
    pub dim: [i16; 8],
    /// `datatype` code.
    pub datatype: i16,
    /// `bitpix`.
    pub bitpix: i16,
    /// `pixdim[0..8]`.
    pub pixdim: [f32; 8],
    /// `vox_offset`.
    pub vox_offset: f32,
    /// `scl_slope`.
    pub scl_slope: f32,
    /// `scl_inter`.
    pub scl_inter: f32,
    /// Byte order of the header and data.
    pub big_endian: bool,
    /// `magic`.
    pub magic: [u8; 4],
    /// `srow_x`, `srow_y`, `srow_z` with `sform_code` 1 (scanner anatomical), or no sform.
    pub sform: Option<[[f32; 4]; 3]>,
}

impl NiftiSpec {
    /// A 3-D volume of `dims` samples of type `t` with the given spacing, no scaling, samples at
    /// byte 352.
    pub fn new(t: ScalarType, dims: [u32; 3], spacing: [f32; 3]) -> Self {
        Self {
            dim: [
                3,
                dims[0] as i16,
                dims[1] as i16,
                dims[2] as i16,
                1,
                1,
                1,
                1,
            ],
            datatype: nifti_code(t),
            bitpix: 8 * t.size_bytes() as i16,
            pixdim: [1.0, spacing[0], spacing[1], spacing[2], 0.0, 0.0, 0.0, 0.0],
            vox_offset: 352.0,
            scl_slope: 0.0,
            scl_inter: 0.0,
            big_endian: false,
            magic: *b"n+1\0",
            sform: None,
        }
    }

    /// The 348-byte header, written field by field at the offsets of nifti1.h.
    pub fn header_bytes(&self) -> Vec<u8> {
        let mut h = vec![0u8; 348];
        let be = self.big_endian;
        let mut put = |offset: usize, bytes: &[u8]| {
            h[offset..offset + bytes.len()].copy_from_slice(bytes);
        };
        let i32b = |v: i32| if be { v.to_be_bytes() } else { v.to_le_bytes() };
        let i16b = |v: i16| if be { v.to_be_bytes() } else { v.to_le_bytes() };
        let f32b = |v: f32| if be { v.to_be_bytes() } else { v.to_le_bytes() };
        put(0, &i32b(348));
        for (i, &d) in self.dim.iter().enumerate() {
            put(40 + 2 * i, &i16b(d));
        }
        put(70, &i16b(self.datatype));
        put(72, &i16b(self.bitpix));
        for (i, &p) in self.pixdim.iter().enumerate() {
            put(76 + 4 * i, &f32b(p));
        }
        put(108, &f32b(self.vox_offset));
        put(112, &f32b(self.scl_slope));
        put(116, &f32b(self.scl_inter));
        put(344, &self.magic);
        if let Some(rows) = self.sform {
            put(254, &i16b(1));
            for (r, row) in rows.iter().enumerate() {
                for (c, v) in row.iter().enumerate() {
                    put(280 + 16 * r + 4 * c, &f32b(*v));
                }
            }
        }
        h
    }

    /// A whole `.nii` file: header, zero padding up to `vox_offset`, then `data`.
    pub fn file(&self, data: &[u8]) -> Vec<u8> {
        let mut bytes = self.header_bytes();
        bytes.resize(self.vox_offset.max(348.0) as usize, 0);
        bytes.extend_from_slice(data);
        bytes
    }
}

/// Loads a file with default options, panicking with the error's message on failure.
pub fn load_ok(path: &Path) -> Volume {
    load_volume(path, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("loading should succeed: {e}"))
}

/// Loads a file that must fail; checks that the message is one line ending with the path.
pub fn load_err(path: &Path, options: &LoadOptions) -> LoadError {
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

/// Loads a file with default options that must fail; returns the problem.
pub fn fails(path: &Path) -> VolumeError {
    load_err(path, &LoadOptions::default()).problem
}

/// Options that read a file as raw little-endian samples with 1 mm spacing.
pub fn raw_options(dims: [u32; 3], scalar_type: ScalarType) -> LoadOptions {
    LoadOptions {
        raw: Some(RawParams {
            dims,
            scalar_type,
            spacing_mm: [1.0; 3],
            big_endian: false,
        }),
        ..LoadOptions::default()
    }
}

/// The values of the box `lo..hi` of samples of a volume of `dims` (x fastest), as f64: what a
/// box read from a streamed source must hold.
pub fn box_values(
    samples: &leapview::volume::Samples,
    dims: [u32; 3],
    lo: [u32; 3],
    hi: [u32; 3],
) -> Vec<f64> {
    let mut out = Vec::new();
    for z in lo[2]..hi[2] {
        for y in lo[1]..hi[1] {
            for x in lo[0]..hi[0] {
                out.push(samples.get_f64((x + dims[0] * (y + dims[1] * z)) as usize));
            }
        }
    }
    out
}
