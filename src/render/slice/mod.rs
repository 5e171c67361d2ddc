//! Slice views on the GPU: one compute pass samples the volume texture (the ray caster's own,
//! `VolumeRenderer::volume_texture`) at each pixel's voxel coordinates and writes the value (data
//! units, f32) and its grey through the window. The pixel grid is the pure
//! `mpr::SliceView::voxel_grid`; the f64 twin is `reference::slice`.

mod timing;

use crate::mpr::{PatientFrame, Slab, SlabMode, SliceView};
use crate::volume::Volume;

use super::context::GpuContext;
use super::gpu_data::{SLAB_MEAN, SLAB_MINIP, SLAB_MIP, SliceParams, WORKGROUP};
use super::readback::read_buffer;
use super::shader::{ShaderError, compose, shader_module};
use super::volume_texture::{VolumeTexture, texel_units};

/// How a view is sampled and shown.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SliceLook {
    /// The window (data units): grey 0 at the low end, 255 at the high end.
    pub window: [f64; 2],
    /// The nearest voxel instead of trilinear interpolation.
    pub nearest: bool,
    /// A thick slab instead of a thin slice.
    pub slab: Option<Slab>,
}

/// The parameters of one view's pass: the view's pixel grid in `frame`'s voxel coordinates, the
/// texels' encoding and the window. `pitch`: u32 words per image row.
pub fn slice_params(
    view: &SliceView,
    frame: &PatientFrame,
    volume: &Volume,
    format: wgpu::TextureFormat,
    look: SliceLook,
    pitch: u32,
) -> SliceParams {
    let grid = view.voxel_grid(frame);
    let v4 = |v: glam::DVec3| [v.x as f32, v.y as f32, v.z as f32, 0.0];
    let (texel_max, unit_scale, unit_bias) = texel_units(volume, format);
    let normal = view.plane.normal();
    let (slab_count, slab_step_mm) = look.slab.map_or((1, 0.0), |s| s.samples(frame, normal));
    let slab_step = frame.axes().inverse() * (normal * slab_step_mm);
    let slab_mode = match look.slab.map(|s| s.mode) {
        Some(SlabMode::MinIp) => SLAB_MINIP,
        Some(SlabMode::Mean) => SLAB_MEAN,
        _ => SLAB_MIP,
    };
    SliceParams {
        first: v4(grid.first),
        step_x: v4(grid.step_x),
        step_y: v4(grid.step_y),
        slab_step: v4(slab_step),
        width: view.size[0],
        height: view.size[1],
        nearest: u32::from(look.nearest),
        pitch,
        texel_max: texel_max as f32,
        unit_scale: unit_scale as f32,
        unit_bias: unit_bias as f32,
        window_lo: look.window[0] as f32,
        window_hi: look.window[1] as f32,
        slab_count,
        slab_mode,
        _pad0: 0,
    }
}

/// The sampling pass, compiled once per device.
pub struct SliceRenderer {
    pipeline: wgpu::ComputePipeline,
}

/// One view's buffers, for one image size: its parameters, the values and the grey image (rows
/// padded to a texture copy's alignment, so the window can copy it into a texture).
pub struct SliceTarget {
    /// Image size in pixels.
    pub size: [u32; 2],
    /// u32 words (pixels) per row of `image`.
    pub pitch: u32,
    params: wgpu::Buffer,
    /// One f32 per pixel, row-major: the value in data units, NaN where there is none.
    pub values: wgpu::Buffer,
    /// One RGBA8 pixel per u32, `pitch` per row: grey through the window.
    pub image: wgpu::Buffer,
}

/// A slice read back to the CPU.
#[derive(Clone, Debug, PartialEq)]
pub struct SliceImage {
    /// Width and height in pixels.
    pub size: [u32; 2],
    /// The value of each pixel (data units, f32; NaN outside the volume or where a sample is
    /// missing), row-major, row 0 at the top.
    pub values: Vec<f32>,
    /// The grey level of each pixel through the window.
    pub grey: Vec<u8>,
}

/// Why a slice could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum SliceError {
    /// The slice shader does not compose (a bug in `shaders/`).
    #[error(transparent)]
    Shader(#[from] ShaderError),
    /// The image is larger than the device's buffers or dispatches allow.
    #[error("a {0} x {1} slice image is larger than this GPU allows")]
    TooLarge(u32, u32),
    /// Reading the result back failed.
    #[error("reading the slice back from the GPU failed: {0}")]
    Readback(String),
}

impl SliceTarget {
    /// Buffers for a `size` image on `device`.
    pub fn new(device: &wgpu::Device, size: [u32; 2]) -> Result<Self, SliceError> {
        let limits = device.limits();
        let [w, h] = size;
        let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT / 4;
        let pitch = w.div_ceil(align) * align;
        let image_bytes = u64::from(pitch) * u64::from(h) * 4;
        let max_groups = u64::from(limits.max_compute_workgroups_per_dimension);
        let groups = |n: u32| u64::from(n.div_ceil(WORKGROUP));
        if w == 0
            || h == 0
            || image_bytes > limits.max_storage_buffer_binding_size
            || groups(w) > max_groups
            || groups(h) > max_groups
        {
            return Err(SliceError::TooLarge(w, h));
        }
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
            params: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("slice params"),
                size: std::mem::size_of::<SliceParams>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            values: storage("slice values", u64::from(w) * u64::from(h) * 4),
            image: storage("slice image", image_bytes),
        })
    }
}

impl SliceRenderer {
    /// Compiles the sampling pass.
    pub fn new(device: &wgpu::Device) -> Result<Self, SliceError> {
        let module = shader_module(device, "slice", compose("entry/slice.wgsl", &[])?);
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("slice"),
            layout: None,
            module: &module,
            entry_point: Some("slice"),
            compilation_options: Default::default(),
            cache: None,
        });
        Ok(Self { pipeline })
    }

    /// Records the pass of `params` into `target` (the parameters are written now, so each
    /// view needs its own target within one submission).
    pub fn encode(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        volume: &wgpu::TextureView,
        target: &SliceTarget,
        params: &SliceParams,
    ) {
        queue.write_buffer(&target.params, 0, bytemuck::bytes_of(params));
        let group = self.bind_group(device, volume, target);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("slice"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(
            params.width.div_ceil(WORKGROUP),
            params.height.div_ceil(WORKGROUP),
            1,
        );
    }

    /// The pass's resources: the volume, `target`'s parameters, values and image.
    fn bind_group(
        &self,
        device: &wgpu::Device,
        volume: &wgpu::TextureView,
        target: &SliceTarget,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("slice"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(volume),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: target.params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: target.values.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: target.image.as_entire_binding(),
                },
            ],
        })
    }

    /// Draws `view` of `volume` (already in `texture`) and reads it back: the headless path of
    /// `leapview slice` and the tests.
    pub fn render(
        &self,
        ctx: &GpuContext,
        volume: &Volume,
        texture: &VolumeTexture,
        view: &SliceView,
        look: SliceLook,
    ) -> Result<SliceImage, SliceError> {
        let target = SliceTarget::new(&ctx.device, view.size)?;
        let frame = PatientFrame::of(volume);
        let format = texture.encoding.format;
        let params = slice_params(view, &frame, volume, format, look, target.pitch);
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("slice"),
            });
        self.encode(
            &ctx.device,
            &ctx.queue,
            &mut encoder,
            &texture.view,
            &target,
            &params,
        );
        ctx.queue.submit([encoder.finish()]);
        let [w, h] = view.size;
        let pixels = w as usize * h as usize;
        let values =
            read_buffer(ctx, &target.values, pixels as u64 * 4).map_err(SliceError::Readback)?;
        let image = read_buffer(
            ctx,
            &target.image,
            u64::from(target.pitch) * u64::from(h) * 4,
        )
        .map_err(SliceError::Readback)?;
        let values: Vec<f32> = values
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        // The red byte of each RGBA8 word, rows unpadded.
        let grey = (0..h as usize)
            .flat_map(|y| {
                let row = y * target.pitch as usize * 4;
                (0..w as usize).map(move |x| row + x * 4)
            })
            .map(|at| image[at])
            .collect();
        Ok(SliceImage {
            size: view.size,
            values,
            grey,
        })
    }
}
