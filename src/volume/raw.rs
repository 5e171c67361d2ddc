//! Headerless raw volumes described on the command line.

use super::ScalarType;

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
