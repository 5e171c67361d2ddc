//! The GPU side of empty-space leaping: the min/max pyramid (built once per volume), the
//! emptiness table and node flags (rebuilt when the transfer function changes), and the distance
//! field over leaf blocks (rebuilt when the flags or the block size change). Everything is built
//! lazily, only when a leaping frame needs it. The CPU references are in `crate::accel`.

use crate::accel::distance::MAX_DISTANCE;
use crate::accel::emptiness::TABLE_SIZE;
use crate::accel::pyramid::Pyramid;

use super::context::GpuContext;
use super::lut_texture::TableTexture;
use super::shader::{ShaderError, compose};

/// One pyramid level as the shaders read it. Keep in sync with `LevelInfo` in
/// `shaders/leap_common.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LevelInfo {
    /// Nodes per axis.
    pub nodes: [u32; 3],
    /// First node's index in the flat arrays.
    pub offset: u32,
    /// Brick edge in voxels.
    pub brick_vox: u32,
    /// Padding to 32 bytes.
    pub pad: [u32; 3],
}

const _: () = assert!(std::mem::size_of::<LevelInfo>() == 32);
const MAX_DISTANCE_IN_SHADER: u32 = 31;
const _: () = assert!(
    MAX_DISTANCE == MAX_DISTANCE_IN_SHADER,
    "keep build_distance.wgsl in sync"
);

/// The builder pipelines, created once per renderer.
pub struct LeapPipelines {
    base: wgpu::ComputePipeline,
    parent: wgpu::ComputePipeline,
    scan: wgpu::ComputePipeline,
    table: wgpu::ComputePipeline,
    flags: wgpu::ComputePipeline,
    distance: wgpu::ComputePipeline,
}

fn compute(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: None,
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

impl LeapPipelines {
    /// Compiles the builders.
    pub fn new(device: &wgpu::Device) -> Result<Self, ShaderError> {
        let module = |name: &str| -> Result<wgpu::ShaderModule, ShaderError> {
            Ok(device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(name),
                source: wgpu::ShaderSource::Wgsl(compose(name, &[])?.into()),
            }))
        };
        let minmax = module("build_minmax.wgsl")?;
        let emptiness = module("build_emptiness.wgsl")?;
        let distance = module("build_distance.wgsl")?;
        Ok(Self {
            base: compute(device, &minmax, "build_base"),
            parent: compute(device, &minmax, "build_parent"),
            scan: compute(device, &emptiness, "scan_lut"),
            table: compute(device, &emptiness, "build_table"),
            flags: compute(device, &emptiness, "flag_nodes"),
            distance: compute(device, &distance, "distance_pass"),
        })
    }
}

fn buffer(
    device: &wgpu::Device,
    label: &str,
    size: u64,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16),
        usage,
        mapped_at_creation: false,
    })
}

/// A 16-byte uniform buffer, written with `queue.write_buffer` before each use.
fn uniform(device: &wgpu::Device, label: &str) -> wgpu::Buffer {
    buffer(
        device,
        label,
        16,
        wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
    )
}

fn entry(binding: u32, resource: wgpu::BindingResource<'_>) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource }
}

fn groups_for(count: u32, per_group: u32) -> (u32, u32) {
    let groups = count.div_ceil(per_group).max(1);
    if groups <= 65535 {
        (groups, 1)
    } else {
        (65535, groups.div_ceil(65535))
    }
}

/// What makes a node empty, and the inputs that rule depends on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FlagRule {
    /// DVR: the transfer function is zero over the node's values (generation of the function).
    Transfer(u64),
    /// X-ray: no value above the window's low end (normalised, as f32 bits).
    AtMost(u32),
}

/// The leaping structures of one volume.
pub struct LeapStructures {
    /// Layout of the pyramid.
    pub pyramid: Pyramid,
    level_buffer: wgpu::Buffer,
    /// Per-node (min, max) of normalised values, all levels (vec2<f32>).
    pub minmax: wgpu::Buffer,
    /// Per-node emptiness flags (u32 0/1), all levels.
    pub node_empty: wgpu::Buffer,
    /// The emptiness table, `TABLE_SIZE²` u32 (1 = empty), indexed `max_bin * TABLE_SIZE + min_bin`.
    pub table: wgpu::Buffer,
    prefix: wgpu::Buffer,
    /// Distance field over the leaf level (u32 per block), and its ping-pong partner.
    pub distance: [wgpu::Buffer; 2],
    level_params: Vec<wgpu::Buffer>,
    emptiness_params: wgpu::Buffer,
    distance_params: [wgpu::Buffer; 3],
    /// Whether the pyramid has been built.
    minmax_ready: bool,
    /// What the node flags were built for, if anything.
    pub flags_for: Option<FlagRule>,
    /// The flags and leaf level the distance field was built for, if anything.
    pub distance_for: Option<(FlagRule, u32)>,
}

impl LeapStructures {
    /// Allocates the structures for a volume of `dims` whose texels decode as
    /// `s = texel * scale + bias`.
    pub fn new(ctx: &GpuContext, dims: [u32; 3], texel_scale: f32, texel_bias: f32) -> Self {
        use wgpu::BufferUsages as U;
        let device = &ctx.device;
        let pyramid = Pyramid::new(dims);
        let nodes = pyramid.node_count() as u64;
        let infos: Vec<LevelInfo> = pyramid
            .levels
            .iter()
            .map(|l| LevelInfo {
                nodes: l.nodes,
                offset: l.offset,
                brick_vox: l.brick_vox,
                pad: [0; 3],
            })
            .collect();
        let level_buffer = buffer(
            device,
            "pyramid levels",
            (infos.len() * 32) as u64,
            U::STORAGE | U::COPY_DST,
        );
        ctx.queue
            .write_buffer(&level_buffer, 0, bytemuck::cast_slice(&infos));
        let leaf_max = pyramid.levels[0].count() as u64 * 4;
        let storage = U::STORAGE | U::COPY_SRC | U::COPY_DST;
        let level_params = (0..pyramid.levels.len() as u32)
            .map(|l| {
                let b = uniform(device, "build params");
                let words = [l, texel_scale.to_bits(), texel_bias.to_bits(), 0];
                ctx.queue.write_buffer(&b, 0, bytemuck::cast_slice(&words));
                b
            })
            .collect();
        let emptiness_params = uniform(device, "emptiness params");
        Self {
            minmax: buffer(device, "node min/max", nodes * 8, storage),
            node_empty: buffer(device, "node emptiness", nodes * 4, storage),
            table: buffer(
                device,
                "emptiness table",
                (TABLE_SIZE * TABLE_SIZE * 4) as u64,
                storage,
            ),
            prefix: buffer(
                device,
                "opacity prefix",
                (crate::transfer::lut::LUT_SIZE as u64 + 1) * 4,
                storage,
            ),
            distance: [
                buffer(device, "block distance", leaf_max, storage),
                buffer(device, "block distance (pass)", leaf_max, storage),
            ],
            level_params,
            emptiness_params,
            distance_params: [0, 1, 2].map(|_| uniform(device, "distance params")),
            pyramid,
            level_buffer,
            minmax_ready: false,
            flags_for: None,
            distance_for: None,
        }
    }

    /// Records the pyramid build (once per volume); returns whether it recorded one.
    pub fn build_minmax(
        &mut self,
        ctx: &GpuContext,
        pipelines: &LeapPipelines,
        volume_view: &wgpu::TextureView,
        encoder: &mut wgpu::CommandEncoder,
    ) -> bool {
        if self.minmax_ready {
            return false;
        }
        let device = &ctx.device;
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("min/max pyramid"),
            timestamp_writes: None,
        });
        for (l, level) in self.pyramid.levels.iter().enumerate() {
            let pipeline = if l == 0 {
                &pipelines.base
            } else {
                &pipelines.parent
            };
            let layout = pipeline.get_bind_group_layout(0);
            let mut entries = vec![
                entry(0, self.level_params[l].as_entire_binding()),
                entry(1, self.level_buffer.as_entire_binding()),
                entry(2, self.minmax.as_entire_binding()),
            ];
            if l == 0 {
                entries.push(entry(3, wgpu::BindingResource::TextureView(volume_view)));
            }
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("min/max build"),
                layout: &layout,
                entries: &entries,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &group, &[]);
            let n = level.nodes;
            pass.dispatch_workgroups(n[0].div_ceil(4), n[1].div_ceil(4), n[2].div_ceil(4));
        }
        drop(pass);
        self.minmax_ready = true;
        true
    }

    /// Records the rebuild of the emptiness table and node flags from the lookup table (after
    /// every transfer-function change), timed with `timestamps` when given.
    pub fn build_flags(
        &mut self,
        ctx: &GpuContext,
        pipelines: &LeapPipelines,
        rule: FlagRule,
        lut: &TableTexture,
        encoder: &mut wgpu::CommandEncoder,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let device = &ctx.device;
        let (lut_view, lut_size) = (&lut.view, lut.entries());
        let nodes = self.pyramid.node_count();
        let (rule_code, threshold) = match rule {
            FlagRule::Transfer(_) => (0, 0),
            FlagRule::AtMost(bits) => (1, bits),
        };
        ctx.queue.write_buffer(
            &self.emptiness_params,
            0,
            bytemuck::cast_slice(&[lut_size, nodes, rule_code, threshold]),
        );
        let entries_for = |pipeline: &wgpu::ComputePipeline, bindings: &[u32]| {
            let all = [
                entry(0, self.emptiness_params.as_entire_binding()),
                entry(1, wgpu::BindingResource::TextureView(lut_view)),
                entry(2, self.prefix.as_entire_binding()),
                entry(3, self.table.as_entire_binding()),
                entry(4, self.minmax.as_entire_binding()),
                entry(5, self.node_empty.as_entire_binding()),
            ];
            let entries: Vec<_> = all
                .into_iter()
                .filter(|e| bindings.contains(&e.binding))
                .collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("emptiness build"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            })
        };
        let scan = entries_for(&pipelines.scan, &[0, 1, 2]);
        let table = entries_for(&pipelines.table, &[0, 2, 3]);
        let flags = entries_for(&pipelines.flags, &[0, 3, 4, 5]);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("emptiness"),
            timestamp_writes: timestamps,
        });
        pass.set_pipeline(&pipelines.scan);
        pass.set_bind_group(0, &scan, &[]);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(&pipelines.table);
        pass.set_bind_group(0, &table, &[]);
        let t = (TABLE_SIZE as u32).div_ceil(16);
        pass.dispatch_workgroups(t, t, 1);
        pass.set_pipeline(&pipelines.flags);
        pass.set_bind_group(0, &flags, &[]);
        let (gx, gy) = groups_for(nodes, 256);
        pass.dispatch_workgroups(gx, gy, 1);
        drop(pass);
        self.flags_for = Some(rule);
    }

    /// Records the distance-field build over leaf level `leaf` (three 1D passes ending in
    /// `distance[0]`).
    pub fn build_distance(
        &mut self,
        ctx: &GpuContext,
        pipelines: &LeapPipelines,
        leaf: u32,
        encoder: &mut wgpu::CommandEncoder,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let device = &ctx.device;
        let layout = pipelines.distance.get_bind_group_layout(0);
        let level = self.pyramid.levels[leaf as usize];
        // Axis 0 writes distance[1], axis 1 reads it and writes distance[0], axis 2 back to [1]…
        // so the order of targets is [1, 0, 1]; copy the last into [0] afterwards.
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("distance field"),
            timestamp_writes: timestamps,
        });
        for axis in 0..3u32 {
            ctx.queue.write_buffer(
                &self.distance_params[axis as usize],
                0,
                bytemuck::cast_slice(&[leaf, axis, 0, 0]),
            );
            let (src, dst) = if axis == 1 { (1, 0) } else { (0, 1) };
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("distance pass"),
                layout: &layout,
                entries: &[
                    entry(0, self.distance_params[axis as usize].as_entire_binding()),
                    entry(1, self.level_buffer.as_entire_binding()),
                    entry(2, self.node_empty.as_entire_binding()),
                    entry(3, self.distance[src].as_entire_binding()),
                    entry(4, self.distance[dst].as_entire_binding()),
                ],
            });
            pass.set_pipeline(&pipelines.distance);
            pass.set_bind_group(0, &group, &[]);
            let n = level.nodes;
            pass.dispatch_workgroups(n[0].div_ceil(4), n[1].div_ceil(4), n[2].div_ceil(4));
        }
        drop(pass);
        encoder.copy_buffer_to_buffer(
            &self.distance[1],
            0,
            &self.distance[0],
            0,
            level.count() as u64 * 4,
        );
        self.distance_for = self.flags_for.map(|rule| (rule, leaf));
    }

    /// The ray loop's bind group (levels, node flags, distances) for `layout` (group 3).
    pub fn march_group(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("leap"),
            layout,
            entries: &[
                entry(0, self.level_buffer.as_entire_binding()),
                entry(1, self.node_empty.as_entire_binding()),
                entry(2, self.distance[0].as_entire_binding()),
                entry(3, self.minmax.as_entire_binding()),
            ],
        })
    }

    /// Number of pyramid levels.
    pub fn level_count(&self) -> u32 {
        self.pyramid.levels.len() as u32
    }
}
