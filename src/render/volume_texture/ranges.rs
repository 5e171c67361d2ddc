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

/// The lowest texel of some voxels (with its page-table constant, where one holds it exactly)
/// and the highest, as the texture unit returns them.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Span {
    lo: f32,
    constant: Option<u32>,
    hi: f32,
}

impl Span {
    /// No voxels.
    const EMPTY: Self = Self {
        lo: f32::INFINITY,
        constant: None,
        hi: f32::NEG_INFINITY,
    };

    /// Takes texel `t` (constant `c`) in.
    fn take(&mut self, (t, c): (f32, Option<u32>)) {
        if t < self.lo {
            (self.lo, self.constant) = (t, c);
        }
        self.hi = self.hi.max(t);
    }

    /// Takes another span's voxels in.
    fn join(&mut self, other: &Self) {
        if other.lo < self.lo {
            (self.lo, self.constant) = (other.lo, other.constant);
        }
        self.hi = self.hi.max(other.hi);
    }
}

/// Each brick of level 0's range over its texels and those within [`REACH`] of it (clamped to
/// the volume), decoded as the shaders decode them (`s = texel * scale + bias`), and a constant
/// within it, on `threads` threads; `None` for a colour format or a volume with non-finite
/// samples (their marker is no value a constant may stand for). Each voxel is read once: a
/// brick's range over 27 parts of it (the first [`REACH`] voxels of each axis, the middle, the
/// last [`REACH`]), then each brick's from its own parts and its neighbours' nearest ones (with
/// the reach read from the neighbours, every voxel was read 1.95 times at 32³).
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
    if brick_vox < 2 * REACH {
        return brick_ranges_directly(volume, encoding, brick_vox, threads);
    }
    let layout = BrickLayout::geometry(volume.dims(), brick_vox, 0);
    let source = TexelSource::of(volume);
    let format = encoding.format;
    let dims = volume.dims();
    let (b, r) = (brick_vox as usize, REACH as usize);
    // A brick-relative coordinate's part along its axis: 0, 1 or 2.
    let part = |v: usize| usize::from(v >= r) + usize::from(v >= b - r);
    let [gx, gy, gz] = layout.bricks.map(|g| g as usize);
    let (row, plane) = (dims[0] as usize, dims[0] as usize * dims[1] as usize);
    let bpt = bytes_per_texel(format);
    // A task per row of bricks along x, reading whole rows of the volume in order, each
    // brick's part of a row by its extremes: 2.0 s at 1024³ on one core here, where a task per
    // brick decoding each texel of its 32-voxel pieces of rows a plane apart took 5.9-7.3 s
    // (docs/benchmarks/nvidia-h100-bricks-stream §13).
    let rows = parallel_on(threads, gy * gz, &|| false, &|j| {
        let (y0, z0) = ((j % gy) * b, (j / gy) * b);
        let (y1, z1) = (
            (y0 + b).min(dims[1] as usize),
            (z0 + b).min(dims[2] as usize),
        );
        let mut spans = vec![[Span::EMPTY; 27]; gx];
        let mut out = Vec::with_capacity(row * bpt);
        for z in z0..z1 {
            for y in y0..y1 {
                let base = z * plane + y * row;
                out.clear();
                encode_texels(&source, encoding, base..base + row, &mut out);
                let at = 9 * part(z - z0) + 3 * part(y - y0);
                for (bx, brick) in spans.iter_mut().enumerate() {
                    // The brick's three parts along x, each by its extremes.
                    let x0 = bx * b;
                    let texels = (row - x0).min(b);
                    let cuts = [0, r.min(texels), (b - r).min(texels), texels];
                    for p in 0..3 {
                        let bytes = &out[(x0 + cuts[p]) * bpt..(x0 + cuts[p + 1]) * bpt];
                        if let Some((lo, hi)) = extremes(format, bytes) {
                            brick[at + p].take(lo);
                            brick[at + p].hi = brick[at + p].hi.max(hi);
                        }
                    }
                }
            }
        }
        spans
    });
    // Bricks in the layout's order, x fastest: row j of bricks holds bricks gx·j … gx·j + gx − 1.
    let parts: Vec<[Span; 27]> = rows
        .into_iter()
        .collect::<Option<Vec<_>>>()?
        .into_iter()
        .flatten()
        .collect();
    let grid = layout.bricks;
    // Along an axis: the previous brick's last part, all of this one's, the next one's first.
    let reach = [(-1i64, 2..3), (0, 0..3), (1, 0..1)];
    let ranges = (0..layout.count())
        .map(|i| {
            let at = layout.brick_at(i);
            let mut span = Span::EMPTY;
            for (dz, pz) in &reach {
                for (dy, py) in &reach {
                    for (dx, px) in &reach {
                        let n =
                            [(at[0], dx), (at[1], dy), (at[2], dz)].map(|(c, d)| i64::from(c) + d);
                        if (0..3).any(|a| n[a] < 0 || n[a] >= i64::from(grid[a])) {
                            continue;
                        }
                        let index = n[0] + i64::from(grid[0]) * (n[1] + i64::from(grid[1]) * n[2]);
                        let spans = &parts[index as usize];
                        for z in pz.clone() {
                            for y in py.clone() {
                                for x in px.clone() {
                                    span.join(&spans[x + 3 * (y + 3 * z)]);
                                }
                            }
                        }
                    }
                }
            }
            range_of(span, encoding)
        })
        .collect();
    Some(ranges)
}

/// [`brick_ranges`] reading each brick's voxels and those within [`REACH`] of it directly
/// (bricks narrower than twice the reach, whose parts would overlap).
fn brick_ranges_directly(
    volume: &Volume,
    encoding: &TexelEncoding,
    brick_vox: u32,
    threads: usize,
) -> Option<Vec<BrickRange>> {
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
        let mut all = Span::EMPTY;
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
                    all.take(decode_texel(format, texel));
                }
            }
        }
        range_of(all, encoding)
    });
    ranges.into_iter().collect()
}

/// The range and constant of a brick whose texels (and those within reach) span `span`.
fn range_of(span: Span, encoding: &TexelEncoding) -> BrickRange {
    // An f32 texel becomes the first f16 at or above the lowest, if the range reaches it.
    let constant = match encoding.format {
        wgpu::TextureFormat::R32Float => f16_at_least(span.lo)
            .filter(|h| h.to_f32() <= span.hi)
            .map(|h| u32::from(h.to_bits()) | CONSTANT_F16),
        _ => span.constant,
    };
    let decode = |t: f32| t * encoding.scale + encoding.bias;
    BrickRange {
        lo: decode(span.lo).min(decode(span.hi)),
        hi: decode(span.lo).max(decode(span.hi)),
        constant,
    }
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

/// The lowest of texels `bytes` (of `format`) as [`decode_texel`] gives it, the first of them
/// where several are equally low, and the highest value; `None` for no texels. Unorm texels
/// are compared as integers (as they decode, in order), the others decoded.
fn extremes(format: wgpu::TextureFormat, bytes: &[u8]) -> Option<((f32, Option<u32>), f32)> {
    use wgpu::TextureFormat as F;
    match format {
        F::R8Unorm => {
            let lo = *bytes.iter().min()?;
            let hi = *bytes.iter().max()?;
            Some((decode_texel(format, &[lo]), decode_texel(format, &[hi]).0))
        }
        F::R16Unorm => {
            let values = || {
                bytes
                    .chunks_exact(2)
                    .map(|b| u16::from_le_bytes([b[0], b[1]]))
            };
            let lo = values().min()?;
            let hi = values().max()?;
            let decoded = |v: u16| decode_texel(format, &v.to_le_bytes());
            Some((decoded(lo), decoded(hi).0))
        }
        _ => {
            let mut span = Span::EMPTY;
            for texel in bytes.chunks_exact(bytes_per_texel(format)) {
                span.take(decode_texel(format, texel));
            }
            (span.lo <= span.hi).then_some(((span.lo, span.constant), span.hi))
        }
    }
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
    use crate::volume::{Samples, ValueMapping};

    #[test]
    fn ranges_from_the_bricks_parts_equal_those_read_voxel_by_voxel() {
        use wgpu::TextureFormat as F;
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        // Odd sizes: partial bricks, and a last brick narrower than the reach.
        for dims in [[70u32, 37, 33], [33, 64, 9], [8, 8, 8]] {
            let n = dims.iter().map(|&d| d as usize).product::<usize>();
            // Mostly one value with rare others, so that some bricks are constant and some not.
            let mut u8s: Vec<u8> = (0..n).map(|_| 40).collect();
            for _ in 0..n / 3000 + 1 {
                let at = (next() % n as u64) as usize;
                u8s[at] = (next() % 256) as u8;
            }
            let volumes = [
                (Samples::U8(u8s.clone()), F::R8Unorm),
                (
                    Samples::U16(u8s.iter().map(|&v| u16::from(v) * 200).collect()),
                    F::R16Unorm,
                ),
                (
                    Samples::F32(u8s.iter().map(|&v| f32::from(v) * 0.3 - 7.0).collect()),
                    F::R16Float,
                ),
                (
                    Samples::F32(u8s.iter().map(|&v| f32::from(v) * 0.3 - 7.0).collect()),
                    F::R32Float,
                ),
            ];
            for (samples, format) in volumes {
                let volume = Volume::new("t", dims, [1.0; 3], samples, ValueMapping::IDENTITY)
                    .expect("volume");
                let encoding = super::super::encoding::encoding_for(&volume, format);
                for brick in [8, 16, 32] {
                    let parts = brick_ranges(&volume, &encoding, brick, 2).expect("ranges");
                    let direct =
                        brick_ranges_directly(&volume, &encoding, brick, 2).expect("ranges");
                    assert_eq!(parts, direct, "{dims:?} {format:?} {brick}");
                    assert!(parts.iter().any(|r| r.lo == r.hi) || dims == [8, 8, 8]);
                    assert!(parts.iter().any(|r| r.lo < r.hi));
                }
            }
        }
    }

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
