//! Labels as surfaces on the GPU: the smoothed mask of the shown labels
//! ([`crate::labels::surface`] is its CPU twin), a 3D texture on the labels' grid that the ray
//! loop samples trilinearly (`shaders/shared/label_surface.wgsl`), a channel per class of shown
//! labels ([`crate::labels::classes`]: neighbours in different classes, so that the wall
//! between them is where one class's channel rises): `R8Unorm`, `Rg8Unorm` or `Rgba8Unorm` for
//! 1, 2 or 3-4 classes, and a table of each label value's class. Built by
//! `shaders/build/label_surface.wgsl` in three passes, one per axis, through one buffer of at
//! most [`MOST_SLAB_BYTES`]: each pass covers the grid in slabs and copies each into the texture.
//! Built again only when the shown labels or the smoothing change.

use wgpu::util::DeviceExt;

use crate::accel::label_cells::VoxelBox;
use crate::labels::classes::Classes;
use crate::labels::surface::{occupancy, reduced_grid, smoothing_kernel};
use crate::render::context::GpuContext;
use crate::render::gpu_data::SurfaceParams;
use crate::render::labels::{GpuLabels, TABLE_EDGE, table_texture};
use crate::render::probe::{ProbePool, ProbeSlot};
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

/// The slabs (axis, first voxel, extent) covering `regions[axis]` for each axis's pass: the x
/// and y passes in slabs of `slices` whole slices (z), the z pass in slabs of `rows` whole rows
/// (y), so that no pass reads what it replaces.
fn slabs(regions: [VoxelBox; 3], [slices, rows]: [u32; 2]) -> Vec<(usize, [u32; 3], [u32; 3])> {
    let mut out = Vec::new();
    for (axis, r) in regions.into_iter().enumerate() {
        let (along, step) = if axis < 2 { (2, slices) } else { (1, rows) };
        let mut start = r.first[along];
        while start < r.end[along] {
            let mut origin = r.first;
            let mut extent: [u32; 3] = std::array::from_fn(|a| r.end[a] - r.first[a]);
            origin[along] = start;
            extent[along] = step.min(r.end[along] - start);
            out.push((axis, origin, extent));
            start += step;
        }
    }
    out
}

/// `b` widened by `reach` voxels along `axes`, within the grid `dims`.
fn widened(b: VoxelBox, reach: u32, axes: &[usize], dims: [u32; 3]) -> VoxelBox {
    let mut w = b;
    for &a in axes {
        w.first[a] = b.first[a].saturating_sub(reach);
        w.end[a] = (b.end[a] + reach).min(dims[a]);
    }
    w
}

/// What each pass of a build of the mask over `out` covers: the x pass `out` widened by the
/// kernel's `radius` along y and z (all the y and z passes read), the y pass `out` widened
/// along z, the z pass `out`.
fn pass_regions(out: VoxelBox, radius: u32, dims: [u32; 3]) -> [VoxelBox; 3] {
    [
        widened(out, radius, &[1, 2], dims),
        widened(out, radius, &[2], dims),
        out,
    ]
}

fn voxels(b: VoxelBox) -> u64 {
    (0..3).map(|a| u64::from(b.end[a] - b.first[a])).product()
}

/// Each label value's code in the mask: its class + 1 where shown, else 0.
fn class_codes(classes: &Classes) -> Vec<u8> {
    (0..(TABLE_EDGE * TABLE_EDGE) as usize)
        .map(|v| {
            let class = classes.class.get(v).copied().flatten();
            class.map_or(0, |c| c.saturating_add(1))
        })
        .collect()
}

/// The box of voxels holding every label whose code differs between `before` and `now` (the
/// voxels whose indicators changed); `None` where none of them lies in the grid.
fn changed_box(labels: &GpuLabels, before: &[u8], now: &[u8]) -> Option<VoxelBox> {
    let changed = (before.iter().zip(now).enumerate()).filter(|(_, (b, n))| b != n);
    changed
        .filter_map(|(v, _)| labels.label_box(v as u16))
        .reduce(|a, b| VoxelBox {
            first: std::array::from_fn(|i| a.first[i].min(b.first[i])),
            end: std::array::from_fn(|i| a.end[i].max(b.end[i])),
        })
}

/// How a build covers the grid.
enum Extent {
    /// The mask holds the labels as shown already.
    Nothing,
    /// The whole grid, through the mask itself.
    Whole,
    /// The mask over a region (the z pass's), the passes before it through a scratch texture of
    /// the x pass's region; first the box whose voxels changed, then each pass's region.
    Region(VoxelBox, [VoxelBox; 3]),
}

/// What the mask's first pass smooths.
enum First<'a> {
    /// The labels' texture and each label value's colour (its alpha: shown).
    Labels(&'a wgpu::TextureView, &'a wgpu::TextureView),
    /// Each class's occupancy (its texture, its view), written from the labels on the CPU.
    Occupancy(
        &'a wgpu::Texture,
        &'a wgpu::TextureView,
        &'a std::sync::Arc<crate::labels::LabelMap>,
    ),
}

/// A region's build reaching past this share of the grid makes the whole mask instead (its
/// scratch texture would take as much memory as the mask).
const MOST_REGION_SHARE: u64 = 2;

/// The channels of a mask for `used` classes (there is no three-channel format).
pub(crate) fn channels_for(used: usize) -> u32 {
    match used {
        0 | 1 => 1,
        2 => 2,
        _ => 4,
    }
}

/// What the label surfaces' mask holds and costs ([`crate::render::VolumeRenderer::label_surface_facts`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceFacts {
    /// Bytes on the GPU: the mask, its class table and its build's buffer.
    pub bytes: u64,
    /// The mask's channels (classes).
    pub channels: u32,
    /// Touching shown labels that share a class (no wall between them).
    pub clashes: usize,
    /// The share of the grid its last build made again (1: whole; less after a toggle).
    pub last_build_share: f64,
    /// How many times the labels' grid is reduced on each axis to the mask's (1 but for labels
    /// in bricks past one texture), and the mask's grid.
    pub grid: (u32, [u32; 3]),
}

/// The smoothed mask of one segmentation's shown labels.
pub struct SurfaceMask {
    texture: wgpu::Texture,
    /// The mask, sampled by the ray loop.
    pub(crate) view: wgpu::TextureView,
    /// Each label value's class (its channel) at texel (value % 256, value / 256).
    class_texture: wgpu::Texture,
    /// [`Self::class_texture`]'s view, read by the build and the ray loop.
    pub(crate) classes: wgpu::TextureView,
    /// Channels of the mask: 1, 2 or 4.
    channels: u32,
    format: wgpu::TextureFormat,
    buffer: wgpu::Buffer,
    row_words: u32,
    /// The whole mask's passes.
    passes: Vec<SlabPass>,
    /// Slices per slab of the x and y passes, rows per slab of the z pass.
    steps: [u32; 2],
    /// Each label value's code ([`class_codes`]) the mask was last built for; empty before.
    codes: Vec<u8>,
    /// Voxels the last build made again (the whole grid, or a toggle's region).
    last_voxels: u64,
    /// Where the labels travel in the volume's bricks (no texture of them to read), each
    /// class's occupancy of the mask's grid, written on the CPU ([`occupancy`]): what the first
    /// pass smooths there.
    occupancy: Option<(wgpu::Texture, wgpu::TextureView)>,
    /// The labels' grid reduced this many times on each axis to the mask's (1 but for labels
    /// in bricks past the GPU's 3D textures).
    factor: u32,
    /// The labels' grid.
    full_dims: [u32; 3],
    dims: [u32; 3],
    layers: u32,
    built_for: Option<MaskKey>,
    /// The smoothing the parameter blocks hold.
    params_for: Option<u32>,
}

impl SurfaceMask {
    /// The texture and buffers of a mask of `channels` (1, 2 or 4) on the grid of `labels`
    /// (built by [`Self::build`]).
    pub fn new(ctx: &GpuContext, labels: &GpuLabels, channels: u32) -> Self {
        let most = MOST_SLAB_BYTES
            .min(ctx.limits.max_storage_buffer_binding_size)
            .min(ctx.limits.max_buffer_size);
        let limit = ctx.limits.max_texture_dimension_3d;
        let side = labels.surface_side().map_or(limit, |s| s.min(limit));
        Self::with_slabs_of(ctx, labels, channels, (most, side))
    }

    /// [`Self::new`] building through slabs of at most `most` bytes, on a grid of at most
    /// `side` voxels an axis where the labels travel in bricks.
    fn with_slabs_of(
        ctx: &GpuContext,
        labels: &GpuLabels,
        channels: u32,
        (most, side): (u64, u32),
    ) -> Self {
        let device = &ctx.device;
        let full_dims = labels.dims();
        // Labels in bricks have no texture of their grid: the mask lies on the grid reduced
        // until it fits one, from the classes' occupancy.
        let (factor, dims) = match labels.whole() {
            Some(_) => (1, full_dims),
            None => reduced_grid(full_dims, side),
        };
        let format = match channels {
            1 => wgpu::TextureFormat::R8Unorm,
            2 => wgpu::TextureFormat::Rg8Unorm,
            _ => wgpu::TextureFormat::Rgba8Unorm,
        };
        let class_texture = table_texture(device, wgpu::TextureFormat::R8Uint, "label classes");
        let grid_texture = |label| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: dims[0],
                    height: dims[1],
                    depth_or_array_layers: dims[2],
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D3,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_DST
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        };
        let texture = grid_texture("label surface mask");
        let occupancy = labels.whole().is_none().then(|| {
            let t = grid_texture("label occupancy");
            let view = full_view(&t);
            (t, view)
        });
        let row_bytes = u64::from(dims[0] * channels).next_multiple_of(256);
        // x and y smooth slabs of whole slices (z), z slabs of whole rows (y).
        let slices = (most / (row_bytes * u64::from(dims[1]))).clamp(1, u64::from(dims[2])) as u32;
        let rows = (most / (row_bytes * u64::from(dims[2]))).clamp(1, u64::from(dims[1])) as u32;
        let grid = VoxelBox {
            first: [0; 3],
            end: dims,
        };
        let passes = slabs([grid; 3], [slices, rows])
            .into_iter()
            .map(|(axis, origin, extent)| SlabPass {
                params: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("label surface params"),
                    size: std::mem::size_of::<SurfaceParams>() as u64,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                axis,
                origin,
                extent,
            })
            .collect::<Vec<_>>();
        let slab_bytes = passes
            .iter()
            .map(|p| row_bytes * u64::from(p.extent[1]) * u64::from(p.extent[2]))
            .max()
            .unwrap_or(4);
        Self {
            view: full_view(&texture),
            texture,
            classes: full_view(&class_texture),
            class_texture,
            channels,
            format,
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("label surface slab"),
                size: slab_bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            row_words: (row_bytes / 4) as u32,
            passes,
            steps: [slices, rows],
            codes: Vec::new(),
            last_voxels: 0,
            occupancy,
            factor,
            full_dims,
            dims,
            layers: labels.layers(),
            built_for: None,
            params_for: None,
        }
    }

    /// Whether the mask is of `labels`'s grid with `channels` (else a new one is made).
    pub fn fits(&self, labels: &GpuLabels, channels: u32) -> bool {
        self.full_dims == labels.dims()
            && self.layers == labels.layers()
            && self.channels == channels
            && self.occupancy.is_some() == labels.whole().is_none()
    }

    /// Whether the mask holds `labels` as shown now at `smoothing`.
    pub fn holds(&self, labels: &GpuLabels, smoothing: f32) -> bool {
        self.built_for == Some(Self::key(labels, smoothing))
    }

    fn key(labels: &GpuLabels, smoothing: f32) -> MaskKey {
        (
            std::ptr::from_ref(labels) as usize,
            labels.generation(),
            smoothing.to_bits(),
        )
    }

    /// Box coordinates times this are the mask's: 1, or where the mask lies on the labels' grid
    /// reduced k-fold, N / (k · ceil(N / k)) per axis.
    pub fn scale(&self) -> [f32; 3] {
        std::array::from_fn(|a| self.full_dims[a] as f32 / (self.factor * self.dims[a]) as f32)
    }

    /// How many times the labels' grid is reduced on each axis to the mask's.
    pub fn factor(&self) -> u32 {
        self.factor
    }

    /// The mask's grid.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// The mask's channels (1, 2 or 4): the shader reads no others.
    pub fn channels(&self) -> u32 {
        self.channels
    }

    /// The share of the grid the last build made again (1 for a whole build).
    pub fn last_build_share(&self) -> f64 {
        let grid: u64 = self.dims.iter().map(|&d| u64::from(d)).product();
        self.last_voxels as f64 / grid.max(1) as f64
    }

    /// Bytes on the GPU: the mask (a byte a voxel and channel), the occupancy where the labels
    /// travel in bricks, the class table and the build's buffer.
    pub fn gpu_bytes(&self) -> u64 {
        let voxels: u64 = self.dims.iter().map(|&d| u64::from(d)).product();
        // The occupancy, where labels in bricks have it, is a second grid of the mask's size.
        let grids = 1 + u64::from(self.occupancy.is_some());
        grids * voxels * u64::from(self.channels)
            + u64::from(TABLE_EDGE * TABLE_EDGE)
            + self.buffer.size()
    }

    /// Records the mask's build for `labels` as shown now, in `classes` (of at most
    /// [`Self::channels`]), at `smoothing` (voxels), unless it holds that already; returns
    /// whether it recorded one. After a toggle only the box of the labels whose class or
    /// visibility changed is made again (with the kernel's reach), unless it reaches past half
    /// the grid. Timed into `probe` where given. Labels that travel in the volume's bricks are
    /// read on the CPU: each class's occupancy of the mask's grid over the changed box is
    /// written first, and the first pass smooths that.
    pub fn build(
        &mut self,
        ctx: &GpuContext,
        pipelines: &SurfacePipelines,
        (labels, classes): (&GpuLabels, &Classes),
        smoothing: f32,
        encoder: &mut wgpu::CommandEncoder,
        probe: Option<(&mut ProbePool, &ProbeSlot)>,
    ) -> bool {
        let key = Self::key(labels, smoothing);
        let source = match (labels.whole(), &self.occupancy, labels.brick_source()) {
            (Some(texels), _, _) => First::Labels(texels, &labels.colours),
            (None, Some((texture, view)), Some(map)) => First::Occupancy(texture, view, map),
            _ => return false,
        };
        if self.built_for == Some(key) {
            return false;
        }
        let codes = class_codes(classes);
        let (weights, radius) = smoothing_kernel(smoothing);
        let extent = self.extent_for(labels, key, &codes, radius);
        self.built_for = Some(key);
        if matches!(extent, Extent::Nothing) {
            self.codes = codes;
            return false;
        }
        let table: Vec<u8> = (0..(TABLE_EDGE * TABLE_EDGE) as usize)
            .map(|v| classes.class.get(v).copied().flatten().unwrap_or(0))
            .collect();
        ctx.queue.write_texture(
            self.class_texture.as_image_copy(),
            &table,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(TABLE_EDGE),
                rows_per_image: Some(TABLE_EDGE),
            },
            self.class_texture.size(),
        );
        let written = match extent {
            Extent::Nothing => None,
            Extent::Whole => Some(VoxelBox {
                first: [0; 3],
                end: self.dims,
            }),
            Extent::Region(changed, _) => Some(changed),
        };
        if let (First::Occupancy(texture, _, map), Some(b)) = (&source, written) {
            let bytes = occupancy(map, &codes, (self.factor, self.channels), (b.first, b.end));
            let size: [u32; 3] = std::array::from_fn(|a| b.end[a] - b.first[a]);
            ctx.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d {
                        x: b.first[0],
                        y: b.first[1],
                        z: b.first[2],
                    },
                    aspect: wgpu::TextureAspect::All,
                },
                &bytes,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(size[0] * self.channels),
                    rows_per_image: Some(size[1]),
                },
                wgpu::Extent3d {
                    width: size[0],
                    height: size[1],
                    depth_or_array_layers: size[2],
                },
            );
        }
        self.codes = codes;
        let params = |axis: usize, origin, extent, read_origin| SurfaceParams {
            dims: self.dims,
            axis: axis as u32,
            origin,
            row_words: self.row_words,
            extent,
            radius,
            weights,
            layers: self.layers,
            channels: self.channels,
            _pad1: 0,
            _pad2: 0,
            read_origin,
            _pad3: 0,
        };
        let sources = &source;
        match extent {
            Extent::Nothing => {}
            Extent::Whole => {
                self.last_voxels = self.dims.iter().map(|&d| u64::from(d)).product();
                if self.params_for != Some(key.2) {
                    for pass in &self.passes {
                        let p = params(pass.axis, pass.origin, pass.extent, [0; 3]);
                        ctx.queue
                            .write_buffer(&pass.params, 0, bytemuck::bytes_of(&p));
                    }
                    self.params_for = Some(key.2);
                }
                self.record(ctx, pipelines, sources, &self.passes, None, encoder, probe);
            }
            Extent::Region(_, regions) => {
                self.last_voxels = voxels(regions[2]);
                let scratch_box = regions[0];
                let passes: Vec<SlabPass> = slabs(regions, self.steps)
                    .into_iter()
                    .map(|(axis, origin, extent)| {
                        // The first pass reads the labels or the whole grid's occupancy.
                        let read_origin = if axis == 0 { [0; 3] } else { scratch_box.first };
                        let p = params(axis, origin, extent, read_origin);
                        SlabPass {
                            params: ctx.device.create_buffer_init(
                                &wgpu::util::BufferInitDescriptor {
                                    label: Some("label surface region params"),
                                    contents: bytemuck::bytes_of(&p),
                                    usage: wgpu::BufferUsages::UNIFORM,
                                },
                            ),
                            axis,
                            origin,
                            extent,
                        }
                    })
                    .collect();
                let scratch = self.scratch(&ctx.device, scratch_box);
                let scratch_view = full_view(&scratch);
                let at = (&scratch, &scratch_view, scratch_box.first);
                self.record(ctx, pipelines, sources, &passes, Some(at), encoder, probe);
            }
        }
        true
    }

    /// What a build for `key` with `codes` must cover.
    fn extent_for(&self, labels: &GpuLabels, key: MaskKey, codes: &[u8], radius: u32) -> Extent {
        // Another segmentation, smoothing or number of channels: all of it.
        let same = self.built_for.is_some_and(|k| (k.0, k.2) == (key.0, key.2));
        if !same || self.codes.len() != codes.len() {
            return Extent::Whole;
        }
        let Some(changed) = changed_box(labels, &self.codes, codes) else {
            return Extent::Nothing;
        };
        // On the mask's grid (the labels' reduced `factor`-fold).
        let changed = VoxelBox {
            first: changed.first.map(|v| v / self.factor),
            end: std::array::from_fn(|a| changed.end[a].div_ceil(self.factor).min(self.dims[a])),
        };
        let out = widened(changed, radius, &[0, 1, 2], self.dims);
        let regions = pass_regions(out, radius, self.dims);
        let grid: u64 = self.dims.iter().map(|&d| u64::from(d)).product();
        if voxels(regions[0]) * MOST_REGION_SHARE > grid {
            Extent::Whole
        } else {
            Extent::Region(changed, regions)
        }
    }

    /// A texture in the mask's format holding the passes before the last over `region`.
    fn scratch(&self, device: &wgpu::Device, region: VoxelBox) -> wgpu::Texture {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some("label surface scratch"),
            size: wgpu::Extent3d {
                width: region.end[0] - region.first[0],
                height: region.end[1] - region.first[1],
                depth_or_array_layers: region.end[2] - region.first[2],
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: self.format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        })
    }

    /// Records `passes`: each into the build's buffer and from it into the mask, or for the
    /// passes before the last into `scratch` (its texture, its view, the voxel it starts at)
    /// where given; timed into `probe` from the first pass to the last (the copy of its slab
    /// after it is not: wgpu writes timestamps only at passes).
    #[allow(clippy::too_many_arguments)]
    fn record(
        &self,
        ctx: &GpuContext,
        pipelines: &SurfacePipelines,
        source: &First<'_>,
        passes: &[SlabPass],
        scratch: Option<(&wgpu::Texture, &wgpu::TextureView, [u32; 3])>,
        encoder: &mut wgpu::CommandEncoder,
        mut probe: Option<(&mut ProbePool, &ProbeSlot)>,
    ) {
        for (i, pass) in passes.iter().enumerate() {
            let read = match (pass.axis, source) {
                (0, First::Occupancy(_, view, _)) => view,
                _ => scratch.map_or(&self.view, |s| s.1),
            };
            let (pipeline, entries) =
                if let (0, First::Labels(texels, colours)) = (pass.axis, source) {
                    let entries = vec![
                        entry(0, pass.params.as_entire_binding()),
                        entry(1, wgpu::BindingResource::TextureView(texels)),
                        entry(2, wgpu::BindingResource::TextureView(colours)),
                        entry(4, self.buffer.as_entire_binding()),
                        entry(5, wgpu::BindingResource::TextureView(&self.classes)),
                    ];
                    (&pipelines.from_labels, entries)
                } else {
                    let entries = vec![
                        entry(0, pass.params.as_entire_binding()),
                        entry(3, wgpu::BindingResource::TextureView(read)),
                        entry(4, self.buffer.as_entire_binding()),
                    ];
                    (&pipelines.from_mask, entries)
                };
            let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("label surface"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            });
            let (first, last) = (i == 0, i + 1 == passes.len());
            let timestamp_writes = probe
                .as_mut()
                .filter(|_| first || last)
                .and_then(|(p, s)| p.mask_timestamps(s, first, last));
            let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("label surface"),
                timestamp_writes,
            });
            cpass.set_pipeline(pipeline);
            cpass.set_bind_group(0, &group, &[]);
            let words = (pass.extent[0] * self.channels).div_ceil(4);
            cpass.dispatch_workgroups(
                words.div_ceil(GROUP[0]),
                pass.extent[1].div_ceil(GROUP[1]),
                pass.extent[2].div_ceil(GROUP[2]),
            );
            drop(cpass);
            // The passes before the last write the scratch where there is one, at its place.
            let (texture, origin) = match scratch {
                Some((t, _, first)) if pass.axis < 2 => {
                    (t, std::array::from_fn(|a| pass.origin[a] - first[a]))
                }
                _ => (&self.texture, pass.origin),
            };
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
                    texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d {
                        x: origin[0],
                        y: origin[1],
                        z: origin[2],
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

    /// The GPU's mask, read back (channels interleaved).
    fn read_mask(ctx: &GpuContext, mask: &SurfaceMask) -> Vec<u8> {
        let [w, h, d] = mask.dims;
        let bytes = w * mask.channels;
        let row = bytes.next_multiple_of(256);
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
            .flat_map(|r| r[..bytes as usize].to_vec())
            .collect()
    }

    /// Records and submits `mask`'s build for `labels` in `classes` at `sigma` (it must record
    /// one, without a validation error), and reads the mask back.
    fn build_and_read(
        ctx: &GpuContext,
        pipelines: &SurfacePipelines,
        mask: &mut SurfaceMask,
        (labels, classes): (&GpuLabels, &Classes),
        sigma: f32,
    ) -> Vec<u8> {
        let scope = ctx.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let built = mask.build(ctx, pipelines, (labels, classes), sigma, &mut encoder, None);
        assert!(built);
        ctx.queue.submit([encoder.finish()]);
        if let Some(e) = pollster::block_on(scope.pop()) {
            panic!("{e}");
        }
        read_mask(ctx, mask)
    }

    /// Each channel of the GPU's mask equals its CPU twin (the indicator of that class's shown
    /// labels, smoothed) to one step of 1/255 (their sums may round apart where the GPU fuses a
    /// multiply and an add), in a grid cut into several slabs per pass, for 1, 2 and 4 channels.
    #[test]
    fn the_gpu_mask_matches_its_cpu_twin_over_several_slabs() {
        let ctx = GpuContext::headless().expect("a GPU (lavapipe in CI)");
        let dims = [21u32, 13, 11];
        let n = (dims[0] * dims[1] * dims[2]) as usize;
        // Two layers; labels 1..=4 in touching blobs, label 3 hidden.
        let layer0: Vec<u16> = (0..n).map(|i| ((i * 7 / 13) % 5) as u16).collect();
        let layer1: Vec<u16> = (0..n).map(|i| if i % 17 < 3 { 4 } else { 0 }).collect();
        let map = LabelMap::bare(dims, vec![layer0, layer1]);
        let labels = GpuLabels::new(&ctx.device, &ctx.queue, map.clone()).unwrap();
        let mut table = vec![[0u8; 4]; 1 << 16];
        for (v, c) in table.iter_mut().enumerate().take(5).skip(1) {
            *c = [200, 100, 50, if v == 3 { 0 } else { 255 }];
        }
        labels.write_table_for_tests(&ctx.queue, &table);
        let pipelines = SurfacePipelines::new(&ctx.device).unwrap();
        let shown = (*labels.classes()).clone();
        assert!(shown.used >= 2, "{shown:?}");
        // One class for all, the labels' own classes, and each label a class of its own.
        let one = Classes {
            class: shown.class.iter().map(|c| c.map(|_| 0)).collect(),
            clashes: Vec::new(),
            used: 1,
            last: Vec::new(),
        };
        let own = Classes {
            class: (0..shown.class.len())
                .map(|v| shown.class[v].map(|_| (v % 4) as u8))
                .collect(),
            clashes: Vec::new(),
            used: 4,
            last: Vec::new(),
        };
        for classes in [one, shown, own] {
            let channels = channels_for(classes.used);
            // Slabs of 4 slices (256-byte rows × 13) and of 4 rows (× 11 slices): every pass
            // crosses slab boundaries.
            let mut mask = SurfaceMask::with_slabs_of(&ctx, &labels, channels, (256 * 13 * 4, 64));
            assert_eq!(mask.passes.len(), 3 + 3 + 4);
            let bits = map.shown_classes(&table, &classes.class);
            for sigma in [0.0, 0.7, 1.5] {
                let gpu = build_and_read(&ctx, &pipelines, &mut mask, (&labels, &classes), sigma);
                for c in 0..channels as usize {
                    let shown: Vec<bool> = bits.iter().map(|b| b >> c & 1 == 1).collect();
                    let cpu = smoothed_mask(dims, &shown, sigma);
                    let channel = gpu.iter().skip(c).step_by(channels as usize);
                    let bad: Vec<(usize, u8, u8)> = (channel.zip(&cpu).enumerate())
                        .filter(|(_, (g, c))| g.abs_diff(**c) > 1)
                        .map(|(i, (&g, &c))| (i, g, c))
                        .take(8)
                        .collect();
                    assert!(
                        bad.is_empty(),
                        "{channels} channels, sigma {sigma}, {c}: {bad:?}"
                    );
                    if shown.contains(&true) {
                        assert!(cpu.iter().any(|&c| c > 0) && cpu.iter().any(|&c| c < 128));
                    }
                }
            }
            // The same labels and smoothing: nothing to build.
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            assert!(!mask.build(
                &ctx,
                &pipelines,
                (&labels, &classes),
                1.5,
                &mut encoder,
                None
            ));
        }
    }

    /// A toggle remakes only the toggled labels' region (with the kernel's reach), through a
    /// scratch texture, and the mask it leaves equals, byte for byte, one made whole for the
    /// same labels: hiding a corner block, showing it again, hiding two blocks apart, over
    /// slabs of four slices; a toggle reaching past half the grid makes it whole.
    #[test]
    fn a_toggles_region_leaves_the_mask_a_whole_build_makes() {
        let ctx = GpuContext::headless().expect("a GPU (lavapipe in CI)");
        let dims = [40u32, 30, 30];
        // Blocks of 10 voxels, labels 1..=36, each touching its neighbours.
        let layer: Vec<u16> = (0..(40 * 30 * 30))
            .map(|i: u32| {
                let (x, y, z) = (i % 40 / 10, i / 40 % 30 / 10, i / 1200 / 10);
                (1 + x + 4 * (y + 3 * z)) as u16
            })
            .collect();
        let map = LabelMap::bare(dims, vec![layer]);
        let labels = GpuLabels::new(&ctx.device, &ctx.queue, map).unwrap();
        let pipelines = SurfacePipelines::new(&ctx.device).unwrap();
        let table_without = |hidden: &[usize]| {
            let mut table = vec![[0u8; 4]; 1 << 16];
            for (v, c) in table.iter_mut().enumerate().take(37).skip(1) {
                *c = [200, 100, 50, if hidden.contains(&v) { 0 } else { 255 }];
            }
            table
        };
        let build = |mask: &mut SurfaceMask, classes: &Classes| {
            build_and_read(&ctx, &pipelines, mask, (&labels, classes), 1.5)
        };
        labels.write_table_for_tests(&ctx.queue, &table_without(&[]));
        let classes = labels.classes();
        let channels = channels_for(classes.used);
        let mut mask = SurfaceMask::with_slabs_of(&ctx, &labels, channels, (256 * 30 * 4, 64));
        let first = build(&mut mask, &classes);
        assert!(first.iter().any(|&m| m > 128));
        for hidden in [&[1][..], &[], &[6, 7], &[]] {
            labels.write_table_for_tests(&ctx.queue, &table_without(hidden));
            let classes = labels.classes();
            assert_eq!(channels_for(classes.used), channels, "{hidden:?}");
            let key = SurfaceMask::key(&labels, 1.5);
            let codes = class_codes(&classes);
            let Extent::Region(_, regions) = mask.extent_for(&labels, key, &codes, 3) else {
                panic!("{hidden:?}: a region");
            };
            assert!(voxels(regions[2]) < 40 * 30 * 30 / 4, "{regions:?}");
            let toggled = build(&mut mask, &classes);
            let mut whole = SurfaceMask::with_slabs_of(&ctx, &labels, channels, (256 * 30 * 4, 64));
            let made_whole = build(&mut whole, &classes);
            assert!(toggled == made_whole, "{hidden:?}");
            // Hiding changed the mask; showing all again gave back the first.
            assert_eq!(toggled == first, hidden.is_empty(), "{hidden:?}");
        }
        // Hiding most labels reaches past half the grid: the whole mask.
        let most: Vec<usize> = (2..37).collect();
        labels.write_table_for_tests(&ctx.queue, &table_without(&most));
        let classes = labels.classes();
        let key = SurfaceMask::key(&labels, 1.5);
        let codes = class_codes(&classes);
        assert!(matches!(
            mask.extent_for(&labels, key, &codes, 3),
            Extent::Whole
        ));
    }

    /// Labels in bricks past the GPU's side (forced here: 12 voxels): the mask lies on their grid
    /// halved, smoothed from each class's occupancy written on the CPU; it equals its CPU twin
    /// (the occupancy smoothed) to one step of 1/255, over slabs, and after a toggle its
    /// region's rebuild equals a whole build byte for byte.
    #[test]
    fn labels_in_bricks_take_a_halved_mask_from_their_occupancy() {
        use crate::labels::surface::{occupancy, smoothed_occupancy};
        use crate::render::labels::LabelPlacement;
        let ctx = GpuContext::headless().expect("a GPU (lavapipe in CI)");
        let dims = [24u32, 18, 12];
        let n = (dims[0] * dims[1] * dims[2]) as usize;
        // Blocks of 8 × 6 × 4 voxels, labels 1..=27.
        let layer: Vec<u16> = (0..n as u32)
            .map(|i| {
                let (x, y, z) = (i % 24 / 8, i / 24 % 18 / 6, i / 432 / 4);
                (1 + x + 3 * (y + 3 * z)) as u16
            })
            .collect();
        let map = std::sync::Arc::new(LabelMap::bare(dims, vec![layer]));
        let placed =
            GpuLabels::placed(&ctx.device, &ctx.queue, map.clone(), LabelPlacement::Bricks);
        let labels = placed.unwrap();
        assert!(labels.in_bricks());
        let pipelines = SurfacePipelines::new(&ctx.device).unwrap();
        let build = |mask: &mut SurfaceMask, classes: &Classes| {
            build_and_read(&ctx, &pipelines, mask, (&labels, classes), 0.7)
        };
        let table = |hidden: u16| {
            let mut table = vec![[0u8; 4]; 1 << 16];
            for (v, c) in table.iter_mut().enumerate().take(28).skip(1) {
                *c = [90, 160, 30, if v == usize::from(hidden) { 0 } else { 255 }];
            }
            table
        };
        // Two classes by the block's parity (a toggle keeps every other label's class).
        let classes_without = |hidden: u16| Classes {
            class: (0..1usize << 16)
                .map(|v| (1..28).contains(&v).then_some((v % 2) as u8))
                .enumerate()
                .map(|(v, c)| c.filter(|_| v != usize::from(hidden)))
                .collect(),
            clashes: Vec::new(),
            used: 2,
            last: Vec::new(),
        };
        labels.write_table_for_tests(&ctx.queue, &table(0));
        let classes = classes_without(0);
        let channels = channels_for(classes.used);
        let slabs = (256 * 9 * 2, 12);
        let mut mask = SurfaceMask::with_slabs_of(&ctx, &labels, channels, slabs);
        assert_eq!((mask.factor, mask.dims), (2, [12, 9, 6]));
        let gpu = build(&mut mask, &classes);
        let codes = class_codes(&classes);
        let all = occupancy(&map, &codes, (2, channels), ([0; 3], mask.dims));
        for c in 0..channels as usize {
            let one: Vec<u8> = all
                .iter()
                .skip(c)
                .step_by(channels as usize)
                .copied()
                .collect();
            let cpu = smoothed_occupancy(mask.dims, &one, 0.7);
            let channel = gpu.iter().skip(c).step_by(channels as usize);
            let worst = channel.zip(&cpu).map(|(g, c)| g.abs_diff(*c)).max();
            assert!(worst <= Some(1), "class {c}: {worst:?}");
            assert!(cpu.iter().any(|&m| m > 128));
        }
        // A corner block (label 1) hidden: its region alone, as a whole build makes it.
        labels.write_table_for_tests(&ctx.queue, &table(1));
        let classes = classes_without(1);
        let key = SurfaceMask::key(&labels, 0.7);
        let extent = mask.extent_for(&labels, key, &class_codes(&classes), 2);
        assert!(matches!(extent, Extent::Region(..)));
        let toggled = build(&mut mask, &classes);
        let mut whole = SurfaceMask::with_slabs_of(&ctx, &labels, channels, slabs);
        assert!(toggled == build(&mut whole, &classes));
        assert!(toggled != gpu);
    }

    /// A wall between two touching labels: a box of label 1 (red) against one of label 2
    /// (blue), both at half opacity, seen along x through 1 into 2. The labels take two classes,
    /// so the ray enters 2's surface at the wall and the picture takes its blue (one class would
    /// draw no wall and show no blue); the GPU matches the f64 reference on both paths, and a
    /// leaping strategy matches RC-t.
    #[test]
    fn a_wall_between_touching_labels_shows_and_matches_the_reference() {
        use crate::camera::{Aabb, Camera, ProjectionKind};
        use crate::reference::{self, Labelled};
        use crate::render::VolumeRenderer;
        use crate::settings::effects::LabelView;
        use crate::settings::{RenderPath, RenderSettings, Strategy};
        use crate::volume::{Samples, ValueMapping, Volume};
        use glam::DVec3;
        use std::sync::Arc;

        let dims = [24u32, 12, 12];
        let n = (dims[0] * dims[1] * dims[2]) as usize;
        // Air: transparent under the bone function, so only the surfaces show.
        let volume = Volume::new(
            "wall",
            dims,
            [1.0; 3],
            Samples::F32(vec![-1000.0; n]),
            ValueMapping::IDENTITY,
        )
        .unwrap();
        let layer: Vec<u16> = (0..n)
            .map(|i| {
                let (x, y, z) = (i % 24, i / 24 % 12, i / 288);
                let inner = (3..9).contains(&y) && (3..9).contains(&z);
                match x {
                    _ if !inner => 0,
                    4..12 => 1,
                    12..20 => 2,
                    _ => 0,
                }
            })
            .collect();
        let map = LabelMap::bare(dims, vec![layer]);
        let mut table = vec![[0u8; 4]; 1 << 16];
        table[1] = [230, 30, 30, 128];
        table[2] = [30, 30, 230, 128];
        let tf = crate::transfer::presets::preset("ct-bone").unwrap();
        let mut r = VolumeRenderer::new(GpuContext::headless().expect("a GPU")).unwrap();
        r.set_volume(&volume).unwrap();
        r.set_transfer_function(&tf);
        let ctx = r.context().clone();
        let labels = GpuLabels::new(&ctx.device, &ctx.queue, map.clone()).unwrap();
        labels.write_table_for_tests(&ctx.queue, &table);
        assert_eq!(labels.classes().used, 2);
        r.set_labels(Some(Arc::new(labels))).unwrap();
        let bounds = Aabb::of_volume(dims, [1.0; 3]);
        let camera = Camera::framing(&bounds, DVec3::X, DVec3::Z, ProjectionKind::Orthographic);
        let size = [32, 32];
        let settings = RenderSettings {
            step_vox: 0.5,
            strategy: Strategy::RcT,
            labels: LabelView::Surfaces,
            label_smoothing: 0.7,
            background: [0.0; 3],
            ..RenderSettings::default()
        };
        let labelled = Labelled {
            map: &map,
            table: &table,
        };
        let expected =
            reference::render_labelled(&volume, &tf, &camera, size, &settings, Some(&labelled))
                .image;
        let centre = expected.get(16, 16);
        // Red's surface (half) over blue's wall (half of what is left).
        // (Red's surface alone adds as much green as blue: its colour and the white highlight.)
        assert!(centre[0] > 0.2 && centre[2] > centre[1] + 0.1, "{centre:?}");
        for (strategy, path) in [
            (Strategy::RcT, RenderPath::Compute),
            (Strategy::RcT, RenderPath::Fragment),
            (Strategy::RcS, RenderPath::Compute),
        ] {
            let s = RenderSettings {
                strategy,
                path,
                ..settings
            };
            let actual = r.render_image(&camera, size, &s).unwrap();
            let diff = actual.diff(&expected).unwrap();
            assert!(
                diff.max_abs < 0.05 && diff.rmse < 0.01,
                "{strategy:?} {path:?}: {diff:?}, centre {:?} vs {centre:?}",
                actual.get(16, 16)
            );
        }
    }
}
