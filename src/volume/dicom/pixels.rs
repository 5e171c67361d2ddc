//! A file's pixel data as grey samples: decoded by dicom-pixeldata (every codec it was built
//! with), then each sample taken from its stored bits (`BitsStored` below `BitsAllocated`,
//! `HighBit`), sign-extended where `PixelRepresentation` says so, and inverted for MONOCHROME1 so
//! that larger values are brighter, as in every other photometric interpretation.

use std::path::Path;

use dicom_pixeldata::PixelDecoder;
use dicom_transfer_syntax_registry::{TransferSyntaxIndex, TransferSyntaxRegistry};

use super::error::DicomError;
use super::header::PixelFormat;
use super::{jpeg12, rle};
use crate::volume::ScalarType;

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

/// The value of one sample from its `bits_allocated`-bit container (little endian, as dicom-rs
/// hands native pixel data): stored bits below `HighBit`, sign-extended, MONOCHROME1 inverted.
pub fn sample_value(container: u32, format: &PixelFormat, shift: u32) -> i64 {
    let bits = u32::from(format.bits_stored.clamp(1, 32));
    let mask: u64 = (1u64 << bits) - 1;
    let raw = (u64::from(container) >> shift) & mask;
    let value = if format.signed && raw >> (bits - 1) & 1 == 1 {
        raw as i64 - (1i64 << bits)
    } else {
        raw as i64
    };
    match (format.monochrome1, format.signed) {
        (false, _) => value,
        (true, false) => mask as i64 - value,
        (true, true) => -1 - value,
    }
}

/// Converts one frame's bytes (`bits_allocated / 8` per sample, little endian) into `out`.
/// `encapsulated`: the pixels came from a codec, which puts the value in the low bits whatever
/// `HighBit` says.
pub fn convert_frame<T: Stored>(
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

/// A file's decoded pixel data: every frame's samples, native little endian.
pub struct Decoded {
    /// The bytes of all frames.
    pub bytes: Vec<u8>,
    /// Bytes of one frame.
    pub frame_bytes: usize,
    /// Whether a codec produced them.
    pub encapsulated: bool,
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
pub fn transfer_syntax_name(uid: &str) -> String {
    TransferSyntaxRegistry.get(uid).map_or_else(
        || "an unknown transfer syntax".to_string(),
        |ts| ts.name().to_string(),
    )
}

/// Opens `path` whole and decodes its pixel data. `rows`, `columns`, `frames` and `format` are
/// what its header said (checked against what is there).
pub fn decode_file(
    path: &Path,
    label: &str,
    rows: u32,
    columns: u32,
    frames: u32,
    format: &PixelFormat,
) -> Result<Decoded, DicomError> {
    let obj = dicom_object::open_file(path).map_err(|e| DicomError::Unreadable {
        file: label.to_string(),
        reason: format!("{}; is the file cut short?", error_chain(&e)),
    })?;
    let uid = super::tags::trimmed(obj.meta().transfer_syntax());
    let ts = TransferSyntaxRegistry.get(&uid);
    if !ts.is_some_and(|ts| ts.can_decode_all()) {
        return Err(DicomError::UnsupportedTransferSyntax {
            file: label.to_string(),
            name: transfer_syntax_name(&uid),
            uid,
        });
    }
    if format.samples_per_pixel != 1 {
        return Err(DicomError::BadField {
            file: label.to_string(),
            field: "SamplesPerPixel",
            value: format.samples_per_pixel.to_string(),
            expected: "LeapView shows grey images (1 sample per pixel), not colour ones",
        });
    }
    if format.bits_allocated == 1 {
        return Err(DicomError::BadField {
            file: label.to_string(),
            field: "BitsAllocated",
            value: "1".into(),
            expected: "a bit mask is not an image LeapView shows",
        });
    }
    let encapsulated = ts.is_some_and(|ts| ts.is_encapsulated_pixel_data());
    // Codecs are other people's code, some of it translated from C: a corrupt codestream must
    // become an error naming the file, never take the program down.
    // RLE is decoded here for every sample size: dicom-rs's decoder takes 8 and 16 bits only
    // (RT dose grids are 32) and indexes past a corrupt segment's end (a fuzzer's finding).
    let decoded = if uid == rle::RLE_LOSSLESS {
        let bytes_per_sample = usize::from(format.bits_allocated / 8).max(1);
        let pixels = rows as usize * columns as usize;
        Ok(Ok(rle_frames(
            &obj,
            label,
            pixels,
            bytes_per_sample,
            frames,
        )?))
    } else {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            obj.decode_pixel_data().map(|d| d.into_data())
        }))
    };
    let bytes = match decoded {
        Ok(Ok(bytes)) => bytes,
        // dicom-rs's JPEG decoder reads 8-bit precision only; CT is often 12.
        Ok(Err(_)) if uid == jpeg12::JPEG_EXTENDED && format.bits_allocated == 16 => {
            jpeg12_frames(&obj, label, rows, columns, frames)?
        }
        Ok(Err(e)) => {
            return Err(DicomError::Decode {
                file: label.to_string(),
                reason: error_chain(&e),
            });
        }
        Err(_) => {
            return Err(DicomError::Decode {
                file: label.to_string(),
                reason: "the decoder failed on corrupt data".into(),
            });
        }
    };
    let bytes_per_sample = u32::from(format.bits_allocated / 8);
    let frame_bytes = rows as usize * columns as usize * bytes_per_sample as usize;
    let needed = frame_bytes as u64 * u64::from(frames);
    if (bytes.len() as u64) < needed {
        return Err(DicomError::PixelDataTooShort {
            file: label.to_string(),
            rows,
            columns,
            frames,
            bytes_per_sample,
            needed,
            found: bytes.len() as u64,
        });
    }
    Ok(Decoded {
        bytes,
        frame_bytes,
        encapsulated,
    })
}

/// The fragments of `obj`'s encapsulated pixel data.
fn fragments<'o>(
    obj: &'o dicom_object::DefaultDicomObject,
    label: &str,
) -> Result<&'o [Vec<u8>], DicomError> {
    obj.get(dicom_dictionary_std::tags::PIXEL_DATA)
        .and_then(|e| e.value().fragments())
        .ok_or_else(|| DicomError::Decode {
            file: label.to_string(),
            reason: "the encapsulated pixel data holds no fragments".into(),
        })
}

/// Every frame of a 12-bit JPEG Extended object, decoded by [`jpeg12`].
fn jpeg12_frames(
    obj: &dicom_object::DefaultDicomObject,
    label: &str,
    rows: u32,
    columns: u32,
    frames: u32,
) -> Result<Vec<u8>, DicomError> {
    let fail = |reason: String| DicomError::Decode {
        file: label.to_string(),
        reason: format!("12-bit JPEG Extended: {reason}"),
    };
    let streams = jpeg12::frame_streams(fragments(obj, label)?, frames).map_err(fail)?;
    let mut out = Vec::new();
    for stream in &streams {
        out.extend(jpeg12::decode_frame(stream, columns, rows).map_err(fail)?);
    }
    Ok(out)
}

/// Every frame of an RLE object, decoded by [`rle`].
fn rle_frames(
    obj: &dicom_object::DefaultDicomObject,
    label: &str,
    pixels: usize,
    bytes_per_sample: usize,
    frames: u32,
) -> Result<Vec<u8>, DicomError> {
    let fail = |reason: &str| DicomError::Decode {
        file: label.to_string(),
        reason: reason.to_string(),
    };
    let fragments = fragments(obj, label)?;
    if fragments.len() != frames as usize {
        return Err(fail("an RLE object needs one fragment per frame"));
    }
    let mut out = Vec::new();
    for f in fragments {
        out.extend(
            rle::decode_frame(f, pixels, bytes_per_sample)
                .ok_or_else(|| fail("an RLE segment is corrupt or cut short"))?,
        );
    }
    Ok(out)
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
            monochrome1: mono1,
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
    fn monochrome1_is_inverted_within_the_stored_range() {
        let f = format(16, 12, 11, false, true);
        assert_eq!(sample_value(0, &f, 0), 4095);
        assert_eq!(sample_value(4095, &f, 0), 0);
        let f = format(16, 16, 15, true, true);
        assert_eq!(sample_value(0x8000, &f, 0), 32767);
        assert_eq!(sample_value(0x7FFF, &f, 0), -32768);
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
