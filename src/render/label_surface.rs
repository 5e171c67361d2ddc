//! Labels as surfaces on the GPU: the smoothed mask of the shown labels
//! ([`crate::labels::surface`] is its CPU twin), an `R8Unorm` 3D texture on the labels' grid that
//! the ray loop samples trilinearly (`shaders/shared/label_surface.wgsl`). Built by
//! `shaders/build/label_surface.wgsl` in three passes, one per axis, through one buffer of at
//! most [`MOST_SLAB_BYTES`]: each pass covers the grid in slabs and copies each into the texture.
//! Built again only when the shown labels or the smoothing change.

use crate::labels::surface::smoothing_kernel;
use crate::render::context::GpuContext;
use crate::render::gpu_data::SurfaceParams;
use crate::render::labels::GpuLabels;
use crate::render::shader::{ShaderError, compose, compute_pipeline, shader_module};

use super::texture::full_view;

/// The most bytes the build's buffer holds: a slab of the grid per pass.
const MOST_SLAB_BYTES: u64 = 64 << 20;

/// The mask's workgroup (`@workgroup_size` of build/label_surface.wgsl): words × rows × slices.
const GROUP: [u32; 3] = [8, 8, 4];

/// The builders, created once per renderer.
pub struct SurfacePipelines {
    from_labels: wgpu::ComputePipeline,
    from_mask: wgpu::ComputePipeline,
}

impl SurfacePipelines {
    /// Compiles the builders.
    pub fn new(device: &wgpu::Device) -> Result<Self, ShaderError> {
        let name = "build/label_surface.wgsl";
        let module = shader_module(device, name, compose(name, &[])?);
        Ok(Self {
            from_labels: compute_pipeline(device, &module, "smooth_labels"),
            from_mask: compute_pipeline(device, &module, "smooth_mask"),
        })
    }
}

/// Which labels, at which visibility and smoothing, a mask holds: the labels' address (the same
/// `GpuLabels` while it lives), their generation and the smoothing's bits.
type MaskKey = (usize, u64, u32);

/// One pass over one slab.
struct SlabPass {
    params: wgpu::Buffer,
    axis: usize,
    origin: [u32; 3],
    extent: [u32; 3],
}

/// The smoothed mask of one segmentation's shown labels.
pub struct SurfaceMask {
    texture: wgpu::Texture,
    /// The mask, sampled by the ray loop.
    pub(crate) view: wgpu::TextureView,
    buffer: wgpu::Buffer,
    row_words: u32,
    passes: Vec<SlabPass>,
    dims: [u32; 3],
    layers: u32,
    built_for: Option<MaskKey>,
    /// The smoothing the parameter blocks hold.
    params_for: Option<u32>,
}

impl SurfaceMask {
    /// The texture and buffers of a mask on the grid of `labels` (built by [`Self::build`]).
    pub fn new(ctx: &GpuContext, labels: &GpuLabels) -> Self {
        let most = MOST_SLAB_BYTES
            .min(ctx.limits.max_storage_buffer_binding_size)
            .min(ctx.limits.max_buffer_size);
        Self::with_slabs_of(ctx, labels, most)
    }

    /// [`Self::new`] building through slabs of at most `most` bytes.
    fn with_slabs_of(ctx: &GpuContext, labels: &GpuLabels, most: u64) -> Self {
        let device = &ctx.device;
        let dims = labels.dims();
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("label surface mask"),
            size: wgpu::Extent3d {
                width: dims[0],
                height: dims[1],
                depth_or_array_layers: dims[2],
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: wgpu::TextureFormat::R8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let row_bytes = u64::from(dims[0]).next_multiple_of(256);
        // x and y smooth slabs of whole slices (z), z slabs of whole rows (y).
        let slices = (most / (row_bytes * u64::from(dims[1]))).clamp(1, u64::from(dims[2])) as u32;
        let rows = (most / (row_bytes * u64::from(dims[2]))).clamp(1, u64::from(dims[1])) as u32;
        let mut passes = Vec::new();
        for axis in 0..3 {
            let (along, step) = if axis < 2 { (2, slices) } else { (1, rows) };
            let mut start = 0;
            while start < dims[along] {
                let mut origin = [0; 3];
                let mut extent = dims;
                origin[along] = start;
                extent[along] = step.min(dims[along] - start);
                passes.push(SlabPass {
                    params: device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("label surface params"),
                        size: std::mem::size_of::<SurfaceParams>() as u64,
                        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                        mapped_at_creation: false,
                    }),
                    axis,
                    origin,
                    extent,
                });
                start += step;
            }
        }
        let slab_bytes = passes
            .iter()
            .map(|p| row_bytes * u64::from(p.extent[1]) * u64::from(p.extent[2]))
            .max()
            .unwrap_or(4);
        Self {
            view: full_view(&texture),
            texture,
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("label surface slab"),
                size: slab_bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            row_words: (row_bytes / 4) as u32,
            passes,
            dims,
            layers: labels.layers(),
            built_for: None,
            params_for: None,
        }
    }

    /// Whether the mask is of `labels`'s grid (else a new one is made).
    pub fn fits(&self, labels: &GpuLabels) -> bool {
        self.dims == labels.dims() && self.layers == labels.layers()
    }

    /// Bytes on the GPU: the mask (a byte a voxel) and the build's buffer.
    pub fn gpu_bytes(&self) -> u64 {
        let voxels: u64 = self.dims.iter().map(|&d| u64::from(d)).product();
        voxels + self.buffer.size()
    }

    /// Records the mask's build for `labels` as shown now at `smoothing` (voxels), unless it
    /// holds that already; returns whether it recorded one.
    pub fn build(
        &mut self,
        ctx: &GpuContext,
        pipelines: &SurfacePipelines,
        labels: &GpuLabels,
        smoothing: f32,
        encoder: &mut wgpu::CommandEncoder,
    ) -> bool {
        let key = (
            std::ptr::from_ref(labels) as usize,
            labels.generation(),
            smoothing.to_bits(),
        );
        if self.built_for == Some(key) {
            return false;
        }
        if self.params_for != Some(key.2) {
            let (weights, radius) = smoothing_kernel(smoothing);
            for pass in &self.passes {
                let params = SurfaceParams {
                    dims: self.dims,
                    axis: pass.axis as u32,
                    origin: pass.origin,
                    row_words: self.row_words,
                    extent: pass.extent,
                    radius,
                    weights,
                    layers: self.layers,
                    _pad0: 0,
                    _pad1: 0,
                    _pad2: 0,
                };
                ctx.queue
                    .write_buffer(&pass.params, 0, bytemuck::bytes_of(&params));
            }
            self.params_for = Some(key.2);
        }
        for pass in &self.passes {
            let (pipeline, entries) = if pass.axis == 0 {
                let entries = vec![
                    entry(0, pass.params.as_entire_binding()),
                    entry(1, wgpu::BindingResource::TextureView(&labels.labels)),
                    entry(2, wgpu::BindingResource::TextureView(&labels.colours)),
                    entry(4, self.buffer.as_entire_binding()),
                ];
                (&pipelines.from_labels, entries)
            } else {
                let entries = vec![
                    entry(0, pass.params.as_entire_binding()),
                    entry(3, wgpu::BindingResource::TextureView(&self.view)),
                    entry(4, self.buffer.as_entire_binding()),
                ];
                (&pipelines.from_mask, entries)
            };
            let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("label surface"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            });
            let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("label surface"),
                timestamp_writes: None,
            });
            cpass.set_pipeline(pipeline);
            cpass.set_bind_group(0, &group, &[]);
            let words = pass.extent[0].div_ceil(4);
            cpass.dispatch_workgroups(
                words.div_ceil(GROUP[0]),
                pass.extent[1].div_ceil(GROUP[1]),
                pass.extent[2].div_ceil(GROUP[2]),
            );
            drop(cpass);
            encoder.copy_buffer_to_texture(
                wgpu::TexelCopyBufferInfo {
                    buffer: &self.buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(self.row_words * 4),
                        rows_per_image: Some(pass.extent[1]),
                    },
                },
                wgpu::TexelCopyTextureInfo {
                    texture: &self.texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d {
                        x: pass.origin[0],
                        y: pass.origin[1],
                        z: pass.origin[2],
                    },
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::Extent3d {
                    width: pass.extent[0],
                    height: pass.extent[1],
                    depth_or_array_layers: pass.extent[2],
                },
            );
        }
        self.built_for = Some(key);
        true
    }
}

fn entry(binding: u32, resource: wgpu::BindingResource<'_>) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::labels::LabelMap;
    use crate::labels::surface::smoothed_mask;

    /// The GPU's mask, read back.
    fn read_mask(ctx: &GpuContext, mask: &SurfaceMask) -> Vec<u8> {
        let [w, h, d] = mask.dims;
        let row = w.next_multiple_of(256);
        let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: u64::from(row * h * d),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            mask.texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(h),
                },
            },
            mask.texture.size(),
        );
        super::super::readback::submit_and_map(ctx, encoder, &buffer).unwrap();
        let data = buffer.get_mapped_range(..).unwrap();
        data.chunks_exact(row as usize)
            .flat_map(|r| r[..w as usize].to_vec())
            .collect()
    }

    /// The GPU's mask equals its CPU twin to one step of 1/255 (their sums may round apart where
    /// the GPU fuses a multiply and an add), in a grid cut into several slabs per pass.
    #[test]
    fn the_gpu_mask_matches_its_cpu_twin_over_several_slabs() {
        let ctx = GpuContext::headless().expect("a GPU (lavapipe in CI)");
        let dims = [21u32, 13, 11];
        let n = (dims[0] * dims[1] * dims[2]) as usize;
        // Two layers; labels 1..=4 in blobs, label 3 hidden.
        let layer0: Vec<u16> = (0..n).map(|i| ((i * 7 / 13) % 5) as u16).collect();
        let layer1: Vec<u16> = (0..n).map(|i| if i % 17 < 3 { 4 } else { 0 }).collect();
        let map = LabelMap::bare(dims, vec![layer0, layer1]);
        let labels = GpuLabels::new(&ctx.device, &ctx.queue, &map).unwrap();
        let mut table = vec![[0u8; 4]; 1 << 16];
        for (v, c) in table.iter_mut().enumerate().take(5).skip(1) {
            *c = [200, 100, 50, if v == 3 { 0 } else { 255 }];
        }
        labels.write_table_for_tests(&ctx.queue, &table);
        let pipelines = SurfacePipelines::new(&ctx.device).unwrap();
        // Slabs of 4 slices (256-byte rows × 13) and of 4 rows (× 11 slices): every pass
        // crosses slab boundaries.
        let mut mask = SurfaceMask::with_slabs_of(&ctx, &labels, 256 * 13 * 4);
        assert_eq!(mask.passes.len(), 3 + 3 + 4);
        for sigma in [0.0, 0.7, 1.5] {
            let scope = ctx.device.push_error_scope(wgpu::ErrorFilter::Validation);
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            assert!(mask.build(&ctx, &pipelines, &labels, sigma, &mut encoder));
            ctx.queue.submit([encoder.finish()]);
            if let Some(e) = pollster::block_on(scope.pop()) {
                panic!("{e}");
            }
            let gpu = read_mask(&ctx, &mask);
            let cpu = smoothed_mask(dims, &map.shown_voxels(&table), sigma);
            let worst = gpu
                .iter()
                .zip(&cpu)
                .map(|(&g, &c)| (i32::from(g) - i32::from(c)).abs())
                .max();
            let bad: Vec<(usize, u8, u8)> = (gpu.iter().zip(&cpu).enumerate())
                .filter(|(_, (g, c))| g.abs_diff(**c) > 1)
                .map(|(i, (&g, &c))| (i, g, c))
                .take(8)
                .collect();
            assert!(
                worst <= Some(1),
                "sigma {sigma}: off by {worst:?} at {bad:?}"
            );
            assert!(cpu.iter().any(|&c| c > 128) && cpu.iter().any(|&c| c < 128));
        }
        // The same labels and smoothing: nothing to build.
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        assert!(!mask.build(&ctx, &pipelines, &labels, 1.5, &mut encoder));
    }
}
