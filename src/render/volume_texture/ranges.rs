//! Each brick of level 0's value range as the shaders decode its texels, and a constant that
//! can stand for it in the page table.

use super::encoding::{TexelEncoding, TexelSource, bytes_per_texel, encode_texels};
use super::unseen::REACH;
use crate::accel::bricks::BrickLayout;
use crate::accel::residency::CONSTANT_F16;
use crate::parallel::parallel_on;
use crate::volume::Volume;

/// A brick of level 0's texels and those within [`REACH`] of it, as the shaders decode them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct BrickRange {
    /// Lowest normalised value.
    pub lo: f32,
    /// Highest normalised value.
    pub hi: f32,
    /// The lowest texel as a page-table constant (`accel::residency::CONSTANT`'s low bits),
    /// where one holds it exactly.
    pub constant: Option<u32>,
}

/// Each brick of level 0's range over its texels and those within [`REACH`] of it (clamped to
/// the volume), decoded as the shaders decode them (`s = texel * scale + bias`), and a constant
/// within it, on all cores; `None` for a colour format or a volume with non-finite samples
/// (their marker is no value a constant may stand for).
pub(super) fn brick_ranges(
    volume: &Volume,
    encoding: &TexelEncoding,
    brick_vox: u32,
    threads: usize,
) -> Option<Vec<BrickRange>> {
    use wgpu::TextureFormat as F;
    if volume.non_finite_count() > 0
        || !matches!(
            encoding.format,
            F::R8Unorm | F::R16Unorm | F::R16Float | F::R32Float
        )
    {
        return None;
    }
    let layout = BrickLayout::geometry(volume.dims(), brick_vox, 0);
    let source = TexelSource::of(volume);
    let format = encoding.format;
    let dims = volume.dims();
    let ranges = parallel_on(threads, layout.count() as usize, &|| false, &|i| {
        let brick = layout.brick_at(i as u32);
        // Voxels [first, last] of each axis.
        let span: [(usize, usize); 3] = std::array::from_fn(|a| {
            let first = (brick[a] * brick_vox).saturating_sub(REACH);
            let last = ((brick[a] + 1) * brick_vox + REACH - 1).min(dims[a] - 1);
            (first as usize, last as usize)
        });
        let (row, plane) = (dims[0] as usize, dims[0] as usize * dims[1] as usize);
        let mut out = Vec::new();
        let mut lo = (f32::INFINITY, None);
        let mut hi = f32::NEG_INFINITY;
        for z in span[2].0..=span[2].1 {
            for y in span[1].0..=span[1].1 {
                let base = z * plane + y * row;
                out.clear();
                encode_texels(
                    &source,
                    encoding,
                    base + span[0].0..base + span[0].1 + 1,
                    &mut out,
                );
                for texel in out.chunks_exact(bytes_per_texel(format)) {
                    let (t, constant) = decode_texel(format, texel);
                    if t < lo.0 {
                        lo = (t, constant);
                    }
                    hi = hi.max(t);
                }
            }
        }
        // An f32 texel becomes the first f16 at or above the lowest, if the range reaches it.
        let constant = match format {
            F::R32Float => f16_at_least(lo.0)
                .filter(|h| h.to_f32() <= hi)
                .map(|h| u32::from(h.to_bits()) | CONSTANT_F16),
            _ => lo.1,
        };
        let decode = |t: f32| t * encoding.scale + encoding.bias;
        BrickRange {
            lo: decode(lo.0).min(decode(hi)),
            hi: decode(lo.0).max(decode(hi)),
            constant,
        }
    });
    ranges.into_iter().collect()
}

/// The smallest finite f16 at or above `t`.
fn f16_at_least(t: f32) -> Option<half::f16> {
    let h = half::f16::from_f32(t);
    if h.to_f32() >= t {
        return h.is_finite().then_some(h);
    }
    let bits = h.to_bits();
    let up = match bits {
        0x8000 => 1,
        b if b & 0x8000 == 0 => b + 1,
        b => b - 1,
    };
    let u = half::f16::from_bits(up);
    (u.is_finite() && u.to_f32() >= t).then_some(u)
}

/// A texel's value as the texture unit returns it, and its page-table constant (unorm16 bits,
/// or f16 bits with [`CONSTANT_F16`]) where one holds it exactly.
fn decode_texel(format: wgpu::TextureFormat, b: &[u8]) -> (f32, Option<u32>) {
    use wgpu::TextureFormat as F;
    match format {
        F::R8Unorm => (f32::from(b[0]) / 255.0, Some(u32::from(b[0]) * 257)),
        F::R16Unorm => {
            let v = u16::from_le_bytes([b[0], b[1]]);
            (f32::from(v) / 65535.0, Some(u32::from(v)))
        }
        F::R16Float => {
            let v = half::f16::from_le_bytes([b[0], b[1]]);
            (v.to_f32(), Some(u32::from(v.to_bits()) | CONSTANT_F16))
        }
        _ => (f32::from_le_bytes([b[0], b[1], b[2], b[3]]), None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texels_decode_as_the_texture_unit_returns_them_and_constants_hold_them_exactly() {
        use wgpu::TextureFormat as F;
        let (v, c) = decode_texel(F::R8Unorm, &[51]);
        assert_eq!(v, 0.2);
        assert_eq!(c, Some(51 * 257));
        // unorm16 of the constant: 51·257 / 65535 = 51 / 255.
        assert_eq!((51.0f32 * 257.0) / 65535.0, 0.2);
        let (v, c) = decode_texel(F::R16Float, &half::f16::from_f32(0.75).to_le_bytes());
        assert_eq!(v, 0.75);
        assert_eq!(
            c,
            Some(u32::from(half::f16::from_f32(0.75).to_bits()) | CONSTANT_F16)
        );
        // An f32 texel's constant is the first f16 at or above it.
        for t in [0.1f32, -0.1, 0.5, 1e-9, -1e-9, 0.0] {
            let h = f16_at_least(t).expect("finite").to_f32();
            assert!(
                h >= t && f64::from(h - t) <= f64::from(t.abs()) / 1024.0 + 6e-8,
                "{t}: {h}"
            );
        }
        assert_eq!(f16_at_least(1e6), None);
    }
}
