//! Colour volumes: three channels (red, green, blue) per voxel, as colour photographs, secondary
//! captures, ultrasound, endoscopy, histology and the Visible Human are stored. A colour volume's
//! scalar samples are its luminance (ITU-R BT.601: 0.299 R + 0.587 G + 0.114 B, on 0–255): what
//! the transfer function's opacity, the leaping structures and the statistics work on, as VTK
//! does with dependent components; the samples' own colour is what the picture shows.

use super::samples::Samples;

/// The red, green and blue channels of every voxel, each stored as the file stores it.
#[derive(Clone, Debug, PartialEq)]
pub struct Colour {
    channels: [Samples; 3],
    bits: u16,
}

impl Colour {
    /// Channels of equal length holding unsigned values of up to `bits` bits (8 to 32).
    pub fn new(channels: [Samples; 3], bits: u16) -> Option<Self> {
        let len = channels[0].len();
        (channels.iter().all(|c| c.len() == len) && (1..=32).contains(&bits))
            .then_some(Self { channels, bits })
    }

    /// Red, green and blue, x fastest as the volume's samples.
    pub fn channels(&self) -> &[Samples; 3] {
        &self.channels
    }

    /// The bits each channel's values occupy.
    pub fn bits(&self) -> u16 {
        self.bits
    }

    /// Voxel `index`'s colour with 8 bits a channel, for display.
    pub fn rgb8(&self, index: usize) -> [u8; 3] {
        let shift = i32::from(self.bits) - 8;
        std::array::from_fn(|c| {
            let v = self.channels[c].get_f64(index).max(0.0);
            let v = if shift > 0 {
                (v as u64) >> shift
            } else {
                v as u64
            };
            v.min(255) as u8
        })
    }

    /// Every voxel's luminance on 0–255 (rounded), from its 8-bit colour.
    pub fn luminance(&self) -> Vec<u8> {
        (0..self.channels[0].len())
            .map(|i| luminance(self.rgb8(i)))
            .collect()
    }

    /// Mirrors every channel along x (`row` samples a row), as [`Samples::reverse_rows`].
    pub(crate) fn reverse_rows(&mut self, row: usize) {
        for c in &mut self.channels {
            c.reverse_rows(row);
        }
    }
}

/// The luminance of an 8-bit colour, rounded: ITU-R BT.601's weights (as JPEG's YCbCr and
/// VTK's and ITK's RGB-to-luminance filters use).
pub fn luminance([r, g, b]: [u8; 3]) -> u8 {
    (0.299 * f64::from(r) + 0.587 * f64::from(g) + 0.114 * f64::from(b)).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn luminance_weighs_green_most_and_wide_channels_show_their_top_bits() {
        assert_eq!(luminance([255, 255, 255]), 255);
        assert_eq!(luminance([0, 255, 0]), 150);
        assert_eq!(luminance([255, 0, 0]), 76);
        let c = Colour::new(
            [
                Samples::U16(vec![0xFFFF, 0x8000]),
                Samples::U16(vec![0, 0x0100]),
                Samples::U16(vec![0x00FF, 0]),
            ],
            16,
        )
        .expect("equal channels");
        assert_eq!(c.rgb8(0), [255, 0, 0]);
        assert_eq!(c.rgb8(1), [128, 1, 0]);
        assert_eq!(c.luminance(), vec![76, 39]);
        assert!(
            Colour::new(
                [
                    Samples::U8(vec![1]),
                    Samples::U8(vec![]),
                    Samples::U8(vec![1])
                ],
                8
            )
            .is_none()
        );
    }
}
