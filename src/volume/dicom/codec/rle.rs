//! RLE Lossless (PS3.5 Annex G), for every sample size and grey or colour (dicom-rs's decoder
//! takes 8 and 16 bits only, and indexes past a corrupt segment's end): each frame one fragment,
//! a 64-byte header of segment offsets, one PackBits segment per byte plane, sample by sample
//! (R, G, B), the most significant plane of each first.

use super::FrameSpec;

/// The RLE Lossless transfer syntax.
pub const RLE_LOSSLESS: &str = "1.2.840.10008.1.2.5";

/// Decodes one frame `spec` describes into little-endian containers, samples interleaved.
pub(crate) fn decode_frame(fragment: &[u8], spec: &FrameSpec) -> Result<Vec<u8>, String> {
    decode(
        fragment,
        spec.pixels(),
        usize::from(spec.samples_per_pixel),
        spec.bytes_per_sample(),
    )
    .ok_or_else(|| "an RLE segment is corrupt or cut short".to_string())
}

/// `pixels` pixels of `samples` samples of `bytes_per_sample` bytes; `None` for a fragment that
/// does not hold them.
fn decode(
    fragment: &[u8],
    pixels: usize,
    samples: usize,
    bytes_per_sample: usize,
) -> Option<Vec<u8>> {
    let word = |i: usize| -> Option<usize> {
        let b = fragment.get(4 * i..4 * i + 4)?;
        Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let segments = word(0)?;
    if segments != samples * bytes_per_sample || segments > 15 {
        return None;
    }
    let stride = samples * bytes_per_sample;
    let mut out = vec![0u8; pixels * stride];
    for s in 0..segments {
        let start = word(1 + s)?;
        let end = if s + 1 < segments {
            word(2 + s)?
        } else {
            fragment.len()
        };
        let data = fragment.get(start..end.max(start))?;
        // Segment s holds byte (bytes_per_sample - 1 - s % bytes_per_sample) of sample
        // s / bytes_per_sample, little endian.
        let (sample, byte) = (
            s / bytes_per_sample,
            bytes_per_sample - 1 - s % bytes_per_sample,
        );
        let plane = unpack(data, pixels)?;
        for (p, v) in plane.into_iter().enumerate() {
            out[p * stride + sample * bytes_per_sample + byte] = v;
        }
    }
    Some(out)
}

/// PackBits: a header byte n ≥ 0 copies n + 1 literal bytes, -127 ≤ n ≤ -1 repeats the next byte
/// 1 - n times, -128 does nothing. Exactly `len` bytes, or `None`.
fn unpack(data: &[u8], len: usize) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(len);
    let mut i = 0;
    while out.len() < len && i < data.len() {
        let n = data[i] as i8;
        i += 1;
        match n {
            0..=127 => {
                let count = n as usize + 1;
                out.extend_from_slice(data.get(i..i + count)?);
                i += count;
            }
            -127..=-1 => {
                let v = *data.get(i)?;
                i += 1;
                out.extend(std::iter::repeat_n(v, 1 + (-(n as i32)) as usize));
            }
            -128 => {}
        }
    }
    (out.len() >= len).then(|| {
        out.truncate(len);
        out
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planes_are_unpacked_most_significant_first() {
        // Two 16-bit samples 0x0102, 0x0304: segment 1 = high bytes [1, 3], segment 2 = low [2, 4].
        let mut fragment = vec![0u8; 64];
        fragment[0] = 2;
        fragment[4] = 64;
        fragment[8] = 67;
        fragment.extend_from_slice(&[1, 1, 3]); // literal run of 2
        fragment.extend_from_slice(&[1, 2, 4]);
        assert_eq!(decode(&fragment, 2, 1, 2), Some(vec![2, 1, 4, 3]));
        // A repeat run: -1 repeats twice.
        assert_eq!(unpack(&[0xFF, 9], 2), Some(vec![9, 9]));
        // Short data is refused, not padded.
        assert_eq!(unpack(&[0xFF, 9], 3), None);
        assert_eq!(decode(&fragment[..10], 2, 1, 2), None);
        // The same two bytes as two 8-bit samples of one pixel (R then G): interleaved.
        assert_eq!(decode(&fragment, 2, 2, 1), Some(vec![1, 2, 3, 4]));
    }
}
