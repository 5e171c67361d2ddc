//! NIfTI-1 single-file volumes (`.nii`, `.nii.gz`). The `nifti` crate parses the 348-byte header
//! (and detects its byte order); the samples are read here, through the same bounded decoding as
//! NRRD, starting at `vox_offset`.
//!
//! Choices: a zero or non-finite `pixdim` gives 1 mm with a logged warning (as a NRRD file without
//! spacing does), so the volume still opens; `scl_slope` 0 or non-finite means no scaling, as the
//! standard says.

use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use flate2::bufread::MultiGzDecoder;
use nifti::{Endianness, NiftiHeader, NiftiType};

use super::decode::{self, Encoding, SampleLayout};
use super::error::VolumeError;
use super::limits::{self, DataSource};
use super::progress::LoadProgress;
use super::{Orientation, ScalarType, ValueMapping, Volume};

const NIFTI: &str = "NIfTI-1";

/// Size of a NIfTI-1 header.
const HEADER_BYTES: usize = 348;

/// Reads a NIfTI-1 volume, gzip-compressed or not (told by the content, not the name); `name`
/// becomes the volume's name.
pub fn read_nifti(
    path: &Path,
    name: String,
    progress: Option<&LoadProgress>,
) -> Result<Volume, VolumeError> {
    let (file, file_len) = decode::open_file(path)?;
    let mut reader = BufReader::new(file);
    let gzip = reader.fill_buf()?.starts_with(&[0x1f, 0x8b]);
    if gzip {
        read_stream(
            &mut MultiGzDecoder::new(reader),
            Encoding::Gzip,
            file_len,
            name,
            progress,
        )
    } else {
        read_stream(&mut reader, Encoding::Raw, file_len, name, progress)
    }
}

/// Reads header and samples from the (decompressed) stream of a file `file_len` bytes long.
fn read_stream(
    reader: &mut impl Read,
    encoding: Encoding,
    file_len: u64,
    name: String,
    progress: Option<&LoadProgress>,
) -> Result<Volume, VolumeError> {
    let mut bytes = [0u8; HEADER_BYTES];
    let got = read_up_to(reader, &mut bytes, encoding)?;
    if got < HEADER_BYTES {
        return Err(bad_header(format!(
            "the file holds {got} bytes, less than a {HEADER_BYTES}-byte NIfTI-1 header"
        )));
    }
    let header = parse_header(&bytes)?;
    check_dimension_count(&header, &bytes)?;
    let (dims, scalar_type) = (dims_of(&header)?, scalar_type_of(&header)?);
    let vox_offset = vox_offset_of(&header)?;
    let (dims, declared_bytes) = limits::check_dims(dims, scalar_type)?;
    let source = match encoding {
        Encoding::Raw => DataSource::Uncompressed {
            available_bytes: file_len.saturating_sub(vox_offset),
        },
        Encoding::Gzip => DataSource::Gzip {
            compressed_bytes: file_len,
            skip_bytes: vox_offset,
        },
    };
    limits::check_fits(dims, scalar_type, declared_bytes, source)?;
    if let DataSource::Uncompressed { available_bytes } = source
        && available_bytes > declared_bytes
    {
        return Err(VolumeError::DataTooLong {
            dims,
            scalar_type,
            declared_bytes,
            found_bytes: available_bytes,
            exact: true,
        });
    }
    // Extensions between the header and the samples are skipped.
    let extension_bytes = vox_offset - HEADER_BYTES as u64;
    if decode::skip_bytes(reader, extension_bytes, encoding)? < extension_bytes {
        return Err(VolumeError::DataTooShort {
            dims,
            scalar_type,
            declared_bytes,
            found_bytes: 0,
        });
    }
    let layout = SampleLayout {
        dims,
        scalar_type,
        big_endian: header.endianness == Endianness::Big,
    };
    let samples = decode::read_samples_with(reader, layout, encoding, progress)?;
    let spacing_mm = spacing_of(&header);
    Ok(
        Volume::new(name, dims, spacing_mm, samples, mapping_of(&header))?
            .with_orientation(orientation_of(&header))
            .with_provenance(super::Provenance {
                origin_lps: origin_of(&header),
                ..super::Provenance::default()
            }),
    )
}

/// Where the first voxel's centre lies in the patient frame, as LPS millimetres: the sform's
/// translation (preferred, as for the orientation) or the qform's offset, both RAS in NIfTI;
/// `None` when both codes are 0 or the numbers are not finite.
fn origin_of(header: &NiftiHeader) -> Option<[f64; 3]> {
    let ras = if header.sform_code > 0 {
        [header.srow_x[3], header.srow_y[3], header.srow_z[3]]
    } else if header.qform_code > 0 {
        [header.quatern_x, header.quatern_y, header.quatern_z]
    } else {
        return None;
    };
    let [x, y, z] = ras.map(f64::from);
    [x, y, z]
        .iter()
        .all(|v| v.is_finite())
        .then_some([-x, -y, z])
}

/// The anatomical orientation from the sform (preferred, as nibabel) or the qform; `None` when
/// both codes are 0 (unknown).
fn orientation_of(header: &NiftiHeader) -> Option<Orientation> {
    if header.sform_code > 0 {
        let rows = [header.srow_x, header.srow_y, header.srow_z];
        return Orientation::from_ras_columns([0, 1, 2].map(|a| rows.map(|r| f64::from(r[a]))));
    }
    if header.qform_code > 0 {
        // NIfTI-1 quaternion: a = √(1 − b² − c² − d²); qfac (pixdim[0] < 0) flips k.
        let [b, c, d] = [header.quatern_b, header.quatern_c, header.quatern_d].map(f64::from);
        let a = (1.0 - (b * b + c * c + d * d)).max(0.0).sqrt();
        let qfac = if header.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let r = [
            [
                a * a + b * b - c * c - d * d,
                2.0 * (b * c - a * d),
                2.0 * (b * d + a * c),
            ],
            [
                2.0 * (b * c + a * d),
                a * a + c * c - b * b - d * d,
                2.0 * (c * d - a * b),
            ],
            [
                2.0 * (b * d - a * c),
                2.0 * (c * d + a * b),
                a * a + d * d - c * c - b * b,
            ],
        ];
        return Orientation::from_ras_columns([0, 1, 2].map(|col| {
            let sign = if col == 2 { qfac } else { 1.0 };
            r.map(|row| row[col] * sign)
        }));
    }
    None
}

/// Reads until `buf` is full or the stream ends; returns the bytes read.
fn read_up_to(
    reader: &mut impl Read,
    buf: &mut [u8],
    encoding: Encoding,
) -> Result<usize, VolumeError> {
    let mut filled = 0;
    while filled < buf.len() {
        match reader.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(decode::read_error(e, encoding)),
        }
    }
    Ok(filled)
}

fn parse_header(bytes: &[u8; HEADER_BYTES]) -> Result<NiftiHeader, VolumeError> {
    let size_le = i32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
    let size_be = i32::from_be_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
    if size_le == 540 || size_be == 540 {
        return Err(bad_header(
            "this is a NIfTI-2 file; LeapView reads NIfTI-1".to_string(),
        ));
    }
    if size_le != HEADER_BYTES as i32 && size_be != HEADER_BYTES as i32 {
        return Err(bad_header(format!(
            "the header size field is {size_le}, not {HEADER_BYTES}"
        )));
    }
    let header = NiftiHeader::from_reader(&bytes[..]).map_err(|e| match e {
        nifti::NiftiError::InvalidFormat => {
            bad_header("the header's magic is neither 'n+1' nor 'ni1'".to_string())
        }
        other => bad_header(other.to_string()),
    })?;
    if &header.magic == nifti::header::MAGIC_CODE_NI1 {
        return Err(bad_header(
            "the header says its samples are in a separate .img file (a NIfTI header/image \
             pair); LeapView reads single-file .nii volumes"
                .to_string(),
        ));
    }
    Ok(header)
}

/// `dim[0]`, the number of dimensions, is 1 to 7 in a valid header in one byte order or the
/// other (that is how readers tell the order). A value valid in neither is reported as written
/// (little-endian), not as the byte-swapped number a reader then assumes.
fn check_dimension_count(header: &NiftiHeader, bytes: &[u8]) -> Result<(), VolumeError> {
    if (1..=7).contains(&(header.dim[0] as i16)) {
        return Ok(());
    }
    // Offset 40 holds dim[0] (the header's length was checked before).
    let written = bytes
        .get(40..42)
        .map_or(0, |b| i16::from_le_bytes([b[0], b[1]]));
    Err(VolumeError::BadField {
        format: NIFTI,
        field: "dim[0]".to_string(),
        value: written.to_string(),
        expected: "it must be the number of dimensions, 1 to 7".to_string(),
    })
}

/// `dim[1..=3]`, for `dim[0]` 3 (or 4 with `dim[4] == 1`). `dim` is signed in the standard.
fn dims_of(header: &NiftiHeader) -> Result<[u64; 3], VolumeError> {
    let dim = header.dim.map(|d| d as i16);
    match dim[0] {
        3 => {}
        4 if dim[4] == 1 => {}
        n => {
            return Err(VolumeError::UnsupportedDimension {
                dimension: n.to_string(),
                hint: " (or 4-D with a single time point)",
            });
        }
    }
    if dim[1..=3].iter().any(|&d| d <= 0) {
        return Err(VolumeError::BadField {
            format: NIFTI,
            field: "dim".to_string(),
            value: format!("{:?}", &dim[..=dim[0] as usize]),
            expected: "the sizes dim[1..3] must be positive".to_string(),
        });
    }
    Ok([dim[1], dim[2], dim[3]].map(|d| d as u64))
}

fn scalar_type_of(header: &NiftiHeader) -> Result<ScalarType, VolumeError> {
    let code = header.datatype;
    let nifti_type = header
        .data_type()
        .map_err(|_| VolumeError::UnsupportedType {
            name: format!("datatype code {code}"),
        })?;
    let t = match nifti_type {
        NiftiType::Uint8 => ScalarType::U8,
        NiftiType::Int8 => ScalarType::I8,
        NiftiType::Uint16 => ScalarType::U16,
        NiftiType::Int16 => ScalarType::I16,
        NiftiType::Uint32 => ScalarType::U32,
        NiftiType::Int32 => ScalarType::I32,
        NiftiType::Float32 => ScalarType::F32,
        NiftiType::Float64 => ScalarType::F64,
        other => {
            return Err(VolumeError::UnsupportedType {
                name: format!("{other:?} (NIfTI datatype {code})"),
            });
        }
    };
    if header.bitpix != 8 * t.size_bytes() as i16 {
        log::warn!(
            "NIfTI bitpix {} disagrees with datatype {t}; using the datatype",
            header.bitpix
        );
    }
    Ok(t)
}

/// Where the samples start: at least past the header, and a whole number of bytes.
fn vox_offset_of(header: &NiftiHeader) -> Result<u64, VolumeError> {
    let offset = header.vox_offset;
    if !offset.is_finite() || offset < HEADER_BYTES as f32 || offset.fract() != 0.0 {
        return Err(VolumeError::BadField {
            format: NIFTI,
            field: "vox_offset".to_string(),
            value: offset.to_string(),
            expected: format!("it must be a whole number of bytes, at least {HEADER_BYTES}"),
        });
    }
    Ok(offset as u64)
}

fn spacing_of(header: &NiftiHeader) -> [f64; 3] {
    std::array::from_fn(|a| {
        let p = f64::from(header.pixdim[a + 1]).abs();
        if p.is_finite() && p > 0.0 {
            p
        } else {
            log::warn!("NIfTI pixdim[{}] is {p}; using 1 mm", a + 1);
            1.0
        }
    })
}

/// `scl_slope`/`scl_inter`; a slope of 0 or one that is not finite means no scaling.
fn mapping_of(header: &NiftiHeader) -> ValueMapping {
    let slope = f64::from(header.scl_slope);
    let intercept = f64::from(header.scl_inter);
    if slope == 0.0 || !slope.is_finite() {
        return ValueMapping::IDENTITY;
    }
    if !intercept.is_finite() {
        log::warn!("NIfTI scl_inter is {intercept}; using 0");
    }
    ValueMapping {
        slope,
        intercept: if intercept.is_finite() {
            intercept
        } else {
            0.0
        },
    }
}

fn bad_header(reason: String) -> VolumeError {
    VolumeError::BadHeader {
        format: NIFTI,
        reason,
    }
}
