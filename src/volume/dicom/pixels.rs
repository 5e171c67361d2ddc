//! A file's pixel data as samples: native data as it is stored (either byte order), encapsulated
//! data through LeapView's codec adapters ([`super::codec`]), then each sample taken from its
//! stored bits (`BitsStored` below `BitsAllocated`, `HighBit`) and sign-extended where
//! `PixelRepresentation` says so. MONOCHROME1 values are not inverted: the values are the
//! modality's (PS3.3 C.7.6.3.1.2: the photometric interpretation is for display), and the
//! display inverts its grey ramp instead.

use std::path::Path;

use dicom_transfer_syntax_registry::{TransferSyntaxIndex, TransferSyntaxRegistry};

use super::codec::{Codec, fragments};
use super::colour::read_palette;
use super::header::{EXPLICIT_VR_BIG_ENDIAN, FrameHeader, Photometric, PixelFormat, sample_value};
use crate::volume::error::dicom::DicomError;
use crate::volume::samples::ScalarType;

/// The stored type that holds `format`'s values exactly: the smallest integer of its stored bits
/// and signedness.
pub fn scalar_type(format: &PixelFormat) -> ScalarType {
    match (format.bits_stored, format.signed) {
        (0..=8, false) => ScalarType::U8,
        (0..=8, true) => ScalarType::I8,
        (9..=16, false) => ScalarType::U16,
        (9..=16, true) => ScalarType::I16,
        (_, false) => ScalarType::U32,
        (_, true) => ScalarType::I32,
    }
}

/// A sample type the volume can store, made from a decoded value that fits it.
pub trait Stored: Copy + Send + Sync + Default + 'static {
    /// The value, which [`scalar_type`] guarantees fits.
    fn from_i64(v: i64) -> Self;
    /// As f64, for interpolation.
    fn to_f64(self) -> f64;
    /// The nearest value to `v`, clamped to the type's range.
    fn from_f64_rounded(v: f64) -> Self;
}

macro_rules! stored {
    ($($t:ty),*) => {$(
        impl Stored for $t {
            fn from_i64(v: i64) -> Self {
                v as $t
            }
            fn to_f64(self) -> f64 {
                self as f64
            }
            fn from_f64_rounded(v: f64) -> Self {
                v.round().clamp(<$t>::MIN as f64, <$t>::MAX as f64) as $t
            }
        }
    )*};
}
stored!(u8, i8, u16, i16, u32, i32);

impl Stored for f32 {
    fn from_i64(v: i64) -> Self {
        v as f32
    }
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    fn from_f64_rounded(v: f64) -> Self {
        v as f32
    }
}

/// Converts one frame's bytes (`bits_allocated / 8` per sample, little endian) into `out`.
/// `encapsulated`: the pixels came from a codec, which puts the value in the low bits whatever
/// `HighBit` says.
pub(crate) fn convert_frame<T: Stored>(
    bytes: &[u8],
    format: &PixelFormat,
    encapsulated: bool,
    out: &mut [T],
) {
    let width = usize::from(format.bits_allocated / 8).max(1);
    let shift = if encapsulated {
        0
    } else {
        u32::from(format.high_bit + 1).saturating_sub(u32::from(format.bits_stored))
    };
    for (o, chunk) in out.iter_mut().zip(bytes.chunks_exact(width)) {
        let container = match width {
            1 => u32::from(chunk[0]),
            2 => u32::from(u16::from_le_bytes([chunk[0], chunk[1]])),
            _ => u32::from_le_bytes([chunk[0], chunk[1], chunk[2], chunk[3]]),
        };
        *o = T::from_i64(sample_value(container, format, shift));
    }
}

/// A file's decoded pixel data: every frame's samples, in little-endian containers of
/// `BitsAllocated` bits, interleaved for colour.
pub struct Decoded {
    /// The bytes of all frames.
    pub bytes: Vec<u8>,
    /// Bytes of one frame.
    pub frame_bytes: usize,
    /// Whether a codec produced them (the value then sits in the low bits, whatever `HighBit`
    /// says).
    pub encapsulated: bool,
    /// What a user should know about how the codestreams disagreed with the header while still
    /// being read (one line, for the file's first frame that gave one).
    pub note: Option<String>,
    /// The codec that decoded them (`None` for native data).
    pub codec: Option<Codec>,
    /// The file's palette, for PALETTE COLOR.
    pub palette: Option<super::colour::Palette>,
}

impl Decoded {
    /// The bytes of frame `f`.
    pub fn frame(&self, f: u32) -> &[u8] {
        let start = f as usize * self.frame_bytes;
        self.bytes
            .get(start..start + self.frame_bytes)
            .unwrap_or(&[])
    }
}

/// The name of a transfer syntax, for messages.
fn transfer_syntax_name(uid: &str) -> String {
    TransferSyntaxRegistry.get(uid).map_or_else(
        || "an unknown transfer syntax".to_string(),
        |ts| ts.name().to_string(),
    )
}

/// Native (uncompressed) pixel data as little-endian containers of `bits_allocated` bits, from
/// the value dicom-rs read: bytes (OB) in file order, or 16- or 32-bit words (OW, OL) already
/// in the machine's order. In big endian files a 32-bit sample in OW words is the first word's
/// bits above the second's (an RT dose grid); 8-bit samples in OW words take the low byte of
/// each word first in either byte order (as pydicom reads them).
fn native_bytes(
    value: &dicom_core::PrimitiveValue,
    big_endian: bool,
    bits_allocated: u16,
) -> Vec<u8> {
    use dicom_core::PrimitiveValue as P;
    let width = usize::from(bits_allocated / 8).max(1);
    match value {
        P::U8(bytes) => {
            let mut out = bytes.to_vec();
            if big_endian && width > 1 {
                out.chunks_exact_mut(width).for_each(<[u8]>::reverse);
            }
            out
        }
        P::U16(words) if big_endian && width == 4 => words
            .chunks_exact(2)
            .flat_map(|p| ((u32::from(p[0]) << 16) | u32::from(p[1])).to_le_bytes())
            .collect(),
        P::U16(words) => words.iter().flat_map(|w| w.to_le_bytes()).collect(),
        P::I16(words) => words.iter().flat_map(|w| w.to_le_bytes()).collect(),
        P::U32(words) => words.iter().flat_map(|w| w.to_le_bytes()).collect(),
        P::I32(words) => words.iter().flat_map(|w| w.to_le_bytes()).collect(),
        other => other.to_bytes().into_owned(),
    }
}

/// Opens `path` whole and decodes the pixel data of its frames, each as `header` (any of its
/// frames' headers) says (checked against what the codestreams hold).
pub(crate) fn decode_file(
    path: &Path,
    label: &str,
    header: &FrameHeader,
) -> Result<Decoded, DicomError> {
    let spec = &header.frame_spec();
    // A mosaic's tiles come from one frame of its size.
    let frames = if header.mosaic.is_some() {
        1
    } else {
        header.frames_in_file
    };
    // The scan's guard checked this file's lengths and nesting before it was first read, and
    // found how its data set is encoded.
    let options = dicom_object::OpenFileOptions::new();
    let opened = if header.implicit_vr {
        options
            .transfer_syntax_index(super::guard::ImplicitForExplicit)
            .open_file(path)
    } else {
        options.open_file(path)
    };
    let obj = opened.map_err(|e| DicomError::Unreadable {
        file: label.to_string(),
        reason: format!("{}; is the file cut short?", error_chain(&e)),
    })?;
    let uid = super::tags::trimmed(obj.meta().transfer_syntax());
    if spec.bits_allocated == 1 {
        return Err(DicomError::BadField {
            file: label.to_string(),
            field: "BitsAllocated",
            value: "1".into(),
            expected: "a bit mask is not an image LeapView shows",
        });
    }
    let decode_error = |reason: String| DicomError::Decode {
        file: label.to_string(),
        reason,
    };
    let pixel_data = obj
        .get(dicom_dictionary_std::tags::PIXEL_DATA)
        .ok_or_else(|| decode_error("the file holds no PixelData element".into()))?;
    let big_endian = uid == EXPLICIT_VR_BIG_ENDIAN;
    let palette = (header.pixel.photometric == Photometric::Palette)
        .then(|| read_palette(&obj, big_endian))
        .transpose()
        .map_err(decode_error)?;
    let native = matches!(pixel_data.value(), dicom_core::DicomValue::Primitive(_));
    // Native 4:2:2 colour holds two samples a pixel (Y Y Cb Cr for each pair).
    let frame_bytes = if native && header.pixel.photometric == Photometric::YbrFull422 {
        spec.frame_bytes() / 3 * 2
    } else {
        spec.frame_bytes()
    };
    let needed = frame_bytes as u64 * u64::from(frames);
    let mut codec = None;
    let (bytes, encapsulated, note) = match pixel_data.value() {
        dicom_core::DicomValue::Primitive(value) => (
            native_bytes(value, big_endian, spec.bits_allocated),
            false,
            None,
        ),
        dicom_core::DicomValue::PixelSequence(sequence) => {
            let found = Codec::of(&uid).ok_or_else(|| DicomError::UnsupportedTransferSyntax {
                file: label.to_string(),
                name: transfer_syntax_name(&uid),
                uid: uid.clone(),
            })?;
            codec = Some(found);
            let codec = found;
            let streams = if codec == Codec::Rle && sequence.fragments().len() != frames as usize {
                return Err(decode_error(
                    "an RLE object needs one fragment per frame".into(),
                ));
            } else {
                fragments::frame_streams(sequence.fragments(), sequence.offset_table(), frames)
                    .map_err(decode_error)?
            };
            let mut bytes = Vec::new();
            bytes
                .try_reserve_exact(needed as usize)
                .map_err(|_| decode_error("not enough memory for the decoded frames".into()))?;
            let mut note = None;
            for (f, stream) in streams.iter().enumerate() {
                let frame = codec.decode(stream, spec).map_err(|reason| {
                    let syntax = transfer_syntax_name(&uid);
                    decode_error(if frames > 1 {
                        format!("{syntax}, frame {}: {reason}", f + 1)
                    } else {
                        format!("{syntax}: {reason}")
                    })
                })?;
                note = note.or(frame.note);
                bytes.extend_from_slice(&frame.bytes);
            }
            (bytes, true, note)
        }
        dicom_core::DicomValue::Sequence(_) => {
            return Err(decode_error(
                "PixelData holds a sequence, not pixels".into(),
            ));
        }
    };
    if (bytes.len() as u64) < needed {
        return Err(DicomError::PixelDataTooShort {
            file: label.to_string(),
            rows: spec.rows,
            columns: spec.columns,
            frames,
            bytes_per_sample: u32::from(spec.bits_allocated / 8),
            needed,
            found: bytes.len() as u64,
        });
    }
    if let Some(mosaic) = &header.mosaic {
        let pixel_bytes = usize::from(spec.samples_per_pixel) * spec.bytes_per_sample();
        let tiles = header.frames_in_file;
        return Ok(Decoded {
            bytes: super::mosaic::cut(&bytes, mosaic, tiles, pixel_bytes),
            frame_bytes: frame_bytes / (mosaic.per_side * mosaic.per_side) as usize,
            encapsulated,
            note,
            codec,
            palette,
        });
    }
    Ok(Decoded {
        bytes,
        frame_bytes,
        encapsulated,
        note,
        codec,
        palette,
    })
}

/// An error and its causes, joined: dicom-rs wraps the codec's reason.
pub(crate) fn error_chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        let s_text = s.to_string();
        if !text.contains(&s_text) {
            text.push_str(": ");
            text.push_str(&s_text);
        }
        source = s.source();
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn format(allocated: u16, stored: u16, high: u16, signed: bool, mono1: bool) -> PixelFormat {
        PixelFormat {
            bits_allocated: allocated,
            bits_stored: stored,
            high_bit: high,
            signed,
            samples_per_pixel: 1,
            photometric: if mono1 {
                super::super::header::Photometric::Monochrome1
            } else {
                super::super::header::Photometric::Monochrome2
            },
            planar: false,
        }
    }

    #[test]
    fn stored_bits_are_masked_and_sign_extended() {
        // 12 bits stored in 16, unsigned: the top nibble (overlay bits) is dropped.
        let f = format(16, 12, 11, false, false);
        assert_eq!(sample_value(0xF123, &f, 0), 0x123);
        assert_eq!(scalar_type(&f), ScalarType::U16);
        // Signed 12-bit: 0xFFF is -1, 0x800 is -2048.
        let f = format(16, 12, 11, true, false);
        assert_eq!(sample_value(0x0FFF, &f, 0), -1);
        assert_eq!(sample_value(0x0800, &f, 0), -2048);
        assert_eq!(sample_value(0x07FF, &f, 0), 2047);
        // HighBit 15 with 12 bits stored: the value sits in the top bits.
        let f = format(16, 12, 15, false, false);
        let mut out = [0u16; 1];
        convert_frame(&0x1230u16.to_le_bytes(), &f, false, &mut out);
        assert_eq!(out[0], 0x123);
        // 8 bits stored in 16: a u8 volume.
        assert_eq!(scalar_type(&format(16, 8, 7, false, false)), ScalarType::U8);
        assert_eq!(
            scalar_type(&format(32, 32, 31, true, false)),
            ScalarType::I32
        );
    }

    #[test]
    fn monochrome1_values_are_the_stored_values() {
        // Inverting is the display's business: values stay the modality's.
        let f = format(16, 12, 11, false, true);
        assert_eq!(sample_value(0, &f, 0), 0);
        assert_eq!(sample_value(4095, &f, 0), 4095);
        let f = format(16, 16, 15, true, true);
        assert_eq!(sample_value(0x8000, &f, 0), -32768);
    }

    #[test]
    fn native_words_become_little_endian_containers_in_either_byte_order() {
        use dicom_core::PrimitiveValue as P;
        // An RT dose grid's 32-bit samples in OW words of a big endian file: 0x0001_0002 is
        // the words [0x0001, 0x0002].
        let words = P::U16(vec![0x0001, 0x0002].into());
        assert_eq!(native_bytes(&words, true, 32), 0x0001_0002u32.to_le_bytes());
        assert_eq!(
            native_bytes(&words, false, 32),
            0x0002_0001u32.to_le_bytes()
        );
        assert_eq!(native_bytes(&words, false, 16), [1, 0, 2, 0]);
        assert_eq!(native_bytes(&words, true, 16), [1, 0, 2, 0]);
        // 8-bit samples in OW words: the low byte of each word first, in either byte order.
        assert_eq!(native_bytes(&words, true, 8), [1, 0, 2, 0]);
        assert_eq!(native_bytes(&words, false, 8), [1, 0, 2, 0]);
        // OB bytes of 16-bit samples in a big endian file.
        let bytes = P::U8(vec![0x12, 0x34].into());
        assert_eq!(native_bytes(&bytes, true, 16), [0x34, 0x12]);
    }

    #[test]
    fn frames_convert_from_little_endian_containers() {
        let f = format(32, 32, 31, false, false);
        let bytes: Vec<u8> = [7u32, 70000].iter().flat_map(|v| v.to_le_bytes()).collect();
        let mut out = [0u32; 2];
        convert_frame(&bytes, &f, true, &mut out);
        assert_eq!(out, [7, 70000]);
        assert_eq!(u8::from_f64_rounded(300.0), 255);
        assert_eq!(i16::from_f64_rounded(-2.5), -3);
    }
}
