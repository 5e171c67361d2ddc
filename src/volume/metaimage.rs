//! MetaImage (ITK's format): `.mha` with the samples after the header (`ElementDataFile = LOCAL`)
//! and `.mhd` naming a data file, or `LIST` of slice files, raw or zlib-compressed
//! (`CompressedData`), `MET_UCHAR` … `MET_DOUBLE`, either byte order. `ElementSpacing` (else
//! `ElementSize`) gives the spacing; `TransformMatrix` (the direction of each index axis in ITK's
//! LPS world, one triple per axis) the orientation; `Offset` the first voxel's position.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

use flate2::read::ZlibDecoder;

use super::decode::{self, Encoding, SampleLayout};
use super::error::VolumeError;
use super::limits::{self, DataSource};
use super::progress::LoadProgress;
use super::{
    model::Provenance, model::Volume, orientation::Orientation, samples::ScalarType,
    samples::ValueMapping,
};

const FORMAT: &str = "MetaImage";
/// The longest header read: a MetaImage header is a few hundred bytes.
const MAX_HEADER_BYTES: u64 = 1 << 20;
/// Most slice files a `LIST` may name.
const MAX_LIST_FILES: usize = 65536;

/// Where the samples are.
#[derive(Clone, Debug, PartialEq)]
pub enum DataFile {
    /// After the header, in the same file.
    Local,
    /// One file, relative to the header's folder.
    File(String),
    /// Slice files, in order, each holding whole slices.
    List(Vec<String>),
}

/// A MetaImage header's meaning.
#[derive(Clone, Debug, PartialEq)]
pub struct MetaHeader {
    /// Samples along x, y, z (a 2-D image has one slice).
    pub dims: [u64; 3],
    /// Stored type.
    pub scalar_type: ScalarType,
    /// Spacing in mm.
    pub spacing_mm: [f64; 3],
    /// Multi-byte samples are big-endian.
    pub big_endian: bool,
    /// zlib-compressed.
    pub compressed: bool,
    /// Bytes to skip at the start of the data file; `None` for `HeaderSize = -1` (the samples are
    /// the file's last bytes).
    pub header_size: Option<u64>,
    /// The direction of each index axis (LPS).
    pub axes: Option<[[f64; 3]; 3]>,
    /// The first voxel's position (LPS, mm).
    pub offset: Option<[f64; 3]>,
    /// Where the samples are.
    pub data_file: DataFile,
}

fn bad(reason: impl Into<String>) -> VolumeError {
    VolumeError::BadHeader {
        format: FORMAT,
        reason: reason.into(),
    }
}

fn bad_field(field: &str, value: &str, expected: &str) -> VolumeError {
    VolumeError::BadField {
        format: FORMAT,
        field: field.to_string(),
        value: value.to_string(),
        expected: expected.to_string(),
    }
}

fn numbers(field: &str, value: &str, count: usize) -> Result<Vec<f64>, VolumeError> {
    let v: Vec<f64> = value
        .split_whitespace()
        .map(str::parse::<f64>)
        .collect::<Result<_, _>>()
        .map_err(|_| bad_field(field, value, "it must be numbers"))?;
    if v.len() < count || v.iter().any(|x| !x.is_finite()) {
        return Err(bad_field(
            field,
            value,
            "it must hold a finite number for each axis",
        ));
    }
    Ok(v)
}

fn boolean(field: &str, value: &str) -> Result<bool, VolumeError> {
    match value.trim().to_ascii_lowercase().as_str() {
        "true" | "1" => Ok(true),
        "false" | "0" => Ok(false),
        _ => Err(bad_field(field, value, "it must be True or False")),
    }
}

fn scalar_type(value: &str) -> Result<ScalarType, VolumeError> {
    Ok(match value.trim() {
        "MET_UCHAR" => ScalarType::U8,
        "MET_CHAR" => ScalarType::I8,
        "MET_USHORT" => ScalarType::U16,
        "MET_SHORT" => ScalarType::I16,
        // MetaIO's MET_LONG and MET_ULONG are 4 bytes (metaTypes.h), as MET_INT and MET_UINT.
        "MET_UINT" | "MET_ULONG" => ScalarType::U32,
        "MET_INT" | "MET_LONG" => ScalarType::I32,
        "MET_FLOAT" => ScalarType::F32,
        "MET_DOUBLE" => ScalarType::F64,
        other => {
            return Err(VolumeError::UnsupportedType {
                name: other.to_string(),
            });
        }
    })
}

/// Interprets a header's text (everything up to and including the `ElementDataFile` line, and
/// for `LIST` the file names after it).
pub fn parse_header(text: &str) -> Result<MetaHeader, VolumeError> {
    let mut ndims = None;
    let mut dims = None;
    let mut ty = None;
    let mut spacing = None;
    let mut size = None;
    let mut big_endian = false;
    let mut compressed = false;
    let mut header_size = Some(0);
    let mut axes = None;
    let mut offset = None;
    let mut channels = 1u64;
    let mut lines = text.lines();
    let mut data_file = None;
    while let Some(line) = lines.next() {
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        let Some((key, value)) = line.split_once('=') else {
            return Err(bad(format!("the line '{line}' is not 'Key = Value'")));
        };
        let (key, value) = (key.trim(), value.trim());
        match key {
            "ObjectType" if !value.eq_ignore_ascii_case("Image") => {
                return Err(bad_field(key, value, "LeapView reads Image objects"));
            }
            "NDims" => {
                let n: u64 = value
                    .parse()
                    .map_err(|_| bad_field(key, value, "it must be 2 or 3"))?;
                if !(2..=3).contains(&n) {
                    return Err(VolumeError::UnsupportedDimension {
                        dimension: n.to_string(),
                        hint: "",
                    });
                }
                ndims = Some(n as usize);
            }
            "DimSize" => {
                let sizes: Vec<i64> = value
                    .split_whitespace()
                    .map(str::parse)
                    .collect::<Result<_, _>>()
                    .map_err(|_| bad_field(key, value, "it must be whole numbers, one per axis"))?;
                if sizes.iter().any(|&n| n <= 0) {
                    return Err(bad_field(key, value, "each axis's size must be 1 or more"));
                }
                let d: Vec<u64> = sizes.into_iter().map(|n| n as u64).collect();
                dims = Some(d);
            }
            "ElementType" => ty = Some(scalar_type(value)?),
            "ElementSpacing" => spacing = Some(numbers(key, value, 1)?),
            "ElementSize" => size = Some(numbers(key, value, 1)?),
            "BinaryDataByteOrderMSB" | "ElementByteOrderMSB" => big_endian = boolean(key, value)?,
            "CompressedData" => compressed = boolean(key, value)?,
            "HeaderSize" => {
                header_size = match value.parse::<i64>() {
                    Ok(-1) => None,
                    Ok(n) if n >= 0 => Some(n as u64),
                    _ => return Err(bad_field(key, value, "it must be -1 or a byte count")),
                }
            }
            "TransformMatrix" | "Rotation" | "Orientation" => {
                let m = numbers(key, value, 4)?;
                if m.len() == 9 {
                    axes = Some([[m[0], m[1], m[2]], [m[3], m[4], m[5]], [m[6], m[7], m[8]]]);
                }
            }
            "Offset" | "Position" | "Origin" => {
                let o = numbers(key, value, 2)?;
                offset = Some([o[0], o[1], o.get(2).copied().unwrap_or(0.0)]);
            }
            "ElementNumberOfChannels" => {
                channels = value
                    .parse()
                    .map_err(|_| bad_field(key, value, "it must be a whole number"))?;
            }
            "ElementDataFile" => {
                let mut words = value.split_whitespace();
                data_file = Some(match words.next() {
                    Some(v) if v.eq_ignore_ascii_case("LOCAL") => DataFile::Local,
                    Some(v) if v.eq_ignore_ascii_case("LIST") => {
                        let names: Vec<String> = lines
                            .by_ref()
                            .map(str::trim)
                            .filter(|l| !l.is_empty())
                            .take(MAX_LIST_FILES + 1)
                            .map(str::to_string)
                            .collect();
                        if names.is_empty() || names.len() > MAX_LIST_FILES {
                            return Err(bad_field(
                                key,
                                value,
                                "a LIST must be followed by 1 to 65536 file names",
                            ));
                        }
                        DataFile::List(names)
                    }
                    Some(_) if words.next().is_some() => {
                        return Err(bad_field(
                            key,
                            value,
                            "file name patterns ('name%03d.raw 1 10 1') are not supported; use \
                             LIST",
                        ));
                    }
                    Some(_) => DataFile::File(value.to_string()),
                    None => return Err(bad_field(key, value, "it must name the data")),
                });
                break;
            }
            _ => {}
        }
    }
    let Some(data_file) = data_file else {
        return Err(VolumeError::MissingField {
            format: FORMAT,
            field: "ElementDataFile",
            why: ": it ends the header and says where the samples are",
        });
    };
    let missing = |field| VolumeError::MissingField {
        format: FORMAT,
        field,
        why: "",
    };
    let n = ndims.ok_or_else(|| missing("NDims"))?;
    let d = dims.ok_or_else(|| missing("DimSize"))?;
    if d.len() != n {
        return Err(bad_field(
            "DimSize",
            &format!("{d:?}"),
            &format!("it must have NDims ({n}) values"),
        ));
    }
    if channels != 1 {
        return Err(bad_field(
            "ElementNumberOfChannels",
            &channels.to_string(),
            "LeapView reads scalar images (1 channel)",
        ));
    }
    let dims = [d[0], d[1], d.get(2).copied().unwrap_or(1)];
    let scalar_type = ty.ok_or_else(|| missing("ElementType"))?;
    let spacing = spacing.or(size).unwrap_or_else(|| vec![1.0; n]);
    if spacing.len() < n || spacing.iter().take(n).any(|s| *s <= 0.0) {
        return Err(bad_field(
            "ElementSpacing",
            &format!("{spacing:?}"),
            &format!("it must be {n} positive numbers"),
        ));
    }
    let spacing_mm = [
        spacing[0],
        spacing[1],
        if n == 3 {
            spacing[2]
        } else {
            spacing[0].min(spacing[1])
        },
    ];
    if compressed && header_size.is_none() {
        return Err(bad_field(
            "HeaderSize",
            "-1",
            "compressed data cannot be found from the end of the file",
        ));
    }
    Ok(MetaHeader {
        dims,
        scalar_type,
        spacing_mm,
        big_endian,
        compressed,
        header_size,
        axes: if n == 3 { axes } else { None },
        offset,
        data_file,
    })
}

/// Reads the header text up to the end of its `ElementDataFile` line (for LIST, to the end of
/// the file, which must then be short); returns it and its length in bytes.
fn read_header_text(
    reader: &mut impl BufRead,
    file_len: u64,
) -> Result<(String, u64), VolumeError> {
    let mut text = String::new();
    let mut used = 0u64;
    loop {
        let mut line = Vec::new();
        let n = reader
            .by_ref()
            .take(MAX_HEADER_BYTES.saturating_sub(used) + 1)
            .read_until(b'\n', &mut line)?;
        if n == 0 {
            return Ok((text, used));
        }
        used += n as u64;
        if used > MAX_HEADER_BYTES {
            return Err(bad(
                "the header is longer than 1 MiB; is this a MetaImage file?",
            ));
        }
        let line = String::from_utf8(line).map_err(|_| {
            // Binary bytes after header lines: the samples, reached without the line that
            // should have come before them.
            if ["ObjectType", "NDims", "DimSize", "ElementType"]
                .iter()
                .any(|k| text.contains(k))
            {
                bad(
                    "the header ends without an ElementDataFile line, which says where the \
                     samples are (LOCAL: right after the header)",
                )
            } else {
                bad("the header holds bytes that are not text; is this a MetaImage file?")
            }
        })?;
        let is_data_line = line.trim_start().starts_with("ElementDataFile");
        let is_list = is_data_line && line.contains("LIST");
        text.push_str(&line);
        if is_data_line && !is_list {
            return Ok((text, used));
        }
        if is_list && file_len > MAX_HEADER_BYTES {
            return Err(bad("a header with a LIST must be a small .mhd file"));
        }
    }
}

fn data_path(header: &Path, name: &str) -> PathBuf {
    match Path::new(name) {
        p if p.is_absolute() => p.to_path_buf(),
        p => header
            .parent()
            .map_or_else(PathBuf::new, Path::to_path_buf)
            .join(p),
    }
}

/// Opens a data file the header names.
fn open_data(header: &Path, name: &str) -> Result<(File, u64), VolumeError> {
    decode::open_file(&data_path(header, name)).map_err(|e| match e {
        VolumeError::Io { source } => VolumeError::DataFileUnreadable {
            name: name.to_string(),
            source,
        },
        VolumeError::NotFound => VolumeError::DataFileUnreadable {
            name: name.to_string(),
            source: std::io::ErrorKind::NotFound.into(),
        },
        VolumeError::NotRegularFile { kind } => VolumeError::DataFileNotRegular {
            name: name.to_string(),
            kind,
        },
        // The data file, not the header the user named, is the folder.
        VolumeError::IsDirectory => VolumeError::DataFileNotRegular {
            name: name.to_string(),
            kind: "folder",
        },
        e => e,
    })
}

/// What the header of the MetaImage file at `path` says, its samples unread.
pub(crate) fn header_facts(path: &Path) -> Result<super::load::HeaderFacts, VolumeError> {
    let (file, file_len) = decode::open_file(path)?;
    let (text, _) = read_header_text(&mut BufReader::new(file), file_len)?;
    let meta = parse_header(&text)?;
    Ok(super::load::HeaderFacts::new(
        meta.dims,
        meta.scalar_type,
        ValueMapping::IDENTITY,
    ))
}

/// Reads a MetaImage volume; `name` becomes the volume's name.
pub(crate) fn read_metaimage(
    path: &Path,
    name: String,
    progress: Option<&LoadProgress>,
) -> Result<Volume, VolumeError> {
    let (file, file_len) = decode::open_file(path)?;
    let mut reader = BufReader::new(file);
    let (text, header_len) = read_header_text(&mut reader, file_len)?;
    let meta = parse_header(&text)?;
    let (dims, declared) = limits::check_dims(meta.dims, meta.scalar_type)?;
    let layout = SampleLayout {
        dims,
        scalar_type: meta.scalar_type,
        big_endian: meta.big_endian,
    };
    // The data as one stream, with the bytes it has in all.
    let (mut data, available): (Box<dyn Read>, u64) = match &meta.data_file {
        DataFile::Local => (Box::new(reader), file_len - header_len),
        DataFile::File(name) => {
            let (f, len) = open_data(path, name)?;
            (Box::new(f), len)
        }
        DataFile::List(names) => {
            let mut chain: Box<dyn Read> = Box::new(std::io::empty());
            let mut total = 0u64;
            for name in names {
                let (f, len) = open_data(path, name)?;
                total += len;
                chain = Box::new(chain.chain(f));
            }
            (chain, total)
        }
    };
    let skip = match meta.header_size {
        Some(n) if meta.data_file != DataFile::Local => n,
        Some(_) => 0,
        None => available.saturating_sub(declared),
    };
    let available = available.saturating_sub(skip);
    if decode::skip_bytes(&mut data, skip, Encoding::Raw)? < skip {
        return Err(bad("HeaderSize is larger than the data file"));
    }
    let samples = if meta.compressed {
        let source = DataSource::Gzip {
            compressed_bytes: available,
            skip_bytes: 0,
        };
        limits::check_fits(dims, meta.scalar_type, declared, source)?;
        decode::read_samples_with(
            &mut ZlibDecoder::new(data),
            layout,
            Encoding::Gzip,
            progress,
        )
        .map_err(|e| match e {
            VolumeError::CorruptGzip { reason } => VolumeError::CorruptZlib { reason },
            e => e,
        })?
    } else {
        let source = DataSource::Uncompressed {
            available_bytes: available,
        };
        limits::check_fits(dims, meta.scalar_type, declared, source)?;
        decode::read_samples_with(&mut data, layout, Encoding::Raw, progress)?
    };
    let orientation = meta.axes.and_then(Orientation::from_lps_columns);
    Ok({
        let (dims, spacing) = super::progress::strided(dims, meta.spacing_mm, progress);
        Volume::new(name, dims, spacing, samples, ValueMapping::IDENTITY)?
    }
    .with_orientation(orientation)
    .with_provenance(Provenance {
        origin_lps: meta.offset,
        ..Provenance::default()
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "ObjectType = Image\nNDims = 3\nBinaryData = True\n\
        BinaryDataByteOrderMSB = False\nCompressedData = False\n\
        TransformMatrix = -1 0 0 0 -1 0 0 0 1\nOffset = 1 2 3\nElementSpacing = 0.5 0.5 2\n\
        DimSize = 4 3 2\nElementType = MET_SHORT\nElementDataFile = LOCAL\n";

    #[test]
    fn a_header_is_read_as_itk_writes_it() {
        let h = parse_header(HEADER).expect("valid");
        assert_eq!(h.dims, [4, 3, 2]);
        assert_eq!(h.scalar_type, ScalarType::I16);
        assert_eq!(h.spacing_mm, [0.5, 0.5, 2.0]);
        assert_eq!(h.offset, Some([1.0, 2.0, 3.0]));
        assert_eq!(h.data_file, DataFile::Local);
        // Axis i points to -x in LPS: the patient's right. RAS.
        let o = h
            .axes
            .and_then(Orientation::from_lps_columns)
            .expect("orientation");
        assert_eq!(o.code(), "RAS");
    }

    #[test]
    fn lists_sizes_and_types_are_checked() {
        let list = HEADER.replace(
            "ElementDataFile = LOCAL\n",
            "ElementDataFile = LIST\na.raw\nb.raw\n",
        );
        assert_eq!(
            parse_header(&list).expect("valid").data_file,
            DataFile::List(vec!["a.raw".into(), "b.raw".into()])
        );
        let spacing = HEADER.replace("ElementSpacing = 0.5 0.5 2", "ElementSize = 1 1 3");
        assert_eq!(
            parse_header(&spacing).expect("valid").spacing_mm,
            [1.0, 1.0, 3.0]
        );
        for (from, to) in [
            ("MET_SHORT", "MET_LONG_ARRAY"),
            ("DimSize = 4 3 2", "DimSize = 4 3"),
            ("DimSize = 4 3 2", "DimSize = 4 -3 2"),
            ("ElementSpacing = 0.5 0.5 2", "ElementSpacing = 0.5 0 2"),
            ("ElementSpacing = 0.5 0.5 2", "ElementSpacing = 0.5 nan 2"),
            ("NDims = 3", "NDims = 4"),
            ("ElementDataFile = LOCAL\n", ""),
            (
                "ElementDataFile = LOCAL",
                "ElementDataFile = slice%03d.raw 1 10 1",
            ),
            ("CompressedData = False", "CompressedData = maybe"),
        ] {
            let text = HEADER.replace(from, to);
            assert!(parse_header(&text).is_err(), "{to} accepted");
        }
        let flat = HEADER
            .replace("NDims = 3", "NDims = 2")
            .replace("DimSize = 4 3 2", "DimSize = 4 3")
            .replace("ElementSpacing = 0.5 0.5 2", "ElementSpacing = 0.5 0.25");
        let h = parse_header(&flat).expect("2-D");
        assert_eq!((h.dims, h.spacing_mm), ([4, 3, 1], [0.5, 0.25, 0.25]));
    }
}
