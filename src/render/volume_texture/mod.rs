//! The volume on the GPU: one 3D texture, or bricks in an atlas found through a page table
//! (`accel::bricks`; [`Bricking`] says which), uploaded in slabs or brick by brick. Every shader
//! reads it through `shaders/shared/volume.wgsl`, which hides which.

mod admission;
mod atlas;
mod encoding;
mod fetch;
mod label_atlas;
mod plan;
mod ranges;
mod resident;
mod tiling;
mod unseen;

pub use admission::admission;
pub use encoding::{MISSING, MISSING_BELOW, TexelEncoding, texel_units};
pub(crate) use encoding::{bytes_per_texel, forced_format};

use crate::settings::{Bricking, TexturePrecision, Upload};
use crate::volume::Volume;
use std::sync::Arc;

use wgpu::util::DeviceExt;

use super::context::GpuContext;
use super::gpu_data::VolumeGeometry;
use super::labels::GpuLabels;
use encoding::{TexelSource, choose_encoding, encode_texels, encoding_for};
use plan::{Plan, PlanError, coarser_note, footprint_note, plan};
use resident::Resident;
pub use resident::{Pace, ResidencyStatus, Update};
pub use unseen::{Cull, REACH_STEP_VOX, SlicePlane, Unseen};

/// Why a volume cannot go to the GPU.
#[derive(Debug, thiserror::Error)]
pub enum VolumeTextureError {
    /// A dimension is larger than the adapter's 3D texture limit.
    #[error(
        "the volume is {dims:?} voxels but this GPU ({adapter}) takes at most {max} per axis in one \
         3D texture; leave it to be bricked (--bricks auto), or crop or downsample it: {name}"
    )]
    TooLarge {
        /// The volume's path (else its name).
        name: String,
        /// Volume dimensions.
        dims: [u32; 3],
        /// The adapter's `max_texture_dimension_3d`.
        max: u32,
        /// Adapter name.
        adapter: String,
    },
    /// The GPU ran out of memory creating the texture.
    #[error(
        "the GPU ({adapter}) has not enough memory for a {megabytes:.0} MB volume texture: {name}"
    )]
    OutOfMemory {
        /// The volume's path (else its name).
        name: String,
        /// Texture size.
        megabytes: f64,
        /// Adapter name.
        adapter: String,
    },
    /// No layout fits the adapter's limits and the GPU memory budget.
    #[error("the volume does not fit this GPU: {why}: {name}")]
    Layout {
        /// The volume's path (else its name).
        name: String,
        /// Why not.
        why: String,
    },
    /// Any other error creating or filling the texture.
    #[error("the GPU refused the volume texture: {0}")]
    Gpu(String),
    /// The precision asked for cannot hold this volume on this adapter.
    #[error("{precision} texels are not possible here: {why}")]
    Precision {
        /// The precision's label.
        precision: &'static str,
        /// Why not.
        why: String,
    },
}

/// What a shader binds to read the volume (`shaders/shared/volume.wgsl`): its texels, the page
/// table and the geometry that find a voxel among them. Cheap to clone.
#[derive(Clone, Debug)]
pub struct VolumeView {
    /// The whole volume, or the atlas of its bricks.
    pub texels: wgpu::TextureView,
    /// The page table (one entry, unread, for a volume in one texture).
    pub pages: wgpu::Buffer,
    /// The `VolumeGeometry` uniform.
    pub geometry: wgpu::Buffer,
    /// Whether the volume is bricked (the shaders' `BRICKED` variants read it).
    pub bricked: bool,
    /// Edge of its level-0 bricks in voxels (0: one texture).
    pub brick_vox: u32,
}

impl VolumeView {
    /// The bind group entries of the texels, the page table and the geometry at `bindings`, as
    /// a pipeline compiled for this layout with an automatic layout uses them: the page table
    /// only where the volume is bricked.
    pub fn entries(&self, bindings: [u32; 3]) -> Vec<wgpu::BindGroupEntry<'_>> {
        let mut entries = vec![
            wgpu::BindGroupEntry {
                binding: bindings[0],
                resource: wgpu::BindingResource::TextureView(&self.texels),
            },
            wgpu::BindGroupEntry {
                binding: bindings[2],
                resource: self.geometry.as_entire_binding(),
            },
        ];
        if self.bricked {
            entries.push(wgpu::BindGroupEntry {
                binding: bindings[1],
                resource: self.pages.as_entire_binding(),
            });
        }
        entries
    }
}

/// One of a shader's pipelines (or anything else) for each layout of the volume: compiled
/// without and with `BRICKED`.
pub(crate) struct PerLayout<T> {
    single: T,
    bricked: T,
}

impl<T> PerLayout<T> {
    /// Makes both, `make` taking the preprocessor symbols that select the layout.
    pub(crate) fn new<E>(make: impl Fn(&[&str]) -> Result<T, E>) -> Result<Self, E> {
        Ok(Self {
            single: make(&[])?,
            bricked: make(&["BRICKED"])?,
        })
    }

    /// The one for the layout of `view`.
    pub(crate) fn pick(&self, view: &VolumeView) -> &T {
        if view.bricked {
            &self.bricked
        } else {
            &self.single
        }
    }
}

/// The share of the GPU memory budget the leaping structures may take, as its divisor: a
/// quarter (8³ blocks of a 2048 × 2048 × 1024 volume under 1 GB, 182 MB; its 4³ blocks would
/// take 1.46 GB).
const LEAP_SHARE: u64 = 4;

/// The upload's staging copies take at most this divisor's share of the budget (tests' budgets
/// of a few bricks), at most [`STAGING_MOST`].
const STAGING_SHARE: u64 = 16;

/// A frame's targets take at most this divisor's share of the budget, at most those of a frame
/// of [`FRAME_RESERVE`] (50 MB; a budget of 256 MB keeps them all).
const FRAME_SHARE: u64 = 4;

/// Bytes an upload sends before it waits for the GPU to take them (what wgpu's staging copies
/// hold at most, besides the batch or slab being written), where the budget allows: frames of
/// 8 ms of uploads sent 112-192 bricks of 34³ uint8 texels (4-8 MB) on the H100 machine
/// (`bench --stream`, docs/benchmarks/nvidia-h100-bricks-stream §9).
const STAGING_MOST: u64 = 32 << 20;

/// The frame's targets the budget keeps room for: an image of 1920 × 1080 (a larger one takes
/// more, outside the volume's budget).
const FRAME_RESERVE: [u32; 2] = [1920, 1080];

/// What the budget keeps back from the volume's texels for the upload's staging copies and a
/// frame's targets: (staging, frame).
fn reserves(budget: Option<u64>) -> (u64, u64) {
    let frame = crate::render::raycast::targets::Targets::bytes(FRAME_RESERVE);
    match budget {
        Some(b) => (
            (b / STAGING_SHARE).min(STAGING_MOST),
            (b / FRAME_SHARE).min(frame),
        ),
        None => (STAGING_MOST, 0),
    }
}

/// What a `budget` holds beside the texels of a volume of `dims`: its leaping structures (at
/// most a [`LEAP_SHARE`] of it), page tables, the upload's staging and a frame's targets
/// ([`reserves`]), what the driver holds for the process ([`crate::render::memory::DeviceMemory::held_besides`])
/// and a block of wgpu's allocator left unused (a share of a small budget). The upload and the
/// load's admission check both lay the texels out in the rest.
pub(super) fn besides_texels(ctx: &GpuContext, dims: [u32; 3], budget: Option<u64>) -> u64 {
    let Some(budget) = budget else {
        return 0;
    };
    let most = budget / LEAP_SHARE;
    let leap = crate::accel::pyramid::Pyramid::within(dims, ctx.largest_binding(), Some(most));
    let pages = atlas::page_table_bytes(dims, crate::accel::bricks::DEFAULT_BRICK_VOX);
    let (staging, frame) = reserves(Some(budget));
    let before = ctx.memory.map_or(0, |m| m.held_besides(budget));
    // A small budget (tests') keeps a share back, as for staging.
    let unused = crate::render::context::ALLOCATOR_BLOCK.min(budget / STAGING_SHARE);
    leap.gpu_bytes() + 2 * pages + staging + frame + before + unused
}

/// The volume on the GPU.
pub struct VolumeTexture {
    /// The 3D texture: the whole volume, or the atlas of its bricks.
    pub texture: wgpu::Texture,
    /// Bytes the texture took (see [`Self::texture_bytes`]).
    taken: u64,
    /// What the rays bind to read it.
    pub view: VolumeView,
    /// How texels map to normalised values.
    pub encoding: TexelEncoding,
    /// Where the GPU holds a coarser level than the volume's own: which, and why (one line).
    pub coarser: Option<String>,
    /// The GPU memory budget it was laid out within (given, or the adapter's default).
    pub budget: Option<u64>,
    /// The most the volume's leaping structures may take of that budget (a share of it; the
    /// texels have what they and the page tables leave).
    pub leap_most: Option<u64>,
    /// What that budget keeps back for the upload's staging copies (their bound) and for a
    /// frame's targets.
    pub reserved: (u64, u64),
    /// The bricks' residency, where the volume is bricked.
    resident: Option<Resident>,
    /// The slices' page table (data everywhere, never a constant), where bricked.
    slice_pages: Option<wgpu::Buffer>,
    /// The 3D texture limit the layout was made for, and the atlas size the GPU ran out of
    /// memory at before the budget was lowered, if it did (the note says so).
    limits: (u32, Option<u64>),
}

impl VolumeTexture {
    /// Checks the size against the adapter, creates the texture in the best format the adapter
    /// filters (one texture where the volume fits, else bricks) and uploads the samples (tests:
    /// the volume is copied where it is bricked; the renderer shares its own).
    pub fn upload(ctx: &GpuContext, volume: &Volume) -> Result<Self, VolumeTextureError> {
        Self::upload_with(ctx, &Arc::new(volume.clone()), &Upload::default())
    }

    /// [`Self::upload`] with the texel precision, the layout and the GPU memory budget `upload`
    /// asks for. A bricked volume keeps `volume` to upload bricks from as the view asks for
    /// them; its first residency is complete: every brick at the finest level that fits.
    /// Past the first upload, residency follows each frame (see [`Self::update_residency`]).
    pub fn upload_with(
        ctx: &GpuContext,
        volume: &Arc<Volume>,
        upload: &Upload,
    ) -> Result<Self, VolumeTextureError> {
        Self::upload_streaming(ctx, volume, upload, None)
    }

    /// [`Self::upload_with`], a bricked volume's first bricks uploaded for at most `time`
    /// (the coarsest first, at least one batch), the rest left to later frames
    /// ([`Self::update_residency`]).
    pub fn upload_streaming(
        ctx: &GpuContext,
        volume: &Arc<Volume>,
        upload: &Upload,
        time: Option<std::time::Duration>,
    ) -> Result<Self, VolumeTextureError> {
        let dims = volume.dims();
        let max = ctx.limits.max_texture_dimension_3d;
        let encoding = Self::encoding(ctx, volume, upload.precision)?;
        if let Some(w) = encoding.warning {
            log::warn!("{w} ({})", volume.name());
        }
        let bpt = bytes_per_texel(encoding.format);
        let mut budget = upload.gpu_budget.or_else(|| ctx.default_gpu_budget());
        // The budget holds the leaping structures, page tables, staging and a frame too
        // (`besides_texels`): the structures take at most a share of it (coarser blocks where
        // finer would take more), the texels the rest.
        let leap_most = budget.map(|b| b / LEAP_SHARE);
        let reserved = reserves(budget);
        let besides = besides_texels(ctx, dims, budget);
        let texels = |budget: Option<u64>| budget.map(|b| b.saturating_sub(besides).max(1));
        let given = budget;
        let layout_error = |e: PlanError| match e {
            PlanError::TooLarge { max } => VolumeTextureError::TooLarge {
                name: volume.label(),
                dims,
                max,
                adapter: ctx.adapter_info.name.clone(),
            },
            other => VolumeTextureError::Layout {
                name: volume.label(),
                why: match given {
                    Some(b) if besides > 0 => format!(
                        "{other} (the texels' share of a budget of {}: its leaping structures, \
                         page tables, upload staging and a frame's targets take {})",
                        crate::text::bytes(b),
                        crate::text::bytes(besides)
                    ),
                    _ => other.to_string(),
                },
            },
        };
        // Where the GPU runs out of memory for the texture, the budget is halved below it and
        // the layout chosen again (fewer slots), until one fits or none is left. A texture that
        // would take more than its texels' share (the driver's tiling) is laid out again smaller.
        let mut lowered = None;
        // A volume read from its store has no whole grid to send: it is bricked.
        let bricking = match upload.bricking {
            Bricking::Off if volume.streaming().is_some() => {
                return Err(VolumeTextureError::Layout {
                    name: volume.label(),
                    why: "it is read from its store brick by brick, so it cannot be one texture \
                          (--bricks off)"
                        .into(),
                });
            }
            _ if volume.streaming().is_some() => Bricking::On,
            b => b,
        };
        let (plan, texture, taken) = loop {
            let share = texels(budget);
            let plan = plan(dims, bricking, (max, share), bpt as u64).map_err(layout_error)?;
            let replan = |lower: u64| match bricking {
                Bricking::Off => None,
                b => self::plan::plan(dims, b, (max, Some(lower)), bpt as u64).ok(),
            };
            let plan = share
                .and_then(|s| tiling::fit(ctx, plan, s, replan, encoding.format))
                .unwrap_or(plan);
            let bytes = plan.bytes(bpt as u64);
            match allocate(ctx, plan.extent(), encoding.format) {
                Ok((texture, taken)) => break (plan, texture, taken.unwrap_or(bytes)),
                Err(Allocation::OutOfMemory) if bricking != Bricking::Off && bytes > 1 => {
                    log::warn!(
                        "the GPU ran out of memory for a {} volume texture",
                        crate::text::bytes(bytes)
                    );
                    budget = Some(bytes / 2 + besides);
                    lowered = Some(bytes);
                }
                Err(Allocation::OutOfMemory) => {
                    return Err(VolumeTextureError::OutOfMemory {
                        name: volume.label(),
                        megabytes: bytes as f64 / 1e6,
                        adapter: ctx.adapter_info.name.clone(),
                    });
                }
                Err(Allocation::Refused(e)) => return Err(VolumeTextureError::Gpu(e)),
            }
        };
        let uploaded = ctx.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let (pages, resident) = match plan {
            Plan::Single(_) => {
                upload_slabs(ctx, &texture, volume, &encoding, reserved.0);
                (atlas::no_page_table(ctx), None)
            }
            Plan::Bricked(atlas) => {
                let table = atlas::page_table_bytes(dims, atlas.brick_vox);
                let most = ctx.largest_binding();
                if table > most {
                    return Err(VolumeTextureError::Layout {
                        name: volume.label(),
                        why: format!(
                            "its page table of {} is past the adapter's largest storage buffer ({})",
                            crate::text::bytes(table),
                            crate::text::bytes(most)
                        ),
                    });
                }
                let mut resident = Resident::new(
                    ctx,
                    Arc::clone(volume),
                    encoding,
                    (atlas.brick_vox, atlas.slots, atlas.capacity),
                    reserved.0,
                );
                let pace = Pace { time, ..Pace::ALL };
                resident.update(ctx, &texture, &Unseen::NOTHING, pace);
                (resident.rays_pages().clone(), Some(resident))
            }
        };
        if let Some(e) = pollster::block_on(uploaded.pop()) {
            return Err(VolumeTextureError::Gpu(e.to_string()));
        }
        let geometry = geometry(dims, plan);
        let view = VolumeView {
            texels: texture.create_view(&wgpu::TextureViewDescriptor::default()),
            pages,
            geometry: ctx
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("volume geometry"),
                    contents: bytemuck::bytes_of(&geometry),
                    usage: wgpu::BufferUsages::UNIFORM,
                }),
            bricked: resident.is_some(),
            brick_vox: geometry.brick_vox,
        };
        let slice_pages = resident.as_ref().map(|r| r.slice_pages().clone());
        let mut texture = Self {
            texture,
            taken,
            view,
            encoding,
            coarser: None,
            budget,
            leap_most,
            reserved,
            resident,
            slice_pages,
            limits: (max, lowered),
        };
        texture.note(ctx);
        if let Some(note) = &texture.coarser {
            log::info!("{note} ({})", volume.name());
        }
        Ok(texture)
    }

    /// Bytes its page tables take on the GPU (the rays' and the slices'; 0 for one texture).
    pub fn page_table_bytes(&self) -> u64 {
        (self.slice_pages.as_ref()).map_or(0, |s| s.size() + self.view.pages.size())
    }

    /// Bytes of its 3D texture as allocated (the whole atlas, however many slots are used):
    /// as wgpu's allocator reported them, else its texels.
    pub fn texture_bytes(&self) -> u64 {
        self.taken
    }

    /// What the slices bind: the rays' view with the slices' page table (data everywhere).
    pub fn slice_view(&self) -> VolumeView {
        let mut view = self.view.clone();
        if let Some(pages) = &self.slice_pages {
            view.pages = pages.clone();
        }
        view
    }

    /// Puts `labels` in the bricks beside the volume's samples where they travel in bricks
    /// ([`GpuLabels::in_bricks`]): a label atlas of the volume atlas's extent, every resident
    /// brick's labels written at once and each brick's sent with it from then on; `None`, or
    /// labels of one texture of their own, take the atlas away. Refused where the volume is one
    /// texture, and where the GPU has no memory for the atlas.
    pub fn attach_labels(
        &mut self,
        ctx: &GpuContext,
        labels: Option<&GpuLabels>,
    ) -> Result<(), VolumeTextureError> {
        let source = labels.and_then(|l| l.brick_source().map(|map| (l, map)));
        let Some((labels, map)) = source else {
            if let Some(resident) = &mut self.resident {
                resident.set_labels(ctx, None);
            }
            return Ok(());
        };
        let owner = std::ptr::from_ref(labels) as usize;
        let Some(resident) = &mut self.resident else {
            return Err(VolumeTextureError::Layout {
                name: map.name().to_string(),
                why: format!(
                    "its labels ({:?}) travel in the volume's bricks, but the volume is one \
                     texture: open it with --bricks on",
                    map.dims()
                ),
            });
        };
        if resident.labels().is_some_and(|a| a.owner == owner) {
            return Ok(());
        }
        // The old atlas goes before the new one is made: both may not fit.
        resident.set_labels(ctx, None);
        let size = self.texture.size();
        let extent = [size.width, size.height, size.depth_or_array_layers];
        let shape = (extent, resident.brick_vox(), resident.levels());
        let atlas = label_atlas::LabelAtlas::new(ctx, shape, Arc::clone(map), owner)?;
        // The atlas was laid out for the volume's texels alone: the labels' go beside them.
        if let Some(budget) = self.budget
            && self.taken + atlas.bytes() > budget
        {
            log::warn!(
                "the labels' atlas of bricks ({}) and the volume's ({}) take more than the GPU \
                 budget of {}",
                crate::text::bytes(atlas.bytes()),
                crate::text::bytes(self.taken),
                crate::text::bytes(budget)
            );
        }
        labels.set_atlas(Some(atlas.view.clone()));
        resident.set_labels(ctx, Some(atlas));
        Ok(())
    }

    /// Bytes of the label atlas, where a segmentation travels in the bricks.
    pub fn label_atlas_bytes(&self) -> u64 {
        (self.resident.as_ref())
            .and_then(Resident::labels)
            .map_or(0, label_atlas::LabelAtlas::bytes)
    }

    /// Decides again which bricks the rays need, leaving out what `unseen` says they cannot
    /// see, and uploads what is missing as `pace` lets it: see [`Resident::update`]. Nothing
    /// to do for a volume in one texture.
    pub fn update_residency(&mut self, ctx: &GpuContext, unseen: &Unseen, pace: Pace) -> Update {
        let Some(resident) = &mut self.resident else {
            return Update {
                changed: false,
                bricks: None,
                complete: true,
            };
        };
        let update = resident.update(ctx, &self.texture, unseen, pace);
        if update.changed {
            self.note(ctx);
        }
        update
    }

    /// How far the bricks' residency is (`None` for one texture).
    pub fn residency(&self) -> Option<&ResidencyStatus> {
        self.resident.as_ref().map(Resident::status)
    }

    /// Sets [`Self::coarser`] from the level the bricks are held at: coarser than the volume's
    /// own where the budget holds no finer, or where the view needs no finer.
    fn note(&mut self, ctx: &GpuContext) {
        let Some(resident) = &self.resident else {
            return;
        };
        let ((max, lowered), budget) = (self.limits, self.budget);
        let bpt = bytes_per_texel(self.encoding.format) as u64;
        let status = resident.status();
        let mut coarser = coarser_note(
            (resident.dims(), resident.brick_vox(), status.fits),
            (max, budget),
            bpt,
        );
        if let (Some(note), Some(memory)) = (&mut coarser, ctx.memory)
            && budget == ctx.default_gpu_budget()
        {
            note.push_str(&format!(
                " (by default {:.0} % of the {} the GPU's driver reports; --gpu-budget sets it)",
                crate::render::memory::DEFAULT_SHARE * 100.0,
                crate::text::bytes(memory.available_bytes.unwrap_or(memory.heap_bytes))
            ));
        }
        if coarser.is_none() && status.level > 0 {
            coarser = Some(footprint_note(resident.dims(), status.level));
        }
        if let Some(failed) = lowered {
            let said = format!(
                "the GPU ran out of memory for {}: the budget was lowered to {}",
                crate::text::bytes(failed),
                crate::text::bytes(budget.unwrap_or(0))
            );
            coarser = Some(match coarser {
                Some(note) => format!("{note}; {said}"),
                None => said,
            });
        }
        self.coarser = coarser;
    }

    /// How far a bricked volume's residency is, for the overlay (`None` for one texture):
    /// the levels the rays read, bricks resident of those wanted, and memory of the budget.
    pub fn residency_line(&self) -> Option<String> {
        let s = self.residency()?;
        let budget = self
            .budget
            .map_or(String::new(), |b| format!(" of {}", crate::text::bytes(b)));
        let levels = if s.levels.count_ones() > 1 {
            "levels"
        } else {
            "level"
        };
        let reading = match s.reading {
            0 => String::new(),
            n => format!(", {n} being read from the store"),
        };
        Some(format!(
            "bricks: {levels} {} read, {} of {} wanted resident, {}{budget}{reading}",
            s.levels_read(),
            s.wanted - s.missing,
            s.wanted,
            crate::text::bytes(s.bytes)
        ))
    }

    /// How the GPU holds the volume, for the developer readout: one texture, or how many bricks
    /// of which levels, and the memory they take.
    pub fn describe(&self) -> String {
        let held = match &self.resident {
            None => format!(
                "one 3D texture, {}",
                crate::text::bytes(self.texture_bytes())
            ),
            Some(r) => {
                let s = r.status();
                format!(
                    "bricks of {}³: {} resident of {} wanted (finest level wanted {}, levels {} read), \
                     {} empty, {}",
                    r.brick_vox(),
                    s.resident,
                    s.wanted,
                    s.level,
                    s.levels_read(),
                    s.constant,
                    crate::text::bytes(s.bytes)
                )
            }
        };
        let held = match self.label_atlas_bytes() {
            0 => held,
            b => format!("{held}, and the labels' atlas {}", crate::text::bytes(b)),
        };
        match self.budget {
            Some(budget) => format!("{held} (budget {})", crate::text::bytes(budget)),
            None => held,
        }
    }

    /// The encoding `precision` asks for, where this adapter and `volume` allow it.
    fn encoding(
        ctx: &GpuContext,
        volume: &Volume,
        precision: TexturePrecision,
    ) -> Result<TexelEncoding, VolumeTextureError> {
        match forced_format(precision) {
            None => Ok(choose_encoding(volume, |f| ctx.is_filterable(f))),
            Some(_) if volume.colour().is_some() => Err(VolumeTextureError::Precision {
                precision: precision.label(),
                why: "a colour volume is stored as 8-bit luminance and colour".into(),
            }),
            Some(format) => {
                let refuse = |why: String| VolumeTextureError::Precision {
                    precision: precision.label(),
                    why,
                };
                if !ctx.is_filterable(format) {
                    return Err(refuse(format!(
                        "{} cannot filter {format:?} textures",
                        ctx.adapter_info.name
                    )));
                }
                if format != wgpu::TextureFormat::R32Float && volume.may_be_non_finite() {
                    return Err(refuse(format!(
                        "{} NaN or infinite samples need a float format",
                        volume.non_finite_count()
                    )));
                }
                Ok(encoding_for(volume, format))
            }
        }
    }
}

/// Why a texture could not be allocated.
pub(super) enum Allocation {
    /// The GPU ran out of memory.
    OutOfMemory,
    /// The device refused it (the message).
    Refused(String),
}

/// A 3D texture of `extent` texels in `format` for the volume, refused at once where the device
/// cannot make it (before any sample is encoded and sent).
pub(super) fn allocate(
    ctx: &GpuContext,
    extent: [u32; 3],
    format: wgpu::TextureFormat,
) -> Result<(wgpu::Texture, Option<u64>), Allocation> {
    let [width, height, depth] = extent;
    let before = tiling::allocated_bytes(ctx);
    let oom = ctx.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = ctx.device.push_error_scope(wgpu::ErrorFilter::Validation);
    let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("volume"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: depth,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let refused = pollster::block_on(validation.pop());
    if pollster::block_on(oom.pop()).is_some() {
        texture.destroy();
        return Err(Allocation::OutOfMemory);
    }
    match refused {
        Some(e) => Err(Allocation::Refused(e.to_string())),
        None => {
            let taken =
                (tiling::allocated_bytes(ctx).zip(before)).map(|(a, b)| a.saturating_sub(b));
            Ok((texture, taken.filter(|&t| t > 0)))
        }
    }
}

/// The `VolumeGeometry` uniform of a volume of `dims` laid out by `plan`.
fn geometry(dims: [u32; 3], plan: Plan) -> VolumeGeometry {
    let extent = plan.extent();
    let brick_vox = match plan {
        Plan::Single(_) => 0,
        Plan::Bricked(atlas) => atlas.brick_vox,
    };
    let texel_size = extent.map(|e| 1.0 / e as f32);
    let bricked = brick_vox != 0;
    let last_brick = dims.map(|d| {
        if bricked {
            d.div_ceil(brick_vox) - 1
        } else {
            0
        }
    });
    let bricks_per_box = dims.map(|d| {
        if bricked {
            d as f32 / brick_vox as f32
        } else {
            0.0
        }
    });
    VolumeGeometry {
        dims,
        brick_vox,
        texel_size,
        _pad0: 0,
        bricks_per_box,
        _pad1: 0,
        last_brick,
        _pad2: 0,
        atlas_per_box: std::array::from_fn(|a| dims[a] as f32 * texel_size[a]),
        _pad3: 0,
    }
}

/// Encodes `volume`'s samples in `encoding` and writes them into `texture`, a slab of slices at a
/// time: at most `staging_most` bytes (the budget's staging reserve, as bricks are bounded by),
/// or one slice where that is larger, in memory and in wgpu's staging copy at once.
fn upload_slabs(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    volume: &Volume,
    encoding: &TexelEncoding,
    staging_most: u64,
) {
    let dims = volume.dims();
    let bpt = bytes_per_texel(encoding.format);
    let slice_texels = dims[0] as usize * dims[1] as usize;
    let slab_bytes = usize::try_from(staging_most).unwrap_or(usize::MAX);
    let slices_per_slab = (slab_bytes / (slice_texels * bpt).max(1)).max(1);
    let mut bytes = Vec::new();
    let mut z = 0usize;
    while z < dims[2] as usize {
        let z_end = (z + slices_per_slab).min(dims[2] as usize);
        bytes.clear();
        encode_texels(
            &TexelSource::of(volume),
            encoding,
            z * slice_texels..z_end * slice_texels,
            &mut bytes,
        );
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d {
                    x: 0,
                    y: 0,
                    z: z as u32,
                },
                aspect: wgpu::TextureAspect::All,
            },
            &bytes,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(dims[0] * bpt as u32),
                rows_per_image: Some(dims[1]),
            },
            wgpu::Extent3d {
                width: dims[0],
                height: dims[1],
                depth_or_array_layers: (z_end - z) as u32,
            },
        );
        z = z_end;
        // One slab's staging copy in memory at a time.
        ctx.queue.submit([]);
        let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
    }
}
