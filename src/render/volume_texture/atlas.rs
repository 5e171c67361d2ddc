//! A brick's slot as the atlas holds it (the brick and its apron, encoded), page-table entries
//! as the shaders read them, and the page table of a volume in one texture.

use super::encoding::{TexelEncoding, TexelSource, bytes_per_texel, encode_texels};
use crate::accel::bricks::{APRON, BrickLayout};
use crate::accel::residency::{CONSTANT, CONSTANT_F16};
use crate::render::context::GpuContext;

/// The box of a level that a brick's samples were read as: its first voxel and voxels per
/// axis (the whole level, or the slot's box of it that a streamed volume reads).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct HeldBox {
    /// The box's first voxel, in the level.
    pub origin: [u32; 3],
    /// Its voxels per axis.
    pub dims: [u32; 3],
}

impl HeldBox {
    /// The whole level `layout` holds.
    pub(super) fn whole(layout: &BrickLayout) -> Self {
        Self {
            origin: [0; 3],
            dims: layout.level_dims(),
        }
    }

    /// The voxels of `brick`'s slot (its apron and overhang repeat these): the brick and the
    /// apron around it, inside the level.
    pub(super) fn slot(layout: &BrickLayout, brick: [u32; 3]) -> Self {
        let last = layout.voxel_of(brick, [layout.slot_vox() - 1; 3]);
        let origin = layout.voxel_of(brick, [0; 3]);
        Self {
            origin,
            dims: std::array::from_fn(|a| last[a] - origin[a] + 1),
        }
    }
}

/// Appends the texels of `brick`'s slot (apron included, x fastest) to `out`, from `source`
/// (the samples of the box `held` of the level `layout` holds, which covers the slot's voxels).
pub(super) fn encode_brick(
    source: &TexelSource<'_>,
    encoding: &TexelEncoding,
    (layout, held): (&BrickLayout, HeldBox),
    brick: [u32; 3],
    out: &mut Vec<u8>,
) {
    let s = layout.slot_vox();
    let bpt = bytes_per_texel(encoding.format);
    let [ox, oy, oz] = held.origin.map(|o| o as usize);
    let row = held.dims[0] as usize;
    let plane = row * held.dims[1] as usize;
    // The slot's row in x: voxels x0..=x1 of the volume, then the edge voxels repeated.
    let first = layout.voxel_of(brick, [0, 0, 0])[0] as usize;
    let last = layout.voxel_of(brick, [s - 1, 0, 0])[0] as usize;
    let start = i64::from(brick[0] * layout.brick_vox) - 1;
    let before = (-start).max(0) as usize;
    let after = s as usize - before - (last - first + 1);
    for z in 0..s {
        for y in 0..s {
            let v = layout.voxel_of(brick, [0, y, z]);
            let base = (v[2] as usize - oz) * plane + (v[1] as usize - oy) * row;
            let at = out.len();
            encode_texels(
                source,
                encoding,
                base + first - ox..base + last + 1 - ox,
                out,
            );
            let edge_lo = out[at..at + bpt].to_vec();
            let edge_hi = out[out.len() - bpt..].to_vec();
            for _ in 0..after {
                out.extend_from_slice(&edge_hi);
            }
            for _ in 0..before {
                out.splice(at..at, edge_lo.iter().copied());
            }
        }
    }
}

/// Bytes of one page-table entry (see [`gpu_page`]).
pub(super) const PAGE_BYTES: u64 = 16;

/// Bytes of one page table of a volume of `dims` in bricks of `brick_vox`: an entry a brick.
pub(super) fn page_table_bytes(dims: [u32; 3], brick_vox: u32) -> u64 {
    dims.iter()
        .map(|&d| u64::from(d.div_ceil(brick_vox)))
        .product::<u64>()
        * PAGE_BYTES
}

/// A page-table entry as the shaders read it (`shaders/shared/volume.wgsl`: four f32, as u32
/// bits, so that a sample needs no integer decoding): for brick `brick` (of `brick_vox`
/// voxels) held in a slot, the atlas texel of its level's voxel 0 (exact integers: past the
/// slot's apron, back by the held brick's first voxel) and 2^-level; for a constant, (value, 0,
/// 0, 0).
pub(super) fn gpu_page(entry: u32, brick: [u32; 3], brick_vox: u32) -> [u32; 4] {
    if entry & CONSTANT != 0 {
        let value = if entry & CONSTANT_F16 != 0 {
            half::f16::from_bits(entry as u16).to_f32()
        } else {
            (entry & 0xffff) as f32 / 65535.0
        };
        return [value.to_bits(), 0, 0, 0];
    }
    let (slot, level) = BrickLayout::decode_entry(entry);
    let slot_vox = brick_vox + 2 * APRON;
    let origin = |a: usize| {
        let held = i64::from((brick[a] >> level) * brick_vox);
        (i64::from(slot[a] * slot_vox + APRON) - held) as f32
    };
    [
        origin(0).to_bits(),
        origin(1).to_bits(),
        origin(2).to_bits(),
        0.5f32.powi(level as i32).to_bits(),
    ]
}

/// A page table of one entry for a volume in one texture: bound, never read.
pub(super) fn no_page_table(ctx: &GpuContext) -> wgpu::Buffer {
    page_buffer(ctx, 1, "no page table")
}

/// A page table of `entries` entries, zeroed, written with `Queue::write_buffer`.
pub(super) fn page_buffer(ctx: &GpuContext, entries: u64, label: &str) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: entries.max(1) * PAGE_BYTES,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::{Samples, ValueMapping, Volume};

    #[test]
    fn a_brick_slot_holds_its_voxels_and_repeats_the_edges() {
        let dims = [5u32, 3, 2];
        let n = (dims[0] * dims[1] * dims[2]) as usize;
        let volume = Volume::new(
            "t",
            dims,
            [1.0; 3],
            Samples::U8((0..n as u8).collect()),
            ValueMapping::IDENTITY,
        )
        .expect("valid");
        let encoding = TexelEncoding {
            format: wgpu::TextureFormat::R8Unorm,
            scale: 1.0,
            bias: 0.0,
            warning: None,
        };
        let layout = BrickLayout::new(dims, 4, 64).expect("fits");
        assert_eq!(layout.bricks, [2, 1, 1]);
        for index in 0..layout.count() {
            let brick = layout.brick_at(index);
            let mut out = Vec::new();
            encode_brick(
                &TexelSource::of(&volume),
                &encoding,
                (&layout, HeldBox::whole(&layout)),
                brick,
                &mut out,
            );
            // From the slot's box alone, as a streamed volume reads it: the same texels.
            let held = HeldBox::slot(&layout, brick);
            let boxed: Vec<u8> = (0..held.dims[2])
                .flat_map(|z| (0..held.dims[1]).map(move |y| (y, z)))
                .flat_map(|(y, z)| {
                    (0..held.dims[0]).map(move |x| {
                        let [i, j, k] = [x, y, z].map(|c| c as usize);
                        let [ox, oy, oz] = held.origin.map(|o| o as usize);
                        ((i + ox) + dims[0] as usize * ((j + oy) + dims[1] as usize * (k + oz)))
                            as u8
                    })
                })
                .collect();
            let boxed = Samples::U8(boxed);
            let mut from_box = Vec::new();
            encode_brick(
                &TexelSource::of(&volume).with_samples(&boxed),
                &encoding,
                (&layout, held),
                brick,
                &mut from_box,
            );
            assert_eq!(from_box, out, "brick {brick:?} from its slot's box");
            let s = layout.slot_vox();
            assert_eq!(out.len(), (s * s * s) as usize);
            for (t, &byte) in out.iter().enumerate() {
                let t = t as u32;
                let v = layout.voxel_of(brick, [t % s, (t / s) % s, t / (s * s)]);
                let want = v[0] + dims[0] * (v[1] + dims[1] * v[2]);
                assert_eq!(u32::from(byte), want, "brick {brick:?} texel {t}");
            }
        }
    }
}
