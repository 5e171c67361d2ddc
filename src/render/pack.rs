//! Reading an image back as 8-bit RGBA, quantised on the GPU: what a screenshot or a saved PNG
//! holds, and what the peers (VTK, vispy, pygfx) read back when they are timed as
//! `render + read-back`. Half the bytes of the f16 image, no conversion on the CPU, and staging
//! buffers kept from one read to the next (the f16 path allocates its own each time).

use crate::render::context::GpuContext;
use crate::render::gpu_data::WORKGROUP;
use crate::render::readback::submit_and_map;
use crate::render::shader::{ShaderError, compose, compute_pipeline, shader_module};

/// The packing pass and its buffers.
pub struct Rgba8Reader {
    pipeline: wgpu::ComputePipeline,
    /// Rebuilt when the image size changes.
    buffers: Option<PackBuffers>,
}

struct PackBuffers {
    size: [u32; 2],
    /// One u32 per pixel, written by the pass.
    packed: wgpu::Buffer,
    /// The CPU's copy of `packed`.
    staging: wgpu::Buffer,
}

impl Rgba8Reader {
    /// Compiles the packing pass.
    pub fn new(device: &wgpu::Device) -> Result<Self, ShaderError> {
        let module = shader_module(device, "pack rgba8", compose("entry/pack_rgba8.wgsl", &[])?);
        Ok(Self {
            pipeline: compute_pipeline(device, &module, "pack_rgba8"),
            buffers: None,
        })
    }

    /// Bytes of the packed image of `size` pixels, or `None` when it is empty or larger than
    /// the device's largest storage buffer (128 MiB by default: 33.5 M pixels).
    fn packed_bytes(ctx: &GpuContext, size: [u32; 2]) -> Option<u64> {
        ctx.per_pixel_storage_bytes(size, 4)
    }

    /// Quantises `image` (an RGBA texture of `size` pixels that shaders can sample) to 8 bits per
    /// channel and copies it to the CPU, waiting for the GPU. `Ok(None)` when the image is too
    /// large for one storage buffer ([`Rgba8Reader::packed_bytes`]).
    pub fn read(
        &mut self,
        ctx: &GpuContext,
        image: &wgpu::TextureView,
        size: [u32; 2],
    ) -> Result<Option<image::RgbaImage>, String> {
        let Some(bytes) = Self::packed_bytes(ctx, size) else {
            return Ok(None);
        };
        if self.buffers.as_ref().is_none_or(|b| b.size != size) {
            self.buffers = Some(PackBuffers::new(&ctx.device, size, bytes));
        }
        let Some(buffers) = self.buffers.as_ref() else {
            return Ok(None);
        };
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pack rgba8"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(image),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: buffers.packed.as_entire_binding(),
                },
            ],
        });
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("pack rgba8"),
            });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("pack rgba8"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(size[0].div_ceil(WORKGROUP), size[1].div_ceil(WORKGROUP), 1);
        }
        encoder.copy_buffer_to_buffer(&buffers.packed, 0, &buffers.staging, 0, bytes);
        submit_and_map(ctx, encoder, &buffers.staging)?;
        let data = buffers
            .staging
            .get_mapped_range(..)
            .map_err(|e| e.to_string())?;
        let pixels = data.to_vec();
        drop(data);
        buffers.staging.unmap();
        // `pixels` holds exactly width × height × 4 bytes (the buffer's size).
        Ok(image::RgbaImage::from_raw(size[0], size[1], pixels))
    }
}

impl PackBuffers {
    fn new(device: &wgpu::Device, size: [u32; 2], bytes: u64) -> Self {
        let buffer = |label, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage,
                mapped_at_creation: false,
            })
        };
        use wgpu::BufferUsages as B;
        Self {
            size,
            packed: buffer("packed rgba8", B::STORAGE | B::COPY_SRC),
            staging: buffer("packed rgba8 staging", B::MAP_READ | B::COPY_DST),
        }
    }
}
