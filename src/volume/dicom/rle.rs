//! RLE Lossless (PS3.5 Annex G), for every sample size (dicom-rs's decoder takes 8 and 16 bits
//! only, and indexes past a corrupt segment's end): each frame one fragment, a 64-byte header of segment offsets, one PackBits
//! segment per byte plane, the most significant plane first.

/// The RLE Lossless transfer syntax.
pub const RLE_LOSSLESS: &str = "1.2.840.10008.1.2.5";

/// Decodes one frame of `pixels` grey samples of `bytes_per_sample` bytes into little-endian
/// containers; `None` for a fragment that does not hold them.
pub fn decode_frame(fragment: &[u8], pixels: usize, bytes_per_sample: usize) -> Option<Vec<u8>> {
    let word = |i: usize| -> Option<usize> {
        let b = fragment.get(4 * i..4 * i + 4)?;
        Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let segments = word(0)?;
    if segments != bytes_per_sample || segments > 15 {
        return None;
    }
    let mut out = vec![0u8; pixels * bytes_per_sample];
    for s in 0..segments {
        let start = word(1 + s)?;
        let end = if s + 1 < segments {
            word(2 + s)?
        } else {
            fragment.len()
        };
        let data = fragment.get(start..end.max(start))?;
        // Segment s holds byte (bytes_per_sample - 1 - s) of each sample, little endian.
        let byte = bytes_per_sample - 1 - s;
        let plane = unpack(data, pixels)?;
        for (p, v) in plane.into_iter().enumerate() {
            out[p * bytes_per_sample + byte] = v;
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
        assert_eq!(decode_frame(&fragment, 2, 2), Some(vec![2, 1, 4, 3]));
        // A repeat run: -1 repeats twice.
        assert_eq!(unpack(&[0xFF, 9], 2), Some(vec![9, 9]));
        // Short data is refused, not padded.
        assert_eq!(unpack(&[0xFF, 9], 3), None);
        assert_eq!(decode_frame(&fragment[..10], 2, 2), None);
    }
}
