//! Progressive refinement of a still view: frames of the same view rendered with their sample
//! grids shifted along the rays by stratified offsets, averaged on the GPU. A half-voxel step
//! aliases sharp transfer functions into wood-grain rings; the mean of `n` frames samples each
//! ray at `n` times the density for the cost of `n` frames, spent only while nothing changes.
//! With jittered ray starts the offsets rotate each pixel's jitter (Cranley–Patterson), so
//! noise averages out the same way.

use crate::render::context::GpuContext;
use crate::render::gpu_data::{AccumulateParams, WORKGROUP};
use crate::render::shader::{ShaderError, compose, compute_pipeline, shader_module};
use crate::render::texture::{OUTPUT_FORMAT, full_view, texture_2d};
use crate::settings::{RenderSettings, Shadows};

/// Sample offset (in steps, in `[0, 1)`) of refinement frame `k`: 0.5 for the first (the offset
/// of an unrefined frame), then the van der Corput sequence rotated by ½, so that the first
/// `2^m` frames sample the step at `2^m` evenly spaced offsets.
pub fn offset(k: u32) -> f64 {
    (0.5 + radical_inverse(k)).fract()
}

/// `settings` as refinement frame `k` renders them: the first sample at [`offset`]`(k)`, soft
/// shadows at the light's sample [`crate::sampling::light_sample`]`(k)`. Frame 0 is the
/// unrefined frame of defaulted settings, so one view's frames share frame 0's settings but
/// for these two.
pub fn frame_settings(settings: &RenderSettings, k: u32) -> RenderSettings {
    RenderSettings {
        sample_offset: offset(k),
        shadows: Shadows {
            sample: crate::sampling::light_sample(k),
            ..settings.shadows
        },
        ..*settings
    }
}

/// `k`'s bits mirrored behind the binary point (0, ½, ¼, ¾, ⅛, …).
fn radical_inverse(k: u32) -> f64 {
    f64::from(k.reverse_bits()) / 4_294_967_296.0
}

/// The running mean of the frames of one view, on the GPU.
pub struct Accumulator {
    pipeline: wgpu::ComputePipeline,
    params: wgpu::Buffer,
    /// Per-pixel f32 sums, and the mean texture; rebuilt when the size changes.
    images: Option<Images>,
    count: u32,
}

struct Images {
    size: [u32; 2],
    mean: wgpu::Texture,
    mean_view: wgpu::TextureView,
    /// The frame it reads (the renderer's output), and the pass's bindings for it.
    latest: wgpu::TextureView,
    group: wgpu::BindGroup,
}

impl Accumulator {
    /// Compiles the accumulation pass.
    pub fn new(device: &wgpu::Device) -> Result<Self, ShaderError> {
        let module = shader_module(device, "accumulate", compose("entry/accumulate.wgsl", &[])?);
        let pipeline = compute_pipeline(device, &module, "accumulate");
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("accumulate params"),
            size: std::mem::size_of::<AccumulateParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Self {
            pipeline,
            params,
            images: None,
            count: 0,
        })
    }

    /// Bytes of the per-pixel sums for `size`, checked against the device's limits: `None` when
    /// the image is too large to refine.
    fn sum_bytes(ctx: &GpuContext, size: [u32; 2]) -> Option<u64> {
        ctx.per_pixel_storage_bytes(size, 16)
    }

    /// Records a pass that adds `latest` (the output texture, `size` pixels) to the mean;
    /// `restart` drops the frames before. Returns the number of frames in the mean, or `None`
    /// when the image is too large for the sums (see [`Accumulator::sum_bytes`]).
    pub fn add(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        latest: &wgpu::TextureView,
        size: [u32; 2],
        restart: bool,
    ) -> Option<u32> {
        let bytes = Self::sum_bytes(ctx, size)?;
        // Rebuilt only when the image size or the output texture changed.
        if self
            .images
            .as_ref()
            .is_none_or(|i| i.size != size || i.latest != *latest)
        {
            self.images = Some(self.images_for(&ctx.device, latest, size, bytes));
            self.count = 0;
        }
        let images = self.images.as_ref()?;
        self.count = if restart { 1 } else { self.count + 1 };
        let params = AccumulateParams {
            count: self.count,
            width: size[0],
            height: size[1],
            _pad0: 0,
        };
        ctx.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("accumulate"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &images.group, &[]);
        pass.dispatch_workgroups(size[0].div_ceil(WORKGROUP), size[1].div_ceil(WORKGROUP), 1);
        Some(self.count)
    }

    /// Frames in the mean.
    pub fn count(&self) -> u32 {
        self.count
    }

    /// The mean texture and its size, once a frame was added.
    pub fn mean(&self) -> Option<(&wgpu::Texture, &wgpu::TextureView, [u32; 2])> {
        self.images
            .as_ref()
            .filter(|_| self.count > 0)
            .map(|i| (&i.mean, &i.mean_view, i.size))
    }
}

impl Accumulator {
    /// The sums (`bytes`), the mean texture and the bind group for frames read from `latest`.
    fn images_for(
        &self,
        device: &wgpu::Device,
        latest: &wgpu::TextureView,
        size: [u32; 2],
        bytes: u64,
    ) -> Images {
        use wgpu::TextureUsages as U;
        let sum = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("accumulated sums"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let mean = texture_2d(
            device,
            size,
            OUTPUT_FORMAT,
            U::STORAGE_BINDING | U::TEXTURE_BINDING | U::COPY_SRC,
            "refined mean",
        );
        let mean_view = full_view(&mean);
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("accumulate"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(latest),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: sum.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&mean_view),
                },
            ],
        });
        Images {
            size,
            mean,
            mean_view,
            latest: latest.clone(),
            group,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_zero_is_the_unrefined_frame() {
        let settings = RenderSettings::default();
        assert_eq!(frame_settings(&settings, 0), settings);
        let third = frame_settings(&settings, 3);
        assert_ne!(third.sample_offset, settings.sample_offset);
        assert_ne!(third.shadows.sample, settings.shadows.sample);
    }

    #[test]
    fn offsets_start_at_one_half_and_stratify_every_power_of_two() {
        assert_eq!(offset(0), 0.5);
        assert_eq!(offset(1), 0.0);
        for m in 0..6u32 {
            let n = 1u32 << m;
            let mut seen: Vec<f64> = (0..n).map(offset).collect();
            seen.sort_by(f64::total_cmp);
            for (i, o) in seen.iter().enumerate() {
                // The n offsets are i/n rotated by ½ (mod 1): evenly spaced, one per stratum.
                let expected = (0.5 + i as f64 / f64::from(n)).fract();
                assert!(
                    seen.iter().any(|s| (s - expected).abs() < 1e-12),
                    "{m}: {o}"
                );
            }
            assert!(seen.iter().all(|o| (0.0..1.0).contains(o)));
        }
    }
}
