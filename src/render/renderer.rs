//! The long-lived volume renderer: owns the GPU resources that change with the volume, the
//! transfer function or the viewport size, builds pipeline variants on demand, and records a
//! frame's passes. The window, the command line and the tests all render through it.

use crate::camera::Camera;
use crate::imaging::ImageF32;
use crate::transfer::{TransferFunction, lut, preintegration};
use crate::volume::{ValueRange, Volume};

use super::context::GpuContext;
use super::leap::{FlagRule, LeapPipelines, LeapStructures};
use super::lut_texture::TableTexture;
use super::pipelines::{
    ConcretePath, Layouts, PipelineCache, PipelineKey, ProxyPipelines, RaycastPipeline, WORKGROUP,
};
use super::probe::{FrameResults, ProbePool, ProbeSlot};
use super::readback::read_texture;
use super::refine::{self, Accumulator};
use super::settings::{Mode, RenderPath, RenderSettings, SettingsError, Strategy};
use super::shader::ShaderError;
use super::targets::Targets;
use super::uniforms::{FrameGeometry, FrameUniforms, LeapLevels, SampleDecoding, frame_uniforms};
use super::volume_texture::{TexturePrecision, VolumeTexture, VolumeTextureError};

/// Why a frame could not be rendered.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// `render` was called before any volume was set.
    #[error("no volume is loaded")]
    NoVolume,
    /// A setting is out of range.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// The image is larger than the adapter's 2D texture limit (or empty).
    #[error(
        "an image of {width}×{height} pixels is not possible on this GPU ({adapter}): each side must be 1 to {max}"
    )]
    ImageSize {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
        /// The adapter's `max_texture_dimension_2d`.
        max: u32,
        /// Adapter name.
        adapter: String,
    },
    /// The volume could not be put on the GPU.
    #[error(transparent)]
    Volume(#[from] VolumeTextureError),
    /// A shader module is malformed (a bug).
    #[error("internal shader error: {0}")]
    Shader(#[from] ShaderError),
    /// The GPU reported an error while rendering.
    #[error("the GPU reported an error: {0}")]
    Gpu(String),
}

/// One frame to render.
#[derive(Clone, Copy, Debug)]
pub struct FrameRequest<'a> {
    /// Camera in world millimetres.
    pub camera: &'a Camera,
    /// Image size in pixels.
    pub size: [u32; 2],
    /// Mode, strategy, path and quality knobs.
    pub settings: &'a RenderSettings,
    /// Use the statistics variant (counts samples; slower).
    pub stats: bool,
}

/// What was submitted for a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubmittedFrame {
    /// Sequence number (matches [`FrameResults::frame`]).
    pub frame: u64,
    /// The pipeline variant used.
    pub key: PipelineKey,
}

struct LoadedVolume {
    texture: VolumeTexture,
    dims: [u32; 3],
    spacing_mm: [f64; 3],
    range: ValueRange,
}

/// The renderer. See the module documentation.
pub struct VolumeRenderer {
    ctx: GpuContext,
    layouts: Layouts,
    proxy: ProxyPipelines,
    pipelines: PipelineCache,
    sampler: wgpu::Sampler,
    uniforms: wgpu::Buffer,
    lut: TableTexture,
    integrals: TableTexture,
    /// Transfer-function generation the integral table was built for; `None` = stale.
    integrals_built_for: Option<u64>,
    volume: Option<LoadedVolume>,
    frame_group: Option<wgpu::BindGroup>,
    transfer: TransferFunction,
    /// (transfer-function generation, step) the table was baked for; `None` = stale.
    lut_baked_for: Option<(u64, u64)>,
    transfer_generation: u64,
    targets: Option<(Targets, wgpu::BindGroup, wgpu::BindGroup)>,
    stats_group: wgpu::BindGroup,
    probes: ProbePool,
    frame_counter: u64,
    leap_pipelines: LeapPipelines,
    /// Leaping structures of the current volume (built lazily) and their ray-loop bind group.
    leap: Option<(LeapStructures, wgpu::BindGroup)>,
    pub(super) auto_path: Option<ConcretePath>,
    work: WorkCounts,
    /// The running mean of progressive refinement (built on first use).
    refine: Option<Accumulator>,
}

/// How often the renderer did each piece of work since it was made: what tests read to prove
/// that nothing is recomputed that did not change.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WorkCounts {
    /// Frames submitted.
    pub frames: u64,
    /// Lookup tables baked and uploaded (transfer function, value range or step changed).
    pub lut_bakes: u64,
    /// Min/max pyramids built (once per volume, on the first leaping frame).
    pub minmax_builds: u64,
    /// Emptiness tables and node flags built (transfer function, or the X-ray window for the
    /// distance field, changed).
    pub flag_builds: u64,
    /// Distance fields built (flags or block size changed).
    pub distance_builds: u64,
    /// Pre-integration tables built (transfer function or value range changed while
    /// pre-integration is on).
    pub integral_builds: u64,
}

impl VolumeRenderer {
    /// Creates the renderer's long-lived resources on `ctx`.
    pub fn new(ctx: GpuContext) -> Result<Self, RenderError> {
        let device = &ctx.device;
        let layouts = Layouts::new(device);
        let proxy = ProxyPipelines::new(device, &layouts)?;
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
        let leap_pipelines = LeapPipelines::new(device)?;
        let stats_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("stats"),
            layout: &layouts.stats,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: probes.counters.as_entire_binding(),
            }],
        });
        Ok(Self {
            lut: TableTexture::lut(&ctx, lut::LUT_SIZE as u32),
            integrals: TableTexture::integrals(&ctx, lut::LUT_SIZE as u32),
            integrals_built_for: None,
            ctx,
            layouts,
            proxy,
            pipelines: PipelineCache::default(),
            sampler,
            uniforms,
            volume: None,
            frame_group: None,
            transfer: TransferFunction::grey_ramp(),
            lut_baked_for: None,
            transfer_generation: 0,
            targets: None,
            stats_group,
            probes,
            frame_counter: 0,
            work: WorkCounts::default(),
            leap_pipelines,
            leap: None,
            auto_path: None,
            refine: None,
        })
    }

    /// The device the renderer works on.
    pub fn context(&self) -> &GpuContext {
        &self.ctx
    }

    /// Uploads `volume`, replacing the current one. On error the current volume stays.
    pub fn set_volume(&mut self, volume: &Volume) -> Result<(), RenderError> {
        self.set_volume_with(volume, TexturePrecision::Auto)
    }

    /// [`Self::set_volume`] with the texel precision forced (the accuracy benchmark's knob).
    pub fn set_volume_with(
        &mut self,
        volume: &Volume,
        precision: TexturePrecision,
    ) -> Result<(), RenderError> {
        let texture = VolumeTexture::upload_with(&self.ctx, volume, precision)?;
        self.frame_group = Some(
            self.ctx
                .device
                .create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("frame"),
                    layout: &self.layouts.frame,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: self.uniforms.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::TextureView(&texture.view),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: wgpu::BindingResource::Sampler(&self.sampler),
                        },
                        wgpu::BindGroupEntry {
                            binding: 3,
                            resource: wgpu::BindingResource::TextureView(&self.lut.view),
                        },
                        wgpu::BindGroupEntry {
                            binding: 4,
                            resource: wgpu::BindingResource::TextureView(&self.integrals.view),
                        },
                    ],
                }),
        );
        let structures = LeapStructures::new(
            &self.ctx,
            volume.dims(),
            texture.encoding.scale,
            texture.encoding.bias,
        );
        let group = structures.march_group(&self.ctx.device, &self.layouts.leap);
        self.leap = Some((structures, group));
        self.volume = Some(LoadedVolume {
            texture,
            dims: volume.dims(),
            spacing_mm: volume.spacing_mm(),
            range: volume.normalization_range(),
        });
        self.lut_baked_for = None;
        self.integrals_built_for = None;
        Ok(())
    }

    /// Whether a volume is loaded.
    pub fn has_volume(&self) -> bool {
        self.volume.is_some()
    }

    /// Sets the transfer function; the table is re-baked before the next frame.
    pub fn set_transfer_function(&mut self, transfer: &TransferFunction) {
        if *transfer != self.transfer {
            self.transfer = transfer.clone();
            self.transfer_generation += 1;
        }
    }

    /// The current transfer function.
    pub fn transfer_function(&self) -> &TransferFunction {
        &self.transfer
    }

    /// Re-bakes the lookup table when the transfer function, volume range or step changed.
    fn refresh_lut(&mut self, step_vox: f64) {
        let Some(volume) = &self.volume else { return };
        let wanted = (self.transfer_generation, step_vox.to_bits());
        if self.lut_baked_for != Some(wanted) {
            let table = lut::bake(&self.transfer, volume.range, step_vox);
            self.lut.write(&self.ctx.queue, &table);
            self.lut_baked_for = Some(wanted);
            self.work.lut_bakes += 1;
        }
    }

    /// Rebuilds the pre-integration table when the transfer function or volume range changed
    /// (it does not depend on the step).
    fn refresh_integrals(&mut self) {
        let Some(volume) = &self.volume else { return };
        if self.integrals_built_for != Some(self.transfer_generation) {
            let rows = preintegration::integral_table(&self.transfer, volume.range);
            self.integrals.write(&self.ctx.queue, &rows);
            self.integrals_built_for = Some(self.transfer_generation);
            self.work.integral_builds += 1;
        }
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
        if self
            .targets
            .as_ref()
            .is_some_and(|(t, _, _)| t.size == size)
        {
            return Ok(());
        }
        let device = &self.ctx.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let targets = Targets::new(device, size);
        let view = |v| wgpu::BindingResource::TextureView(v);
        let fragment_io = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("fragment io"),
            layout: &self.layouts.fragment_io,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: view(&targets.exit),
            }],
        });
        let compute_io = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("compute io"),
            layout: &self.layouts.compute_io,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: view(&targets.output_view),
            }],
        });
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RenderError::Gpu(format!(
                "out of GPU memory for a {}×{} image: {e}",
                size[0], size[1]
            )));
        }
        self.targets = Some((targets, fragment_io, compute_io));
        Ok(())
    }

    /// Records and submits one frame. Its measurements arrive through [`Self::collect_results`].
    pub fn render(&mut self, request: &FrameRequest) -> Result<SubmittedFrame, RenderError> {
        self.render_with(request, None).map(|(frame, _)| frame)
    }

    /// [`Self::render`], adding the frame to the refinement mean in the same submission when
    /// `accumulate` says so (`Some(true)`: as its first frame); returns the frames the mean
    /// then holds (`None`: not added).
    fn render_with(
        &mut self,
        request: &FrameRequest,
        accumulate: Option<bool>,
    ) -> Result<(SubmittedFrame, Option<u32>), RenderError> {
        request.settings.validate()?;
        let path = self.resolve_path(request.settings.path)?;
        let key = PipelineKey::new(request.settings, path, request.stats);
        self.ensure_targets(request.size)?;
        self.refresh_lut(request.settings.opacity_step_vox());
        if request.settings.preintegrated && request.settings.mode == Mode::Dvr {
            self.refresh_integrals();
        }
        let Some(volume) = &self.volume else {
            return Err(RenderError::NoVolume);
        };
        let geometry =
            FrameGeometry::new(request.camera, request.size, volume.dims, volume.spacing_mm);
        let decoding = SampleDecoding {
            texel_scale: volume.texture.encoding.scale,
            texel_bias: volume.texture.encoding.bias,
            lut_size: self.lut.entries(),
            range: volume.range,
        };
        let uniforms = frame_uniforms(
            &geometry,
            request.size,
            volume.dims,
            volume.spacing_mm,
            request.settings,
            decoding,
            LeapLevels::default(),
        );
        let scope = self
            .ctx
            .device
            .push_error_scope(wgpu::ErrorFilter::Validation);
        self.frame_counter += 1;
        self.work.frames += 1;
        let slot = self.probes.acquire(self.frame_counter, request.stats);
        let mut encoder = self
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("frame"),
            });
        if request.stats {
            self.probes.clear_counters(&mut encoder);
        }
        let leap_levels = if key.strategy.leaps() {
            self.prepare_leaping(
                &mut encoder,
                slot.as_ref(),
                request.settings,
                uniforms.window[0],
            )
        } else {
            LeapLevels::default()
        };
        let uniforms = FrameUniforms {
            leaf_level: leap_levels.leaf_level,
            level_count: leap_levels.level_count,
            ..uniforms
        };
        self.ctx
            .queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&uniforms));
        let device = &self.ctx.device;
        let pipeline = self.pipelines.get(device, &self.layouts, key)?;
        let (Some((targets, fragment_io, compute_io)), Some(frame_group)) =
            (&self.targets, &self.frame_group)
        else {
            return Err(RenderError::NoVolume);
        };
        let leap_group = self
            .leap
            .as_ref()
            .map(|(_, g)| g)
            .filter(|_| key.strategy.leaps());
        let proxy_vertices = if geometry.needs_near_cap {
            0..39
        } else {
            0..36
        };
        let bg = request.settings.background;
        let background = wgpu::Color {
            r: bg[0],
            g: bg[1],
            b: bg[2],
            a: 1.0,
        };
        let timestamps = |first, last| {
            slot.as_ref()
                .and_then(|s| self.probes.render_timestamps(s, first, last))
        };
        match pipeline {
            RaycastPipeline::Fragment(raycast) => {
                // Pass 1: back faces → exit points.
                {
                    let mut pass = begin_pass(
                        &mut encoder,
                        &targets.exit,
                        wgpu::Color::TRANSPARENT,
                        timestamps(true, false),
                        "exit points",
                    );
                    pass.set_pipeline(&self.proxy.exit);
                    pass.set_bind_group(0, frame_group, &[]);
                    pass.draw(0..36, 0..1);
                }
                // Pass 2: front faces (and the near cap) run the ray loop.
                let mut pass = begin_pass(
                    &mut encoder,
                    &targets.output_view,
                    background,
                    timestamps(false, true),
                    "ray cast",
                );
                pass.set_pipeline(raycast);
                pass.set_bind_group(0, frame_group, &[]);
                pass.set_bind_group(1, fragment_io, &[]);
                if request.stats {
                    pass.set_bind_group(2, &self.stats_group, &[]);
                }
                if let Some(g) = leap_group {
                    pass.set_bind_group(3, g, &[]);
                }
                pass.draw(proxy_vertices, 0..1);
            }
            RaycastPipeline::Compute(raycast) => {
                // One pass: each invocation intersects its ray with the box.
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("ray cast"),
                    timestamp_writes: slot
                        .as_ref()
                        .and_then(|s| self.probes.compute_timestamps(s, true)),
                });
                pass.set_pipeline(raycast);
                pass.set_bind_group(0, frame_group, &[]);
                pass.set_bind_group(1, compute_io, &[]);
                if request.stats {
                    pass.set_bind_group(2, &self.stats_group, &[]);
                }
                if let Some(g) = leap_group {
                    pass.set_bind_group(3, g, &[]);
                }
                pass.dispatch_workgroups(
                    request.size[0].div_ceil(WORKGROUP),
                    request.size[1].div_ceil(WORKGROUP),
                    1,
                );
            }
        }
        // In the frame's own submission: a separate one upsets lavapipe's timestamps of every
        // later frame (they read ~0.1 ms; seen with Mesa 22.3, not on the H100).
        let accumulated = match (accumulate, self.refine.as_mut()) {
            (Some(restart), Some(acc)) => acc.add(
                &self.ctx,
                &mut encoder,
                &targets.output_view,
                targets.size,
                restart,
            ),
            _ => None,
        };
        if let Some(s) = &slot {
            self.probes.finish(s, &mut encoder);
        }
        self.ctx.queue.submit([encoder.finish()]);
        if let Some(s) = slot {
            self.probes.submitted(s);
        }
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RenderError::Gpu(e.to_string()));
        }
        let frame = SubmittedFrame {
            frame: self.frame_counter,
            key,
        };
        Ok((frame, accumulated))
    }

    /// Results of finished frames, oldest first; with `wait`, waits for all submitted frames.
    pub fn collect_results(&mut self, wait: bool) -> Vec<FrameResults> {
        self.probes.collect(&self.ctx.device, wait)
    }

    /// Whether measurements of submitted frames are still on their way. The window polls
    /// [`Self::collect_results`] without waiting and asks for another pass while this is true.
    pub fn results_pending(&self) -> bool {
        self.probes.any_in_flight()
    }

    /// Renders a frame and waits for its measurements.
    pub fn render_and_wait(
        &mut self,
        request: &FrameRequest,
    ) -> Result<(SubmittedFrame, FrameResults), RenderError> {
        let submitted = self.render(request)?;
        let results = self.collect_results(true);
        let mine = results
            .into_iter()
            .find(|r| r.frame == submitted.frame)
            .unwrap_or_default();
        Ok((submitted, mine))
    }

    /// The rendered image's view (for display in the window), once a frame was rendered.
    pub fn output_view(&self) -> Option<&wgpu::TextureView> {
        self.targets.as_ref().map(|(t, _, _)| &t.output_view)
    }

    /// Copies the last rendered image to the CPU (waits for the GPU).
    pub fn read_image(&self) -> Result<ImageF32, RenderError> {
        let (targets, _, _) = self.targets.as_ref().ok_or(RenderError::NoVolume)?;
        read_texture(&self.ctx, &targets.output, targets.size).map_err(RenderError::Gpu)
    }

    /// Resolves `auto` to the faster path on this adapter (measured once, then remembered).
    pub fn resolve_path(&mut self, path: RenderPath) -> Result<ConcretePath, RenderError> {
        match path {
            RenderPath::Fragment => Ok(ConcretePath::Fragment),
            RenderPath::Compute => Ok(ConcretePath::Compute),
            RenderPath::Auto => match self.auto_path {
                Some(p) => Ok(p),
                None => {
                    let p = super::auto_path::calibrate(self)?;
                    self.auto_path = Some(p);
                    Ok(p)
                }
            },
        }
    }

    /// Number of pipeline variants built so far.
    pub fn pipeline_count(&self) -> usize {
        self.pipelines.len()
    }
}

fn begin_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    view: &wgpu::TextureView,
    clear: wgpu::Color,
    timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    label: &str,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(clear),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: timestamps,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

impl VolumeRenderer {
    /// Records whatever the leaping structures still need for this frame and returns the levels
    /// the ray loop uses: the pyramid once per volume; node flags when the rule they follow
    /// changed (DVR: the transfer function; X-ray with the distance field: the window); the
    /// distance field when its flags or the block size changed. MIP, MinIP, isosurfaces and
    /// octree X-ray read the min/max pyramid directly.
    fn prepare_leaping(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        slot: Option<&ProbeSlot>,
        settings: &RenderSettings,
        window_lo: f32,
    ) -> LeapLevels {
        let (Some((leap, _)), Some(volume)) = (&mut self.leap, &self.volume) else {
            return LeapLevels::default();
        };
        // validate() admitted only sizes the pyramid has.
        let leaf = leap.pyramid.level_of_block(settings.block_vox).unwrap_or(0) as u32;
        if leap.build_minmax(
            &self.ctx,
            &self.leap_pipelines,
            &volume.texture.view,
            encoder,
        ) {
            self.work.minmax_builds += 1;
        }
        let levels = LeapLevels {
            leaf_level: leaf,
            level_count: leap.level_count(),
        };
        let distance = settings.strategy.for_mode(settings.mode) == Strategy::RcSDistance;
        let rule = match settings.mode {
            Mode::Dvr => FlagRule::Transfer(self.transfer_generation),
            Mode::Xray | Mode::XrayAttenuation if distance => FlagRule::AtMost(window_lo.to_bits()),
            _ => return levels,
        };
        let need_flags = leap.flags_for != Some(rule);
        let need_distance = distance && (need_flags || leap.distance_for != Some((rule, leaf)));
        if need_flags {
            let ts = slot.and_then(|s| self.probes.rebuild_timestamps(s, true, !need_distance));
            leap.build_flags(
                &self.ctx,
                &self.leap_pipelines,
                rule,
                &self.lut,
                encoder,
                ts,
            );
            self.work.flag_builds += 1;
        }
        if need_distance {
            let ts = slot.and_then(|s| self.probes.rebuild_timestamps(s, !need_flags, true));
            leap.build_distance(&self.ctx, &self.leap_pipelines, leaf, encoder, ts);
            self.work.distance_builds += 1;
        }
        levels
    }

    /// What work the renderer has done so far.
    pub fn work_counts(&self) -> WorkCounts {
        self.work
    }

    /// The loaded volume's camera-independent description: dims, spacing.
    pub fn volume_geometry(&self) -> Option<([u32; 3], [f64; 3])> {
        self.volume.as_ref().map(|v| (v.dims, v.spacing_mm))
    }

    /// Renders `camera` at `size` and returns the image (waits for the GPU).
    pub fn render_image(
        &mut self,
        camera: &Camera,
        size: [u32; 2],
        settings: &RenderSettings,
    ) -> Result<ImageF32, RenderError> {
        self.render(&FrameRequest {
            camera,
            size,
            settings,
            stats: false,
        })?;
        self.read_image()
    }
}

impl VolumeRenderer {
    /// Renders `request` and adds it to the refinement mean (`restart`: as its first frame);
    /// returns the frame and the frames the mean holds, `None` when the image is too large for
    /// the per-pixel sums (more than the device's largest storage buffer: 128 MiB, 8.4 M pixels,
    /// by default).
    pub fn render_accumulated(
        &mut self,
        request: &FrameRequest,
        restart: bool,
    ) -> Result<(SubmittedFrame, Option<u32>), RenderError> {
        if self.refine.is_none() {
            self.refine = Some(Accumulator::new(&self.ctx.device)?);
        }
        self.render_with(request, Some(restart))
    }

    /// Whether any frame was ever added to a refinement mean.
    pub fn has_accumulated(&self) -> bool {
        self.refine.as_ref().is_some_and(|a| a.count() > 0)
    }

    /// The refinement mean's view (for display), once a frame was added to it.
    pub fn refined_view(&self) -> Option<&wgpu::TextureView> {
        self.refine.as_ref()?.mean().map(|(_, view, _)| view)
    }

    /// Copies the refinement mean to the CPU (waits for the GPU).
    pub fn read_refined(&self) -> Result<ImageF32, RenderError> {
        let (texture, _, size) = self
            .refine
            .as_ref()
            .and_then(Accumulator::mean)
            .ok_or(RenderError::NoVolume)?;
        read_texture(&self.ctx, texture, size).map_err(RenderError::Gpu)
    }

    /// Renders `frames` frames of the view at the offsets of [`refine::offset`] and returns
    /// their mean (one plain frame for `frames` ≤ 1, or when the image is too large for the
    /// sums: then with a warning in the log).
    pub fn render_refined(
        &mut self,
        camera: &Camera,
        size: [u32; 2],
        settings: &RenderSettings,
        frames: u32,
    ) -> Result<ImageF32, RenderError> {
        if frames <= 1 {
            return self.render_image(camera, size, settings);
        }
        for k in 0..frames {
            let shifted = RenderSettings {
                sample_offset: refine::offset(k),
                ..*settings
            };
            let request = FrameRequest {
                camera,
                size,
                settings: &shifted,
                stats: false,
            };
            if self.render_accumulated(&request, k == 0)?.1.is_none() {
                log::warn!(
                    "a {}×{} image is too large to refine; rendered once",
                    size[0],
                    size[1]
                );
                return self.render_image(camera, size, settings);
            }
        }
        // The frames' timings are nobody's: free their probes for the frames that follow.
        self.collect_results(true);
        self.read_refined()
    }

    /// The leaping structures of the current volume (for tests and diagnostics).
    pub fn leap_structures(&self) -> Option<&LeapStructures> {
        self.leap.as_ref().map(|(l, _)| l)
    }
}
