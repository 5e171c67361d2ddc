//! The transfer function on the GPU: its lookup table (an N×1 RGBA texture sampled linearly) and
//! the running integrals of pre-integrated classification (N×4, read with `textureLoad`). Both
//! are small RGBA float tables written whole from the CPU.

use super::context::GpuContext;
use super::texture::{extent, full_view, texture_2d};
use crate::transfer::preintegration::INTEGRAL_ROWS;

/// A 2D RGBA float table: the transfer function's lookup table or its running integrals.
pub struct TableTexture {
    texture: wgpu::Texture,
    /// A view for binding.
    pub view: wgpu::TextureView,
    format: wgpu::TextureFormat,
    size: [u32; 2],
}

impl TableTexture {
    /// The lookup table of `entries` texels, RGBA16F: 16-bit floats filter at full rate, 32-bit
    /// ones at a fraction of it, and RGBA32F made RC-t DVR measurably slower on both paths
    /// (docs/benchmarks/README.md, "Figures moved from code comments"). The depths are stored
    /// scaled ([`crate::transfer::lut::f16_depth_scale`]) so that faint ones stay normal numbers.
    pub fn lut(ctx: &GpuContext, entries: u32) -> Self {
        Self::new(
            &ctx.device,
            "transfer function",
            [entries, 1],
            wgpu::TextureFormat::Rgba16Float,
        )
    }

    /// The colours a slice view blends in (`transfer::lut::slice_colours`): `entries` texels of
    /// RGBA16F, sampled linearly as the lookup table.
    pub(crate) fn slice_colours(device: &wgpu::Device, entries: u32) -> Self {
        Self::new(
            device,
            "slice colours",
            [entries, 1],
            wgpu::TextureFormat::Rgba16Float,
        )
    }

    /// The running integrals of pre-integration: `entries` × [`INTEGRAL_ROWS`] texels of
    /// RGBA32F, never filtered (so no adapter feature is needed).
    pub fn integrals(ctx: &GpuContext, entries: u32) -> Self {
        Self::new(
            &ctx.device,
            "pre-integration",
            [entries, INTEGRAL_ROWS as u32],
            wgpu::TextureFormat::Rgba32Float,
        )
    }

    fn new(
        device: &wgpu::Device,
        label: &str,
        size: [u32; 2],
        format: wgpu::TextureFormat,
    ) -> Self {
        let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST;
        let texture = texture_2d(device, size, format, usage, label);
        Self {
            view: full_view(&texture),
            texture,
            format,
            size,
        }
    }

    /// Texels per row (the number of table entries).
    pub fn entries(&self) -> u32 {
        self.size[0]
    }

    /// Uploads the whole table, row by row (`texels.len()` must be width × height).
    pub fn write(&self, queue: &wgpu::Queue, texels: &[[f32; 4]]) {
        let (bytes, bytes_per_texel): (Vec<u8>, u32) = match self.format {
            wgpu::TextureFormat::Rgba32Float => (bytemuck::cast_slice(texels).to_vec(), 16),
            _ => (
                texels
                    .iter()
                    .flat_map(|texel| texel.map(half::f16::from_f32))
                    .flat_map(|h| h.to_le_bytes())
                    .collect(),
                8,
            ),
        };
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &self.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            &bytes,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(self.size[0] * bytes_per_texel),
                rows_per_image: Some(self.size[1]),
            },
            extent(self.size),
        );
    }
}
