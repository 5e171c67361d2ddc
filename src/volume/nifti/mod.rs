//! NIfTI single-file volumes (`.nii`, `.nii.gz`), version 1 and 2 ([`header`] reads both), 3-D
//! or 4-D (fMRI time series, diffusion directions: one volume of the series opens, the first
//! unless the caller names another). The samples are read here, through the same bounded
//! decoding as NRRD, starting at `vox_offset` (and past the volumes before the one chosen).
//!
//! Choices: a zero or non-finite `pixdim` gives 1 mm with a logged warning (as a NRRD file without
//! spacing does), so the volume still opens; `scl_slope` 0 or non-finite means no scaling, as the
//! standard says.

pub mod header;

use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use flate2::bufread::MultiGzDecoder;

use self::header::{Header, NIFTI1_BYTES, NIFTI2_BYTES};
use super::decode::{self, Encoding, SampleLayout};
use super::error::VolumeError;
use super::limits::{self, DataSource};
use super::progress::LoadProgress;
use super::{
    model::Volume, model::VolumeIndex, orientation::Orientation, samples::ScalarType,
    samples::ValueMapping,
};

const NIFTI: &str = "NIfTI";

/// Reads a NIfTI volume, gzip-compressed or not (told by the content, not the name); `name`
/// becomes the volume's name. Of a 4-D file, volume `volume` (counted from 0; the first when
/// `None`).
pub(crate) fn read_nifti(
    path: &Path,
    name: String,
    volume: Option<u32>,
    progress: Option<&LoadProgress>,
) -> Result<Volume, VolumeError> {
    let (file, file_len) = decode::open_file(path)?;
    let mut reader = BufReader::new(file);
    let gzip = reader.fill_buf()?.starts_with(&[0x1f, 0x8b]);
    let stream = Stream {
        file_len,
        name,
        volume,
        progress,
    };
    if gzip {
        read_stream(&mut MultiGzDecoder::new(reader), Encoding::Gzip, stream)
    } else {
        read_stream(&mut reader, Encoding::Raw, stream)
    }
}

/// What [`read_stream`] reads besides the bytes.
struct Stream<'a> {
    file_len: u64,
    name: String,
    volume: Option<u32>,
    progress: Option<&'a LoadProgress>,
}

/// `NIFTI_INTENT_LABEL`: the samples are label indices.
const INTENT_LABEL: i32 = 1002;

/// What the header of the NIfTI file at `path` says, its samples unread.
pub(crate) fn header_facts(path: &Path) -> Result<super::load::HeaderFacts, VolumeError> {
    let (file, _) = decode::open_file(path)?;
    let mut reader = BufReader::new(file);
    let gzip = reader.fill_buf()?.starts_with(&[0x1f, 0x8b]);
    let header = if gzip {
        read_header(&mut MultiGzDecoder::new(reader), Encoding::Gzip)?
    } else {
        read_header(&mut reader, Encoding::Raw)?
    };
    check_dimension_count(&header)?;
    Ok(super::load::HeaderFacts::new(
        dims_of(&header)?,
        scalar_type_of(&header)?,
        mapping_of(&header),
    )
    .with_label_intent(header.intent_code == INTENT_LABEL))
}

/// Reads the header: its first 348 bytes, and the rest of a NIfTI-2 header.
fn read_header(reader: &mut impl Read, encoding: Encoding) -> Result<Header, VolumeError> {
    let mut bytes = vec![0u8; NIFTI1_BYTES];
    let got = read_up_to(reader, &mut bytes, encoding)?;
    if got < NIFTI1_BYTES {
        return Err(bad_header(format!(
            "the file holds {got} bytes, less than a {NIFTI1_BYTES}-byte NIfTI header"
        )));
    }
    let first = [bytes[0], bytes[1], bytes[2], bytes[3]];
    let Some((version, big_endian)) = header::version_of(first) else {
        return Err(bad_header(format!(
            "the header size field is {}, neither {NIFTI1_BYTES} (NIfTI-1) nor {NIFTI2_BYTES} \
             (NIfTI-2)",
            i32::from_le_bytes(first)
        )));
    };
    if version == 2 {
        bytes.resize(NIFTI2_BYTES, 0);
        let more = read_up_to(reader, &mut bytes[NIFTI1_BYTES..], encoding)?;
        if NIFTI1_BYTES + more < NIFTI2_BYTES {
            return Err(bad_header(format!(
                "the file holds {} bytes, less than a {NIFTI2_BYTES}-byte NIfTI-2 header",
                NIFTI1_BYTES + more
            )));
        }
    }
    let header = header::parse(&bytes, version, big_endian).map_err(bad_header)?;
    if header.pair {
        return Err(bad_header(
            "the header says its samples are in a separate .img file (a NIfTI header/image \
             pair); LeapView reads single-file .nii volumes"
                .to_string(),
        ));
    }
    Ok(header)
}

/// Reads header and samples from the (decompressed) stream of a file `file_len` bytes long.
fn read_stream(
    reader: &mut impl Read,
    encoding: Encoding,
    stream: Stream<'_>,
) -> Result<Volume, VolumeError> {
    let header = read_header(reader, encoding)?;
    check_dimension_count(&header)?;
    let (dims, scalar_type) = (dims_of(&header)?, scalar_type_of(&header)?);
    let count = volume_count(&header)?;
    let chosen = stream.volume.unwrap_or(0);
    if u64::from(chosen) >= count {
        return Err(VolumeError::NoSuchVolume {
            asked: u64::from(chosen) + 1,
            count,
        });
    }
    let vox_offset = vox_offset_of(&header)?;
    let (dims, volume_bytes) = limits::check_dims(dims, scalar_type)?;
    // The file must hold every volume its header declares, not only the one chosen.
    let declared_bytes = volume_bytes.saturating_mul(count);
    let source = match encoding {
        Encoding::Raw => DataSource::Uncompressed {
            available_bytes: stream.file_len.saturating_sub(vox_offset),
        },
        Encoding::Gzip => DataSource::Gzip {
            compressed_bytes: stream.file_len,
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
    // Extensions between the header and the samples, and the volumes before the chosen one,
    // are skipped.
    let skip = vox_offset - header.bytes() as u64 + volume_bytes * u64::from(chosen);
    if decode::skip_bytes(reader, skip, encoding)? < skip {
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
        big_endian: header.big_endian,
    };
    // Volumes after the chosen one follow its samples: read them as the stream's end only for
    // the last (whose end the reader checks).
    let samples = if u64::from(chosen) + 1 < count {
        let mut volume = reader.take(volume_bytes);
        decode::read_samples_with(&mut volume, layout, encoding, stream.progress)?
    } else {
        decode::read_samples_with(reader, layout, encoding, stream.progress)?
    };
    let spacing_mm = spacing_of(&header);
    let volumes = (count > 1).then_some(VolumeIndex {
        chosen,
        count: count.min(u64::from(u32::MAX)) as u32,
    });
    let mut notes = Vec::new();
    if let Some(v) = volumes {
        notes.push(format!(
            "volume {} of the {} this 4-D {} file holds (another: --volume N, or the window's \
             Volume slider)",
            v.chosen + 1,
            v.count,
            header.format()
        ));
    }
    Ok({
        let (dims, spacing) = super::progress::strided(dims, spacing_mm, stream.progress);
        Volume::new(stream.name, dims, spacing, samples, mapping_of(&header))?
    }
    .with_orientation(orientation_of(&header))
    .with_provenance(super::model::Provenance {
        origin_lps: origin_of(&header),
        notes,
        volumes,
        ..super::model::Provenance::default()
    }))
}

/// The volumes a file holds: the product of the sizes past the third dimension (time points,
/// diffusion directions, components), at least 1.
fn volume_count(header: &Header) -> Result<u64, VolumeError> {
    let n = header.dim[0].clamp(0, 7) as usize;
    let mut count: u64 = 1;
    for &d in &header.dim[4..=n.max(3)] {
        if d <= 0 {
            return Err(VolumeError::BadField {
                format: header.format(),
                field: "dim".to_string(),
                value: format!("{:?}", &header.dim[..=n]),
                expected: "every size past the third must be 1 or more".to_string(),
            });
        }
        count = count.saturating_mul(d as u64);
    }
    Ok(count)
}

/// Where the first voxel's centre lies in the patient frame, as LPS millimetres: the sform's
/// translation (preferred, as for the orientation) or the qform's offset, both RAS in NIfTI;
/// `None` when both codes are 0 or the numbers are not finite.
fn origin_of(header: &Header) -> Option<[f64; 3]> {
    let [x, y, z] = if header.sform_code > 0 {
        header.srow.map(|row| row[3])
    } else if header.qform_code > 0 {
        header.qoffset
    } else {
        return None;
    };
    [x, y, z]
        .iter()
        .all(|v| v.is_finite())
        .then_some([-x, -y, z])
}

/// The anatomical orientation from the sform (preferred, as nibabel) or the qform; `None` when
/// both codes are 0 (unknown).
fn orientation_of(header: &Header) -> Option<Orientation> {
    if header.sform_code > 0 {
        let rows = header.srow;
        return Orientation::from_ras_columns([0, 1, 2].map(|a| rows.map(|r| r[a])));
    }
    if header.qform_code > 0 {
        // The quaternion: a = √(1 − b² − c² − d²); qfac (pixdim[0] < 0) flips k.
        let [b, c, d] = header.quatern;
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

/// `dim[0]`, the number of dimensions, is 1 to 7 in a valid header.
fn check_dimension_count(header: &Header) -> Result<(), VolumeError> {
    if (1..=7).contains(&header.dim[0]) {
        return Ok(());
    }
    Err(VolumeError::BadField {
        format: header.format(),
        field: "dim[0]".to_string(),
        value: header.dim[0].to_string(),
        expected: "it must be the number of dimensions, 1 to 7".to_string(),
    })
}

/// `dim[1..=3]` (a 2-D image is one slice: 1 along the axes it does not have). `dim` is signed
/// in the standard.
fn dims_of(header: &Header) -> Result<[u64; 3], VolumeError> {
    let n = header.dim[0] as usize;
    let dims: [i64; 3] = std::array::from_fn(|a| if a < n { header.dim[a + 1] } else { 1 });
    if dims.iter().any(|&d| d <= 0) {
        return Err(VolumeError::BadField {
            format: header.format(),
            field: "dim".to_string(),
            value: format!("{:?}", &header.dim[..=n]),
            expected: "the sizes dim[1..3] must be positive".to_string(),
        });
    }
    Ok(dims.map(|d| d as u64))
}

fn scalar_type_of(header: &Header) -> Result<ScalarType, VolumeError> {
    let code = header.datatype;
    let t = match code {
        2 => ScalarType::U8,
        256 => ScalarType::I8,
        512 => ScalarType::U16,
        4 => ScalarType::I16,
        768 => ScalarType::U32,
        8 => ScalarType::I32,
        16 => ScalarType::F32,
        64 => ScalarType::F64,
        other => {
            let name = match other {
                32 => "complex64",
                128 => "RGB24",
                1024 => "int64",
                1280 => "uint64",
                1536 => "float128",
                1792 => "complex128",
                2048 => "complex256",
                2304 => "RGBA32",
                _ => "an unknown type",
            };
            return Err(VolumeError::UnsupportedType {
                name: format!("{name} (NIfTI datatype {code})"),
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
fn vox_offset_of(header: &Header) -> Result<u64, VolumeError> {
    let offset = header.vox_offset;
    let least = header.bytes() as f64;
    if !offset.is_finite() || offset < least || offset.fract() != 0.0 || offset > 1e15 {
        return Err(VolumeError::BadField {
            format: header.format(),
            field: "vox_offset".to_string(),
            value: offset.to_string(),
            expected: format!("it must be a whole number of bytes, at least {least}"),
        });
    }
    Ok(offset as u64)
}

fn spacing_of(header: &Header) -> [f64; 3] {
    std::array::from_fn(|a| {
        let p = header.pixdim[a + 1].abs();
        if p.is_finite() && p > 0.0 {
            p
        } else {
            log::warn!("NIfTI pixdim[{}] is {p}; using 1 mm", a + 1);
            1.0
        }
    })
}

/// `scl_slope`/`scl_inter`; a slope of 0 or one that is not finite means no scaling.
fn mapping_of(header: &Header) -> ValueMapping {
    let (slope, intercept) = (header.scl_slope, header.scl_inter);
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
