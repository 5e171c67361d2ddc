//! NRRD volumes: attached headers (`.nrrd`) and detached ones (`.nhdr` naming a single data file),
//! raw or gzip-encoded, in any of the eight stored types. The declared size is checked against
//! [`super::limits`] before anything is allocated.

mod fields;
mod header;
mod names;
pub mod write;

use std::fs::File;
use std::io::{BufRead, BufReader, ErrorKind};
use std::path::{Path, PathBuf};

use flate2::bufread::MultiGzDecoder;

use super::decode::{self, Encoding, SampleLayout};
use super::error::VolumeError;
use super::limits::{self, DataSource};
use super::progress::LoadProgress;
use super::{model::Volume, samples::Samples};

use fields::NrrdHeader;
use header::HeaderEnd;

/// The `key:=value` fields of the NRRD header at `path` (where a `.seg.nrrd` describes its
/// segments), read without its samples.
pub(crate) fn key_values(
    path: &Path,
) -> Result<std::collections::HashMap<String, String>, VolumeError> {
    let (file, _) = decode::open_file(path)?;
    let (text, _, _) = header::read_header_text(&mut BufReader::new(file))?;
    Ok(text.key_values)
}

/// What the header of the NRRD file at `path` says, its samples unread (a layered file's grid is
/// one layer's).
pub(crate) fn header_facts(path: &Path) -> Result<super::load::HeaderFacts, VolumeError> {
    let (file, _) = decode::open_file(path)?;
    let (text, _, _) = header::read_header_text(&mut BufReader::new(file))?;
    let nrrd = fields::interpret(&text, true)?;
    let segments = text.key_values.keys().any(|k| k.starts_with("Segment0_"));
    Ok(
        super::load::HeaderFacts::new(nrrd.dims, nrrd.scalar_type, nrrd.mapping)
            .with_segments(segments || nrrd.layers > 1),
    )
}

/// Reads a NRRD volume; `name` becomes the volume's name.
pub(crate) fn read_nrrd(
    path: &Path,
    name: String,
    progress: Option<&LoadProgress>,
) -> Result<Volume, VolumeError> {
    let (nrrd, dims, samples) = read_file(path, false, progress)?;
    volume_of(&nrrd, name, dims, samples, progress)
}

/// Reads a NRRD file whose 4-D samples interleave layers along the first axis (Slicer's
/// `.seg.nrrd` of overlapping segments), or a 3-D one (one layer): each layer as a volume of the
/// file's grid and geometry.
pub(crate) fn read_nrrd_layers(path: &Path, name: String) -> Result<Vec<Volume>, VolumeError> {
    let (nrrd, dims, samples) = read_file(path, true, None)?;
    // At most `MOST_LAYERS`: a usize.
    let n = nrrd.layers as usize;
    if n == 1 {
        return Ok(vec![volume_of(&nrrd, name, dims, samples, None)?]);
    }
    (0..n)
        .map(|k| volume_of(&nrrd, name.clone(), dims, samples.channel(k, n), None))
        .collect()
}

/// The header and samples of the NRRD file at `path` (`layered`: the first axis of a 4-D file
/// may be layers, read interleaved), with the grid's dimensions (one layer's).
fn read_file(
    path: &Path,
    layered: bool,
    progress: Option<&LoadProgress>,
) -> Result<(NrrdHeader, [u32; 3], Samples), VolumeError> {
    let (file, file_len) = decode::open_file(path)?;
    let mut reader = BufReader::new(file);
    let (text, end, header_len) = header::read_header_text(&mut reader)?;
    let nrrd = fields::interpret(&text, layered)?;
    let [x, y, z] = nrrd.dims;
    // Layers interleave fastest: the samples read as a grid `layers` times as wide.
    let (wide, _) = limits::check_dims([x * nrrd.layers, y, z], nrrd.scalar_type)?;
    let dims = [wide[0] / nrrd.layers as u32, wide[1], wide[2]];
    let layout = SampleLayout {
        dims: wide,
        scalar_type: nrrd.scalar_type,
        big_endian: nrrd.big_endian,
    };
    let samples = match &nrrd.data_file {
        Some(data_file) => {
            let (file, len) = open_data_file(path, data_file)?;
            read_data(&mut BufReader::new(file), len, &nrrd, layout, progress)?
        }
        None if end == HeaderEnd::EndOfFile => {
            return Err(header::bad_header(
                "no blank line ends the header, and no 'data file' field names a separate data \
                 file"
                    .to_string(),
            ));
        }
        None => read_data(&mut reader, file_len - header_len, &nrrd, layout, progress)?,
    };
    Ok((nrrd, dims, samples))
}

/// The volume of `samples` on the grid `dims` with the header's geometry and value mapping.
fn volume_of(
    nrrd: &NrrdHeader,
    name: String,
    dims: [u32; 3],
    samples: Samples,
    progress: Option<&LoadProgress>,
) -> Result<Volume, VolumeError> {
    Ok({
        let (dims, spacing) = super::progress::strided(dims, nrrd.spacing_mm, progress);
        Volume::new(name, dims, spacing, samples, nrrd.mapping)?
    }
    .with_orientation(nrrd.orientation)
    .with_modality(nrrd.modality.clone())
    .with_provenance(super::model::Provenance {
        origin_lps: nrrd.origin_lps,
        ..super::model::Provenance::default()
    }))
}

/// Reads the samples from `reader`, positioned at the start of the data with `available` bytes
/// left in the file (before line and byte skips).
fn read_data(
    reader: &mut impl BufRead,
    mut available: u64,
    nrrd: &NrrdHeader,
    layout: SampleLayout,
    progress: Option<&LoadProgress>,
) -> Result<Samples, VolumeError> {
    let declared_bytes = layout.byte_len();
    let too_short = |found_bytes| VolumeError::DataTooShort {
        dims: layout.dims,
        scalar_type: layout.scalar_type,
        declared_bytes,
        found_bytes,
    };
    for _ in 0..nrrd.line_skip {
        let n = reader.skip_until(b'\n')? as u64;
        if n == 0 {
            return Err(too_short(0));
        }
        available = available.saturating_sub(n);
    }
    match nrrd.encoding {
        Encoding::Raw => {
            // `byte skip: -1`: the samples are the last bytes of the file.
            let skip = nrrd
                .byte_skip
                .unwrap_or(available.saturating_sub(declared_bytes));
            let data_bytes = available.saturating_sub(skip);
            let source = DataSource::Uncompressed {
                available_bytes: data_bytes,
            };
            limits::check_fits(layout.dims, layout.scalar_type, declared_bytes, source)?;
            if data_bytes > declared_bytes {
                return Err(VolumeError::DataTooLong {
                    dims: layout.dims,
                    scalar_type: layout.scalar_type,
                    declared_bytes,
                    found_bytes: data_bytes,
                    exact: true,
                });
            }
            if decode::skip_bytes(reader, skip, Encoding::Raw)? < skip {
                return Err(too_short(0));
            }
            decode::read_samples_with(reader, layout, Encoding::Raw, progress)
        }
        Encoding::Gzip => {
            // The header parser refuses `byte skip: -1` with gzip.
            let skip = nrrd.byte_skip.unwrap_or(0);
            let source = DataSource::Gzip {
                compressed_bytes: available,
                skip_bytes: skip,
            };
            limits::check_fits(layout.dims, layout.scalar_type, declared_bytes, source)?;
            let mut decoder = MultiGzDecoder::new(reader);
            if decode::skip_bytes(&mut decoder, skip, Encoding::Gzip)? < skip {
                return Err(too_short(0));
            }
            decode::read_samples_with(&mut decoder, layout, Encoding::Gzip, progress)
        }
    }
}

/// Opens the data file a detached header names, relative to the header's folder.
fn open_data_file(header_path: &Path, name: &str) -> Result<(File, u64), VolumeError> {
    let unreadable = |source| VolumeError::DataFileUnreadable {
        name: name.to_string(),
        source,
    };
    let path = match Path::new(name) {
        p if p.is_absolute() => p.to_path_buf(),
        p => header_path
            .parent()
            .map_or_else(PathBuf::new, Path::to_path_buf)
            .join(p),
    };
    // Asked before opening: opening a named pipe blocks until someone writes to it.
    let metadata = std::fs::metadata(&path).map_err(unreadable)?;
    if metadata.is_dir() {
        return Err(unreadable(ErrorKind::IsADirectory.into()));
    }
    if let Some(kind) = decode::special_kind(&metadata) {
        return Err(VolumeError::DataFileNotRegular {
            name: name.to_string(),
            kind,
        });
    }
    let file = File::open(&path).map_err(unreadable)?;
    Ok((file, metadata.len()))
}
