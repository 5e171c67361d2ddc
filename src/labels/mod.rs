//! Segmentations beside the image: label volumes (NIfTI, NRRD and Slicer's `.seg.nrrd`,
//! MetaImage) and DICOM SEG, their segments' names and colours (from the file, an ITK-SNAP label description
//! or a colour table beside it, else a palette), put on the image's voxel grid by patient
//! coordinates (nearest label).
//!
//! A [`LabelMap`] holds one or more layers of labels on the image's grid, each voxel a `u16`
//! (0 is no label); a segment is a label value in a layer. Overlapping segments (Slicer's layers)
//! are layers of their own (a DICOM SEG's overlapping segments go into as few layers as hold them
//! apart).

pub mod classes;
mod dicom_seg;
mod error;
mod layered;
pub(crate) mod levels;
mod names;
mod palette;
mod read;
mod resample;
mod sniff;
pub mod surface;

pub use self::error::LabelError;
pub use self::read::{LabelOptions, load_labels};
pub use self::sniff::{DropGuess, guess_dropped};

/// Whether the file at `path` can only be a segmentation: a Slicer `.seg.nrrd` or a DICOM SEG
/// (a dropped file is opened as the labels of the volume on screen then).
pub fn is_segmentation_file(path: &std::path::Path) -> bool {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    name.ends_with(".seg.nrrd")
        || (path.is_file()
            && crate::volume::dicom::scan::looks_like_dicom(path)
            && dicom_seg::is_seg(path))
}

/// One segment: a label value in a layer, its name and colour.
#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    /// The label value its voxels hold in [`Segment::layer`].
    pub value: u16,
    /// The layer holding it (0 but for overlapping segments).
    pub layer: u16,
    /// Its name: the file's, else "label N".
    pub name: String,
    /// Its colour, sRGB: the file's, else the palette's.
    pub colour: [u8; 3],
    /// Its voxels on the image's grid.
    pub voxels: u64,
}

/// Labels on an image's voxel grid, in layers, with their segments.
#[derive(Clone, Debug)]
pub struct LabelMap {
    /// The image's dimensions.
    dims: [u32; 3],
    /// Each layer's label per voxel, x fastest, as the image's samples.
    layers: Vec<Vec<u16>>,
    /// Every segment with at least one voxel, or named by the file, by layer then value.
    segments: Vec<Segment>,
    /// What was done to the file's labels, for the user (resampled, partly outside, …).
    notes: Vec<String>,
    /// The file's name.
    name: String,
}

impl LabelMap {
    /// The image's dimensions, which the layers have.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// Each layer's label per voxel.
    pub fn layers(&self) -> &[Vec<u16>] {
        &self.layers
    }

    /// The segments, by layer then value.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// What was done to the labels on the way to the image's grid.
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// The label file's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Each label value's colour (sRGB) and whether it is shown (alpha 255) or hidden or absent
    /// (alpha 0; between: shown at that opacity, [`Self::styled_table`]): a table of every `u16`,
    /// indexed by value, as the GPU and the CPU reference read it. Label values name one segment across the layers (a DICOM SEG's segment numbers do).
    pub fn colour_table(&self, visible: impl Fn(&Segment) -> bool) -> Vec<[u8; 4]> {
        self.styled_table(|s| {
            let [r, g, b] = s.colour;
            [r, g, b, if visible(s) { 255 } else { 0 }]
        })
    }

    /// [`Self::colour_table`] with each segment's colour and opacity as `style` says (sRGB,
    /// alpha its opacity: 0 hidden).
    pub fn styled_table(&self, style: impl Fn(&Segment) -> [u8; 4]) -> Vec<[u8; 4]> {
        let mut table = vec![[0u8; 4]; 1 << 16];
        for s in &self.segments {
            table[usize::from(s.value)] = style(s);
        }
        table
    }

    /// Per voxel, whether its label in some layer is shown by `table` (alpha above 0): the
    /// indicator [`surface::smoothed_mask`] smooths.
    pub fn shown_voxels(&self, table: &[[u8; 4]]) -> Vec<bool> {
        let voxels = self.dims.iter().map(|&d| d as usize).product::<usize>();
        (0..voxels)
            .map(|i| {
                self.layers.iter().any(|layer| {
                    let l = layer[i];
                    l != 0 && table.get(usize::from(l)).is_some_and(|c| c[3] > 0)
                })
            })
            .collect()
    }

    /// Per voxel, the classes of its shown labels as bits (bit c: some layer's label there is
    /// shown by `table` and of class c in `class`): each bit's indicator is a channel of the
    /// surfaces' mask ([`classes`]).
    pub(crate) fn shown_classes(&self, table: &[[u8; 4]], class: &[Option<u8>]) -> Vec<u8> {
        let voxels = self.dims.iter().map(|&d| d as usize).product::<usize>();
        (0..voxels)
            .map(|i| {
                let mut bits = 0u8;
                for layer in self.layers.iter().take(4) {
                    let l = usize::from(layer[i]);
                    if l != 0 && table.get(l).is_some_and(|c| c[3] > 0) {
                        bits |= class.get(l).copied().flatten().map_or(0, |c| 1 << c);
                    }
                }
                bits
            })
            .collect()
    }

    /// Bare layers of labels on a grid of `dims`, no segment described (tests of what reads
    /// the layers alone).
    #[cfg(test)]
    pub(crate) fn bare(dims: [u32; 3], layers: Vec<Vec<u16>>) -> Self {
        Self {
            dims,
            layers,
            segments: Vec::new(),
            notes: Vec::new(),
            name: "test".into(),
        }
    }

    /// The segment holding voxel index `i` of layer `layer`, if any.
    pub fn segment_at(&self, layer: usize, i: usize) -> Option<&Segment> {
        let value = *self.layers.get(layer)?.get(i)?;
        (value != 0).then_some(())?;
        self.segments
            .iter()
            .find(|s| usize::from(s.layer) == layer && s.value == value)
    }
}
