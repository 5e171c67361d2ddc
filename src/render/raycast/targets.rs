//! What lives as long as one image size: the exit-point texture (fragment path), the output image
//! and the bind groups that read or write them, recreated only when the size changes.

use crate::render::texture::{OUTPUT_FORMAT, full_view, texture_2d};

use super::layouts::Layouts;

/// Format of the exit- and entry-point textures: box coordinates need f32 (f16 would put them
/// an eighth of a voxel off in a 256³ volume).
pub const POSITION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// The per-size textures of a frame and their bind groups.
pub struct Targets {
    /// Size in pixels.
    pub size: [u32; 2],
    /// Exit points from the back faces (box coordinates, w = 1 where covered).
    pub exit: wgpu::TextureView,
    /// The rendered image.
    pub output: wgpu::Texture,
    /// A view of `output`.
    pub output_view: wgpu::TextureView,
    /// Group 1 of the fragment path (reads `exit`).
    pub fragment_io: wgpu::BindGroup,
    /// Group 1 of the compute path (writes `output`).
    pub compute_io: wgpu::BindGroup,
}

impl Targets {
    /// Bytes of the textures of an image of `size` pixels: the output (RGBA16F) and the exit
    /// points (RGBA32F).
    pub fn bytes(size: [u32; 2]) -> u64 {
        u64::from(size[0]) * u64::from(size[1]) * (8 + 16)
    }

    /// Creates the textures for `size` pixels and their groups (the caller has checked the size
    /// against the device's limits).
    pub fn new(device: &wgpu::Device, layouts: &Layouts, size: [u32; 2]) -> Self {
        use wgpu::TextureUsages as U;
        let output = texture_2d(
            device,
            size,
            OUTPUT_FORMAT,
            U::RENDER_ATTACHMENT | U::STORAGE_BINDING | U::TEXTURE_BINDING | U::COPY_SRC,
            "output",
        );
        let exit = full_view(&texture_2d(
            device,
            size,
            POSITION_FORMAT,
            U::RENDER_ATTACHMENT | U::TEXTURE_BINDING,
            "exit points",
        ));
        let output_view = full_view(&output);
        Self {
            size,
            fragment_io: layouts.fragment_io_group(device, &exit),
            compute_io: layouts.compute_io_group(device, &output_view),
            exit,
            output,
            output_view,
        }
    }
}
