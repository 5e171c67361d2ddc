//! The long-lived volume renderer. It orchestrates small owners, one per lifetime: the pipelines
//! (the device's), the volume's resources, the transfer function's tables, the per-size targets,
//! and the probes (`measurements.rs`) and refinement of frames. The window, the command
//! line and the tests all render through it: a frame's request and result types are in
//! [`super::request`], its errors in [`super::error`], refined images in [`super::refined`], and
//! the frames a caller waits for, with their pixels, in `waited.rs`.

use std::sync::Arc;

use crate::render::context::GpuContext;
use crate::render::label_surface::{SurfaceFacts, SurfaceMask};
use crate::render::labels::{GpuLabels, NoLabels};
use crate::render::pack::Rgba8Reader;
use crate::render::probe::{FrameResults, ProbePool};
use crate::render::volume_texture::VolumeTexture;
use crate::render::volume_texture::{Cull, Pace, REACH_STEP_VOX, SlicePlane, Unseen};
use crate::settings::{ConcretePath, LabelView, Mode, RenderPath, RenderSettings, Upload};
use crate::transfer::TransferFunction;
use crate::volume::Volume;

use super::error::RenderError;
use super::gpu_volume::{FrameShared, GpuVolume};
use super::leap::{LeapRequest, LeapStructures};
use super::leap_labels::{LabelUse, coarse_reach, surface_reach};
use super::measurements::Measurements;
use super::passes::RaycastPasses;
use super::pipelines::Pipelines;
use super::refine::Accumulator;
use super::request::{Accumulate, FrameRequest, SubmittedFrame, WorkCounts};
use super::strategy_choice::{self, ChoiceKey, StrategyChoice};
use super::targets::Targets;
use super::uniforms::FrameGeometry;
use super::variant::PipelineKey;
use crate::render::gpu_data::{FrameUniforms, SPLIT_GROUP_ROWS, WORKGROUP};

/// Level-0 page entries the bricks one streaming frame uploads stand for at most (a level-2
/// preview brick stands for 64): under a cap of 4096 the pyramid's partial rebuild took up to
/// 17 ms a frame on the H100.
const STREAM_ENTRIES: usize = 1024;

/// The renderer. See the module documentation.
pub struct VolumeRenderer {
    pub(super) ctx: GpuContext,
    pipelines: Pipelines,
    /// The frame uniforms (rewritten every frame) and the volume sampler.
    uniforms: wgpu::Buffer,
    sampler: wgpu::Sampler,
    transfer: super::transfer_tables::TransferTables,
    volume: Option<GpuVolume>,
    pub(super) targets: Option<Targets>,
    measurements: Measurements,
    /// The running mean of progressive refinement (built on first use).
    refine: Option<Accumulator>,
    /// The 8-bit read-back (built on first use).
    pub(super) rgba8: Option<Rgba8Reader>,
    /// The path `auto` stands for on this adapter, once chosen ([`super::auto_path::choose`]).
    auto_path: Option<ConcretePath>,
    /// What the `auto` strategy stands for on the inputs last chosen for
    /// ([`super::auto_strategy::choose`]); forgotten with the volume.
    strategy_choice: Option<StrategyChoice>,
    /// How long one frame may upload bricks (`None`: until the frame is complete).
    residency_time: Option<std::time::Duration>,
    /// How long the last frame's residency update took on the CPU (ms).
    residency_ms: f64,
    /// Frames that some wanted brick was missing from.
    bricks_generation: u64,
    /// Residency updates that changed the page tables (the slices' pictures too).
    pages_generation: u64,
    /// The slice planes shown beside the rays (their bricks hold data).
    slice_planes: Vec<SlicePlane>,
    /// Bound in place of a segmentation where the volume has none.
    no_labels: NoLabels,
}

/// Continuous voxel coordinates (voxel `i`'s centre at `i + ½`) → the frame's clip space.
fn clip_from_voxel(request: &FrameRequest, dims: [u32; 3], spacing_mm: [f64; 3]) -> glam::DMat4 {
    let bounds = crate::camera::Aabb::of_volume(dims, spacing_mm);
    let world_from_voxel = glam::DMat4::from_scale(glam::DVec3::from_array(spacing_mm))
        * glam::DMat4::from_translation(glam::DVec3::splat(-0.5));
    request.camera.clip_from_world(request.size, &bounds) * world_from_voxel
}

impl VolumeRenderer {
    /// Creates the renderer's long-lived resources on `ctx`.
    pub fn new(ctx: GpuContext) -> Result<Self, RenderError> {
        let device = &ctx.device;
        let pipelines = Pipelines::new(device)?;
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("linear clamp"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame uniforms"),
            size: std::mem::size_of::<FrameUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let probes = ProbePool::new(device, &ctx.queue, ctx.has_timestamps());
        let measurements = Measurements {
            stats_group: pipelines.layouts.stats_group(device, &probes.counters),
            probes,
            frames_submitted: 0,
            work: WorkCounts::default(),
        };
        Ok(Self {
            no_labels: NoLabels::new(device),
            transfer: super::transfer_tables::TransferTables::new(&ctx),
            ctx,
            pipelines,
            uniforms,
            sampler,
            volume: None,
            targets: None,
            measurements,
            refine: None,
            rgba8: None,
            auto_path: None,
            strategy_choice: None,
            residency_time: None,
            residency_ms: 0.0,
            bricks_generation: 0,
            pages_generation: 0,
            slice_planes: Vec::new(),
        })
    }

    /// The device the renderer works on.
    pub fn context(&self) -> &GpuContext {
        &self.ctx
    }

    /// Uploads a copy of `volume` (kept where it is bricked, to upload bricks from), replacing
    /// the current one. On error the current volume stays.
    pub fn set_volume(&mut self, volume: &Volume) -> Result<(), RenderError> {
        self.set_volume_with(&std::sync::Arc::new(volume.clone()), &Upload::default())
    }

    /// [`Self::set_volume`] with the texel precision (the accuracy benchmark's knob), the layout
    /// (one texture or bricks: the benchmark's) and the GPU memory budget `upload` asks for.
    pub fn set_volume_with(
        &mut self,
        volume: &std::sync::Arc<Volume>,
        upload: &Upload,
    ) -> Result<(), RenderError> {
        let shared = FrameShared {
            uniforms: &self.uniforms,
            sampler: &self.sampler,
            tables: &self.transfer,
            no_labels: &self.no_labels,
        };
        let uploaded = GpuVolume::new(
            &self.ctx,
            &self.pipelines.layouts,
            &shared,
            volume,
            (upload, self.residency_time),
        )?;
        self.volume = Some(uploaded);
        self.transfer.invalidate();
        self.strategy_choice = None;
        Ok(())
    }

    /// Shows `labels` over the volume loaded (on its grid: `labels::load_labels` puts them
    /// there), or none. Refused where no volume is loaded and where the labels lie on another
    /// grid. Labels past one texture ([`GpuLabels::in_bricks`]) go into the bricked volume's
    /// label atlas, slot for slot with its bricks (refused over a volume in one texture).
    pub fn set_labels(&mut self, labels: Option<Arc<GpuLabels>>) -> Result<(), RenderError> {
        let volume = self.volume.as_mut().ok_or(RenderError::NoVolume)?;
        if let Some(l) = &labels
            && l.dims() != volume.dims
        {
            return Err(RenderError::Labels(format!(
                "the labels lie on a {:?} grid, the volume on {:?}",
                l.dims(),
                volume.dims
            )));
        }
        (volume.texture)
            .attach_labels(&self.ctx, labels.as_deref())
            .map_err(|e| RenderError::Labels(e.to_string()))?;
        let shared = FrameShared {
            uniforms: &self.uniforms,
            sampler: &self.sampler,
            tables: &self.transfer,
            no_labels: &self.no_labels,
        };
        volume.set_labels(&self.ctx, &self.pipelines.layouts, &shared, labels);
        Ok(())
    }

    /// The label surfaces' mask, where a frame drew them.
    pub fn label_surface_facts(&self) -> Option<SurfaceFacts> {
        let volume = self.volume.as_ref()?;
        let clashes = volume
            .labels
            .as_ref()
            .map_or(0, |l| l.classes().clashes.len());
        (volume.surface.as_ref()).map(|s| SurfaceFacts {
            bytes: s.gpu_bytes(),
            channels: s.channels(),
            clashes,
            last_build_share: s.last_build_share(),
            grid: (s.factor(), s.dims()),
        })
    }

    /// How long each frame may spend uploading bricks of a bricked volume before it renders
    /// with what is resident (`None`, the default: every frame is complete, as the CLI needs).
    pub fn set_residency_time(&mut self, time: Option<std::time::Duration>) {
        self.residency_time = time;
    }

    /// How long the last frame's residency update (deciding, uploading, page tables) took on
    /// the CPU, in ms.
    pub fn residency_ms(&self) -> f64 {
        self.residency_ms
    }

    /// Whether the last frame found every brick it wanted resident (else a later frame refines
    /// it).
    pub fn residency_complete(&self) -> bool {
        self.volume_texture()
            .and_then(|t| t.residency())
            .is_none_or(|s| s.complete)
    }

    /// Bumped by every frame that some wanted brick was missing from: while it changes, the
    /// view is worth rendering again.
    pub fn bricks_generation(&self) -> u64 {
        self.bricks_generation
    }

    /// Bumped whenever residency changed the page tables: what the slices show may have changed.
    pub fn pages_generation(&self) -> u64 {
        self.pages_generation
    }

    /// Sets the slice planes shown beside the rays: a bricked volume over its budget keeps the
    /// bricks they cross at the rays' level, whatever the rays leave unseen. Returns whether
    /// they changed.
    pub fn set_slice_planes(&mut self, planes: &[SlicePlane]) -> bool {
        if self.slice_planes == planes {
            return false;
        }
        self.slice_planes = planes.to_vec();
        true
    }

    /// Whether the volume's bricks leave out some the rays do not see (slices then decide
    /// residency too).
    pub fn residency_culls(&self) -> bool {
        self.volume_texture()
            .and_then(|t| t.residency())
            .is_some_and(|s| s.constant > 0)
    }

    /// Whether a volume is loaded.
    pub fn has_volume(&self) -> bool {
        self.volume.is_some()
    }

    /// The loaded volume's texture, for other kinds of drawing of the same volume.
    pub fn volume_texture(&self) -> Option<&VolumeTexture> {
        self.volume.as_ref().map(|v| &v.texture)
    }

    /// Bytes the volume's leaping structures take on the GPU.
    pub fn leap_bytes(&self) -> Option<u64> {
        self.volume.as_ref().map(|v| v.leap.pyramid.gpu_bytes())
    }

    /// Sets the transfer function; the tables are rebuilt before the next frame that needs
    /// them. Returns whether the function changed.
    pub fn set_transfer_function(&mut self, transfer: &TransferFunction) -> bool {
        self.transfer.set(transfer)
    }

    /// The current transfer function.
    pub fn transfer_function(&self) -> &TransferFunction {
        self.transfer.function()
    }

    /// The transfer function's generation: it changes exactly when the function does, so it is
    /// the one signal that a frame must be rendered again for a new function.
    pub(crate) fn transfer_generation(&self) -> u64 {
        self.transfer.generation()
    }

    /// Makes sure the per-size textures exist for `size`.
    fn ensure_targets(&mut self, size: [u32; 2]) -> Result<(), RenderError> {
        let max = self.ctx.limits.max_texture_dimension_2d;
        if size.iter().any(|&s| s == 0 || s > max) {
            return Err(RenderError::ImageSize {
                width: size[0],
                height: size[1],
                max,
                adapter: self.ctx.adapter_info.name.clone(),
            });
        }
        if self.targets.as_ref().is_some_and(|t| t.size == size) {
            return Ok(());
        }
        let device = &self.ctx.device;
        let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let targets = Targets::new(device, &self.pipelines.layouts, size);
        let refused = pollster::block_on(validation.pop());
        let out_of_memory = pollster::block_on(oom.pop());
        if let Some(e) = out_of_memory.or(refused) {
            return Err(RenderError::TargetsRefused {
                width: size[0],
                height: size[1],
                megabytes: Targets::bytes(size) as f64 / 1e6,
                adapter: self.ctx.adapter_info.name.clone(),
                reason: e.to_string().lines().next().unwrap_or_default().to_string(),
            });
        }
        self.targets = Some(targets);
        Ok(())
    }

    /// Whether the volume shown has non-finite voxels (its variants sample around them).
    fn has_missing_voxels(&self) -> bool {
        self.volume.as_ref().is_some_and(|v| !v.all_finite)
    }

    /// Whether the volume shown is bricked (its variants read through the page table).
    fn is_bricked(&self) -> bool {
        self.volume.as_ref().is_some_and(|v| v.texture.view.bricked)
    }

    /// What the volume shown adds to a variant's key under `settings`: whether it has missing
    /// voxels, whether it is bricked, and how its segmentation shows (`Off` without one).
    fn volume_traits(&self, settings: &RenderSettings) -> (bool, bool, LabelView) {
        let labelled = self.volume.as_ref().is_some_and(|v| v.labels.is_some());
        let view = if labelled {
            settings.labels
        } else {
            LabelView::Off
        };
        (self.has_missing_voxels(), self.is_bricked(), view)
    }

    /// Bakes what the frame's settings need of the transfer function's tables.
    fn refresh_tables(&mut self, settings: &RenderSettings) {
        let Some(volume) = &self.volume else { return };
        let work = &mut self.measurements.work;
        if self
            .transfer
            .refresh_lut(&self.ctx, volume.range, settings.opacity_step_vox())
        {
            work.lut_bakes += 1;
        }
        if settings.preintegrated
            && settings.mode == Mode::Dvr
            && self.transfer.refresh_integrals(&self.ctx, volume.range)
        {
            work.integral_builds += 1;
        }
    }

    /// Records and submits one frame. Its measurements arrive through [`Self::collect_results`].
    pub fn render(&mut self, request: &FrameRequest) -> Result<SubmittedFrame, RenderError> {
        let rows = [0, request.size[1]];
        self.render_frame(request, None, rows)
            .map(|(frame, _)| frame)
    }

    /// Records and submits rows `rows` (`[first, end)`) of `request`'s frame: a frame rendered
    /// in bands, one submission each, so that no submission keeps the GPU busy for long (whatever
    /// else shares the queue, such as the window's own drawing, waits behind it). Bands must come
    /// in order, from row 0 to the last row, with the same request. The first band clears the
    /// image; the last one adds it to the refinement mean when `accumulate` says how
    /// (returning the frames the mean then holds). Each band has its own measurements (GPU time;
    /// a statistics frame's counters add up over its bands, complete in the last band's).
    pub fn render_band(
        &mut self,
        request: &FrameRequest,
        rows: [u32; 2],
        accumulate: Option<Accumulate>,
    ) -> Result<(SubmittedFrame, Option<u32>), RenderError> {
        if rows[0] >= rows[1] || rows[1] > request.size[1] {
            return Err(RenderError::Gpu(format!(
                "rows {}..{} are not a band of a {}-row image",
                rows[0], rows[1], request.size[1]
            )));
        }
        if accumulate.is_some() && self.refine.is_none() {
            self.refine = Some(Accumulator::new(&self.ctx.device)?);
        }
        self.render_frame(request, accumulate, rows)
    }

    /// Records and submits rows `rows` of `request`'s frame (all of them for a whole frame),
    /// adding the image to the refinement mean in the submission of its last row when
    /// `accumulate` says so; returns the frames the mean then holds (`None`: not added).
    fn render_frame(
        &mut self,
        request: &FrameRequest,
        accumulate: Option<Accumulate>,
        rows: [u32; 2],
    ) -> Result<(SubmittedFrame, Option<u32>), RenderError> {
        request.settings.validate()?;
        let mut concrete = self.concrete_settings(request.settings, request.size);
        let path = self.resolve_path(concrete.path)?;
        let volume_traits = self.volume_traits(&concrete);
        self.ensure_targets(request.size)?;
        let (first, last) = (rows[0] == 0, rows[1] >= request.size[1]);
        self.refresh_tables(&concrete);
        let settings = &concrete;
        let volume = self.volume.as_mut().ok_or(RenderError::NoVolume)?;
        let geometry =
            FrameGeometry::new(request.camera, request.size, volume.dims, volume.spacing_mm);
        let frame = (request.size, settings);
        let lut = (self.transfer.lut().entries(), self.transfer.depth_unit());
        let mut uniforms = volume.uniforms(frame, &geometry, lut);
        if first {
            // Bricks the rays cannot see under this frame's mode and function need no data.
            let cull = match (settings.mode, self.transfer.opacity()) {
                (Mode::Dvr, Some((generation, index))) => {
                    Cull::Transparent(Arc::clone(index), *generation)
                }
                (Mode::Iso, _) => Cull::OneSide(uniforms.iso_threshold),
                _ => Cull::Nothing,
            };
            let eye = (request.camera.eye / glam::DVec3::from_array(volume.spacing_mm))
                + glam::DVec3::splat(0.5);
            let unseen = Unseen {
                cull,
                long_steps: settings.step_vox > REACH_STEP_VOX,
                eye: Some(eye.to_array()),
                slices: self.slice_planes.clone(),
                frustum: Some(clip_from_voxel(request, volume.dims, volume.spacing_mm)),
                // Streaming under a time budget (the window) holds each brick at the level its
                // footprint needs; without one (`render`) every brick is wanted at level 0.
                footprint: self.residency_time.map(|_| request.size),
            };
            // Past what the pyramid's partial rebuild lists it is built whole (200-230 ms at
            // 2048 × 2048 × 1024 on the H100), and the partial rebuild grows with the list (up
            // to 17 ms under a cap of 4096: docs/benchmarks/nvidia-h100-bricks-stream §11), so
            // a streaming frame sends no more bricks than stand for STREAM_ENTRIES; but where
            // the pyramid is to be built whole anyway (the first frame), as many as its upload
            // time allows, and every brick standing for more than a later frame may send (a
            // coarse preview brick stands for 4096 entries at 2048 × 2048 × 1024; sent alone
            // after the first frame, each took a 10-19 ms rebuild: §13-§14).
            let pace = match self.residency_time {
                Some(time) => Pace {
                    time: Some(time),
                    entries: if volume.leap.pyramid_ready() {
                        volume.leap.listing_room().min(STREAM_ENTRIES)
                    } else {
                        usize::MAX
                    },
                    later: STREAM_ENTRIES,
                },
                None => Pace::ALL,
            };
            let started = std::time::Instant::now();
            let update = volume.texture.update_residency(&self.ctx, &unseen, pace);
            self.residency_ms = started.elapsed().as_secs_f64() * 1e3;
            if update.changed {
                volume.leap.bricks_changed(update.bricks.as_deref());
                self.pages_generation += 1;
            }
            self.bricks_generation += u64::from(!update.complete);
        }
        // While bricks arrive the distance field waits (its rebuild measured 16 ms a frame at
        // 2048 × 2048 × 1024 on an H100): the pyramid's flags, rebuilt every frame, leap exactly
        // meanwhile, and the field is built once residency is complete. Every band of a frame
        // reads the status its first band's update left.
        let streaming = (volume.texture.residency()).is_some_and(|s| !s.complete);
        if streaming && concrete.strategy == crate::settings::Strategy::RcSDistance {
            // The variant the frame that completes needs is compiled now, in a frame that waits
            // for the pyramid's whole build anyway, not in that one (a 73 ms frame at 2048 ×
            // 2048 × 1024 on the H100, §13).
            let later = PipelineKey::new(&concrete, path, request.stats, request.size)
                .for_volume(volume_traits.0, volume_traits.1)
                .with_labels(volume_traits.2);
            if first && !volume.leap.pyramid_ready() && !self.pipelines.has(&later) {
                self.pipelines.for_frame(&self.ctx.device, later)?;
            }
            concrete.strategy = crate::settings::Strategy::RcS;
        }
        let settings = &concrete;
        let key = PipelineKey::new(settings, path, request.stats, request.size)
            .for_volume(volume_traits.0, volume_traits.1)
            .with_labels(volume_traits.2);
        uniforms.row_offset = rows[0];
        uniforms.row_end = rows[1];
        let scope = self
            .ctx
            .device
            .push_error_scope(wgpu::ErrorFilter::Validation);
        let mut encoder = self
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("frame"),
            });
        let m = &mut self.measurements;
        let slot = m.begin(&self.ctx.device, request.stats, [first, last], &mut encoder);
        if key.labels.surfaces() {
            let shared = FrameShared {
                uniforms: &self.uniforms,
                sampler: &self.sampler,
                tables: &self.transfer,
                no_labels: &self.no_labels,
            };
            let builders = (&self.pipelines.layouts, &self.pipelines.surfaces);
            let smoothing = settings.label_smoothing as f32;
            let probe = slot.as_ref().map(|s| (&mut m.probes, s));
            let into = (&mut encoder, probe);
            if volume.prepare_surfaces(&self.ctx, builders, &shared, smoothing, into) {
                m.work.label_surface_builds += 1;
            }
            // The mask's channels may have changed with the shown labels' classes.
            uniforms.surface_channels = volume.surface.as_ref().map_or(0, SurfaceMask::channels);
            uniforms.surface_scale = volume.surface.as_ref().map_or([1.0; 3], SurfaceMask::scale);
        }
        if key.strategy.leaps() {
            let leap_request = LeapRequest {
                settings,
                transfer_generation: self.transfer.generation(),
                lut: self.transfer.lut(),
                window_lo: uniforms.window_lo,
                iso_threshold: uniforms.iso_threshold,
                volume: &volume.texture.view,
                labels: volume.labels.as_deref().and_then(|l| {
                    let use_ = if key.labels.cuts() {
                        // Labels in bricks are read at the level each brick is held at.
                        let coarsest = (volume.texture.residency())
                            .filter(|_| l.in_bricks())
                            .map_or(0, |s| u32::BITS - s.levels.leading_zeros());
                        LabelUse::Cut(coarse_reach(coarsest.saturating_sub(1)))
                    } else if key.labels.surfaces() {
                        let factor = volume.surface.as_ref().map_or(1, SurfaceMask::factor);
                        LabelUse::Surfaces(surface_reach(factor))
                    } else {
                        return None;
                    };
                    Some((l, use_))
                }),
            };
            let probe = slot.as_ref().map(|s| (&mut m.probes, s));
            let (levels, builds) = volume.leap.prepare(
                &self.ctx,
                &self.pipelines.leap,
                &leap_request,
                &mut encoder,
                probe,
            );
            m.count_builds(builds);
            if builds.regrouped {
                volume.leap_group =
                    (self.pipelines.layouts).leap_group(&self.ctx.device, &volume.leap.resources());
            }
            uniforms.leaf_level = levels.leaf_level;
            uniforms.level_count = levels.level_count;
        }
        self.ctx
            .queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&uniforms));
        let targets = self.targets.as_ref().ok_or(RenderError::NoVolume)?;
        let passes = RaycastPasses {
            pipelines: self.pipelines.for_frame(&self.ctx.device, key)?,
            frame_group: &volume.frame_group,
            targets,
            stats_group: request.stats.then_some(&m.stats_group),
            leap_group: key.strategy.leaps().then_some(&volume.leap_group),
            near_cap: geometry.needs_near_cap,
            background: settings.background,
            rows,
            group_rows: if key.split {
                SPLIT_GROUP_ROWS
            } else {
                WORKGROUP
            },
        };
        passes.record(&mut encoder, slot.as_ref().map(|s| (&m.probes, s)));
        // In the frame's own submission: a separate one upsets lavapipe's timestamps of every
        // later frame (they read ~0.1 ms; seen with Mesa 22.3, not on a data-centre GPU).
        let accumulated = match (accumulate.filter(|_| last), self.refine.as_mut()) {
            (Some(a), Some(acc)) => acc.add(
                &self.ctx,
                &mut encoder,
                &targets.output_view,
                targets.size,
                a == Accumulate::Restart,
            ),
            _ => None,
        };
        m.submit(&self.ctx, encoder, slot);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RenderError::Gpu(e.to_string()));
        }
        let frame = SubmittedFrame {
            frame: m.frames_submitted,
            key,
        };
        Ok((frame, accumulated))
    }

    /// Results of finished frames, oldest first; with `wait`, waits for all submitted frames.
    pub fn collect_results(&mut self, wait: bool) -> Vec<FrameResults> {
        self.measurements.probes.collect(&self.ctx.device, wait)
    }

    /// Whether measurements of submitted frames are still on their way. The window polls
    /// [`Self::collect_results`] without waiting and asks for another pass while this is true.
    pub(crate) fn results_pending(&self) -> bool {
        self.measurements.probes.any_in_flight()
    }

    /// The path `path` stands for: itself, or for `auto` the path chosen on this adapter
    /// ([`RenderError::AutoPathNotChosen`] before [`super::auto_path::choose`] ran).
    pub fn resolve_path(&self, path: RenderPath) -> Result<ConcretePath, RenderError> {
        match path {
            RenderPath::Fragment => Ok(ConcretePath::Fragment),
            RenderPath::Compute => Ok(ConcretePath::Compute),
            RenderPath::Auto => self.auto_path.ok_or(RenderError::AutoPathNotChosen),
        }
    }

    /// The path `auto` stands for, once chosen.
    pub fn auto_path(&self) -> Option<ConcretePath> {
        self.auto_path
    }

    /// Sets the path `auto` stands for (what [`super::auto_path::choose`] measured).
    pub(crate) fn set_auto_path(&mut self, path: ConcretePath) {
        self.auto_path = Some(path);
    }

    /// Whether a frame with `settings` (and statistics when `stats`) can be submitted without
    /// slow work on the CPU first: its path is known (`auto` was timed) and its shader variant is
    /// compiled, for an image of `size` pixels. A window keeps such work off its own thread.
    pub(crate) fn ready_for(&self, settings: &RenderSettings, stats: bool, size: [u32; 2]) -> bool {
        let settings = &self.concrete_settings(settings, size);
        self.resolve_path(settings.path).is_ok_and(|path| {
            self.pipelines.has(
                &PipelineKey::new(settings, path, stats, size)
                    .for_volume(self.has_missing_voxels(), self.is_bricked())
                    .with_labels(self.volume_traits(settings).2),
            )
        })
    }

    /// Compiles the shader variant a frame with `settings` (and statistics when `stats`) needs,
    /// for an image of `size` pixels, if it is not built yet (slow on a CPU driver: a second or
    /// so).
    pub(crate) fn prepare_pipeline(
        &mut self,
        settings: &RenderSettings,
        stats: bool,
        size: [u32; 2],
    ) -> Result<(), RenderError> {
        let settings = &self.concrete_settings(settings, size);
        let key = PipelineKey::new(settings, self.resolve_path(settings.path)?, stats, size)
            .for_volume(self.has_missing_voxels(), self.is_bricked())
            .with_labels(self.volume_traits(settings).2);
        self.pipelines.for_frame(&self.ctx.device, key)?;
        Ok(())
    }

    /// The inputs a choice for the `auto` strategy of a frame with `settings` at `size` would
    /// hold for (the current transfer function's included).
    pub fn choice_key(&self, settings: &RenderSettings, size: [u32; 2]) -> ChoiceKey {
        ChoiceKey::new(settings, size, self.transfer.generation())
    }

    /// The last choice made for the `auto` strategy, if any ([`super::auto_strategy::choose`]).
    pub fn strategy_choice(&self) -> Option<&StrategyChoice> {
        self.strategy_choice.as_ref()
    }

    /// Sets what the `auto` strategy stands for on `choice.key`'s inputs (what
    /// [`super::auto_strategy::choose`] decided).
    pub fn set_strategy_choice(&mut self, choice: StrategyChoice) {
        self.strategy_choice = Some(choice);
    }

    /// `settings` as a frame at `size` renders them: the `auto` strategy replaced by the
    /// strategy chosen for these inputs, or the leaping one where none was
    /// ([`strategy_choice::concrete`]).
    fn concrete_settings(&self, settings: &RenderSettings, size: [u32; 2]) -> RenderSettings {
        let key = self.choice_key(settings, size);
        RenderSettings {
            strategy: strategy_choice::concrete(settings, &key, self.strategy_choice.as_ref()),
            ..*settings
        }
    }

    /// What work the renderer has done so far.
    pub fn work_counts(&self) -> WorkCounts {
        self.measurements.work
    }

    /// The loaded volume's camera-independent description: dims, spacing.
    pub fn volume_geometry(&self) -> Option<([u32; 3], [f64; 3])> {
        self.volume.as_ref().map(|v| (v.dims, v.spacing_mm))
    }

    /// The leaping structures of the current volume (for tests and diagnostics).
    pub fn leap_structures(&self) -> Option<&LeapStructures> {
        self.volume.as_ref().map(|v| &v.leap)
    }

    /// The refinement mean's accumulator, once a frame was added to one.
    pub(super) fn refinement(&self) -> Option<&Accumulator> {
        self.refine.as_ref()
    }
}
