//! JPEG-LS (lossless and near-lossless), decoded by CharLS after the frame header has been
//! checked against the DICOM header ([`super::markers`]). CharLS hands colour planes one after
//! another where the stream's scans are not interleaved; they are interleaved here.

use charls::CharLS;

use super::{Frame, FrameSpec, check_shape, markers, put_sample};

/// Decodes one JPEG-LS codestream of the frame `spec` describes into little-endian containers
/// (interleaved RGB for colour).
pub(crate) fn decode_frame(stream: &[u8], spec: &FrameSpec) -> Result<Frame, String> {
    let header = markers::read_header(stream)?;
    if header.sof != 0xF7 {
        return Err("the stream is JPEG, not the JPEG-LS its transfer syntax names".into());
    }
    let note = check_shape("JPEG-LS", &header.shape, spec)?;
    let decoded = CharLS::default()
        .decode(stream)
        .map_err(|e| format!("JPEG-LS: {e}"))?;
    let wide = header.shape.precision > 8;
    let samples = spec.pixels() * usize::from(spec.samples_per_pixel);
    let have = if wide {
        decoded.len() / 2
    } else {
        decoded.len()
    };
    if have < samples {
        return Err(format!(
            "the JPEG-LS stream decodes to {have} samples; the frame needs {samples}"
        ));
    }
    let value = |i: usize| -> i64 {
        if wide {
            i64::from(u16::from_ne_bytes([decoded[2 * i], decoded[2 * i + 1]]))
        } else {
            i64::from(decoded[i])
        }
    };
    let components = usize::from(spec.samples_per_pixel);
    let planar = components > 1 && header.interleave == Some(0);
    let pixels = spec.pixels();
    let width = spec.bytes_per_sample();
    let mut bytes = vec![0u8; samples * width];
    for (i, cell) in bytes.chunks_exact_mut(width).enumerate() {
        let source = if planar {
            (i % components) * pixels + i / components
        } else {
            i
        };
        put_sample(cell, value(source));
    }
    Ok(Frame { bytes, note })
}
