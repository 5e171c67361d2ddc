//! Leaping over hidden labels: one flag per pyramid node, whether it holds a shown label
//! (`shaders/build/labels.wgsl`), built from a segmentation's cell lists and visibility bits
//! ([`GpuLabels`]) when the shown labels change; and, for the flag rules that read `node_empty`,
//! the nodes without a shown label marked empty after the flag pass. Views that cut the image to
//! the shown labels leap over the rest; nothing is built for views that do not.

use crate::accel::pyramid::Pyramid;
use crate::render::context::GpuContext;
use crate::render::gpu_data::LabelParams;
use crate::render::labels::GpuLabels;
use crate::render::shader::{ShaderError, compose, compute_pipeline, shader_module};

use super::leap::dispatch_over_nodes;

/// The builders, created once per renderer.
pub struct LabelFlagPipelines {
    base: wgpu::ComputePipeline,
    parent: wgpu::ComputePipeline,
    cut: wgpu::ComputePipeline,
    keep: wgpu::ComputePipeline,
}

impl LabelFlagPipelines {
    /// Compiles the builders.
    pub fn new(device: &wgpu::Device) -> Result<Self, ShaderError> {
        let name = "build/labels.wgsl";
        let module = shader_module(device, name, compose(name, &[])?);
        Ok(Self {
            base: compute_pipeline(device, &module, "shown_base"),
            parent: compute_pipeline(device, &module, "shown_parent"),
            cut: compute_pipeline(device, &module, "cut_flags"),
            keep: compute_pipeline(device, &module, "keep_flags"),
        })
    }
}

/// What a view does with the nodes of the shown labels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LabelUse {
    /// The image is cut to the shown labels: nodes without one are empty. The cells around a
    /// node whose labels count as its own besides: where labels travel in bricks held at a
    /// coarser level, a sample reads a label of its block of that level
    /// ([`coarse_reach`]).
    Cut(u32),
    /// The shown labels are drawn as surfaces: nodes near one are not empty, within this many
    /// cells ([`surface_reach`]).
    Surfaces(u32),
}

impl LabelUse {
    /// Cells around a level-0 node whose labels count as its own.
    fn apron(self) -> u32 {
        match self {
            Self::Cut(reach) | Self::Surfaces(reach) => reach,
        }
    }
}

/// Cells past a shown voxel that its surface's mask reaches where the mask lies on the labels'
/// grid reduced `factor`-fold: the kernel's radius and the trilinear filter's voxel, each of
/// `factor` voxels, from a reduced voxel reaching `factor` − 1 voxels past the shown one; at
/// factor 1 one cell (three voxels of kernel and one of filter).
pub fn surface_reach(factor: u32) -> u32 {
    let voxels = factor * (crate::labels::surface::MOST_RADIUS + 1) + factor - 1;
    voxels.div_ceil(crate::accel::label_cells::CELL_VOX)
}

/// Cells of [`CELL_VOX`](crate::accel::label_cells::CELL_VOX) voxels past its own that a
/// sample's label may come from where the labels are read at level `level`: a coarse voxel
/// holds a label of the aligned block of 2^level finest voxels it covers
/// ([`crate::labels::levels`]), which reaches into the blocks' other cells.
pub fn coarse_reach(level: u32) -> u32 {
    let cell = crate::accel::label_cells::CELL_VOX;
    let block = 1u32 << level.min(16);
    block.div_ceil(cell) - 1
}

/// Which segmentation, at which visibility, flags were built for, and for what: its address
/// (the same `GpuLabels` while it lives), its generation and the view's use of them.
pub type ShownKey = (usize, u64, LabelUse);

/// The key of `labels` as it is now, used as `use_` says.
pub fn shown_key(labels: &GpuLabels, use_: LabelUse) -> ShownKey {
    (
        std::ptr::from_ref(labels) as usize,
        labels.generation(),
        use_,
    )
}

/// The per-node flags of one volume's pyramid.
pub struct LabelFlags {
    /// 1 where the node holds a shown label (a 4-byte stand-in until a cut view needs them).
    pub node_shown: wgpu::Buffer,
    /// One parameter block per level, made with the flags.
    params: Vec<wgpu::Buffer>,
    /// The apron the parameter blocks hold.
    params_apron: Option<u32>,
    /// What the flags hold.
    pub built_for: Option<ShownKey>,
}

impl LabelFlags {
    /// A stand-in: nothing built.
    pub fn new(device: &wgpu::Device) -> Self {
        Self {
            node_shown: node_buffer(device, 1),
            params: Vec::new(),
            params_apron: None,
            built_for: None,
        }
    }

    /// Whether the flags hold `key` (else [`Self::build`] records their build).
    pub fn holds(&self, key: ShownKey) -> bool {
        self.built_for == Some(key)
    }

    /// Records the flags' build for `labels` used as `use_` over `pyramid` (whose levels are
    /// in `levels`); returns whether the flag buffer was made anew (its bind groups must be made
    /// again).
    #[allow(clippy::too_many_arguments)]
    pub fn build(
        &mut self,
        ctx: &GpuContext,
        pipelines: &LabelFlagPipelines,
        (pyramid, levels): (&Pyramid, &wgpu::Buffer),
        (labels, use_): (&GpuLabels, LabelUse),
        encoder: &mut wgpu::CommandEncoder,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) -> bool {
        let device = &ctx.device;
        let nodes = u64::from(pyramid.node_count());
        let made = self.node_shown.size() < nodes * 4;
        if made {
            self.node_shown = node_buffer(device, nodes);
        }
        // The cells follow the volume's grid, as the levels do: written once per apron.
        if self.params.len() != pyramid.levels.len() {
            self.params = (0..pyramid.levels.len())
                .map(|_| param_buffer(device))
                .collect();
            self.params_apron = None;
        }
        if self.params_apron != Some(use_.apron()) {
            self.params_apron = Some(use_.apron());
            for (l, buffer) in self.params.iter().enumerate() {
                let params = LabelParams {
                    cells: labels.cells,
                    level: l as u32,
                    apron: use_.apron(),
                    _pad0: 0,
                    _pad1: 0,
                    _pad2: 0,
                };
                ctx.queue
                    .write_buffer(buffer, 0, bytemuck::bytes_of(&params));
            }
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("label flags"),
            timestamp_writes: timestamps,
        });
        for (l, level) in pyramid.levels.iter().enumerate() {
            let (pipeline, entries) = if l == 0 {
                let entries = vec![
                    entry(0, self.params[l].as_entire_binding()),
                    entry(1, levels.as_entire_binding()),
                    entry(2, self.node_shown.as_entire_binding()),
                    entry(3, labels.cell_offsets.as_entire_binding()),
                    entry(4, labels.cell_labels.as_entire_binding()),
                    entry(5, labels.shown_bits.as_entire_binding()),
                ];
                (&pipelines.base, entries)
            } else {
                let entries = vec![
                    entry(0, self.params[l].as_entire_binding()),
                    entry(1, levels.as_entire_binding()),
                    entry(2, self.node_shown.as_entire_binding()),
                ];
                (&pipelines.parent, entries)
            };
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("label flags"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &group, &[]);
            dispatch_over_nodes(&mut pass, level.nodes);
        }
        drop(pass);
        self.built_for = Some(shown_key(labels, use_));
        made
    }

    /// Records, after the flag pass wrote `node_empty`, the marking of every node without a
    /// shown label as empty (`Cut`) or of every node near one as not empty (`Surfaces`).
    pub fn fold(
        &self,
        ctx: &GpuContext,
        pipelines: &LabelFlagPipelines,
        (pyramid, levels): (&Pyramid, &wgpu::Buffer),
        (node_empty, use_): (&wgpu::Buffer, LabelUse),
        encoder: &mut wgpu::CommandEncoder,
    ) {
        let pipeline = match use_ {
            LabelUse::Cut(_) => &pipelines.cut,
            LabelUse::Surfaces(_) => &pipelines.keep,
        };
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("cut to the shown labels"),
            timestamp_writes: None,
        });
        for (l, level) in pyramid.levels.iter().enumerate() {
            let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("cut to the shown labels"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &[
                    entry(0, self.params[l].as_entire_binding()),
                    entry(1, levels.as_entire_binding()),
                    entry(2, self.node_shown.as_entire_binding()),
                    entry(6, node_empty.as_entire_binding()),
                ],
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &group, &[]);
            dispatch_over_nodes(&mut pass, level.nodes);
        }
    }
}

fn entry(binding: u32, resource: wgpu::BindingResource<'_>) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource }
}

fn node_buffer(device: &wgpu::Device, nodes: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("node holds a shown label"),
        size: nodes * 4,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

fn param_buffer(device: &wgpu::Device) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("label flag params"),
        size: std::mem::size_of::<LabelParams>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reach covers the reduced mask's kernel and filter, and no cell more: one cell at
    /// factor 1 (three voxels of kernel, one of filter), three at factor 2.
    #[test]
    fn a_reduced_masks_reach_covers_its_kernel_and_filter() {
        use crate::accel::label_cells::CELL_VOX;
        use crate::labels::surface::MOST_RADIUS;
        assert_eq!((surface_reach(1), surface_reach(2)), (1, 3));
        for factor in [1, 2, 4, 8, 16] {
            let voxels = factor * (MOST_RADIUS + 1) + factor - 1;
            let reach = surface_reach(factor);
            assert!(reach * CELL_VOX >= voxels && (reach - 1) * CELL_VOX < voxels);
        }
    }
    use crate::accel::label_cells::CELL_VOX;

    /// A coarse voxel's block of the finest level reaches this many cells past any of its own
    /// voxels' cells: brute force over every voxel of blocks of levels 0 to 6.
    #[test]
    fn the_coarse_reach_covers_every_cell_a_voxels_block_touches() {
        for level in 0..=6u32 {
            let block = 1u32 << level;
            let farthest = (0..4 * block)
                .map(|v| {
                    let first = v / block * block;
                    let cells = [first / CELL_VOX, (first + block - 1) / CELL_VOX];
                    let own = v / CELL_VOX;
                    (own - cells[0]).max(cells[1] - own)
                })
                .max()
                .unwrap_or(0);
            assert_eq!(coarse_reach(level), farthest, "level {level}");
        }
    }
}
