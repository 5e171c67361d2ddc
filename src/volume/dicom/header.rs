//! What LeapView takes from one DICOM image frame, as plain values: no dicom-rs type appears
//! here, so series assembly ([`super::series`], [`super::geometry`]) is pure, unit-tested and
//! fuzzed over arbitrary tag values. [`super::tags`] fills these from a file.

/// How the samples of a pixel make its colour (`PhotometricInterpretation`, PS3.3 C.7.6.3.1.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Photometric {
    /// Grey, the lowest value shown white.
    Monochrome1,
    /// Grey, the lowest value shown black (also where the file names none).
    Monochrome2,
    /// Red, green, blue.
    Rgb,
    /// Luminance and two chroma samples at full resolution (ITU-R BT.601, full range).
    YbrFull,
    /// As `YbrFull` with chroma at half the horizontal resolution (native data holds
    /// Y Y Cb Cr for each pair of pixels).
    YbrFull422,
    /// Colour a codec has already turned into RGB (the JPEG 2000 transforms YBR_RCT and
    /// YBR_ICT, JPEG's YBR_PARTIAL_420 and _422).
    YbrDecodedToRgb,
    /// One index per pixel into the file's red, green and blue palette tables.
    Palette,
    /// One the standard does not define, or retired (ARGB, CMYK, HSV).
    Unsupported,
}

impl Photometric {
    /// Reads `PhotometricInterpretation` (empty: MONOCHROME2, the common default).
    pub fn parse(text: &str) -> Self {
        match text {
            "MONOCHROME1" => Self::Monochrome1,
            "MONOCHROME2" | "" => Self::Monochrome2,
            "RGB" => Self::Rgb,
            "YBR_FULL" => Self::YbrFull,
            "YBR_FULL_422" => Self::YbrFull422,
            "YBR_RCT" | "YBR_ICT" | "YBR_PARTIAL_420" | "YBR_PARTIAL_422" => Self::YbrDecodedToRgb,
            "PALETTE COLOR" => Self::Palette,
            _ => Self::Unsupported,
        }
    }

    /// Whether pixels are shown in colour (three samples, or a palette).
    pub(crate) fn is_colour(self) -> bool {
        !matches!(self, Self::Monochrome1 | Self::Monochrome2)
    }
}

/// How one frame's pixels are stored (PS3.3 C.7.6.3, image pixel module).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PixelFormat {
    /// `BitsAllocated`: 8, 16 or 32 (1 for bit masks, which are not read).
    pub bits_allocated: u16,
    /// `BitsStored`: the bits of each sample that hold its value.
    pub bits_stored: u16,
    /// `HighBit`: the most significant stored bit (usually `bits_stored - 1`).
    pub high_bit: u16,
    /// `PixelRepresentation` 1: two's complement samples.
    pub signed: bool,
    /// `SamplesPerPixel`: 1 for grey and palette images, 3 for colour.
    pub samples_per_pixel: u16,
    /// `PhotometricInterpretation`.
    pub photometric: Photometric,
    /// `PlanarConfiguration` 1: native colour samples stored plane by plane (all red, then all
    /// green, then all blue) rather than pixel by pixel.
    pub planar: bool,
}

impl PixelFormat {
    /// Why a frame of this format cannot be shown, or `None` where it can: grey (one sample)
    /// or colour (three, or a palette), 8 to 32 bits.
    pub fn unsupported(&self) -> Option<String> {
        if !matches!(self.bits_allocated, 8 | 16 | 32) {
            return Some(format!(
                "BitsAllocated is {}; LeapView shows images of 8, 16 or 32 bits",
                self.bits_allocated
            ));
        }
        let samples_fit = match self.photometric {
            Photometric::Monochrome1 | Photometric::Monochrome2 | Photometric::Palette => {
                self.samples_per_pixel == 1
            }
            Photometric::Unsupported => false,
            _ => self.samples_per_pixel == 3,
        };
        (!samples_fit).then(|| {
            format!(
                "{} samples per pixel of a photometric interpretation LeapView does not show \
                 (it shows MONOCHROME1/2 and PALETTE COLOR with 1, RGB and YBR with 3)",
                self.samples_per_pixel
            )
        })
    }
}

/// `RescaleSlope` and `RescaleIntercept` (or an RT dose grid's `DoseGridScaling`): data units are
/// `stored * slope + intercept` (Hounsfield units for CT).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rescale {
    /// Multiplier.
    pub slope: f64,
    /// Offset.
    pub intercept: f64,
}

impl Rescale {
    /// No rescaling.
    pub const IDENTITY: Self = Self {
        slope: 1.0,
        intercept: 0.0,
    };
}

pub use crate::volume::model::SeriesFacts;

/// One frame of a DICOM image: a slice of a classic series, or one frame of a multi-frame
/// (enhanced CT/MR, RT dose) object.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameHeader {
    /// Index of the file in the scan's file list.
    pub file: usize,
    /// Frame within the file (0 for single-frame files).
    pub frame: u32,
    /// How messages name the frame: the file's name, and the frame where the file has several.
    pub label: String,
    /// `NumberOfFrames` of the file (1 for single-frame files).
    pub frames_in_file: u32,
    /// The series the frame belongs to.
    pub series: SeriesFacts,
    /// `Rows`: the image height.
    pub rows: u32,
    /// `Columns`: the image width.
    pub columns: u32,
    /// `ImageOrientationPatient`: the direction of a row (increasing column index), then of a
    /// column (increasing row index), as unit vectors in the patient frame (LPS).
    pub orientation: Option<[f64; 6]>,
    /// `PatientOrientation` (0020,0020): the patient direction of a row, then of a column
    /// (`L\F`, `A\FR`…), for images without ImageOrientationPatient (radiographs, NM,
    /// secondary captures).
    pub patient_orientation: Option<String>,
    /// `ImagePositionPatient`: the centre of the first transmitted voxel, in mm (LPS).
    pub position: Option<[f64; 3]>,
    /// `PixelSpacing`: the spacing between rows, then between columns, in mm.
    pub pixel_spacing: Option<[f64; 2]>,
    /// `SliceThickness`, in mm.
    pub slice_thickness: Option<f64>,
    /// `SpacingBetweenSlices`, in mm.
    pub spacing_between_slices: Option<f64>,
    /// How the pixels are stored.
    pub pixel: PixelFormat,
    /// The map to data units.
    pub rescale: Rescale,
    /// `WindowCenter`, `WindowWidth` (the first pair), in data units.
    pub window: Option<[f64; 2]>,
    /// `InstanceNumber`, for messages only: never used to order slices.
    pub instance_number: Option<i64>,
    /// `SOPInstanceUID`: one object, however many files hold a copy of it.
    pub instance_uid: String,
    /// The file's transfer syntax UID.
    pub transfer_syntax: String,
    /// Whether the file's data set is written in implicit VR though its transfer syntax says
    /// explicit (read so, as pydicom does).
    pub implicit_vr: bool,
    /// For a tile of a Siemens mosaic (`frame` is its tile), the mosaic's own size.
    pub mosaic: Option<Mosaic>,
}

/// The image a mosaic's tiles are cut from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Mosaic {
    /// `Rows` of the mosaic.
    pub rows: u32,
    /// `Columns` of the mosaic.
    pub columns: u32,
    /// Tiles along each side.
    pub per_side: u32,
}

impl FrameHeader {
    /// How messages name the frame's file: its path below the folder scanned (the label
    /// without the frame or the mosaic slice).
    pub(crate) fn file_label(&self) -> &str {
        if self.frames_in_file <= 1 {
            return &self.label;
        }
        [" frame ", " slice "]
            .iter()
            .find_map(|s| self.label.rsplit_once(s).map(|(file, _)| file))
            .unwrap_or(&self.label)
    }

    /// What the header says one frame holds, for the codecs to check their streams against.
    pub(crate) fn frame_spec(&self) -> super::codec::FrameSpec {
        // A mosaic's tiles are cut from one frame of the mosaic's size.
        let (rows, columns) = self
            .mosaic
            .map_or((self.rows, self.columns), |m| (m.rows, m.columns));
        super::codec::FrameSpec {
            rows,
            columns,
            samples_per_pixel: self.pixel.samples_per_pixel,
            bits_allocated: self.pixel.bits_allocated,
            bits_stored: self.pixel.bits_stored,
            signed: self.pixel.signed,
            rgb: self.pixel.photometric == Photometric::Rgb,
        }
    }

    /// The window as its lowest and highest value in data units: `centre ∓ width / 2`.
    pub(crate) fn window_range(&self) -> Option<[f64; 2]> {
        let [centre, width] = self.window?;
        (centre.is_finite() && width.is_finite() && width > 0.0)
            .then(|| [centre - width / 2.0, centre + width / 2.0])
    }
}

/// Explicit VR big endian: retired from the standard, still in old archives.
pub const EXPLICIT_VR_BIG_ENDIAN: &str = "1.2.840.10008.1.2.2";

/// The value of one sample from its `bits_allocated`-bit container (little endian): the stored
/// bits below `HighBit`, sign-extended.
pub(crate) fn sample_value(container: u32, format: &PixelFormat, shift: u32) -> i64 {
    let bits = u32::from(format.bits_stored.clamp(1, 32));
    let mask: u64 = (1u64 << bits) - 1;
    let raw = (u64::from(container) >> shift) & mask;
    if format.signed && raw >> (bits - 1) & 1 == 1 {
        raw as i64 - (1i64 << bits)
    } else {
        raw as i64
    }
}
