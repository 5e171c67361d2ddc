//! Colour pixels into RGB (PS3.3 C.7.6.3.1.2): YBR_FULL and YBR_FULL_422 converted as the
//! standard gives (and as pydicom does), native colour planes interleaved, and PALETTE COLOR
//! indices looked up in the file's red, green and blue tables (C.7.6.3.1.5, C.7.6.3.1.6).
//! Codecs that turn YCbCr into RGB themselves (JPEG through libjpeg-turbo; JPEG 2000's YBR_RCT
//! and YBR_ICT, undone by the decoder) hand RGB already.

use dicom_dictionary_std::tags;

use super::header::sample_value;
use super::header::{Photometric, PixelFormat};

/// A palette: the index of the first entry, and each channel's table.
#[derive(Clone, Debug, PartialEq)]
pub struct Palette {
    /// The pixel value the first entry maps (may be negative for signed pixels).
    pub first: i64,
    /// Red, green and blue entries.
    pub tables: [Vec<u16>; 3],
    /// Bits of each entry: 8 or 16.
    pub bits: u16,
}

impl Palette {
    /// The colour of pixel value `v`: values below the first mapped one take the first entry,
    /// values past the table the last (as pydicom and the standard's C.7.6.3.1.5).
    pub fn lookup(&self, v: i64) -> [u32; 3] {
        std::array::from_fn(|c| {
            let t = &self.tables[c];
            let i = (v - self.first).clamp(0, t.len() as i64 - 1) as usize;
            u32::from(t[i])
        })
    }
}

/// Reads the red, green and blue palette tables of `obj` (descriptors and data; segmented
/// tables are not read).
pub(crate) fn read_palette(obj: &super::tags::Object, big_endian: bool) -> Result<Palette, String> {
    let descriptors = [
        tags::RED_PALETTE_COLOR_LOOKUP_TABLE_DESCRIPTOR,
        tags::GREEN_PALETTE_COLOR_LOOKUP_TABLE_DESCRIPTOR,
        tags::BLUE_PALETTE_COLOR_LOOKUP_TABLE_DESCRIPTOR,
    ];
    let data = [
        tags::RED_PALETTE_COLOR_LOOKUP_TABLE_DATA,
        tags::GREEN_PALETTE_COLOR_LOOKUP_TABLE_DATA,
        tags::BLUE_PALETTE_COLOR_LOOKUP_TABLE_DATA,
    ];
    let descriptor = obj
        .get(descriptors[0])
        .and_then(|e| e.to_multi_int::<i64>().ok())
        .filter(|d| d.len() == 3)
        .ok_or("PALETTE COLOR without a red palette descriptor")?;
    // 0 entries means 65536; the first mapped value is US or SS as the pixels are.
    let entries = if descriptor[0] == 0 {
        65536
    } else {
        descriptor[0] as usize
    };
    let first = descriptor[1];
    let mut tables: [Vec<u16>; 3] = Default::default();
    let mut bits = 16;
    for (c, tag) in data.iter().enumerate() {
        let Some(element) = obj.get(*tag) else {
            return Err(
                if obj
                    .get(tags::SEGMENTED_RED_PALETTE_COLOR_LOOKUP_TABLE_DATA)
                    .is_some()
                {
                    "a segmented palette, which LeapView does not read".into()
                } else {
                    "PALETTE COLOR without palette data".into()
                },
            );
        };
        let bytes = element
            .to_bytes()
            .map_err(|e| format!("the palette data is unreadable ({e})"))?;
        // The entries' size follows from the data's length, as pydicom reads it: 8-bit
        // entries may come packed two to a 16-bit word.
        tables[c] = if bytes.len() == entries {
            bits = 8;
            let mut b = bytes.into_owned();
            if big_endian {
                b.chunks_exact_mut(2).for_each(<[u8]>::reverse);
            }
            b.into_iter().map(u16::from).collect()
        } else if bytes.len() == 2 * entries {
            bytes
                .chunks_exact(2)
                .map(|w| u16::from_le_bytes([w[0], w[1]]))
                .collect()
        } else {
            return Err(format!(
                "the palette holds {} bytes for {entries} entries",
                bytes.len()
            ));
        };
    }
    Ok(Palette {
        first,
        tables,
        bits,
    })
}

/// How a frame's bytes are laid out before they are RGB.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// Native pixel data, as the file stores it (planar or not, 4:2:2 or not).
    Native,
    /// A codec's output, pixel-interleaved; `rgb`: the codec turned YCbCr into RGB.
    Decoded {
        /// Whether the codec already converted to RGB.
        rgb: bool,
    },
}

/// One frame's pixels as RGB values (three per pixel, each of the format's stored bits, or a
/// palette's bits), from `bytes` (containers of `BitsAllocated` bits, little endian) laid out
/// as `layout` says.
pub(crate) fn frame_rgb(
    bytes: &[u8],
    format: &PixelFormat,
    layout: Layout,
    palette: Option<&Palette>,
    pixels: usize,
) -> Result<Vec<u32>, String> {
    let width = usize::from(format.bits_allocated / 8).max(1);
    let shift = match layout {
        Layout::Native => {
            u32::from(format.high_bit + 1).saturating_sub(u32::from(format.bits_stored))
        }
        Layout::Decoded { .. } => 0,
    };
    let value = |i: usize| -> i64 {
        let c = &bytes[i * width..(i + 1) * width];
        let container = match width {
            1 => u32::from(c[0]),
            2 => u32::from(u16::from_le_bytes([c[0], c[1]])),
            _ => u32::from_le_bytes([c[0], c[1], c[2], c[3]]),
        };
        sample_value(container, format, shift)
    };
    let have = bytes.len() / width;
    if format.photometric == Photometric::Palette {
        let palette = palette.ok_or("PALETTE COLOR without a palette")?;
        if have < pixels {
            return Err(format!("{have} samples for {pixels} pixels"));
        }
        return Ok((0..pixels).flat_map(|p| palette.lookup(value(p))).collect());
    }
    let subsampled = layout == Layout::Native && format.photometric == Photometric::YbrFull422;
    let needed = if subsampled { 2 * pixels } else { 3 * pixels };
    if have < needed {
        return Err(format!("{have} samples for {pixels} colour pixels"));
    }
    let mut out: Vec<u32> = Vec::with_capacity(3 * pixels);
    for p in 0..pixels {
        let sample = |c: usize| -> i64 {
            if subsampled {
                // Y Y Cb Cr for each pair of pixels.
                let pair = p / 2;
                value(4 * pair + if c == 0 { p % 2 } else { 1 + c })
            } else if layout == Layout::Native && format.planar {
                value(c * pixels + p)
            } else {
                value(3 * p + c)
            }
        };
        let s = [sample(0), sample(1), sample(2)];
        let to_rgb = match layout {
            Layout::Decoded { rgb: true } => false,
            _ => matches!(
                format.photometric,
                Photometric::YbrFull | Photometric::YbrFull422
            ),
        };
        let rgb = if to_rgb {
            ybr_full_to_rgb(s, format.bits_stored)
        } else {
            s.map(|v| v.max(0) as u32)
        };
        out.extend(rgb);
    }
    Ok(out)
}

/// YCbCr (full range, `bits` bits) to RGB, as the standard (C.7.6.3.1.2) and pydicom give it:
/// chroma centred on half the range, rounded half up, clamped.
fn ybr_full_to_rgb([y, cb, cr]: [i64; 3], bits: u16) -> [u32; 3] {
    let max = ((1u64 << bits.clamp(1, 32)) - 1) as f64;
    let half = (1u64 << (bits.clamp(1, 32) - 1)) as f64;
    let (y, cb, cr) = (y as f64, cb as f64 - half, cr as f64 - half);
    let r = y + 1.402 * cr;
    let g = y - (0.114 * 1.772 / 0.587) * cb - (0.299 * 1.402 / 0.587) * cr;
    let b = y + 1.772 * cb;
    [r, g, b].map(|v| (v + 0.5).floor().clamp(0.0, max) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn format(photometric: Photometric, planar: bool) -> PixelFormat {
        PixelFormat {
            bits_allocated: 8,
            bits_stored: 8,
            high_bit: 7,
            signed: false,
            samples_per_pixel: if photometric == Photometric::Palette {
                1
            } else {
                3
            },
            photometric,
            planar,
        }
    }

    #[test]
    fn ybr_full_converts_as_the_standard_says() {
        assert_eq!(ybr_full_to_rgb([128, 128, 128], 8), [128, 128, 128]);
        assert_eq!(ybr_full_to_rgb([76, 85, 255], 8), [254, 0, 0]);
        assert_eq!(ybr_full_to_rgb([255, 128, 128], 8), [255, 255, 255]);
        assert_eq!(ybr_full_to_rgb([0, 0, 0], 8), [0, 135, 0]);
    }

    #[test]
    fn native_layouts_planar_and_subsampled_become_interleaved_rgb() {
        let two = 2;
        // Planar: R R, G G, B B.
        let rgb = frame_rgb(
            &[1, 2, 3, 4, 5, 6],
            &format(Photometric::Rgb, true),
            Layout::Native,
            None,
            two,
        )
        .expect("planar");
        assert_eq!(rgb, vec![1, 3, 5, 2, 4, 6]);
        // 4:2:2: Y0 Y1 Cb Cr, grey chroma.
        let ybr = frame_rgb(
            &[10, 20, 128, 128],
            &format(Photometric::YbrFull422, false),
            Layout::Native,
            None,
            two,
        )
        .expect("4:2:2");
        assert_eq!(ybr, vec![10, 10, 10, 20, 20, 20]);
        // A codec's RGB output is left alone.
        let out = frame_rgb(
            &[0, 0, 0],
            &format(Photometric::YbrFull, false),
            Layout::Decoded { rgb: true },
            None,
            1,
        )
        .expect("RGB");
        assert_eq!(out, vec![0, 0, 0]);
        assert!(
            frame_rgb(
                &[1, 2],
                &format(Photometric::Rgb, false),
                Layout::Native,
                None,
                1
            )
            .is_err()
        );
    }

    #[test]
    fn palette_indices_clamp_to_the_table() {
        let palette = Palette {
            first: 10,
            tables: [vec![1, 2], vec![3, 4], vec![5, 6]],
            bits: 8,
        };
        assert_eq!(palette.lookup(9), [1, 3, 5]);
        assert_eq!(palette.lookup(11), [2, 4, 6]);
        assert_eq!(palette.lookup(500), [2, 4, 6]);
        let out = frame_rgb(
            &[10, 11],
            &format(Photometric::Palette, false),
            Layout::Native,
            Some(&palette),
            2,
        )
        .expect("palette");
        assert_eq!(out, vec![1, 3, 5, 2, 4, 6]);
    }
}
