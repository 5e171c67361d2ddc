//! Where a slice pass writes: [`SliceTarget`] (values and grey in buffers, read back by the
//! tests and `leapview slice --exact`) and [`DisplayTarget`] (grey straight into a texture: the
//! window shows it, `leapview slice` reads it back).

use super::SliceError;
use crate::render::context::GpuContext;
use crate::render::gpu_data::{SliceParams, WORKGROUP};
use crate::render::readback::read_buffer;

/// Whether `device` can run a pass over `size` pixels whose largest buffer holds `bytes`.
fn check_size(device: &wgpu::Device, size: [u32; 2], bytes: u64) -> Result<(), SliceError> {
    let limits = device.limits();
    let [w, h] = size;
    let max_groups = u64::from(limits.max_compute_workgroups_per_dimension);
    let groups = |n: u32| u64::from(n.div_ceil(WORKGROUP));
    if w == 0
        || h == 0
        || bytes > limits.max_storage_buffer_binding_size
        || bytes > limits.max_buffer_size
        || w > limits.max_texture_dimension_2d
        || h > limits.max_texture_dimension_2d
        || groups(w) > max_groups
        || groups(h) > max_groups
    {
        return Err(SliceError::TooLarge(w, h));
    }
    Ok(())
}

/// A pass's parameter block.
fn params_buffer(device: &wgpu::Device) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("slice params"),
        size: std::mem::size_of::<SliceParams>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Rows of `width` RGBA8 pixels padded to a texture copy's alignment: u32 words per row.
fn padded_pitch(width: u32) -> u32 {
    let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT / 4;
    width.div_ceil(align) * align
}

/// The byte offsets of each RGBA8 pixel of rows of `pitch` u32 words, row-major, unpadded.
fn pixel_offsets(size: [u32; 2], pitch: u32) -> impl Iterator<Item = usize> {
    let [w, h] = size.map(|n| n as usize);
    (0..h).flat_map(move |y| (0..w).map(move |x| (y * pitch as usize + x) * 4))
}

/// The red byte of each RGBA8 pixel of `rows` (`pitch` u32 words per row), rows unpadded.
fn red_bytes(rows: &[u8], size: [u32; 2], pitch: u32) -> Vec<u8> {
    pixel_offsets(size, pitch)
        .filter_map(|at| rows.get(at).copied())
        .collect()
}

/// One view's buffers of the exact pass, for one image size: its parameters, the values and the
/// grey image (rows padded to a texture copy's alignment).
pub struct SliceTarget {
    /// Image size in pixels.
    pub size: [u32; 2],
    /// u32 words (pixels) per row of `image`.
    pub pitch: u32,
    pub(super) params: wgpu::Buffer,
    /// One f32 per pixel, row-major: the value in data units, NaN where there is none.
    pub values: wgpu::Buffer,
    /// One RGBA8 pixel per u32, `pitch` per row: grey through the window.
    pub image: wgpu::Buffer,
}

impl SliceTarget {
    /// Buffers for a `size` image on `device`.
    pub fn new(device: &wgpu::Device, size: [u32; 2]) -> Result<Self, SliceError> {
        let [w, h] = size;
        let pitch = padded_pitch(w);
        let image_bytes = u64::from(pitch) * u64::from(h) * 4;
        check_size(device, size, image_bytes)?;
        let storage = |label: &str, bytes: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        };
        Ok(Self {
            size,
            pitch,
            params: params_buffer(device),
            values: storage("slice values", u64::from(w) * u64::from(h) * 4),
            image: storage("slice image", image_bytes),
        })
    }

    /// The values (data units; NaN where there is none) and grey levels, read back.
    pub fn read(&self, ctx: &GpuContext) -> Result<(Vec<f32>, Vec<u8>), SliceError> {
        let [w, h] = self.size.map(u64::from);
        let values = read_buffer(ctx, &self.values, w * h * 4).map_err(SliceError::Readback)?;
        let image = read_buffer(ctx, &self.image, u64::from(self.pitch) * h * 4)
            .map_err(SliceError::Readback)?;
        let values = values
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        Ok((values, red_bytes(&image, self.size, self.pitch)))
    }
}

/// One view's texture of the display pass: RGBA8 grey, written by the pass and sampled by the
/// window (or copied out by [`DisplayTarget::read`]).
pub struct DisplayTarget {
    /// Image size in pixels.
    pub size: [u32; 2],
    pub(super) params: wgpu::Buffer,
    /// The image (RGBA8 unorm; storage, sampled and copied from).
    pub texture: wgpu::Texture,
    /// A view of all of it.
    pub view: wgpu::TextureView,
}

impl DisplayTarget {
    /// A texture for a `size` image on `device`.
    pub fn new(device: &wgpu::Device, size: [u32; 2]) -> Result<Self, SliceError> {
        check_size(device, size, u64::from(size[0]) * u64::from(size[1]) * 4)?;
        use wgpu::TextureUsages as U;
        let texture = crate::render::texture::texture_2d(
            device,
            size,
            wgpu::TextureFormat::Rgba8Unorm,
            U::STORAGE_BINDING | U::TEXTURE_BINDING | U::COPY_SRC,
            "slice view",
        );
        let view = crate::render::texture::full_view(&texture);
        Ok(Self {
            size,
            params: params_buffer(device),
            texture,
            view,
        })
    }

    /// The pixels (RGB), row-major, read back.
    pub fn read(&self, ctx: &GpuContext) -> Result<Vec<[u8; 3]>, SliceError> {
        let [w, h] = self.size;
        let pitch = padded_pitch(w);
        let bytes = u64::from(pitch) * u64::from(h) * 4;
        let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("slice view copy"),
            size: bytes,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("slice view copy"),
            });
        encoder.copy_texture_to_buffer(
            self.texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(pitch * 4),
                    rows_per_image: Some(h),
                },
            },
            crate::render::texture::extent(self.size),
        );
        ctx.queue.submit([encoder.finish()]);
        let rows = read_buffer(ctx, &buffer, bytes).map_err(SliceError::Readback)?;
        Ok(pixel_offsets(self.size, pitch)
            .filter_map(|at| rows.get(at..at + 3))
            .map(|p| [p[0], p[1], p[2]])
            .collect())
    }
}
