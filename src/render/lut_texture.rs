//! The transfer function on the GPU: its lookup table (an N×1 RGBA texture sampled linearly) and
//! the running integrals of pre-integrated classification.

use super::context::GpuContext;
use crate::transfer::preintegration::INTEGRAL_ROWS;

/// The lookup table texture and the format chosen for it.
pub struct LutTexture {
    texture: wgpu::Texture,
    /// A view for binding.
    pub view: wgpu::TextureView,
    format: wgpu::TextureFormat,
    entries: u32,
}

impl LutTexture {
    /// Creates a table of `entries` texels: RGBA32F where the adapter filters it, else RGBA16F.
    pub fn new(ctx: &GpuContext, entries: u32) -> Self {
        let format = if ctx.features.contains(wgpu::Features::FLOAT32_FILTERABLE) {
            wgpu::TextureFormat::Rgba32Float
        } else {
            wgpu::TextureFormat::Rgba16Float
        };
        let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("transfer function"),
            size: wgpu::Extent3d {
                width: entries,
                height: 1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        Self {
            view: texture.create_view(&wgpu::TextureViewDescriptor::default()),
            texture,
            format,
            entries,
        }
    }

    /// Number of entries.
    pub fn entries(&self) -> u32 {
        self.entries
    }

    /// Uploads a baked table (its length must be `entries`).
    pub fn write(&self, queue: &wgpu::Queue, table: &[[f32; 4]]) {
        let bytes: Vec<u8> = match self.format {
            wgpu::TextureFormat::Rgba32Float => bytemuck::cast_slice(table).to_vec(),
            _ => table
                .iter()
                .flat_map(|texel| texel.map(half::f16::from_f32))
                .flat_map(|h| h.to_le_bytes())
                .collect(),
        };
        let bytes_per_texel = if self.format == wgpu::TextureFormat::Rgba32Float {
            16
        } else {
            8
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
                bytes_per_row: Some(self.entries * bytes_per_texel),
                rows_per_image: Some(1),
            },
            wgpu::Extent3d {
                width: self.entries,
                height: 1,
                depth_or_array_layers: 1,
            },
        );
    }
}

/// The running integrals of pre-integrated classification
/// ([`crate::transfer::preintegration::integral_table`]): an N×4 RGBA32F texture read with
/// `textureLoad` (never filtered, so no adapter feature is needed).
pub struct IntegralTexture {
    texture: wgpu::Texture,
    /// A view for binding.
    pub view: wgpu::TextureView,
    entries: u32,
}

impl IntegralTexture {
    /// Creates a table of `entries` × [`INTEGRAL_ROWS`] texels.
    pub fn new(ctx: &GpuContext, entries: u32) -> Self {
        let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("pre-integration"),
            size: wgpu::Extent3d {
                width: entries,
                height: INTEGRAL_ROWS as u32,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        Self {
            view: texture.create_view(&wgpu::TextureViewDescriptor::default()),
            texture,
            entries,
        }
    }

    /// Uploads a table built by `integral_table` (`entries` × [`INTEGRAL_ROWS`] texels).
    pub fn write(&self, queue: &wgpu::Queue, rows: &[[f32; 4]]) {
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &self.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(rows),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(self.entries * 16),
                rows_per_image: Some(INTEGRAL_ROWS as u32),
            },
            wgpu::Extent3d {
                width: self.entries,
                height: INTEGRAL_ROWS as u32,
                depth_or_array_layers: 1,
            },
        );
    }
}
