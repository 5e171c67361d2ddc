//! The bricks a thick slab leaps over: (min, max) of the texel units `u` (see `SliceParams`) of
//! each `SLAB_BRICK`³ brick of the volume, extended by one voxel on every side so that no trilinear sample
//! in a brick's region escapes its range (`accel::pyramid` documents the regions). Built on the
//! GPU once per volume by the min/max pyramid's own leaf builder (`build/minmax.wgsl`), with the
//! texel decoding set to give `u` rather than normalised values.

use crate::render::gpu_data::{BUILD_WORKGROUP, BuildParams, LevelInfo, SLAB_BRICK};

use super::SliceRenderer;
use crate::render::volume_texture::VolumeView;

/// The slab's bricks of one volume texture (`vec2<f32>` per brick, x fastest).
pub struct SliceBricks {
    pub(super) buffer: wgpu::Buffer,
}

impl SliceRenderer {
    /// Builds the bricks of a volume texture of `dims` voxels whose texels are `u / texel_max`
    /// (unorm; 0 for a float texture, whose texels are `u`). Submits its own pass. `None` when
    /// the bricks would not fit in one storage buffer of `device` (slabs then take every
    /// sample).
    pub(crate) fn build_bricks(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        volume: &VolumeView,
        dims: [u32; 3],
        texel_max: f64,
    ) -> Option<SliceBricks> {
        use wgpu::util::DeviceExt;
        let nodes = dims.map(|d| d.div_ceil(SLAB_BRICK).max(1));
        let level = LevelInfo {
            nodes,
            offset: 0,
            brick_vox: SLAB_BRICK,
            _pad0: 0,
            _pad1: 0,
            _pad2: 0,
        };
        let params = BuildParams {
            level: 0,
            texel_scale: if texel_max > 0.0 {
                texel_max as f32
            } else {
                1.0
            },
            texel_bias: 0.0,
            box_edge: 0,
            data_brick: 0,
            _pad0: 0,
            _pad1: 0,
            _pad2: 0,
        };
        let levels = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("slab brick level"),
            contents: bytemuck::bytes_of(&level),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("slab brick params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let count: u64 = nodes.iter().map(|&n| u64::from(n)).product();
        let limits = device.limits();
        if count * 8
            > limits
                .max_storage_buffer_binding_size
                .min(limits.max_buffer_size)
        {
            return None;
        }
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("slab bricks"),
            size: count * 8,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let pipeline = self.bricks_pipeline.pick(volume);
        let mut entries = volume.entries([3, 4, 5]);
        entries.extend([
            wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: levels.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: buffer.as_entire_binding(),
            },
        ]);
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("slab bricks"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        });
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("slab bricks"),
        });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("slab bricks"),
                timestamp_writes: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &group, &[]);
            let [x, y, z] = nodes.map(|n| n.div_ceil(BUILD_WORKGROUP));
            pass.dispatch_workgroups(x, y, z);
        }
        queue.submit([encoder.finish()]);
        Some(SliceBricks { buffer })
    }
}

impl SliceBricks {
    /// The (min, max) of each brick, x fastest, read back (for the tests' brute-force check).
    pub fn read(&self, ctx: &crate::render::context::GpuContext) -> Result<Vec<[f32; 2]>, String> {
        let bytes = crate::render::readback::read_buffer(ctx, &self.buffer, self.buffer.size())?;
        Ok(bytes
            .chunks_exact(8)
            .map(|b| {
                let f = |i: usize| f32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
                [f(0), f(4)]
            })
            .collect())
    }
}
