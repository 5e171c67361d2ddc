//! Volumes: the model ([`model::Volume`], a regular 3D grid of scalar samples, its spacing in
//! millimetres, the mapping from stored values to the data units the user sees, and statistics
//! over those values) with its parts below it (samples, statistics, orientation, modality,
//! colour, errors, progress, limits), the readers of each format and the generated volumes above
//! them, and [`load::load_volume`] on top. Files here import from the file that defines a name,
//! never through this facade, so no arrow runs back up.
//!
//! Conventions shared by every part of LeapView:
//! - Samples are stored x fastest, then y, then z (`index = x + dims[0] * (y + dims[1] * z)`).
//! - Voxel centre `(i, j, k)` sits at world position `(i * sx, j * sy, k * sz)` millimetres, so the
//!   volume's bounding box spans `[-s/2, (n - 1/2) * s]` on each axis: `n * s` millimetres, the
//!   paper's `size_i * spacing_i`.
//! - Data units are `stored * slope + intercept` (NIfTI `scl_slope`/`scl_inter`, DICOM rescale).
//!   Ranges, histograms, transfer functions and iso values are all in data units.
//! - Non-finite samples (NaN, ±Inf in float volumes) are kept out of the range and the histogram
//!   and are rendered transparent.

pub mod colour;
pub mod decode;
pub mod dicom;
pub mod downsample;
pub mod error;
pub mod limits;
pub mod load;
pub mod metaimage;
pub mod modality;
pub mod model;
pub mod nifti;
pub mod nrrd;
pub mod orientation;
pub mod progress;
pub mod raw;
pub mod samples;
pub mod stats;
pub mod streamed;
pub mod synthetic;
mod tiff;
mod tiles;
mod units;
pub mod zarr;

pub use colour::Colour;
pub use error::VolumeError;
pub use load::{LoadOptions, load_volume};
pub use modality::Modality;
pub use model::{Provenance, SeriesFacts, Volume, VolumeIndex};
pub use orientation::{BadOrientationCode, Direction, Orientation, OrientationSource};
pub use progress::LoadProgress;
pub use samples::{Samples, ScalarType, ValueMapping};
pub use stats::{Histogram, ValueRange};
