//! The frame header of a JPEG or JPEG-LS codestream (ITU T.81 B.2, T.87 5.1), read before any
//! decoder sees the stream: its size, components and precision, the process (lossless or DCT),
//! and for JPEG-LS how the scan interleaves colour.

use super::StreamShape;

/// What a JPEG-family stream's frame header says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JpegHeader {
    /// Size, components, precision.
    pub shape: StreamShape,
    /// The SOF marker's low byte (0xC0 baseline … 0xC3 lossless, 0xF7 JPEG-LS).
    pub sof: u8,
    /// JPEG-LS only: the first scan's interleave mode (0 none, 1 line, 2 sample).
    pub interleave: Option<u8>,
    /// Whether a JFIF (APP0) or Adobe (APP14) segment says how colour is coded; without one,
    /// decoders guess (libjpeg-turbo: YCbCr for component ids 1, 2, 3).
    pub colour_marked: bool,
}

impl JpegHeader {
    /// Whether the stream is lossless JPEG (processes 14 and 15: SOF3, 7, 11, 15).
    pub fn lossless(&self) -> bool {
        matches!(self.sof, 0xC3 | 0xC7 | 0xCB | 0xCF)
    }
}

/// Whether a marker's low byte starts a frame (SOF0–15 but DHT, JPG and DAC; SOF55 of JPEG-LS).
fn is_sof(marker: u8) -> bool {
    matches!(marker, 0xC0..=0xCF if !matches!(marker, 0xC4 | 0xC8 | 0xCC)) || marker == 0xF7
}

fn be16(data: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_be_bytes([*data.get(at)?, *data.get(at + 1)?]))
}

/// Reads the frame header of a JPEG or JPEG-LS stream (and, for JPEG-LS, the first scan's
/// interleave mode), walking the marker segments from SOI.
pub fn read_header(stream: &[u8]) -> Result<JpegHeader, String> {
    if !stream.starts_with(&[0xFF, 0xD8]) {
        return Err("the stream does not start with a JPEG start-of-image marker".into());
    }
    let mut at = 2;
    let mut header: Option<JpegHeader> = None;
    let mut colour_marked = false;
    loop {
        // Markers may be preceded by fill bytes 0xFF.
        while stream.get(at) == Some(&0xFF) && stream.get(at + 1) == Some(&0xFF) {
            at += 1;
        }
        let (Some(&0xFF), Some(&marker)) = (stream.get(at), stream.get(at + 1)) else {
            break;
        };
        at += 2;
        // Markers without a length.
        if matches!(marker, 0x01 | 0xD0..=0xD7) {
            continue;
        }
        if marker == 0xD9 {
            break;
        }
        let length = usize::from(be16(stream, at).ok_or("a marker segment is cut short")?);
        let segment = stream
            .get(at + 2..at + length.max(2))
            .ok_or("a marker segment runs past the end of the stream")?;
        // As libjpeg-turbo reads them: a JFIF segment of at least 14 bytes, an Adobe one of 12.
        if (marker == 0xE0 && segment.len() >= 14 && segment.starts_with(b"JFIF\0"))
            || (marker == 0xEE && segment.len() >= 12 && segment.starts_with(b"Adobe"))
        {
            colour_marked = true;
        }
        if is_sof(marker) {
            let (Some(&precision), Some(height), Some(width), Some(&components)) = (
                segment.first(),
                be16(segment, 1),
                be16(segment, 3),
                segment.get(5),
            ) else {
                return Err("the frame header is cut short".into());
            };
            header = Some(JpegHeader {
                shape: StreamShape {
                    width: u32::from(width),
                    height: u32::from(height),
                    components: u16::from(components),
                    precision: u16::from(precision),
                },
                sof: marker,
                interleave: None,
                colour_marked,
            });
            if marker != 0xF7 {
                break;
            }
        } else if marker == 0xDA {
            // Start of scan: JPEG-LS gives the interleave mode after the components.
            let Some(h) = header.as_mut() else {
                return Err("a scan comes before the frame header".into());
            };
            let ns = usize::from(*segment.first().ok_or("the scan header is cut short")?);
            h.interleave = Some(
                *segment
                    .get(1 + 2 * ns + 1)
                    .ok_or("the scan header is cut short")?,
            );
            break;
        }
        at += length;
    }
    header.ok_or_else(|| "the stream holds no frame header".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SOI, an APP0 segment, a baseline SOF of `width` x `height`, 3 components, 8 bits.
    fn stream(sof: u8, width: u16, height: u16) -> Vec<u8> {
        let mut s = vec![
            0xFF, 0xD8, 0xFF, 0xE0, 0x00, 0x04, 0xAB, 0xCD, 0xFF, 0xFF, sof,
        ];
        s.extend([0x00, 17, 8]);
        s.extend(height.to_be_bytes());
        s.extend(width.to_be_bytes());
        s.push(3);
        s.extend([1, 0x22, 0, 2, 0x11, 1, 3, 0x11, 1]);
        s
    }

    #[test]
    fn the_frame_header_is_found_past_other_segments_and_fill_bytes() {
        let h = read_header(&stream(0xC0, 640, 480)).expect("a header");
        assert_eq!(
            h.shape,
            StreamShape {
                width: 640,
                height: 480,
                components: 3,
                precision: 8
            }
        );
        assert!(!h.lossless());
        assert!(!h.colour_marked);
        assert!(
            read_header(&stream(0xC3, 1, 1))
                .expect("lossless")
                .lossless()
        );
    }

    #[test]
    fn the_jpeg_ls_interleave_mode_comes_from_the_first_scan() {
        let mut s = stream(0xF7, 4, 4);
        // SOS: 3 components, (id, table) each, NEAR 0, ILV 2.
        s.extend([0xFF, 0xDA, 0x00, 12, 3, 1, 0, 2, 0, 3, 0, 0, 2, 0]);
        assert_eq!(read_header(&s).expect("JPEG-LS").interleave, Some(2));
    }

    #[test]
    fn streams_without_a_frame_header_are_errors() {
        for bad in [
            &[][..],
            &[0xFF, 0xD8][..],
            &[0xFF, 0xD8, 0xFF, 0xC0, 0x00][..],
            &[0xFF, 0xD8, 0xFF, 0xC0, 0x00, 0x40, 8][..],
            &[0x00; 16][..],
        ] {
            assert!(read_header(bad).is_err(), "{bad:?}");
        }
    }
}
