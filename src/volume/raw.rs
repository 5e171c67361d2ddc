//! Headerless raw volumes described on the command line: the file must hold exactly the samples
//! the given layout calls for.

use std::io::BufReader;
use std::path::Path;

use super::decode::{self, Encoding, SampleLayout};
use super::error::VolumeError;
use super::{limits, model::Volume, samples::ScalarType, samples::ValueMapping};

/// Layout of a raw file: everything a header would otherwise say.
#[derive(Clone, Debug, PartialEq)]
pub struct RawParams {
    /// Samples along x, y, z.
    pub dims: [u32; 3],
    /// Stored type.
    pub scalar_type: ScalarType,
    /// Spacing in millimetres (1, 1, 1 when not given).
    pub spacing_mm: [f64; 3],
    /// Whether multi-byte samples are big-endian.
    pub big_endian: bool,
}

/// Reads a raw volume laid out as `params` says; `name` becomes the volume's name.
pub(crate) fn read_raw(
    path: &Path,
    name: String,
    params: &RawParams,
    progress: Option<&super::progress::LoadProgress>,
) -> Result<Volume, VolumeError> {
    let (dims, expected_bytes) =
        limits::check_dims(params.dims.map(u64::from), params.scalar_type)?;
    let (file, found_bytes) = decode::open_file(path)?;
    if found_bytes != expected_bytes {
        return Err(VolumeError::RawSizeMismatch {
            dims,
            scalar_type: params.scalar_type,
            expected_bytes,
            found_bytes,
        });
    }
    let layout = SampleLayout {
        dims,
        scalar_type: params.scalar_type,
        big_endian: params.big_endian,
    };
    let samples =
        decode::read_samples_with(&mut BufReader::new(file), layout, Encoding::Raw, progress)?;
    let (dims, spacing) = super::progress::strided(dims, params.spacing_mm, progress);
    Volume::new(name, dims, spacing, samples, ValueMapping::IDENTITY)
}
