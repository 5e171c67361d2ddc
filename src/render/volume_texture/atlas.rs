//! The bricked upload: every brick with its apron encoded on all cores (`crate::parallel`) and written into its slot
//! of the atlas, a batch of bricks at a time, and the page table that finds them.

use super::SLAB_BYTES;
use super::encoding::{TexelEncoding, TexelSource, bytes_per_texel, encode_texels};
use crate::accel::bricks::BrickLayout;
use crate::parallel::parallel;
use crate::render::context::GpuContext;

/// Appends the texels of `brick`'s slot (apron included, x fastest) to `out`, from `source`
/// (the samples of the level `layout` holds).
fn encode_brick(
    source: &TexelSource<'_>,
    encoding: &TexelEncoding,
    layout: &BrickLayout,
    brick: [u32; 3],
    out: &mut Vec<u8>,
) {
    let s = layout.slot_vox();
    let bpt = bytes_per_texel(encoding.format);
    let dims = layout.level_dims();
    let row = dims[0] as usize;
    let plane = row * dims[1] as usize;
    // The slot's row in x: voxels x0..=x1 of the volume, then the edge voxels repeated.
    let first = layout.voxel_of(brick, [0, 0, 0])[0] as usize;
    let last = layout.voxel_of(brick, [s - 1, 0, 0])[0] as usize;
    let start = i64::from(brick[0] * layout.brick_vox) - 1;
    let before = (-start).max(0) as usize;
    let after = s as usize - before - (last - first + 1);
    for z in 0..s {
        for y in 0..s {
            let v = layout.voxel_of(brick, [0, y, z]);
            let base = v[2] as usize * plane + v[1] as usize * row;
            let at = out.len();
            encode_texels(source, encoding, base + first..base + last + 1, out);
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

/// Writes every brick of the level `layout` holds (`source`) into its slot of `atlas` (at most
/// [`SLAB_BYTES`] of encoded bricks in memory at once).
pub(super) fn upload_bricks(
    ctx: &GpuContext,
    atlas: &wgpu::Texture,
    source: &TexelSource<'_>,
    encoding: &TexelEncoding,
    layout: &BrickLayout,
) {
    let s = layout.slot_vox();
    let bpt = bytes_per_texel(encoding.format);
    let per_batch = (SLAB_BYTES / (s as usize).pow(3) / bpt).max(1) as u32;
    let mut next = 0;
    while next < layout.count() {
        let end = (next + per_batch).min(layout.count());
        let encoded = parallel((end - next) as usize, &|| false, &|k| {
            let mut out = Vec::new();
            let brick = layout.brick_at(next + k as u32);
            encode_brick(source, encoding, layout, brick, &mut out);
            out
        });
        // Each brick's buffer beside its own index: nothing stops the work, so none is missing.
        for (i, bytes) in (next..end).zip(encoded) {
            let Some(bytes) = bytes else { continue };
            let slot = layout.slot_of(i);
            ctx.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: atlas,
                    mip_level: 0,
                    origin: wgpu::Origin3d {
                        x: slot[0] * s,
                        y: slot[1] * s,
                        z: slot[2] * s,
                    },
                    aspect: wgpu::TextureAspect::All,
                },
                &bytes,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(s * bpt as u32),
                    rows_per_image: Some(s),
                },
                wgpu::Extent3d {
                    width: s,
                    height: s,
                    depth_or_array_layers: s,
                },
            );
        }
        next = end;
        // Submit what was written and wait for it, so that wgpu lets go of the batch's staging
        // copy before the next is encoded: memory holds one batch, not the whole atlas.
        ctx.queue.submit([]);
        let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
    }
}

/// A page table of one texel for a volume in one texture: bound, never read.
pub(super) fn no_page_table(ctx: &GpuContext) -> wgpu::Texture {
    ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("no page table"),
        size: wgpu::Extent3d {
            width: 1,
            height: 1,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: wgpu::TextureFormat::R32Uint,
        usage: wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    })
}

/// The page table of `layout` with every brick of its level resident: a `u32` 3D texture, one
/// texel a brick of level 0.
pub(super) fn page_table(ctx: &GpuContext, layout: &BrickLayout) -> wgpu::Texture {
    let [bx, by, bz] = layout.pages();
    let size = wgpu::Extent3d {
        width: bx,
        height: by,
        depth_or_array_layers: bz,
    };
    let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("volume page table"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: wgpu::TextureFormat::R32Uint,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let pages = layout.resident_pages();
    ctx.queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture: &texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        bytemuck::cast_slice(&pages),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(bx * 4),
            rows_per_image: Some(by),
        },
        size,
    );
    texture
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
                &layout,
                brick,
                &mut out,
            );
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
