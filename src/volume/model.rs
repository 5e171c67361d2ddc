//! The volume: a regular 3D grid of samples with its spacing, value mapping, orientation,
//! statistics and what its file said ([`Volume`], [`Provenance`]). Every loader builds one; it
//! knows no loader.

use super::colour::Colour;
use super::error::VolumeError;
use super::modality::Modality;
use super::orientation::{Orientation, OrientationSource};
use super::samples::{Samples, ScalarType, ValueMapping};
use super::stats::{self, Histogram, ValueRange};
use super::streamed::Streamed;

/// The facts of a DICOM series that a person reads: shown by `leapview info` and in the window.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeriesFacts {
    /// `SeriesInstanceUID`.
    pub uid: String,
    /// `SeriesNumber`, where given.
    pub number: Option<i64>,
    /// `Modality` (CT, MR, RTDOSE, …).
    pub modality: String,
    /// `SeriesDescription`.
    pub description: String,
    /// `SeriesDate`, else `StudyDate`, as written (YYYYMMDD).
    pub date: String,
    /// `FrameOfReferenceUID`.
    pub frame_of_reference: String,
    /// `SOPClassUID` of the series' objects.
    pub sop_class: String,
}

/// What the file said beyond the samples, for people rather than for rendering: notes from
/// loading (a resampled gap, an assumption), the display window of the header, and for DICOM the
/// series and the others found beside it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Provenance {
    /// What a user should know about how the file was read, one sentence each.
    pub notes: Vec<String>,
    /// The header's display window (DICOM `WindowCenter`/`WindowWidth`) as lowest and highest
    /// value, in data units.
    pub window: Option<[f64; 2]>,
    /// The DICOM series the volume is.
    pub series: Option<SeriesFacts>,
    /// Every series found where the volume came from, one line each (numbered as `--series`
    /// takes them); empty for single-volume files.
    pub listing: Vec<String>,
    /// Which line of `listing` this volume is.
    pub chosen: Option<usize>,
    /// What was passed over where the volume came from (files that are not DICOM images).
    pub skipped: Option<String>,
    /// The patient-frame position (LPS, mm) of the first voxel's centre, where the file says.
    pub origin_lps: Option<[f64; 3]>,
    /// The path the volume was opened from, as the user gave it (messages name it).
    pub path: Option<std::path::PathBuf>,
    /// Of a file holding several volumes (a 4-D NIfTI time series), which one this is.
    pub volumes: Option<VolumeIndex>,
    /// Of an image holding several channels (an OME-Zarr `c` axis), which one this is.
    pub channels: Option<VolumeIndex>,
    /// Whether the file asks for its lowest value to be shown white (DICOM MONOCHROME1, as
    /// computed and digital radiographs are stored): the grey ramp is inverted, the values are
    /// not.
    pub invert_grey: bool,
}

/// Which of a file's volumes was read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VolumeIndex {
    /// The volume read, counted from 0.
    pub chosen: u32,
    /// How many the file holds.
    pub count: u32,
}

/// Where a volume's samples are: all in memory, or read from their store as needed.
#[derive(Clone, Debug)]
enum Voxels {
    Whole(Samples),
    Streamed(Streamed),
}

/// A scalar volume on a regular grid, with its statistics computed once at construction.
#[derive(Clone, Debug)]
pub struct Volume {
    name: String,
    dims: [u32; 3],
    spacing_mm: [f64; 3],
    voxels: Voxels,
    mapping: ValueMapping,
    range: Option<ValueRange>,
    histogram: Histogram,
    non_finite_count: u64,
    /// Whether the statistics count every voxel (not a streamed volume's preview alone).
    exact_statistics: bool,
    orientation: Option<Orientation>,
    /// What the header said, kept when the user overrides it.
    header_orientation: Option<Orientation>,
    reversed_i: bool,
    modality: Option<Modality>,
    provenance: Provenance,
    colour: Option<Colour>,
}

impl Volume {
    /// Builds a volume, checking that the sample count matches the dimensions and that the spacing
    /// and mapping are usable, and computes its value range and histogram.
    pub fn new(
        name: impl Into<String>,
        dims: [u32; 3],
        spacing_mm: [f64; 3],
        samples: Samples,
        mapping: ValueMapping,
    ) -> Result<Self, VolumeError> {
        if dims.contains(&0) {
            return Err(VolumeError::ZeroDimension { dims });
        }
        let expected = dims.iter().map(|&d| d as u64).product::<u64>();
        if samples.len() as u64 != expected {
            return Err(VolumeError::SampleCountMismatch {
                dims,
                expected,
                actual: samples.len() as u64,
            });
        }
        Self::with_voxels(
            name.into(),
            dims,
            spacing_mm,
            Voxels::Whole(samples),
            mapping,
        )
    }

    /// A volume whose samples are read from their store as the GPU's bricks need them
    /// ([`Streamed`]); its statistics are those of the preview level (a note says so where the
    /// loader adds one).
    pub fn streamed(
        name: impl Into<String>,
        dims: [u32; 3],
        spacing_mm: [f64; 3],
        streamed: Streamed,
        mapping: ValueMapping,
    ) -> Result<Self, VolumeError> {
        if dims.contains(&0) {
            return Err(VolumeError::ZeroDimension { dims });
        }
        Self::with_voxels(
            name.into(),
            dims,
            spacing_mm,
            Voxels::Streamed(streamed),
            mapping,
        )
    }

    /// The volume with statistics of every voxel given (a streamed volume's store kept them).
    pub(crate) fn with_statistics(
        mut self,
        range: Option<ValueRange>,
        histogram: Histogram,
        non_finite_count: u64,
    ) -> Self {
        self.range = range;
        self.histogram = histogram;
        self.non_finite_count = non_finite_count;
        self.exact_statistics = true;
        self
    }

    fn with_voxels(
        name: String,
        dims: [u32; 3],
        spacing_mm: [f64; 3],
        voxels: Voxels,
        mapping: ValueMapping,
    ) -> Result<Self, VolumeError> {
        if spacing_mm.iter().any(|s| !s.is_finite() || *s <= 0.0) {
            return Err(VolumeError::BadSpacing { spacing_mm });
        }
        if !mapping.slope.is_finite() || mapping.slope == 0.0 || !mapping.intercept.is_finite() {
            return Err(VolumeError::BadValueMapping {
                slope: mapping.slope,
                intercept: mapping.intercept,
            });
        }
        let held = match &voxels {
            Voxels::Whole(s) => s,
            Voxels::Streamed(s) => &s.preview().samples,
        };
        let (range, histogram, non_finite_count) = stats::compute(held, mapping);
        let exact_statistics = matches!(voxels, Voxels::Whole(_));
        Ok(Self {
            name,
            dims,
            spacing_mm,
            voxels,
            mapping,
            range,
            histogram,
            non_finite_count,
            exact_statistics,
            orientation: None,
            header_orientation: None,
            reversed_i: false,
            modality: None,
            provenance: Provenance::default(),
            colour: None,
        })
    }

    /// A colour volume: its samples are the colour's luminance (8 bits, identity mapping), what
    /// transfer functions and statistics work on; [`Volume::colour`] keeps the channels.
    pub fn new_colour(
        name: impl Into<String>,
        dims: [u32; 3],
        spacing_mm: [f64; 3],
        colour: Colour,
    ) -> Result<Self, VolumeError> {
        let luminance = Samples::U8(colour.luminance());
        let mut volume = Self::new(name, dims, spacing_mm, luminance, ValueMapping::IDENTITY)?;
        volume.colour = Some(colour);
        Ok(volume)
    }

    /// The channels of a colour volume; `None` for grey ones.
    pub fn colour(&self) -> Option<&Colour> {
        self.colour.as_ref()
    }

    /// The volume with the anatomical orientation its file gave.
    pub fn with_orientation(mut self, orientation: Option<Orientation>) -> Self {
        self.orientation = orientation;
        self.header_orientation = orientation;
        self
    }

    /// The volume with the orientation the user gave (`--orientation`, the window's orientation
    /// controls) in place of the header's, or of none: for files that lack one or state it wrong.
    /// Call before [`Volume::unmirrored`]; the header's stays in [`Volume::header_orientation`].
    pub(crate) fn with_user_orientation(mut self, orientation: Orientation) -> Self {
        self.orientation = Some(orientation.said_by(OrientationSource::User));
        self
    }

    /// The orientation the file's header gave, whatever the user said.
    pub fn header_orientation(&self) -> Option<Orientation> {
        self.header_orientation
    }

    /// The volume as a right-handed picture of the patient: when its orientation is mirrored (an
    /// odd number of flipped index axes, e.g. LAS), the samples are reversed along i and the
    /// orientation follows (LAS becomes RAS), so that renders show the patient, not their mirror
    /// image: the world frame of the renderer is the index frame. Anything else is unchanged.
    pub fn unmirrored(mut self) -> Self {
        if let Some(o) = self.orientation.filter(Orientation::is_mirrored) {
            self.voxels = match self.voxels {
                Voxels::Whole(mut s) => {
                    s.reverse_rows(self.dims[0] as usize);
                    Voxels::Whole(s)
                }
                Voxels::Streamed(s) => Voxels::Streamed(s.reversed()),
            };
            if let Some(c) = self.colour.as_mut() {
                c.reverse_rows(self.dims[0] as usize);
            }
            self.orientation = Some(o.with_axis_reversed(0));
            self.reversed_i = !self.reversed_i;
        }
        self
    }

    /// The volume with the modality its file declared.
    pub(crate) fn with_modality(mut self, modality: Option<Modality>) -> Self {
        self.modality = modality;
        self
    }

    /// The volume with what its file said beyond the samples.
    pub fn with_provenance(mut self, provenance: Provenance) -> Self {
        self.provenance = provenance;
        self
    }

    /// What the file said beyond the samples: notes from loading, the header's window, the
    /// DICOM series.
    pub fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    /// The modality the file declared (`None` where it says nothing).
    pub fn modality(&self) -> Option<&Modality> {
        self.modality.as_ref()
    }

    /// The anatomical orientation of the index axes as stored here: the header's, except along
    /// i when [`Volume::unmirrored`] reversed it.
    pub fn orientation(&self) -> Option<Orientation> {
        self.orientation
    }

    /// The orientation in the file's index frame (before any reversal): the header's, or the
    /// user's where they gave one.
    pub fn file_orientation(&self) -> Option<Orientation> {
        self.orientation.map(|o| {
            if self.reversed_i {
                o.with_axis_reversed(0)
            } else {
                o
            }
        })
    }

    /// Whether the samples were reversed along i to undo a mirrored orientation: voxel index i
    /// here is `dims[0] - 1 - i` in the file.
    pub fn reversed_i(&self) -> bool {
        self.reversed_i
    }

    /// A short human-readable name (usually the file name).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// How messages name the volume: the path it was opened from, else its name.
    pub fn label(&self) -> String {
        self.provenance
            .path
            .as_ref()
            .map_or_else(|| self.name.clone(), |p| p.display().to_string())
    }

    /// Number of samples along x, y and z.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// Total number of samples.
    pub fn sample_count(&self) -> u64 {
        self.dims.iter().map(|&d| d as u64).product()
    }

    /// Distance between neighbouring voxel centres along x, y and z, in millimetres.
    pub fn spacing_mm(&self) -> [f64; 3] {
        self.spacing_mm
    }

    /// The smallest spacing: the unit length `d0` that transfer-function opacities refer to.
    pub fn min_spacing_mm(&self) -> f64 {
        self.spacing_mm
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min)
    }

    #[cfg(test)] // Only the tests ask.
    /// Size of the bounding box (`dims * spacing`) in millimetres.
    pub(crate) fn extent_mm(&self) -> [f64; 3] {
        std::array::from_fn(|a| self.dims[a] as f64 * self.spacing_mm[a])
    }

    /// The stored samples, x fastest; `None` where they are read from their store as needed
    /// ([`Self::streamed`]).
    pub fn samples(&self) -> Option<&Samples> {
        match &self.voxels {
            Voxels::Whole(s) => Some(s),
            Voxels::Streamed(_) => None,
        }
    }

    /// The samples, or why what `needs` them cannot have them: the volume is streamed.
    pub fn whole_samples(&self, needs: &'static str) -> Result<&Samples, VolumeError> {
        self.samples().ok_or_else(|| VolumeError::Streamed {
            name: self.label(),
            needs,
        })
    }

    /// Where the samples are read from, for a volume too large to hold whole.
    pub fn streaming(&self) -> Option<&Streamed> {
        match &self.voxels {
            Voxels::Whole(_) => None,
            Voxels::Streamed(s) => Some(s),
        }
    }

    /// The samples held in memory: all of them, or a streamed volume's preview level (its
    /// dimensions and which level it is, 0 for the whole volume).
    pub fn held(&self) -> (&Samples, [u32; 3], u32) {
        match &self.voxels {
            Voxels::Whole(s) => (s, self.dims, 0),
            Voxels::Streamed(s) => (&s.preview().samples, s.preview().dims, s.preview_level()),
        }
    }

    /// Whether samples may be NaN or infinite: some are, or a streamed float volume's store
    /// may hold some that its preview does not show.
    pub fn may_be_non_finite(&self) -> bool {
        self.non_finite_count > 0
            || (!self.exact_statistics
                && matches!(self.scalar_type(), ScalarType::F32 | ScalarType::F64))
    }

    /// Whether the range, histogram and non-finite count are of every voxel; a streamed
    /// volume's are its preview's unless its store kept them.
    pub fn exact_statistics(&self) -> bool {
        self.exact_statistics
    }

    /// The stored type of the samples.
    pub fn scalar_type(&self) -> ScalarType {
        self.held().0.scalar_type()
    }

    /// The map from stored values to data units.
    pub fn mapping(&self) -> ValueMapping {
        self.mapping
    }

    /// Smallest and largest finite value in data units; `None` when no sample is finite.
    pub fn value_range(&self) -> Option<ValueRange> {
        self.range
    }

    /// The range used to normalise values for the GPU and the transfer-function lookup: the value
    /// range, widened to a unit interval when the volume is constant (or has no finite sample) so
    /// that normalising never divides by zero.
    pub fn normalization_range(&self) -> ValueRange {
        ValueRange::normalization(self.range)
    }

    /// Histogram of the finite values in data units.
    pub fn histogram(&self) -> &Histogram {
        &self.histogram
    }

    /// Number of NaN or infinite samples (always zero for integer volumes).
    pub fn non_finite_count(&self) -> u64 {
        self.non_finite_count
    }

    /// Linear index of voxel `(x, y, z)`; the caller keeps coordinates inside `dims`.
    pub fn index(&self, x: u32, y: u32, z: u32) -> usize {
        x as usize + self.dims[0] as usize * (y as usize + self.dims[1] as usize * z as usize)
    }

    /// The value of voxel `(x, y, z)` in data units (NaN or ±Inf where the sample is not
    /// finite); of a streamed volume, that of the preview voxel holding it (a mean).
    pub fn value(&self, x: u32, y: u32, z: u32) -> f64 {
        let stored = match &self.voxels {
            Voxels::Whole(s) => s.get_f64(self.index(x, y, z)),
            Voxels::Streamed(s) => {
                let (p, d) = (s.preview_level(), s.preview().dims);
                let [i, j, k] = [x, y, z].map(|c| (c >> p) as usize);
                let index = i.min(d[0] as usize - 1)
                    + d[0] as usize
                        * (j.min(d[1] as usize - 1) + d[1] as usize * k.min(d[2] as usize - 1));
                s.preview().samples.get_f64(index)
            }
        };
        self.mapping.apply(stored)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn new_checks_sample_count_and_spacing() {
        let ok = Volume::new(
            "t",
            [2, 2, 1],
            [1.0, 1.0, 2.0],
            Samples::U8(vec![0, 1, 2, 3]),
            ValueMapping::IDENTITY,
        );
        let v = ok.expect("valid volume");
        assert_eq!(v.value(1, 1, 0), 3.0);
        assert_eq!(v.extent_mm(), [2.0, 2.0, 2.0]);
        assert!(matches!(
            Volume::new(
                "t",
                [2, 2, 2],
                [1.0; 3],
                Samples::U8(vec![0; 4]),
                ValueMapping::IDENTITY
            ),
            Err(VolumeError::SampleCountMismatch { .. })
        ));
        assert!(matches!(
            Volume::new(
                "t",
                [1, 1, 1],
                [1.0, 0.0, 1.0],
                Samples::U8(vec![0]),
                ValueMapping::IDENTITY
            ),
            Err(VolumeError::BadSpacing { .. })
        ));
    }

    #[test]
    fn constant_volume_normalises_over_a_unit_interval() {
        let v = Volume::new(
            "c",
            [2, 1, 1],
            [1.0; 3],
            Samples::I16(vec![7, 7]),
            ValueMapping::IDENTITY,
        )
        .expect("valid volume");
        let r = v.normalization_range();
        assert_eq!((r.min, r.max), (7.0, 8.0));
    }
}
