//! The volume on screen: the window's one [`VolumeRenderer`] (run by the band pump,
//! [`crate::ui::frames::band_pump`]), the camera, the egui texture the image is shown through, and the frame
//! bookkeeping — render only when the inputs changed, in bands that never keep the GPU (and so
//! the window) busy for long ([`crate::ui::frames::frame_job`]), refine a still view, frames per second, GPU
//! time of the last frame.

use std::sync::Arc;
use std::time::{Duration, Instant};

use egui::mutex::RwLock;

use crate::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use crate::counters::FrameCounters;
use crate::imaging::ImageF32;
use crate::render::{GpuContext, RenderError, VolumeRenderer};
use crate::settings::{ConcretePath, Strategy};
use crate::volume::Volume;

use crate::ui::frames::band_pump::{BandPump, Finished, Shared, lock, try_lock};
use crate::ui::frames::frame_job::{FrameJob, JobKind};
use crate::ui::frames::lod::{STILL_AFTER, scaled_size};
use crate::ui::frames::redraw::{FrameInputs, RedrawTracker};
use crate::ui::gestures::interaction::{framed, with_projection};
use crate::ui::view::overlay::{FpsCounter, Readout};
use crate::ui::view::viewport::ViewTexture;
use crate::ui::{ViewerState, VolumeSummary};

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
    texture: ViewTexture,
    camera: Option<Camera>,
    bounds: Option<Aabb>,
    volume: Option<VolumeSummary>,
    volume_generation: u64,
    /// Whether the renderer has been given the editor's function yet (the first one is not an
    /// edit whose latency is measured).
    transfer_given: bool,
    /// When the renderer got a new transfer function whose frame has not come back yet.
    tf_edit_at: Option<Instant>,
    /// Milliseconds from the last transfer-function change to its frame's completion.
    tf_latency_ms: Option<f64>,
    /// Predicted milliseconds of a full-resolution frame of the view, once bands were timed.
    frame_ms: Option<f64>,
    redraw: RedrawTracker,
    fps: FpsCounter,
    gpu_ms: Option<f64>,
    counters: Option<(FrameCounters, u64)>,
    rebuild_ms: Option<f64>,
    path_used: Option<ConcretePath>,
    /// The strategy the last frame ran with (what `auto` stood for).
    strategy_used: Option<Strategy>,
    /// Whether that strategy is final for the last frame's inputs (false: `auto` carried its
    /// last choice over while the user was busy).
    strategy_settled: bool,
    /// The inputs a frame was last started again for, to time `auto` once the user was quiet
    /// (once per inputs, so that a timing that fails is not retried on every pass).
    retimed_for: Option<FrameInputs>,
    frames_rendered: u64,
    quiet_passes: u32,
    /// Pixels of the last frame (for samples per pixel).
    last_pixels: u64,
    /// The view's size when the frame on screen is a reduced preview of it.
    preview_of: Option<[u32; 2]>,
    /// Frames in the refinement mean on screen (0: the plain frame is on screen) and the number
    /// aimed at.
    refined: (u32, u32),
    /// The last complete plain frame, copied out of the renderer's output (which the next
    /// frame's bands overwrite while this one stays on screen): texture, view, size.
    shown: Option<(wgpu::Texture, wgpu::TextureView, [u32; 2])>,
    /// Renderer frame numbers of the last complete plain frame's bands, and the GPU time they
    /// add up to as their results arrive.
    plain_bands: Vec<u64>,
    plain_gpu_ms: (f64, usize),
    /// When the user last did anything (pointer, keys, wheel): refinement waits for quiet.
    last_input: Option<Instant>,
    /// What the renderer is doing while the window cannot reach it (the pump holds it), and
    /// the frame in progress, as seen in the last pass that could look.
    busy: Busy,
    /// A frame that failed, for the next pass to report.
    error: Option<String>,
}

/// What the window knows of the pump's work, from the last pass that could look.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Busy {
    /// The frame in progress: what it is for, the share of its rows submitted, and whether it
    /// has sent out a band yet.
    frame: Option<(JobKind, f64, bool)>,
    /// Whether a band is on the GPU.
    in_flight: bool,
    /// Slow CPU work before the next band.
    preparing: Option<&'static str>,
    /// Whether a frame was ever added to a refinement mean (lavapipe's timestamps go wrong
    /// after one).
    accumulated: bool,
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
        let pump = BandPump::start(VolumeRenderer::new(gpu)?, ctx.clone())
            .map_err(|e| RenderError::Gpu(format!("cannot start the render thread: {e}")))?;
        Ok(Self {
            pump,
            device: rs.device.clone(),
            queue: rs.queue.clone(),
            egui_renderer: rs.renderer.clone(),
            adapter_label,
            has_timestamps,
            cpu_adapter,
            texture: ViewTexture::default(),
            camera: None,
            bounds: None,
            volume: None,
            volume_generation: 0,
            transfer_given: false,
            tf_edit_at: None,
            tf_latency_ms: None,
            frame_ms: None,
            redraw: RedrawTracker::default(),
            fps: FpsCounter::default(),
            gpu_ms: None,
            counters: None,
            rebuild_ms: None,
            path_used: None,
            strategy_used: None,
            strategy_settled: true,
            retimed_for: None,
            frames_rendered: 0,
            quiet_passes: 0,
            last_pixels: 0,
            preview_of: None,
            refined: (0, 0),
            shown: None,
            plain_bands: Vec::new(),
            plain_gpu_ms: (0.0, 0),
            last_input: None,
            busy: Busy::default(),
            error: None,
        })
    }

    /// Uploads `volume` (`from_file`: read from a file, not generated) and frames it in the
    /// default view. On error the old volume stays. Waits for the pump if it is preparing a
    /// frame.
    pub fn show_volume(
        &mut self,
        volume: &Volume,
        projection: ProjectionKind,
        from_file: bool,
    ) -> Result<&VolumeSummary, RenderError> {
        let started = std::time::Instant::now();
        {
            let handle = self.pump.handle();
            let mut shared = lock(&handle);
            shared.job = None;
            shared.renderer.set_volume(volume)?;
            shared.lod.forget();
        }
        log::info!(
            "uploaded {} in {:.0} ms",
            volume.name(),
            started.elapsed().as_secs_f64() * 1e3
        );
        let summary = VolumeSummary {
            from_file,
            ..VolumeSummary::of(volume)
        };
        let bounds = Aabb::of_volume(summary.dims, summary.spacing_mm);
        self.bounds = Some(bounds);
        self.volume = Some(summary);
        self.reset_view(projection);
        self.volume_generation += 1;
        let summary = self.volume.as_ref().ok_or(RenderError::NoVolume)?;
        log::info!("showing {}: {}", summary.name, summary.line());
        Ok(summary)
    }

    /// The volume's texture on the GPU and its format (the slice views sample it too).
    pub fn volume_texture(&self) -> Option<(wgpu::TextureView, wgpu::TextureFormat)> {
        let handle = self.pump.handle();
        let shared = lock(&handle);
        shared
            .renderer
            .volume_texture()
            .map(|t| (t.view.clone(), t.encoding.format))
    }

    /// The view a volume opens in: the patient from the front, superior up (by the file's
    /// orientation, RAS where it has none), as a radiologist looks at a 3D rendering; a 2D image
    /// faces the viewer as its slice view shows it (axial from the feet, coronal from the front,
    /// sagittal from the left).
    pub fn reset_view(&mut self, projection: ProjectionKind) {
        use crate::mpr::PlaneKind;
        use crate::volume::Direction;
        let plane = self
            .volume
            .as_ref()
            .and_then(|v| crate::mpr::frame::image_plane_of(v.dims, v.orientation_or_assumed()));
        let side = match plane {
            Some(PlaneKind::Axial) => Direction::Inferior,
            Some(PlaneKind::Sagittal) => Direction::Left,
            _ => Direction::Anterior,
        };
        self.view_from(side, projection);
    }

    /// The volume on screen.
    pub fn volume(&self) -> Option<&VolumeSummary> {
        self.volume.as_ref()
    }

    /// The camera and the volume's bounding box, once a volume is shown.
    pub fn camera_and_bounds(&self) -> Option<(Camera, Aabb)> {
        self.camera.zip(self.bounds)
    }

    /// The camera, once a volume is shown.
    pub fn camera_mut(&mut self) -> Option<&mut Camera> {
        self.camera.as_mut()
    }

    /// Looks along `preset`, framing the whole volume.
    pub fn set_view(&mut self, preset: ViewPreset, projection: ProjectionKind) {
        if let Some(bounds) = &self.bounds {
            self.camera = Some(framed(bounds, preset, projection));
        }
    }

    /// Looks at the patient from `side` (the orientation from the header, or RAS), framing the
    /// whole volume.
    pub fn view_from(&mut self, side: crate::volume::Direction, projection: ProjectionKind) {
        if let (Some(bounds), Some(volume)) = (&self.bounds, &self.volume) {
            let (dir, up) = volume.orientation_or_assumed().view_from(side);
            self.camera = Some(Camera::framing(bounds, dir, up, projection));
        }
    }

    /// Switches projection without a jump in size.
    pub fn set_projection(&mut self, kind: ProjectionKind) {
        self.camera = self.camera.map(|c| with_projection(&c, kind));
    }

    /// Takes what the pump finished and the GPU measurements that arrived; returns whether more
    /// are on their way. Looks only when the pump is not preparing a frame (no pass waits).
    pub fn collect_measurements(&mut self) -> bool {
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
        self.busy = busy_of(shared);
    }

    /// GPU timings of finished bands: the last plain frame's time adds up over its bands.
    fn take_results(&mut self, shared: &mut Shared) {
        for result in shared.renderer.collect_results(false) {
            if let Some(c) = result.counters
                && self.plain_bands.last() == Some(&result.frame)
            {
                // The counters add up over a frame's bands: the last band's are the frame's.
                self.counters = Some((c, self.last_pixels));
            }
            if result.rebuild_ms.is_some() {
                self.rebuild_ms = result.rebuild_ms;
            }
            if self.plain_bands.contains(&result.frame) {
                if let Some(ms) = result.gpu_ms {
                    self.plain_gpu_ms.0 += ms;
                }
                self.plain_gpu_ms.1 += 1;
                if self.plain_gpu_ms.1 == self.plain_bands.len() {
                    self.gpu_ms = Some(self.plain_gpu_ms.0);
                }
            }
            // The first frame back after a transfer-function change carries it (frames complete
            // in order): from the change to that frame's completion on the GPU.
            if let Some(at) = self.tf_edit_at.take() {
                self.tf_latency_ms = Some(at.elapsed().as_secs_f64() * 1e3);
            }
        }
    }

    /// Starts rendering the current view at `size` pixels at full quality and writing it to
    /// `path`, on a thread of its own ([`crate::ui::frames::band_pump::save_still`]); the outcome, a line
    /// for the user, arrives on the returned channel. The window's frame in progress starts
    /// again afterwards.
    pub fn save_still(
        &mut self,
        state: &ViewerState,
        size: [u32; 2],
        path: std::path::PathBuf,
        ctx: &egui::Context,
    ) -> Result<std::sync::mpsc::Receiver<Result<String, String>>, String> {
        let camera = self.camera.ok_or("no volume on screen")?;
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
    pub fn note_input(&mut self) {
        self.last_input = Some(Instant::now());
        if !matches!(self.busy.frame, Some((JobKind::Refinement, _, _))) {
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
            self.busy = busy_of(&shared);
        }
    }

    /// Moves the view's frame on: starts a frame when anything it depends on changed since the
    /// last one (at a reduced resolution while `interacting` if a full frame would miss the
    /// budget, and the state allows it; else at full resolution, so a preview left on screen is
    /// replaced as soon as the user stops), or the next refinement frame once the user is quiet;
    /// submits its first band at once where that needs no slow CPU work, and leaves the rest to
    /// the pump. Returns whether a frame was started; an error is a one-line message for the
    /// user. When the pump is preparing a frame, nothing happens this pass.
    pub fn render_if_changed(
        &mut self,
        state: &mut ViewerState,
        view_px: [u32; 2],
        interacting: bool,
    ) -> Result<bool, String> {
        let Some(camera) = self.camera else {
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
        self.frame_ms = shared.lod.predicted_ms(view_px);
        let size_px = scaled_size(view_px, scale);
        if !shared.renderer.has_volume() || size_px.contains(&0) {
            return Ok(false);
        }
        let changed = shared.renderer.set_transfer_function(state.editor.tf());
        if changed && self.transfer_given {
            self.tf_edit_at = Some(Instant::now());
        }
        self.transfer_given = true;
        let inputs = FrameInputs {
            camera,
            size_px,
            settings: state.render,
            transfer_generation: shared.renderer.transfer_generation(),
            volume_generation: self.volume_generation,
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
            // Jittered whenever refinement is on, previews too: one set of settings for every
            // frame of a view, so `auto` times one choice.
            let settings = refinable(inputs.settings, state.refine_frames > 1);
            shared.job = Some(FrameJob::new(
                inputs,
                settings,
                JobKind::Plain { refine },
                preview_of,
            ));
            self.refined.1 = state.refine_frames;
            true
        } else if shared.job.is_none() && self.wants_refinement() {
            let index = self.refined.0;
            let settings = crate::settings::RenderSettings {
                sample_offset: crate::render::raycast::refine::offset(index),
                ..refinable(inputs.settings, true)
            };
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
        !self.strategy_settled
            && quiet
            && self.preview_of.is_none()
            && !self.wants_refinement()
            && !self.redraw.needs_render(inputs)
            && self.retimed_for.as_ref() != Some(inputs)
    }

    /// Whether `auto`'s strategy for the frame on screen waits to be timed once the user is
    /// quiet (the window then asks for a pass after [`STILL_AFTER`]).
    pub fn strategy_untimed(&self) -> bool {
        !self.strategy_settled && self.rendering().is_none()
    }

    /// Whether the next refinement frame is due: the frame on screen is a full-resolution one
    /// being refined, and the user has been quiet for [`STILL_AFTER`].
    fn wants_refinement(&self) -> bool {
        let (done, target) = self.refined;
        let quiet = self.last_input.is_none_or(|t| t.elapsed() >= STILL_AFTER);
        done > 0 && done < target && self.preview_of.is_none() && quiet
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
        self.path_used = Some(path);
        self.strategy_used = Some(strategy);
        self.strategy_settled = strategy_settled;
        self.quiet_passes = 0;
        match job.kind {
            JobKind::Plain { refine } => {
                self.copy_to_shown(size, shared);
                self.refined = (if refine { mean.unwrap_or(0) } else { 0 }, self.refined.1);
                self.preview_of = job.preview_of;
                self.frames_rendered += 1;
                self.fps.record(Instant::now());
                self.last_pixels = u64::from(size[0]) * u64::from(size[1]);
                self.plain_bands = job.bands;
                self.plain_gpu_ms = (0.0, 0);
                if !job.inputs.stats {
                    self.counters = None;
                }
                let ms = job.started.map_or(0.0, |t| t.elapsed().as_secs_f64() * 1e3);
                log::debug!(
                    "rendered volume frame {} at {size:?} ({} bands, {ms:.0} ms){}",
                    self.frames_rendered,
                    self.plain_bands.len(),
                    if job.inputs.stats {
                        ", counting samples"
                    } else {
                        ""
                    }
                );
            }
            JobKind::Refinement => match mean {
                Some(n) => {
                    self.refined.0 = n;
                    log::debug!(
                        "refined volume frame {} to a mean of {n}/{}",
                        self.frames_rendered,
                        self.refined.1
                    );
                }
                None => self.refined = (0, 0),
            },
        }
        self.show_frame(size, shared);
    }

    /// Copies the renderer's output (the plain frame just finished) to the texture the view
    /// shows, so that the next frame's bands do not show before it is complete.
    fn copy_to_shown(&mut self, size: [u32; 2], shared: &Shared) {
        if self.shown.as_ref().is_none_or(|(_, _, s)| *s != size) {
            use wgpu::TextureUsages as U;
            let texture = crate::render::texture::texture_2d(
                &self.device,
                size,
                crate::render::texture::OUTPUT_FORMAT,
                U::TEXTURE_BINDING | U::COPY_DST | U::COPY_SRC,
                "view",
            );
            let view = crate::render::texture::full_view(&texture);
            self.shown = Some((texture, view, size));
        }
        let (Some(output), Some((texture, _, _))) = (shared.renderer.output_texture(), &self.shown)
        else {
            return;
        };
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("show frame"),
            });
        encoder.copy_texture_to_texture(
            output.as_image_copy(),
            texture.as_image_copy(),
            crate::render::texture::extent(size),
        );
        // Under the lock: no band of the next frame can go out before this copy.
        self.queue.submit([encoder.finish()]);
    }

    /// Points the view at the refinement mean when it holds more than the plain frame, else at
    /// the plain frame.
    fn show_frame(&mut self, size_px: [u32; 2], shared: &Shared) {
        let view = if self.refined.0 > 1 {
            shared.renderer.refined_view().cloned()
        } else {
            self.shown.as_ref().map(|(_, view, _)| view.clone())
        };
        if let Some(view) = view {
            self.texture.sync(
                &self.egui_renderer,
                &self.device,
                &view,
                size_px,
                self.preview_of.is_some(),
            );
        }
    }

    /// Whether a frame is being rendered (bands still to come or on the GPU), and how far.
    pub fn rendering(&self) -> Option<f64> {
        match (self.busy.frame, self.busy.in_flight) {
            (Some((_, done, _)), _) => Some(done),
            (None, true) => Some(1.0),
            (None, false) => None,
        }
    }

    /// Whether a frame for new inputs is in progress (not a refinement frame).
    pub fn rendering_new_frame(&self) -> bool {
        matches!(self.busy.frame, Some((JobKind::Plain { .. }, _, _)))
    }

    /// The slow CPU work the renderer is doing before it can render (compiling a shader,
    /// timing the ray loops), while it does.
    pub fn preparing(&self) -> Option<&'static str> {
        self.busy.preparing
    }

    /// Whether the GPU timings can be shown: the adapter has timestamp queries, and it is not a
    /// CPU driver that has run a refinement (lavapipe, Mesa 22.3, reports ~0.1 ms for every frame
    /// from the first accumulation on; the H100 reports the same times with and without).
    fn timestamps_reliable(&self) -> bool {
        self.has_timestamps && !(self.cpu_adapter && self.busy.accumulated)
    }

    /// Whether the view is being refined (another refinement frame will come when still).
    pub fn refining(&self) -> bool {
        self.refined.0 > 0 && self.refined.0 < self.refined.1
    }

    /// Draws the last image with its top-left corner at `origin` (a preview stretched over the
    /// view it stands for).
    pub fn paint(&self, ui: &egui::Ui, origin: egui::Pos2) {
        self.texture.paint(ui, origin, self.preview_of);
    }

    /// The preview's scale (per axis) when the frame on screen is a reduced preview.
    pub fn preview_scale(&self) -> Option<f64> {
        let view = self.preview_of?;
        Some(f64::from(self.texture.size_px()[0]) / f64::from(view[0].max(1)))
    }

    /// What the readout shows now.
    pub fn readout(&mut self, state: &ViewerState, now: Instant) -> Readout<'_> {
        Readout {
            developer: state.developer_readout || state.statistics,
            look: Some(look(state)),
            frame_ms: self.frame_ms,
            orientation_note: self.volume.as_ref().and_then(|v| {
                (v.orientation_or_assumed().source == crate::volume::OrientationSource::Assumed)
                    .then_some("no orientation in the file: RAS assumed (side panel › View)")
            }),
            fps: self.fps.fps(now),
            gpu_ms: self.gpu_ms.filter(|_| self.timestamps_reliable()),
            has_timestamps: self.timestamps_reliable(),
            adapter: &self.adapter_label,
            path: self.path_used,
            strategy: self.strategy_used.unwrap_or(state.render.strategy).label(),
            volume: self.volume.as_ref(),
            counters: self.counters,
            rebuild_ms: self
                .rebuild_ms
                .filter(|_| self.strategy_used.unwrap_or(state.render.strategy).leaps()),
            tf_latency_ms: self.tf_latency_ms,
            preview_scale: self.preview_scale(),
            refined: Some(self.refined).filter(|(n, _)| *n > 0),
            rendering: self
                .busy
                .frame
                .filter(|&(_, _, started)| started)
                .map(|(_, done, _)| done),
            preparing: self.busy.preparing,
            blank: self.volume.as_ref().and_then(|v| {
                crate::transfer::blank::why_blank_in(v.range, state.editor.tf(), &state.render)
            }),
        }
    }

    /// When the frame rate shown changes by itself (down to idle), if it will.
    pub fn fps_next_change(&self, now: Instant) -> Option<Duration> {
        self.fps.next_change(now)
    }

    /// The path the last frame used (what `auto` chose).
    pub fn path_used(&self) -> Option<ConcretePath> {
        self.path_used
    }

    /// The strategy the last frame ran with (what `auto` chose).
    pub fn strategy_used(&self) -> Option<Strategy> {
        self.strategy_used
    }

    /// Volume frames rendered so far.
    pub fn frames_rendered(&self) -> u64 {
        self.frames_rendered
    }

    /// Counts a pass; returns the passes since the last rendered frame.
    pub fn note_pass(&mut self) -> u32 {
        self.quiet_passes = self.quiet_passes.saturating_add(1);
        self.quiet_passes
    }

    /// The inputs of the frame on screen.
    pub fn last_inputs(&self) -> Option<&FrameInputs> {
        self.redraw.last()
    }

    /// The frame on screen, read back from the GPU (waits for it, and for the pump).
    pub fn read_image(&self) -> Result<ImageF32, RenderError> {
        let handle = self.pump.handle();
        let shared = lock(&handle);
        if self.refined.0 > 1 {
            return shared.renderer.read_refined();
        }
        let (texture, _, size) = self.shown.as_ref().ok_or(RenderError::NoVolume)?;
        crate::render::readback::read_texture(shared.renderer.context(), texture, *size)
            .map_err(RenderError::Gpu)
    }

    /// Whether GPU timings, or a band, are still on their way.
    pub fn results_pending(&self) -> bool {
        self.busy.in_flight || self.busy.frame.is_some()
    }
}

/// What the window needs to know of the pump's state.
fn busy_of(shared: &Shared) -> Busy {
    Busy {
        frame: shared
            .job
            .as_ref()
            .map(|j| (j.kind, j.progress(), !j.bands.is_empty())),
        in_flight: shared.in_flight.is_some(),
        preparing: shared.preparing,
        accumulated: shared.renderer.has_accumulated(),
    }
}

/// What the picture shows, in a reader's words: the transfer function's preset, the iso value,
/// or the window of a projection.
fn look(state: &ViewerState) -> String {
    let render = &state.render;
    let window = || match render.window {
        Some([lo, hi]) => format!(
            "window {} … {} (W {} L {})",
            crate::text::number(lo),
            crate::text::number(hi),
            crate::text::number(hi - lo),
            crate::text::number(0.5 * (lo + hi))
        ),
        None => "window: the data's".to_string(),
    };
    // The preset the transfer function started from (fitted to the data, perhaps edited since).
    let preset = || format!("preset {}", state.preset);
    match render.mode {
        crate::settings::Mode::Dvr => preset(),
        crate::settings::Mode::Iso => match render.iso.value {
            Some(v) => format!("isosurface at {}", crate::text::number(v)),
            None => "isosurface".to_string(),
        },
        crate::settings::Mode::Mip => format!("MIP · {}", window()),
        crate::settings::Mode::MinIp => format!("MinIP · {}", window()),
        crate::settings::Mode::Xray => format!("X-ray mean · {}", window()),
        crate::settings::Mode::XrayAttenuation => format!("radiograph · {}", window()),
    }
}

/// The settings the window renders with while refinement is on: ray starts jittered per pixel,
/// so that the first frame shows fine noise rather than wood-grain rings, while the mean's
/// offsets rotate each pixel's jitter and converge as without it (docs/benchmarks/window-jitter.md).
fn refinable(
    settings: crate::settings::RenderSettings,
    refine: bool,
) -> crate::settings::RenderSettings {
    crate::settings::RenderSettings {
        jitter: settings.jitter || refine,
        ..settings
    }
}
