//! What is wrong with a label file, in words a user can act on.

use std::path::PathBuf;

use crate::volume::error::LoadError;

/// Why labels cannot be shown over the image.
#[derive(Debug, thiserror::Error)]
pub enum LabelError {
    /// The file cannot be read as a volume.
    #[error(transparent)]
    Load(#[from] LoadError),
    /// A voxel holds a value that is no label.
    #[error(
        "{path}: a label volume holds whole numbers 0 … 65535, but {count} voxels do not \
         (the first {value} at voxel {voxel:?}): is this an image rather than labels?"
    )]
    NotLabels {
        /// The file.
        path: PathBuf,
        /// The first value that is no label.
        value: f64,
        /// Where it is (x, y, z).
        voxel: [u32; 3],
        /// How many voxels hold one.
        count: u64,
    },
    /// The file is larger than memory, so it was not read whole.
    #[error("{path}: a label volume larger than the memory budget is not read (yet)")]
    Streamed {
        /// The file.
        path: PathBuf,
    },
    /// The image is read brick by brick, so there is no grid in memory to put labels on.
    #[error(
        "{path}: labels over a volume larger than the memory budget are not shown (yet): \
         raise --ram-budget so that the image is read whole"
    )]
    ImageStreamed {
        /// The label file.
        path: PathBuf,
    },
    /// A DICOM segmentation that cannot be read.
    #[error("{path}: a DICOM segmentation LeapView cannot show: {reason}")]
    Seg {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// A DICOM segmentation of another series or frame of reference than the image's.
    #[error(
        "{path}: this segmentation is of another scan: it references {referenced}, the image is \
         {image}"
    )]
    OtherScan {
        /// The file.
        path: PathBuf,
        /// What it references (series or frame of reference UIDs).
        referenced: String,
        /// The image's.
        image: String,
    },
    /// The labels and the image share no voxel.
    #[error(
        "{path}: the labels do not overlap the image: their box is {labels} and the image's is \
         {image} (mm, LPS); is it the segmentation of another scan?"
    )]
    NoOverlap {
        /// The file.
        path: PathBuf,
        /// The labels' box in patient coordinates.
        labels: String,
        /// The image's.
        image: String,
    },
    /// The grids differ and one of them has no patient geometry to match them by.
    #[error(
        "{path}: the labels ({labels}) and the image ({image}) have different grids and {which} \
         no orientation in its header, so they cannot be matched by patient position (give \
         --orientation, or labels on the image's grid)"
    )]
    NoGeometry {
        /// The file.
        path: PathBuf,
        /// The labels' dimensions.
        labels: String,
        /// The image's.
        image: String,
        /// Which has none: "the labels have", "the image has".
        which: &'static str,
    },
    /// A segment's description (in the file or a names file) cannot be read.
    #[error("{path}: {reason}")]
    Names {
        /// The file with the description.
        path: PathBuf,
        /// What is wrong, with the line.
        reason: String,
    },
    /// The file's segment metadata disagrees with its voxels.
    #[error("{path}: {reason}")]
    Disagrees {
        /// The file.
        path: PathBuf,
        /// What disagrees.
        reason: String,
    },
}
