#![no_main]
//! One codestream on arbitrary bytes, decoded by one of LeapView's codec adapters (JPEG through
//! libjpeg-turbo, JPEG-LS through CharLS, JPEG 2000 through hayro-jpeg2000, RLE) against a header
//! shaped like the stream's own (so that the decoder runs) or one field off (so that the checks
//! run). The first byte picks the codec (low two bits) and the field put off (the rest).
use leapview::volume::dicom::codec::{Codec, FrameSpec, j2k, markers};

/// Streams that say they hold more pixels than this are skipped: a DICOM header bounds its own
/// frame by the file's size before any decoder runs (`tags::contents`), which this target skips.
const MAX_PIXELS: u64 = 1 << 22;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let Some((&mode, stream)) = data.split_first() else {
        return;
    };
    let codec = match mode & 3 {
        0 => Codec::Jpeg,
        1 => Codec::JpegLs,
        2 => Codec::Jpeg2000,
        _ => Codec::Rle,
    };
    let shape = match codec {
        Codec::Jpeg | Codec::JpegLs => markers::read_header(stream).ok().map(|h| h.shape),
        Codec::Jpeg2000 => j2k::read_siz(stream).ok().map(|s| s.shape),
        Codec::Rle => None,
    };
    let mut spec = FrameSpec {
        rows: 16,
        columns: 16,
        samples_per_pixel: 1,
        bits_allocated: 8,
        bits_stored: 8,
        signed: mode & 0x80 != 0,
        rgb: mode & 0x40 != 0,
    };
    if let Some(s) = shape {
        spec.rows = s.height;
        spec.columns = s.width;
        spec.samples_per_pixel = s.components;
        spec.bits_stored = s.precision;
        spec.bits_allocated = if s.precision > 16 {
            32
        } else if s.precision > 8 {
            16
        } else {
            8
        };
    }
    match (mode >> 2) & 7 {
        1 => spec.rows = spec.rows.saturating_add(1),
        2 => spec.columns = spec.columns.saturating_sub(1),
        3 => spec.bits_allocated = 8,
        4 => spec.samples_per_pixel = 4 - spec.samples_per_pixel.min(3),
        5 => spec.bits_allocated = 16,
        _ => {}
    }
    if u64::from(spec.rows) * u64::from(spec.columns) > MAX_PIXELS || spec.rows == 0 {
        return;
    }
    let _ = codec.decode(stream, &spec);
});
