//! Textures whose size follows the viewport: the exit-point texture (fragment path) and the
//! output image, recreated only when the size changes.

use super::pipelines::{OUTPUT_FORMAT, POSITION_FORMAT};

/// The per-size textures of a frame.
pub struct Targets {
    /// Size in pixels.
    pub size: [u32; 2],
    /// Exit points from the back faces (box coordinates, w = 1 where covered).
    pub exit: wgpu::TextureView,
    /// The rendered image.
    pub output: wgpu::Texture,
    /// A view of `output`.
    pub output_view: wgpu::TextureView,
}

/// A 2D texture of `size` pixels, one mip level, no multisampling.
pub(super) fn texture(
    device: &wgpu::Device,
    size: [u32; 2],
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    label: &str,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size[0],
            height: size[1],
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

impl Targets {
    /// Creates the textures for `size` pixels (the caller has checked the size against limits).
    pub fn new(device: &wgpu::Device, size: [u32; 2]) -> Self {
        use wgpu::TextureUsages as U;
        let view = |t: wgpu::Texture| t.create_view(&wgpu::TextureViewDescriptor::default());
        let positions = U::RENDER_ATTACHMENT | U::TEXTURE_BINDING;
        let output = texture(
            device,
            size,
            OUTPUT_FORMAT,
            U::RENDER_ATTACHMENT | U::STORAGE_BINDING | U::TEXTURE_BINDING | U::COPY_SRC,
            "output",
        );
        Self {
            size,
            exit: view(texture(
                device,
                size,
                POSITION_FORMAT,
                positions,
                "exit points",
            )),
            output_view: output.create_view(&wgpu::TextureViewDescriptor::default()),
            output,
        }
    }
}
