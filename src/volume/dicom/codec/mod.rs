//! The codestreams of encapsulated DICOM pixel data, decoded by LeapView's own adapters around
//! each codec, so that what the stream holds is checked against what the header says before a
//! sample is written: its size (Columns × Rows), its components (SamplesPerPixel) and its depth
//! (BitsAllocated). A stream that disagrees is refused with both values named; none is decoded
//! into a buffer of the header's shape. Codecs: JPEG (every process, through libjpeg-turbo),
//! JPEG-LS (CharLS), JPEG 2000 (hayro-jpeg2000, memory-safe Rust), RLE (here).

pub mod fragments;
pub mod j2k;
pub mod jpeg;
pub mod jpegls;
pub mod markers;
pub mod rle;

/// What the header says one frame holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameSpec {
    /// `Rows`.
    pub rows: u32,
    /// `Columns`.
    pub columns: u32,
    /// `SamplesPerPixel`: 1 (grey, palette) or 3 (colour).
    pub samples_per_pixel: u16,
    /// `BitsAllocated`: 8, 16 or 32.
    pub bits_allocated: u16,
    /// `BitsStored`.
    pub bits_stored: u16,
    /// `PixelRepresentation` 1.
    pub signed: bool,
    /// `PhotometricInterpretation` RGB: three samples that are red, green and blue, not YCbCr.
    pub rgb: bool,
}

impl FrameSpec {
    /// Pixels of one frame.
    pub fn pixels(&self) -> usize {
        self.rows as usize * self.columns as usize
    }

    /// Bytes of one sample's container.
    pub(crate) fn bytes_per_sample(&self) -> usize {
        usize::from(self.bits_allocated / 8).max(1)
    }

    /// Bytes of one decoded frame: every pixel's samples, interleaved.
    pub(crate) fn frame_bytes(&self) -> usize {
        self.pixels() * usize::from(self.samples_per_pixel) * self.bytes_per_sample()
    }
}

/// One decoded frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Every pixel's samples, interleaved (R, G, B per pixel for colour), each in a
    /// little-endian container of `BitsAllocated` bits holding the value's low bits.
    pub bytes: Vec<u8>,
    /// What a user should know about how the stream disagreed with the header while still
    /// being read (a depth or signedness other than the header's).
    pub note: Option<String>,
}

/// The codecs LeapView decodes, by transfer syntax.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Codec {
    /// JPEG baseline, extended (8 and 12 bits) and lossless (2–16 bits).
    Jpeg,
    /// JPEG-LS lossless and near-lossless.
    JpegLs,
    /// JPEG 2000 (lossless, lossy, and the Part 2 multi-component syntaxes).
    Jpeg2000,
    /// RLE Lossless.
    Rle,
}

impl Codec {
    /// The codec of an encapsulated transfer syntax, `None` for one LeapView does not decode.
    pub fn of(transfer_syntax: &str) -> Option<Self> {
        Some(match transfer_syntax {
            "1.2.840.10008.1.2.4.50"
            | "1.2.840.10008.1.2.4.51"
            | "1.2.840.10008.1.2.4.57"
            | "1.2.840.10008.1.2.4.70" => Self::Jpeg,
            "1.2.840.10008.1.2.4.80" | "1.2.840.10008.1.2.4.81" => Self::JpegLs,
            "1.2.840.10008.1.2.4.90"
            | "1.2.840.10008.1.2.4.91"
            | "1.2.840.10008.1.2.4.92"
            | "1.2.840.10008.1.2.4.93" => Self::Jpeg2000,
            rle::RLE_LOSSLESS => Self::Rle,
            _ => return None,
        })
    }

    /// The codec's name, for messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Jpeg => "JPEG",
            Self::JpegLs => "JPEG-LS",
            Self::Jpeg2000 => "JPEG 2000",
            Self::Rle => "RLE",
        }
    }

    /// Decodes one frame's codestream, checked against `spec`.
    pub fn decode(self, stream: &[u8], spec: &FrameSpec) -> Result<Frame, String> {
        match self {
            Self::Jpeg => jpeg::decode_frame(stream, spec),
            Self::JpegLs => jpegls::decode_frame(stream, spec),
            Self::Jpeg2000 => j2k::decode_frame(stream, spec),
            Self::Rle => rle::decode_frame(stream, spec).map(|bytes| Frame { bytes, note: None }),
        }
    }
}

/// What a codestream's own header says of the image it holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StreamShape {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Components (1 grey, 3 colour).
    pub components: u16,
    /// Bits per sample.
    pub precision: u16,
}

/// Refuses a stream whose size, components or depth the header's frame cannot hold; for a depth
/// that differs from `BitsStored` but fits, the note to give.
pub(crate) fn check_shape(
    codec: &str,
    shape: &StreamShape,
    spec: &FrameSpec,
) -> Result<Option<String>, String> {
    if (shape.width, shape.height) != (spec.columns, spec.rows) {
        return Err(format!(
            "the {codec} stream holds a {} x {} image; the header says {} x {} (Columns x Rows)",
            shape.width, shape.height, spec.columns, spec.rows
        ));
    }
    if shape.components != spec.samples_per_pixel {
        return Err(format!(
            "the {codec} stream holds {} component{} per pixel; the header says SamplesPerPixel {}",
            shape.components,
            if shape.components == 1 { "" } else { "s" },
            spec.samples_per_pixel
        ));
    }
    if shape.precision == 0 || shape.precision > spec.bits_allocated {
        return Err(format!(
            "the {codec} stream holds {}-bit samples; the header says BitsAllocated {}",
            shape.precision, spec.bits_allocated
        ));
    }
    Ok((shape.precision != spec.bits_stored).then(|| {
        format!(
            "the {codec} stream holds {}-bit samples where BitsStored says {}: read as the \
             stream holds them",
            shape.precision, spec.bits_stored
        )
    }))
}

/// Writes `value`'s low `bits_allocated` bits into `out` as a little-endian container.
pub(crate) fn put_sample(out: &mut [u8], value: i64) {
    let bytes = value.to_le_bytes();
    out.copy_from_slice(&bytes[..out.len()]);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> FrameSpec {
        FrameSpec {
            rows: 128,
            columns: 96,
            samples_per_pixel: 1,
            bits_allocated: 16,
            bits_stored: 12,
            signed: false,
            rgb: false,
        }
    }

    #[test]
    fn a_stream_that_disagrees_with_the_header_is_named_with_both_values() {
        let shape = |width, height, components, precision| StreamShape {
            width,
            height,
            components,
            precision,
        };
        let e = check_shape("JPEG", &shape(64, 64, 1, 12), &spec()).expect_err("size");
        assert!(
            e.contains("64 x 64") && e.contains("96 x 128 (Columns x Rows)"),
            "{e}"
        );
        let e = check_shape("JPEG 2000", &shape(96, 128, 3, 12), &spec()).expect_err("colour");
        assert!(
            e.contains("3 components") && e.contains("SamplesPerPixel 1"),
            "{e}"
        );
        let e = check_shape("JPEG 2000", &shape(96, 128, 1, 17), &spec()).expect_err("depth");
        assert!(
            e.contains("17-bit") && e.contains("BitsAllocated 16"),
            "{e}"
        );
        assert_eq!(
            check_shape("JPEG", &shape(96, 128, 1, 12), &spec()),
            Ok(None)
        );
        let note = check_shape("JPEG", &shape(96, 128, 1, 8), &spec())
            .expect("an 8-bit stream fits")
            .expect("a note");
        assert!(
            note.contains("8-bit") && note.contains("BitsStored says 12"),
            "{note}"
        );
    }

    #[test]
    fn transfer_syntaxes_name_their_codec() {
        assert_eq!(Codec::of("1.2.840.10008.1.2.4.50"), Some(Codec::Jpeg));
        assert_eq!(Codec::of("1.2.840.10008.1.2.4.80"), Some(Codec::JpegLs));
        assert_eq!(Codec::of("1.2.840.10008.1.2.4.91"), Some(Codec::Jpeg2000));
        assert_eq!(Codec::of("1.2.840.10008.1.2.5"), Some(Codec::Rle));
        assert_eq!(Codec::of("1.2.840.10008.1.2.1"), None);
        assert_eq!(Codec::of("1.2.840.10008.1.2.4.100"), None);
    }
}
