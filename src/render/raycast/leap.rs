//! The GPU side of empty-space leaping: the min/max pyramid (built once per volume), the
//! emptiness table and node flags (rebuilt when the transfer function changes), and the distance
//! field over leaf blocks (rebuilt when the flags or the block size change). Everything is built
//! lazily, only when a leaping frame needs it. The CPU references are in `crate::accel`.

use crate::accel::emptiness::TABLE_SIZE;
use crate::accel::pyramid::Pyramid;
use crate::render::context::GpuContext;
use crate::render::gpu_data::{
    BUILD_WORKGROUP, BuildParams, DISTANCE_ROW_MAX, DISTANCE_TILE_ROWS, DistanceParams,
    EmptinessParams, LevelInfo, MAX_WORKGROUPS_PER_DIMENSION, NODE_WORKGROUP, RULE_AT_MOST,
    RULE_ISO, RULE_TRANSFER, SIDES_EMPTY_FULL, SIDES_ISO, TABLE_WORKGROUP,
};
use crate::render::probe::{ProbePool, ProbeSlot};
use crate::render::shader::{ShaderError, compose, compute_pipeline, shader_module};
use crate::render::table_texture::TableTexture;
use crate::render::volume_texture::{PerLayout, VolumeView};
use crate::settings::{Mode, RenderSettings, Strategy};

use super::layouts::LeapResources;
use super::leap_labels::{LabelFlagPipelines, LabelFlags, LabelUse, ShownKey, shown_key};
use super::uniforms::LeapLevels;
use crate::render::labels::GpuLabels;

/// The builder pipelines, created once per renderer.
pub struct LeapPipelines {
    /// Level 0 of the pyramid: the whole level, and the nodes of listed bricks.
    base: PerLayout<[wgpu::ComputePipeline; 2]>,
    parent: wgpu::ComputePipeline,
    parent_listed: wgpu::ComputePipeline,
    scan: wgpu::ComputePipeline,
    table: wgpu::ComputePipeline,
    flags: wgpu::ComputePipeline,
    distance: wgpu::ComputePipeline,
    distance_rows: wgpu::ComputePipeline,
    labels: LabelFlagPipelines,
}

impl LeapPipelines {
    /// Compiles the builders.
    pub fn new(device: &wgpu::Device) -> Result<Self, ShaderError> {
        let module = |name: &str| -> Result<wgpu::ShaderModule, ShaderError> {
            Ok(shader_module(device, name, compose(name, &[])?))
        };
        let minmax = module("build/minmax.wgsl")?;
        let base = PerLayout::new(|defines| -> Result<_, ShaderError> {
            let module = shader_module(
                device,
                "build/minmax.wgsl",
                compose("build/minmax.wgsl", defines)?,
            );
            Ok([
                compute_pipeline(device, &module, "build_base"),
                compute_pipeline(device, &module, "build_base_listed"),
            ])
        })?;
        let emptiness = module("build/emptiness.wgsl")?;
        let distance = module("build/distance.wgsl")?;
        Ok(Self {
            base,
            parent: compute_pipeline(device, &minmax, "build_parent"),
            parent_listed: compute_pipeline(device, &minmax, "build_parent_listed"),
            scan: compute_pipeline(device, &emptiness, "scan_lut"),
            table: compute_pipeline(device, &emptiness, "build_table"),
            flags: compute_pipeline(device, &emptiness, "flag_nodes"),
            distance: compute_pipeline(device, &distance, "distance_pass"),
            distance_rows: compute_pipeline(device, &distance, "distance_rows"),
            labels: LabelFlagPipelines::new(device)?,
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
    uniform_of(device, label, 16)
}

/// A uniform buffer of `size` bytes.
fn uniform_of(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    buffer(
        device,
        label,
        size,
        wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
    )
}

/// Nodes per axis of a pyramid level of `block`-voxel blocks that read a voxel of one
/// `data_brick`-voxel brick: ⌈b·D/B⌉ − 1 ..= ⌊(b + 1)·D/B⌋, at most D/B + 2 (2 where B > D).
fn box_edge(block: u32, data_brick: u32) -> u32 {
    if block <= data_brick {
        data_brick / block + 2
    } else {
        2
    }
}

/// Bricks one partial build lists at most (past it the pyramid is built whole).
const MAX_LISTED: usize = 4096;

/// Invocations of a partial build's workgroup (`@workgroup_size` of build/minmax.wgsl's
/// `*_listed` entry points).
const LISTED_WORKGROUP: u32 = 64;

/// How many bricks of `data_brick` voxels one partial build of `pyramid` may list: at most
/// [`MAX_LISTED`], and no more than one dispatch's 65 535 workgroups hold at level 0.
fn listed_limit(pyramid: &Pyramid, data_brick: u32) -> usize {
    if data_brick == 0 {
        return 0;
    }
    let per_brick = box_edge(pyramid.levels[0].brick_vox, data_brick).pow(3);
    MAX_LISTED.min(65_535 * LISTED_WORKGROUP as usize / per_brick as usize)
}

fn entry(binding: u32, resource: wgpu::BindingResource<'_>) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource }
}

fn groups_for(count: u32, per_group: u32) -> (u32, u32) {
    let groups = count.div_ceil(per_group).max(1);
    let max = MAX_WORKGROUPS_PER_DIMENSION;
    if groups <= max {
        (groups, 1)
    } else {
        (max, groups.div_ceil(max))
    }
}

/// Dispatches one invocation per node of a level of `nodes` (the 3D builders' workgroups).
pub(super) fn dispatch_over_nodes(pass: &mut wgpu::ComputePass<'_>, nodes: [u32; 3]) {
    let [x, y, z] = nodes.map(|n| n.div_ceil(BUILD_WORKGROUP));
    pass.dispatch_workgroups(x, y, z);
}

/// How one axis pass of the distance field is dispatched.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DistancePass {
    /// `distance_rows`, in these workgroups: `DISTANCE_TILE_ROWS` rows each, side by side along
    /// the first axis across the pass (x), one workgroup row per index of the other (y).
    Rows([u32; 2]),
    /// `distance_pass`, one invocation per block (rows longer than `DISTANCE_ROW_MAX`).
    Window,
}

/// The pass along `axis` over a leaf level of `nodes`.
fn distance_pass_for(nodes: [u32; 3], axis: usize) -> DistancePass {
    if nodes[axis] > DISTANCE_ROW_MAX {
        return DistancePass::Window;
    }
    // The axes across the pass, ordered as `across_axes` in build/distance.wgsl orders them.
    let (side_by_side, other) = match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    DistancePass::Rows([
        nodes[side_by_side].div_ceil(DISTANCE_TILE_ROWS),
        nodes[other],
    ])
}

/// What makes a node empty, and the inputs that rule depends on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FlagRule {
    /// DVR: the transfer function is zero over the node's values (generation of the function).
    Transfer(u64),
    /// X-ray: no value above the window's low end (normalised, as f32 bits).
    AtMost(u32),
    /// Isosurfaces with the distance field: every value on one side of the iso value
    /// (normalised, as f32 bits); two bits per node (`RULE_ISO`).
    Iso(u32),
}

/// What node flags were built for: their rule and, where a view cuts the image to the shown
/// labels, which labels were shown.
pub type FlagKey = (FlagRule, Option<ShownKey>);

/// The leaping structures of one volume.
pub struct LeapStructures {
    /// Layout of the pyramid.
    pub pyramid: Pyramid,
    level_buffer: wgpu::Buffer,
    /// Per-node (min, max) of normalised values, all levels (`vec2<f32>`).
    pub minmax: wgpu::Buffer,
    /// Per-node emptiness flags (u32 0/1; two side bits under [`FlagRule::Iso`]), all levels.
    pub node_empty: wgpu::Buffer,
    /// The emptiness table, `TABLE_SIZE²` u32 (1 = empty), indexed `max_bin * TABLE_SIZE + min_bin`.
    pub table: wgpu::Buffer,
    prefix: wgpu::Buffer,
    /// Two-sided distance field over the leaf level (u32 per block, `accel::distance::sides`),
    /// and its ping-pong partner.
    pub distance: [wgpu::Buffer; 2],
    level_params: Vec<wgpu::Buffer>,
    emptiness_params: wgpu::Buffer,
    distance_params: [wgpu::Buffer; 3],
    /// Whether the pyramid has been built.
    minmax_ready: bool,
    /// Level-0 bricks of a bricked volume whose pages changed since the pyramid was built:
    /// only the nodes that read them are built again.
    listed: Vec<[u32; 3]>,
    /// The list as the partial build reads it (count, then the bricks), where bricked.
    listed_buffer: Option<wgpu::Buffer>,
    /// Bricks a partial build may list (the dispatch's limit).
    listed_max: usize,
    /// Edge of the volume's bricks in voxels (0: one texture).
    data_brick: u32,
    /// What the node flags were built for, if anything.
    pub flags_for: Option<FlagKey>,
    /// The flags and leaf level the distance field was built for, if anything.
    pub distance_for: Option<(FlagKey, u32)>,
    /// Which nodes hold a shown label (views that cut the image to the shown labels).
    labels: LabelFlags,
}

impl LeapStructures {
    /// Allocates the structures for a volume of `dims` whose texels decode as
    /// `s = texel * scale + bias`, held in bricks of `data_brick` voxels (0: one texture), in at
    /// most `most` bytes where given (coarser blocks where finer would take more).
    pub fn new(
        ctx: &GpuContext,
        dims: [u32; 3],
        (texel_scale, texel_bias): (f32, f32),
        data_brick: u32,
        most: Option<u64>,
    ) -> Self {
        use wgpu::BufferUsages as U;
        let device = &ctx.device;
        let binding = ctx.largest_binding();
        let pyramid = Pyramid::within(dims, binding, most);
        let finest = pyramid.levels[0].brick_vox;
        if finest > crate::accel::pyramid::FINEST_BRICK {
            log::info!(
                "leaping blocks of at least {finest} voxels: finer ones' min/max would pass the \
                 GPU's {} MB storage binding limit",
                binding / 1_000_000
            );
        }
        let nodes = pyramid.node_count() as u64;
        let infos: Vec<LevelInfo> = pyramid
            .levels
            .iter()
            .map(|l| LevelInfo {
                nodes: l.nodes,
                offset: l.offset,
                brick_vox: l.brick_vox,
                _pad0: 0,
                _pad1: 0,
                _pad2: 0,
            })
            .collect();
        let level_buffer = buffer(
            device,
            "pyramid levels",
            std::mem::size_of_val(infos.as_slice()) as u64,
            U::STORAGE | U::COPY_DST,
        );
        ctx.queue
            .write_buffer(&level_buffer, 0, bytemuck::cast_slice(&infos));
        let leaf_max = pyramid.levels[0].count() as u64 * 4;
        let storage = U::STORAGE | U::COPY_SRC | U::COPY_DST;
        let level_params = (0..pyramid.levels.len() as u32)
            .map(|l| {
                let b = uniform_of(device, "build params", 32);
                let params = BuildParams {
                    level: l,
                    texel_scale,
                    texel_bias,
                    box_edge: box_edge(pyramid.levels[l as usize].brick_vox, data_brick),
                    data_brick,
                    _pad0: 0,
                    _pad1: 0,
                    _pad2: 0,
                };
                ctx.queue.write_buffer(&b, 0, bytemuck::bytes_of(&params));
                b
            })
            .collect();
        let emptiness_params = uniform(device, "emptiness params");
        let listed_max = listed_limit(&pyramid, data_brick);
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
            listed: Vec::new(),
            listed_buffer: (data_brick > 0).then(|| {
                buffer(
                    device,
                    "bricks to build again",
                    (MAX_LISTED as u64 + 1) * 16,
                    U::STORAGE | U::COPY_DST,
                )
            }),
            listed_max,
            data_brick,
            flags_for: None,
            distance_for: None,
            labels: LabelFlags::new(device),
        }
    }

    /// Forgets the pyramid and what was built from it: the volume's pages changed, and the
    /// pyramid is built through them.
    pub(crate) fn invalidate(&mut self) {
        self.minmax_ready = false;
        self.listed.clear();
        self.flags_for = None;
        self.distance_for = None;
    }

    /// Whether the min/max pyramid is built (else the next frame that leaps builds it whole).
    pub(crate) fn pyramid_ready(&self) -> bool {
        self.minmax_ready
    }

    /// How many more level-0 bricks' page changes a partial rebuild of the pyramid takes
    /// before it is built whole (unbounded while a whole build is due anyway).
    pub(crate) fn listing_room(&self) -> usize {
        if self.minmax_ready {
            self.listed_max.saturating_sub(self.listed.len())
        } else {
            usize::MAX
        }
    }

    /// The pages of these level-0 bricks changed (`None`: of any): the pyramid's nodes that
    /// read them are built again (all of them where the list is long), and what was built
    /// from the pyramid.
    pub(crate) fn bricks_changed(&mut self, bricks: Option<&[[u32; 3]]>) {
        match bricks {
            // The rays' pages stayed as they were (only the slices' changed).
            Some([]) => {}
            Some(b) if self.minmax_ready && self.listed.len() + b.len() <= self.listed_max => {
                self.listed.extend_from_slice(b);
                self.flags_for = None;
                self.distance_for = None;
            }
            _ => self.invalidate(),
        }
    }

    /// Whether [`Self::build_minmax`] will record a build.
    fn minmax_pending(&self) -> bool {
        !self.minmax_ready || (self.listed_buffer.is_some() && !self.listed.is_empty())
    }

    /// Records the pyramid build (once per volume, then of the nodes that read bricks whose
    /// pages changed); returns whether it recorded one of each.
    fn build_minmax(
        &mut self,
        ctx: &GpuContext,
        pipelines: &LeapPipelines,
        volume: &VolumeView,
        encoder: &mut wgpu::CommandEncoder,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) -> (bool, bool) {
        if !self.minmax_ready {
            self.listed.clear();
            self.record_levels(ctx, pipelines, volume, encoder, None, timestamps);
            self.minmax_ready = true;
            return (true, false);
        }
        let Some(list) = self
            .listed_buffer
            .as_ref()
            .filter(|_| !self.listed.is_empty())
        else {
            return (false, false);
        };
        let mut words: Vec<[u32; 4]> = vec![[self.listed.len() as u32, 0, 0, 0]];
        words.extend(self.listed.drain(..).map(|[x, y, z]| [x, y, z, 0]));
        ctx.queue
            .write_buffer(list, 0, bytemuck::cast_slice(&words));
        let bricks = words.len() as u32 - 1;
        self.record_levels(ctx, pipelines, volume, encoder, Some(bricks), timestamps);
        (false, true)
    }

    /// Records the build of every level, bottom up: all its nodes, or (`listed`: that many
    /// bricks in the list buffer) the nodes that read a voxel of a listed brick.
    fn record_levels(
        &self,
        ctx: &GpuContext,
        pipelines: &LeapPipelines,
        volume: &VolumeView,
        encoder: &mut wgpu::CommandEncoder,
        listed: Option<u32>,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let list = self.listed_buffer.as_ref().filter(|_| listed.is_some());
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(match list {
                Some(_) => "min/max pyramid (bricks that arrived)",
                None => "min/max pyramid",
            }),
            timestamp_writes: timestamps,
        });
        let which = usize::from(list.is_some());
        for (l, level) in self.pyramid.levels.iter().enumerate() {
            let pipeline = match l {
                0 => &pipelines.base.pick(volume)[which],
                _ => [&pipelines.parent, &pipelines.parent_listed][which],
            };
            let mut entries = vec![
                entry(0, self.level_params[l].as_entire_binding()),
                entry(1, self.level_buffer.as_entire_binding()),
                entry(2, self.minmax.as_entire_binding()),
            ];
            if l == 0 {
                entries.extend(volume.entries([3, 4, 5]));
            }
            if let Some(list) = list {
                entries.push(entry(6, list.as_entire_binding()));
            }
            let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("min/max build"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &group, &[]);
            match listed {
                Some(bricks) => {
                    let nodes = bricks * box_edge(level.brick_vox, self.data_brick).pow(3);
                    pass.dispatch_workgroups(nodes.div_ceil(LISTED_WORKGROUP), 1, 1);
                }
                None => dispatch_over_nodes(&mut pass, level.nodes),
            }
        }
    }

    /// Records the rebuild of the emptiness table and node flags from the lookup table (after
    /// every transfer-function change), timed with `timestamps` when given.
    fn build_flags(
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
            FlagRule::Transfer(_) => (RULE_TRANSFER, 0.0),
            FlagRule::AtMost(bits) => (RULE_AT_MOST, f32::from_bits(bits)),
            FlagRule::Iso(bits) => (RULE_ISO, f32::from_bits(bits)),
        };
        let params = EmptinessParams {
            lut_size,
            node_count: nodes,
            rule: rule_code,
            threshold,
        };
        ctx.queue
            .write_buffer(&self.emptiness_params, 0, bytemuck::bytes_of(&params));
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
        let flags = entries_for(&pipelines.flags, &[0, 3, 4, 5]);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("emptiness"),
            timestamp_writes: timestamps,
        });
        // The emptiness table only where the rule reads it: the X-ray window and the iso value
        // test each node's min/max directly.
        if rule_code == RULE_TRANSFER {
            let scan = entries_for(&pipelines.scan, &[0, 1, 2]);
            let table = entries_for(&pipelines.table, &[0, 2, 3]);
            pass.set_pipeline(&pipelines.scan);
            pass.set_bind_group(0, &scan, &[]);
            pass.dispatch_workgroups(1, 1, 1);
            pass.set_pipeline(&pipelines.table);
            pass.set_bind_group(0, &table, &[]);
            let t = (TABLE_SIZE as u32).div_ceil(TABLE_WORKGROUP);
            pass.dispatch_workgroups(t, t, 1);
        }
        pass.set_pipeline(&pipelines.flags);
        pass.set_bind_group(0, &flags, &[]);
        let (gx, gy) = groups_for(nodes, NODE_WORKGROUP);
        pass.dispatch_workgroups(gx, gy, 1);
    }

    /// Records the distance-field build over leaf level `leaf` (three 1D passes ending in
    /// `distance[0]`).
    fn build_distance(
        &mut self,
        ctx: &GpuContext,
        pipelines: &LeapPipelines,
        leaf: u32,
        encoder: &mut wgpu::CommandEncoder,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let device = &ctx.device;
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
                bytemuck::bytes_of(&DistanceParams {
                    leaf_level: leaf,
                    axis,
                    sides: match self.flags_for {
                        Some((FlagRule::Iso(_), _)) => SIDES_ISO,
                        _ => SIDES_EMPTY_FULL,
                    },
                    _pad1: 0,
                }),
            );
            let (src, dst) = if axis == 1 { (1, 0) } else { (0, 1) };
            let how = distance_pass_for(level.nodes, axis as usize);
            let pipeline = match how {
                DistancePass::Rows(_) => &pipelines.distance_rows,
                DistancePass::Window => &pipelines.distance,
            };
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("distance pass"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &[
                    entry(0, self.distance_params[axis as usize].as_entire_binding()),
                    entry(1, self.level_buffer.as_entire_binding()),
                    entry(2, self.node_empty.as_entire_binding()),
                    entry(3, self.distance[src].as_entire_binding()),
                    entry(4, self.distance[dst].as_entire_binding()),
                ],
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &group, &[]);
            match how {
                DistancePass::Rows([x, y]) => pass.dispatch_workgroups(x, y, 1),
                DistancePass::Window => dispatch_over_nodes(&mut pass, level.nodes),
            }
        }
        drop(pass);
        encoder.copy_buffer_to_buffer(
            &self.distance[1],
            0,
            &self.distance[0],
            0,
            level.count() as u64 * 4,
        );
        self.distance_for = self.flags_for.map(|key| (key, leaf));
    }

    /// What the ray loop's bind group (group 3) binds.
    pub(crate) fn resources(&self) -> LeapResources<'_> {
        LeapResources {
            levels: &self.level_buffer,
            node_empty: &self.node_empty,
            distance: &self.distance[0],
            minmax: &self.minmax,
            node_shown: &self.labels.node_shown,
        }
    }

    /// Number of pyramid levels.
    pub(crate) fn level_count(&self) -> u32 {
        self.pyramid.levels.len() as u32
    }
}

/// What a leaping frame asks of [`LeapStructures::prepare`].
pub struct LeapRequest<'a> {
    /// The frame's settings (mode, strategy, block size).
    pub settings: &'a RenderSettings,
    /// Generation of the transfer function the lookup table holds.
    pub transfer_generation: u64,
    /// The lookup table (the emptiness table is built from it).
    pub lut: &'a TableTexture,
    /// The window's low end, normalised (X-ray leaps over what lies below it).
    pub window_lo: f32,
    /// The iso value, normalised (isosurfaces with the distance field leap by it).
    pub iso_threshold: f32,
    /// The volume (the pyramid is built from it).
    pub volume: &'a VolumeView,
    /// The segmentation whose shown labels decide which nodes matter, and how (the image cut to
    /// them, or their surfaces drawn), if the frame's view does either.
    pub labels: Option<(&'a GpuLabels, LabelUse)>,
}

/// Which structures one [`LeapStructures::prepare`] recorded a build of.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Builds {
    /// The min/max pyramid (once per volume).
    pub minmax: bool,
    /// The pyramid's nodes that read bricks whose pages changed.
    pub minmax_bricks: bool,
    /// The emptiness table and node flags.
    pub flags: bool,
    /// The distance field.
    pub distance: bool,
    /// Which nodes hold a shown label (the shown labels changed).
    pub labels: bool,
    /// Whether group 3's buffers were made anew (its bind group must be made again).
    pub regrouped: bool,
}

impl LeapStructures {
    /// Records whatever the structures still need for this frame and returns the levels the ray
    /// loop uses: the pyramid once per volume; node flags when the rule they follow changed
    /// (DVR: the transfer function; X-ray with the distance field: the window; isosurfaces with
    /// it: the iso value); the distance field when its flags or the block size changed. MIP,
    /// MinIP, octree isosurfaces and octree X-ray read the min/max pyramid directly. The rebuild
    /// (every pass recorded here, the pyramid's included) is timed into `probe` when given.
    pub(crate) fn prepare(
        &mut self,
        ctx: &GpuContext,
        pipelines: &LeapPipelines,
        request: &LeapRequest<'_>,
        encoder: &mut wgpu::CommandEncoder,
        mut probe: Option<(&mut ProbePool, &ProbeSlot)>,
    ) -> (LeapLevels, Builds) {
        let settings = request.settings;
        // validate() admitted only sizes the pyramid has.
        let leaf = self
            .pyramid
            .level_of_block(settings.leaf_block_vox())
            .unwrap_or(0) as u32;
        let levels = LeapLevels {
            leaf_level: leaf,
            level_count: self.level_count(),
        };
        let distance = settings.strategy.untimed(settings.mode) == Strategy::RcSDistance;
        let rule = match settings.mode {
            Mode::Dvr => Some(FlagRule::Transfer(request.transfer_generation)),
            Mode::Xray | Mode::XrayAttenuation if distance => {
                Some(FlagRule::AtMost(request.window_lo.to_bits()))
            }
            Mode::Iso if distance => Some(FlagRule::Iso(request.iso_threshold.to_bits())),
            _ => None,
        };
        // Views cut to the shown labels: the flags mark nodes without one empty (isosurfaces
        // never cut by node: their crossings are cut one by one). Views drawing their surfaces:
        // nodes near one are not empty.
        let labelled = request.labels;
        let key = rule.map(|r| {
            let folds = |&(_, u): &(&GpuLabels, LabelUse)| {
                matches!(u, LabelUse::Surfaces(_)) || !matches!(r, FlagRule::Iso(_))
            };
            (r, labelled.filter(folds).map(|(l, u)| shown_key(l, u)))
        });
        let shown = labelled.filter(|&(l, u)| !self.labels.holds(shown_key(l, u)));
        let flags = key.is_some_and(|k| self.flags_for != Some(k));
        let builds_distance =
            key.is_some_and(|k| distance && (flags || self.distance_for != Some((k, leaf))));
        // One span times every pass recorded here: its first begins it, its last ends it.
        let passes = [
            self.minmax_pending(),
            shown.is_some(),
            flags,
            builds_distance,
        ];
        let (first, last) = (
            passes.iter().position(|&p| p),
            passes.iter().rposition(|&p| p),
        );
        let ends = |pass: usize| (first == Some(pass), last == Some(pass));
        let ts = if passes[0] {
            rebuild_span(&mut probe, ends(0))
        } else {
            None
        };
        let (minmax, minmax_bricks) =
            self.build_minmax(ctx, pipelines, request.volume, encoder, ts);
        let mut regrouped = false;
        if let Some(labels) = shown {
            let ts = rebuild_span(&mut probe, ends(1));
            let pyramid = (&self.pyramid, &self.level_buffer);
            regrouped = (self.labels).build(ctx, &pipelines.labels, pyramid, labels, encoder, ts);
        }
        let builds = Builds {
            minmax,
            minmax_bricks,
            flags,
            distance: builds_distance,
            labels: shown.is_some(),
            regrouped,
        };
        let Some((rule, cut_key)) = key else {
            return (levels, builds);
        };
        if flags {
            let ts = rebuild_span(&mut probe, ends(2));
            self.build_flags(ctx, pipelines, rule, request.lut, encoder, ts);
            if let Some((_, _, use_)) = cut_key {
                let pyramid = (&self.pyramid, &self.level_buffer);
                let empty = (&self.node_empty, use_);
                (self.labels).fold(ctx, &pipelines.labels, pyramid, empty, encoder);
            }
            self.flags_for = Some((rule, cut_key));
        }
        if builds_distance {
            let ts = rebuild_span(&mut probe, ends(3));
            self.build_distance(ctx, pipelines, leaf, encoder, ts);
        }
        (levels, builds)
    }
}

/// The timestamp writes of one pass of the rebuild's span (`(first, last)`: whether it begins
/// or ends it), where a probe times the frame.
fn rebuild_span<'p>(
    probe: &'p mut Option<(&mut ProbePool, &ProbeSlot)>,
    (first, last): (bool, bool),
) -> Option<wgpu::ComputePassTimestampWrites<'p>> {
    probe
        .as_mut()
        .and_then(|(p, s)| p.rebuild_timestamps(s, first, last))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_up_to_the_tile_take_the_tiled_pass_in_workgroups_covering_every_row() {
        let nodes = [128, 37, 5];
        assert_eq!(distance_pass_for(nodes, 0), DistancePass::Rows([5, 5]));
        assert_eq!(distance_pass_for(nodes, 1), DistancePass::Rows([16, 5]));
        assert_eq!(distance_pass_for(nodes, 2), DistancePass::Rows([16, 37]));
        // Every row covered once: tiles × rows per tile reach the rows across, and no tile more.
        for axis in 0..3 {
            let DistancePass::Rows([x, y]) = distance_pass_for(nodes, axis) else {
                panic!("axis {axis}: a short row takes the tiled pass");
            };
            let across: Vec<u32> = (0..3).filter(|&a| a != axis).map(|a| nodes[a]).collect();
            assert!(x * DISTANCE_TILE_ROWS >= across[0]);
            assert!((x - 1) * DISTANCE_TILE_ROWS < across[0]);
            assert_eq!(y, across[1]);
        }
    }

    #[test]
    fn rows_longer_than_the_tile_take_the_windowed_pass() {
        let edge = DISTANCE_ROW_MAX;
        assert!(matches!(
            distance_pass_for([edge, 2, 2], 0),
            DistancePass::Rows(_)
        ));
        assert_eq!(distance_pass_for([edge + 1, 2, 2], 0), DistancePass::Window);
        assert_eq!(distance_pass_for([2, 2, edge + 1], 2), DistancePass::Window);
        assert!(matches!(
            distance_pass_for([2, 2, edge + 1], 0),
            DistancePass::Rows(_)
        ));
    }
}
