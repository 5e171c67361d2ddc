//! The volume on screen: the window's one [`VolumeRenderer`] (run by the band pump,
//! [`crate::ui::frames::band_pump`]), the camera, the egui texture the image is shown through, and the frame
//! bookkeeping — render only when the inputs changed, in bands that never keep the GPU (and so
//! the window) busy for long ([`crate::ui::frames::frame_job`]), refine a still view, frames per second, GPU
//! time of the last frame.

mod labels;
mod readout;

use std::sync::Arc;
use std::time::Instant;

use egui::mutex::RwLock;

use crate::camera::ProjectionKind;
use crate::imaging::ImageF32;
use crate::render::{GpuContext, RenderError, VolumeRenderer};
use crate::volume::Volume;

use crate::ui::frames::band_pump::{BandPump, Busy, Finished, Shared, lock, try_lock};
use crate::ui::frames::frame_job::{FrameJob, JobKind};
use crate::ui::frames::frame_stats::FrameStats;
use crate::ui::frames::framing::Framing;
use crate::ui::frames::lod::{STILL_AFTER, scaled_size};
use crate::ui::frames::redraw::{FrameInputs, RedrawTracker};
use crate::ui::frames::shown::ShownFrame;
use crate::ui::{ViewerState, VolumeSummary};

/// How long one frame may upload bricks of a volume larger than the GPU memory budget before it
/// renders what is resident (a coarser level where a brick is still missing); the frames after
/// it upload the rest. A choice: a 60 Hz frame's budget less the rendering's.
const BRICK_UPLOAD_PER_FRAME: std::time::Duration = std::time::Duration::from_millis(8);

/// The renderer and everything about the frame on screen.
pub struct Scene {
    pump: BandPump,
    device: wgpu::Device,
    queue: wgpu::Queue,
    egui_renderer: Arc<RwLock<egui_wgpu::Renderer>>,
    adapter_label: String,
    /// Whether the adapter's GPU timestamps can be shown at all (it has timestamp queries).
    has_timestamps: bool,
    /// Whether the adapter is a CPU driver (whose timestamps go wrong after a refinement).
    cpu_adapter: bool,
    /// The camera and the volume it frames.
    framing: Framing,
    redraw: RedrawTracker,
    /// What the window measured of its frames.
    stats: FrameStats,
    /// The inputs a frame was last started again for, to time `auto` once the user was quiet
    /// (once per inputs, so that a timing that fails is not retried on every pass).
    retimed_for: Option<FrameInputs>,
    quiet_passes: u32,
    /// The slice planes shown, given to the renderer before each frame.
    slice_planes: Vec<crate::render::volume_texture::SlicePlane>,
    /// Bumped when the renderer took new slice planes.
    slice_generation: u64,
    /// The renderer's page-table generation when the last frame finished.
    pages_generation: u64,
    /// What the view shows.
    shown: ShownFrame,
    /// When the user last did anything (pointer, keys, wheel): refinement waits for quiet.
    last_input: Option<Instant>,
    /// What the renderer is doing while the window cannot reach it (the pump holds it), and
    /// the frame in progress, as seen in the last pass that could look.
    busy: Busy,
    /// A frame that failed, for the next pass to report.
    error: Option<String>,
    /// The segmentation shown in 3D.
    labels: labels::SceneLabels,
}

impl Scene {
    /// Creates the renderer on eframe's device and starts its band pump (which asks `ctx` to
    /// draw when a frame is finished).
    pub fn new(rs: &egui_wgpu::RenderState, ctx: &egui::Context) -> Result<Self, RenderError> {
        let gpu = GpuContext::new(&rs.adapter, rs.device.clone(), rs.queue.clone());
        let info = &gpu.adapter_info;
        let adapter_label = format!("{} ({:?})", info.name, info.backend);
        let cpu_adapter = info.device_type == wgpu::DeviceType::Cpu;
        let has_timestamps = gpu.has_timestamps();
        log::info!("window GPU: {}", gpu.adapter_summary());
        let mut renderer = VolumeRenderer::new(gpu)?;
        // Bricks stream in: a frame uploads for at most this long, then shows what is there.
        renderer.set_residency_time(Some(BRICK_UPLOAD_PER_FRAME));
        let pump = BandPump::start(renderer, ctx.clone())
            .map_err(|e| RenderError::Gpu(format!("cannot start the render thread: {e}")))?;
        Ok(Self {
            pump,
            device: rs.device.clone(),
            queue: rs.queue.clone(),
            egui_renderer: rs.renderer.clone(),
            adapter_label,
            has_timestamps,
            cpu_adapter,
            framing: Framing::default(),
            redraw: RedrawTracker::default(),
            stats: FrameStats::new(),
            retimed_for: None,
            quiet_passes: 0,
            slice_planes: Vec::new(),
            slice_generation: 0,
            pages_generation: 0,
            shown: ShownFrame::default(),
            last_input: None,
            busy: Busy::default(),
            error: None,
            labels: labels::SceneLabels::default(),
        })
    }

    /// The segmentation to show in 3D this pass (`None`: none), with the generation of its
    /// visibility: the renderer takes it before the next frame.
    pub(crate) fn offer_labels(
        &mut self,
        labels: Option<(Arc<crate::render::labels::GpuLabels>, u64)>,
    ) {
        self.labels.offer(labels);
    }

    /// Uploads `volume` (`from_file`: read from a file, not generated) and frames it in the
    /// default view. On error the old volume stays. Waits for the pump if it is preparing a
    /// frame.
    pub(crate) fn show_volume(
        &mut self,
        volume: &std::sync::Arc<Volume>,
        (projection, gpu_budget): (ProjectionKind, Option<u64>),
        from_file: bool,
    ) -> Result<&VolumeSummary, RenderError> {
        let started = std::time::Instant::now();
        let (coarser, gpu_layout, residency) = {
            let handle = self.pump.handle();
            let mut shared = lock(&handle);
            shared.job = None;
            let upload = crate::settings::Upload {
                gpu_budget,
                ..Default::default()
            };
            shared.renderer.set_volume_with(volume, &upload)?;
            shared.lod.forget();
            let texture = shared.renderer.volume_texture();
            (
                texture.and_then(|t| t.coarser.clone()),
                texture.map(|t| t.describe()),
                texture.and_then(|t| t.residency_line()),
            )
        };
        log::info!(
            "uploaded {} in {:.0} ms",
            volume.name(),
            started.elapsed().as_secs_f64() * 1e3
        );
        let summary = VolumeSummary {
            from_file,
            coarser,
            gpu_layout,
            residency,
            ..VolumeSummary::of(volume)
        };
        self.framing.show(summary, projection);
        self.labels.volume_changed();
        let summary = self.framing.volume().ok_or(RenderError::NoVolume)?;
        log::info!("showing {}: {}", summary.name, summary.line());
        Ok(summary)
    }

    /// The volume's texture on the GPU and its format (the slice views sample it too).
    pub fn volume_texture(
        &self,
    ) -> Option<(
        crate::render::volume_texture::VolumeView,
        wgpu::TextureFormat,
    )> {
        let handle = self.pump.handle();
        let shared = lock(&handle);
        shared
            .renderer
            .volume_texture()
            .map(|t| (t.slice_view(), t.encoding.format))
    }

    /// Sets the slice planes shown (continuous voxel coordinates; none when no slice is
    /// shown): the next frame keeps their bricks resident.
    pub(crate) fn set_slice_planes(
        &mut self,
        planes: Vec<crate::render::volume_texture::SlicePlane>,
    ) {
        self.slice_planes = planes;
    }

    /// The renderer's page-table generation when the last frame finished (the slices redraw
    /// when it changes).
    pub(crate) fn pages_generation(&self) -> u64 {
        self.pages_generation
    }

    /// The volume on screen.
    pub fn volume(&self) -> Option<&VolumeSummary> {
        self.framing.volume()
    }

    /// The camera, the volume's box and its summary.
    pub fn framing(&self) -> &Framing {
        &self.framing
    }

    /// The camera, the volume's box and its summary, to change the view.
    pub(crate) fn framing_mut(&mut self) -> &mut Framing {
        &mut self.framing
    }

    /// Takes what the pump finished and the GPU measurements that arrived; returns whether more
    /// are on their way. Looks only when the pump is not preparing a frame (no pass waits).
    pub(crate) fn collect_measurements(&mut self) -> bool {
        let handle = self.pump.handle();
        let Some(mut shared) = try_lock(&handle) else {
            // Whoever holds the renderer (the pump preparing a frame, an image being saved) asks
            // for a pass when done: no polling meanwhile, each pass would cost the GPU's time.
            return false;
        };
        // Finished frames first: the timings that follow may be of their bands.
        self.take_finished(&mut shared);
        self.take_results(&mut shared);
        // While the GPU works on a frame the pump asks for a pass when it is done; after that the
        // last timings are polled for (their read-back is all that is left).
        shared.renderer.results_pending() && shared.job.is_none() && shared.in_flight.is_none()
    }

    /// Shows the frames the pump finished, notes its error and its state.
    fn take_finished(&mut self, shared: &mut Shared) {
        for f in std::mem::take(&mut shared.finished) {
            self.complete(f, shared);
        }
        if let Some(e) = shared.error.take() {
            log::error!("{e}");
            self.error = Some(e);
        }
        self.busy = shared.busy();
    }

    /// GPU timings of finished bands: the last plain frame's time adds up over its bands.
    fn take_results(&mut self, shared: &mut Shared) {
        for result in shared.renderer.collect_results(false) {
            self.stats.take(result);
        }
    }

    /// Starts rendering the current view at `size` pixels at full quality and writing it to
    /// `path`, on a thread of its own ([`crate::ui::frames::band_pump::save_still`]); the outcome, a line
    /// for the user, arrives on the returned channel. The window's frame in progress starts
    /// again afterwards.
    pub(crate) fn save_still(
        &mut self,
        state: &ViewerState,
        size: [u32; 2],
        path: std::path::PathBuf,
        ctx: &egui::Context,
    ) -> Result<std::sync::mpsc::Receiver<Result<String, String>>, String> {
        let camera = self.framing.camera().ok_or("no volume on screen")?;
        let still = crate::ui::frames::band_pump::Still {
            camera,
            size,
            settings: refinable(state.render, state.refine_frames > 1),
            transfer: state.editor.tf().clone(),
            frames: state.refine_frames,
            path,
        };
        // The still leaves the renderer's output at its size: the view renders again after it.
        self.redraw.invalidate();
        crate::ui::frames::band_pump::save_still(self.pump.handle(), still, ctx.clone())
    }

    /// Notes that the user did something this pass (pointer, keys, wheel): a refinement frame
    /// in progress is dropped, and refinement waits until the user has been quiet for
    /// [`STILL_AFTER`].
    pub(crate) fn note_input(&mut self) {
        self.last_input = Some(Instant::now());
        if !self
            .busy
            .frame
            .is_some_and(|f| f.kind == JobKind::Refinement)
        {
            return;
        }
        let handle = self.pump.handle();
        if let Some(mut shared) = try_lock(&handle)
            && matches!(
                shared.job.as_ref().map(|j| j.kind),
                Some(JobKind::Refinement)
            )
        {
            log::debug!("refinement frame dropped on input");
            shared.job = None;
            self.busy = shared.busy();
        }
    }

    /// Moves the view's frame on: starts a frame when anything it depends on changed since the
    /// last one (at a reduced resolution while `interacting` if a full frame would miss the
    /// budget, and the state allows it; else at full resolution, so a preview left on screen is
    /// replaced as soon as the user stops), or the next refinement frame once the user is quiet;
    /// submits its first band at once where that needs no slow CPU work, and leaves the rest to
    /// the pump. Returns whether a frame was started; an error is a one-line message for the
    /// user. When the pump is preparing a frame, nothing happens this pass.
    pub(crate) fn render_if_changed(
        &mut self,
        state: &mut ViewerState,
        view_px: [u32; 2],
        interacting: bool,
    ) -> Result<bool, String> {
        let Some(camera) = self.framing.camera() else {
            return Ok(false);
        };
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        let handle = self.pump.handle();
        let Some(mut shared) = try_lock(&handle) else {
            return Ok(false);
        };
        shared.last_input = self.last_input;
        let scale = if state.interaction_lod {
            shared.lod.scale(view_px, interacting)
        } else {
            1.0
        };
        self.stats.frame_ms = shared.lod.predicted_ms(view_px);
        let size_px = scaled_size(view_px, scale);
        if !shared.renderer.has_volume() || size_px.contains(&0) {
            return Ok(false);
        }
        if shared.renderer.set_slice_planes(&self.slice_planes) {
            self.slice_generation += 1;
        }
        self.labels.apply(&mut shared.renderer)?;
        let changed = shared.renderer.set_transfer_function(state.editor.tf());
        self.stats.transfer_given(changed);
        let inputs = FrameInputs {
            camera,
            size_px,
            // Jittered whenever refinement is on, previews too: one set of settings for every
            // frame of a view, so `auto` times one choice.
            settings: refinable(state.render, state.refine_frames > 1),
            transfer_generation: shared.renderer.transfer_generation(),
            volume_generation: self.framing.generation(),
            bricks_generation: shared.renderer.bricks_generation(),
            labels_generation: self.labels.generation,
            slices_generation: if shared.renderer.residency_culls() {
                self.slice_generation
            } else {
                0
            },
            stats: state.statistics,
        };
        let preview_of = (size_px != view_px).then_some(view_px);
        // While the user drags, a frame in progress finishes and the newest inputs follow it:
        // dropping it for every pointer move would leave nothing new on screen until the user
        // stops. Only a full-resolution frame gives way at once to the first preview.
        let finish_first = interacting
            && shared.job.as_ref().is_some_and(|j| {
                matches!(j.kind, JobKind::Plain { .. })
                    && !j.bands.is_empty()
                    && (j.preview_of.is_some() || preview_of.is_none())
            });
        // Bricks that arrived while a frame was in progress show in the next one: the frame in
        // progress finishes (dropping it would upload and restart for ever).
        let bricks_only = shared.job.as_ref().is_some_and(|j| {
            j.inputs.bricks_generation != inputs.bricks_generation
                && FrameInputs {
                    bricks_generation: inputs.bricks_generation,
                    ..j.inputs.clone()
                } == inputs
        });
        let finish_first = finish_first || bricks_only;
        // `auto` carried its last choice over for the frame on screen while the user was busy,
        // and no refinement frame will come to time it (refinement off, statistics on): the view
        // is rendered again now that they are quiet, timed first.
        let retime = shared.job.is_none() && self.wants_retiming(&inputs);
        let started = if (self.redraw.needs_render(&inputs) && !finish_first) || retime {
            if retime {
                log::debug!("frame rendered again to time the auto strategy");
                self.retimed_for = Some(inputs.clone());
            }
            // Marked even if the frame fails, so a failing frame is not retried on every pass.
            self.redraw.mark_rendered(inputs.clone());
            // A full frame of a view that may be refined starts the mean; previews and
            // statistics frames are shown as they are.
            let refine = scale == 1.0 && !state.statistics && state.refine_frames > 1;
            if shared.job.is_some() {
                log::debug!("frame in progress dropped for new inputs");
            }
            let settings = inputs.settings;
            shared.job = Some(FrameJob::new(
                inputs,
                settings,
                JobKind::Plain { refine },
                preview_of,
            ));
            self.shown.refinement.target = state.refine_frames;
            true
        } else if shared.job.is_none() && shared.finished.is_empty() && self.wants_refinement() {
            // A finished frame not yet taken has not counted into the mean: the next
            // refinement waits for it (else its index came twice, a mean of 9/8).
            let index = self.shown.refinement.done;
            let settings = crate::render::raycast::refine::frame_settings(&inputs.settings, index);
            shared.job = Some(FrameJob::new(inputs, settings, JobKind::Refinement, None));
            true
        } else {
            false
        };
        if started {
            // A fast GPU finishes the frame before this pass draws: no frame of latency.
            shared.step(false);
            self.pump.wake();
        }
        self.take_finished(&mut shared);
        match self.error.take() {
            Some(e) => Err(e),
            None => Ok(started),
        }
    }

    /// Whether the frame on screen, full resolution and for `inputs`, ran with a strategy `auto`
    /// carried over, the user has been quiet for [`STILL_AFTER`], no refinement frame is due
    /// (it would time the strategy first), and it was not rendered again for that already.
    fn wants_retiming(&self, inputs: &FrameInputs) -> bool {
        let quiet = self.last_input.is_none_or(|t| t.elapsed() >= STILL_AFTER);
        !self.stats.strategy_settled
            && quiet
            && self.shown.preview_of.is_none()
            && !self.wants_refinement()
            && !self.redraw.needs_render(inputs)
            && self.retimed_for.as_ref() != Some(inputs)
    }

    /// Whether `auto`'s strategy for the frame on screen waits to be timed once the user is
    /// quiet (the window then asks for a pass after [`STILL_AFTER`]).
    pub(crate) fn strategy_untimed(&self) -> bool {
        !self.stats.strategy_settled && self.rendering().is_none()
    }

    /// Whether the next refinement frame is due: the frame on screen is a full-resolution one
    /// being refined, and the user has been quiet for [`STILL_AFTER`].
    fn wants_refinement(&self) -> bool {
        let quiet = self.last_input.is_none_or(|t| t.elapsed() >= STILL_AFTER);
        self.shown.refinement.under_way() && self.shown.preview_of.is_none() && quiet
    }

    /// A frame's last band is on the GPU: what it rendered is what the view shows from now on
    /// (the window draws after it in the same queue).
    fn complete(&mut self, finished: Finished, shared: &Shared) {
        let Finished {
            job,
            mean,
            path,
            strategy,
            strategy_settled,
        } = finished;
        let size = job.inputs.size_px;
        self.stats.path_used = Some(path);
        self.stats.strategy_used = Some(strategy);
        self.stats.strategy_settled = strategy_settled;
        self.quiet_passes = 0;
        match job.kind {
            JobKind::Plain { refine } => {
                // Under the pump's lock: no band of the next frame can go out before the copy.
                self.shown
                    .copy_plain(&self.device, &self.queue, &shared.renderer, size);
                self.shown.refinement.done = if refine { mean.unwrap_or(0) } else { 0 };
                self.shown.preview_of = job.preview_of;
                let pixels = u64::from(size[0]) * u64::from(size[1]);
                self.stats.plain_frame(job.bands, pixels, job.inputs.stats);
                let ms = job.started.map_or(0.0, |t| t.elapsed().as_secs_f64() * 1e3);
                log::debug!(
                    "rendered volume frame {} at {size:?} ({} bands, {ms:.0} ms){}",
                    self.stats.frames_rendered,
                    self.stats.plain_band_count(),
                    if job.inputs.stats {
                        ", counting samples"
                    } else {
                        ""
                    }
                );
            }
            JobKind::Refinement => match mean {
                Some(n) => {
                    self.shown.refinement.done = n;
                    log::debug!(
                        "refined volume frame {} to a mean of {n}/{}",
                        self.stats.frames_rendered,
                        self.shown.refinement.target
                    );
                }
                None => self.shown.refinement = Default::default(),
            },
        }
        self.shown
            .show(&self.egui_renderer, &self.device, &shared.renderer, size);
        self.pages_generation = shared.renderer.pages_generation();
        // The bricks resident may have changed with the frame: the lines that say so follow.
        if let (Some(texture), Some(summary)) =
            (shared.renderer.volume_texture(), self.framing.volume_mut())
            && texture.view.bricked
        {
            summary.coarser.clone_from(&texture.coarser);
            summary.gpu_layout = Some(texture.describe());
            summary.residency = texture.residency_line();
        }
    }

    /// Whether a frame is being rendered (bands still to come or on the GPU), and how far.
    pub fn rendering(&self) -> Option<f64> {
        match (self.busy.frame, self.busy.in_flight) {
            (Some(frame), _) => Some(frame.submitted),
            (None, true) => Some(1.0),
            (None, false) => None,
        }
    }

    /// Whether a frame for new inputs is in progress (not a refinement frame).
    pub(crate) fn rendering_new_frame(&self) -> bool {
        self.busy
            .frame
            .is_some_and(|f| matches!(f.kind, JobKind::Plain { .. }))
    }

    /// The slow CPU work the renderer is doing before it can render (compiling a shader,
    /// timing the ray loops), while it does.
    pub fn preparing(&self) -> Option<&'static str> {
        self.busy.preparing
    }

    /// Whether the view is being refined (another refinement frame will come when still).
    pub fn refining(&self) -> bool {
        self.shown.refinement.under_way()
    }

    /// Draws the last image with its top-left corner at `origin` (a preview stretched over the
    /// view it stands for).
    pub(crate) fn paint(&self, ui: &egui::Ui, origin: egui::Pos2) {
        self.shown.paint(ui, origin);
    }

    /// The preview's scale (per axis) when the frame on screen is a reduced preview.
    pub(crate) fn preview_scale(&self) -> Option<f64> {
        self.shown.preview_scale()
    }

    /// Volume frames rendered so far.
    pub(crate) fn frames_rendered(&self) -> u64 {
        self.stats.frames_rendered
    }

    /// Counts a pass; returns the passes since the last rendered frame.
    pub(crate) fn note_pass(&mut self) -> u32 {
        self.quiet_passes = self.quiet_passes.saturating_add(1);
        self.quiet_passes
    }

    /// The inputs of the frame on screen.
    pub(crate) fn last_inputs(&self) -> Option<&FrameInputs> {
        self.redraw.last()
    }

    /// The frame on screen, read back from the GPU (waits for it, and for the pump).
    pub fn read_image(&self) -> Result<ImageF32, RenderError> {
        let handle = self.pump.handle();
        let shared = lock(&handle);
        self.shown.read(&shared.renderer)
    }

    /// Whether GPU timings, or a band, are still on their way.
    pub(crate) fn results_pending(&self) -> bool {
        self.busy.in_flight || self.busy.frame.is_some()
    }
}

/// The settings the window renders with while refinement is on: ray starts jittered per pixel,
/// so that the first frame shows fine noise rather than wood-grain rings, while the mean's
/// offsets rotate each pixel's jitter and converge as without it
/// (docs/benchmarks/window-jitter/README.md).
fn refinable(
    settings: crate::settings::RenderSettings,
    refine: bool,
) -> crate::settings::RenderSettings {
    crate::settings::RenderSettings {
        jitter: settings.jitter || refine,
        ..settings
    }
}
