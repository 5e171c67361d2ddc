//! The volume on screen: the one [`VolumeRenderer`] of the window, the camera, the egui texture
//! the image is shown through, and the frame bookkeeping — render only when the inputs changed,
//! frames per second, GPU time of the last frame.

use std::sync::Arc;
use std::time::{Duration, Instant};

use egui::mutex::RwLock;

use crate::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use crate::counters::FrameCounters;
use crate::imaging::ImageF32;
use crate::render::raycast::auto_path;
use crate::render::{FrameRequest, GpuContext, RenderError, VolumeRenderer};
use crate::settings::ConcretePath;
use crate::volume::Volume;

use super::interaction::{framed, with_projection};
use super::lod::{Lod, scaled_size};
use super::overlay::{FpsCounter, Readout};
use super::redraw::{FrameInputs, RedrawTracker};
use super::viewport::ViewTexture;
use super::{ViewerState, VolumeSummary};

/// The renderer and everything about the frame on screen.
pub struct Scene {
    renderer: VolumeRenderer,
    device: wgpu::Device,
    egui_renderer: Arc<RwLock<egui_wgpu::Renderer>>,
    adapter_label: String,
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
    redraw: RedrawTracker,
    fps: FpsCounter,
    gpu_ms: Option<f64>,
    counters: Option<(FrameCounters, u64)>,
    rebuild_ms: Option<f64>,
    path_used: Option<ConcretePath>,
    frames_rendered: u64,
    quiet_passes: u32,
    /// Pixels of the last frame (for samples per pixel).
    last_pixels: u64,
    /// Interaction level of detail: the cost per pixel and the scale it picks.
    lod: Lod,
    /// The view's size when the frame on screen is a reduced preview of it.
    preview_of: Option<[u32; 2]>,
    /// Frames in the refinement mean on screen (0: the plain frame is on screen) and the number
    /// aimed at.
    refined: (u32, u32),
    /// Renderer frame number of the last plain (not refinement) frame: the readout and the
    /// cost model take timings of plain frames only.
    last_plain_frame: u64,
}

impl Scene {
    /// Creates the renderer on eframe's device.
    pub fn new(rs: &egui_wgpu::RenderState) -> Result<Self, RenderError> {
        let ctx = GpuContext::new(&rs.adapter, rs.device.clone(), rs.queue.clone());
        let info = &ctx.adapter_info;
        let adapter_label = format!("{} ({:?})", info.name, info.backend);
        log::info!("window GPU: {}", ctx.adapter_summary());
        Ok(Self {
            renderer: VolumeRenderer::new(ctx)?,
            device: rs.device.clone(),
            egui_renderer: rs.renderer.clone(),
            adapter_label,
            texture: ViewTexture::default(),
            camera: None,
            bounds: None,
            volume: None,
            volume_generation: 0,
            transfer_given: false,
            tf_edit_at: None,
            tf_latency_ms: None,
            redraw: RedrawTracker::default(),
            fps: FpsCounter::default(),
            gpu_ms: None,
            counters: None,
            rebuild_ms: None,
            path_used: None,
            frames_rendered: 0,
            quiet_passes: 0,
            last_pixels: 0,
            lod: Lod::default(),
            preview_of: None,
            refined: (0, 0),
            last_plain_frame: 0,
        })
    }

    /// Uploads `volume` (`from_file`: read from a file, not generated) and frames it in the
    /// default view. On error the old volume stays.
    pub fn show_volume(
        &mut self,
        volume: &Volume,
        projection: ProjectionKind,
        from_file: bool,
    ) -> Result<&VolumeSummary, RenderError> {
        let started = std::time::Instant::now();
        self.renderer.set_volume(volume)?;
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
        self.lod.forget();
        let summary = self.volume.as_ref().ok_or(RenderError::NoVolume)?;
        log::info!("showing {}: {}", summary.name, summary.line());
        Ok(summary)
    }

    /// The view a volume opens in: the patient from the front, superior up (by the file's
    /// orientation, RAS where it has none), as a radiologist looks at a 3D rendering.
    pub fn reset_view(&mut self, projection: ProjectionKind) {
        self.view_from(crate::volume::Direction::Anterior, projection);
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

    /// Takes the GPU timings that have arrived; returns whether more are on their way.
    pub fn collect_measurements(&mut self) -> bool {
        for result in self.renderer.collect_results(false) {
            // A refinement frame costs what its plain frame cost; lavapipe (Mesa 22.3) also
            // misreports the timestamps of frames after an accumulation (~0.1 ms).
            if result.frame > self.last_plain_frame {
                continue;
            }
            if let Some(ms) = result.gpu_ms {
                self.gpu_ms = Some(ms);
                if self.timestamps_reliable() {
                    self.lod.measured(result.frame, ms);
                }
            }
            if let Some(c) = result.counters {
                self.counters = Some((c, self.last_pixels));
            }
            if result.rebuild_ms.is_some() {
                self.rebuild_ms = result.rebuild_ms;
            }
            // The first frame back after a transfer-function change carries it (frames complete
            // in order): from the change to that frame's completion on the GPU.
            if let Some(at) = self.tf_edit_at.take() {
                self.tf_latency_ms = Some(at.elapsed().as_secs_f64() * 1e3);
            }
        }
        self.renderer.results_pending()
    }

    /// Gives the renderer the editor's transfer function; when it changed, the renderer's
    /// generation moves on (the one change signal: frames are rendered again for it) and the
    /// table and the leaping structures are rebuilt in the next frame.
    fn apply_transfer(&mut self, state: &ViewerState) {
        let changed = self.renderer.set_transfer_function(state.editor.tf());
        // Latency is measured for edits, not for the first function (pipelines still compile).
        if changed && self.transfer_given {
            self.tf_edit_at = Some(Instant::now());
        }
        self.transfer_given = true;
    }

    /// Renders the current view at `size` pixels at full quality, for saving; the window
    /// renders its own frame again on the next pass (the output texture was replaced).
    pub fn render_still(
        &mut self,
        state: &ViewerState,
        size: [u32; 2],
    ) -> Result<crate::imaging::ImageF32, String> {
        let camera = self.camera.ok_or("no volume on screen")?;
        self.apply_transfer(state);
        let settings = state.render;
        let image = auto_path::choose(&mut self.renderer, settings.path)
            .and_then(|_| {
                self.renderer
                    .render_refined(&camera, size, &settings, state.refine_frames)
            })
            .map_err(|e| format!("Cannot render a {}×{} image: {e}", size[0], size[1]));
        self.redraw.invalidate();
        image
    }

    /// Renders a frame for a view of `size_px` when anything it depends on changed since the
    /// last one: at a reduced resolution while `interacting` if a full frame would miss the
    /// budget (and the state allows it), else at full resolution — so a preview left on screen
    /// is replaced as soon as the user stops. Returns whether a frame was rendered; an error is a
    /// one-line message for the user.
    pub fn render_if_changed(
        &mut self,
        state: &mut ViewerState,
        view_px: [u32; 2],
        interacting: bool,
    ) -> Result<bool, String> {
        let scale = if state.interaction_lod {
            self.lod.scale(view_px, interacting)
        } else {
            1.0
        };
        let size_px = scaled_size(view_px, scale);
        let Some(camera) = self.camera else {
            return Ok(false);
        };
        if !self.renderer.has_volume() || size_px.contains(&0) {
            return Ok(false);
        }
        self.apply_transfer(state);
        let inputs = FrameInputs {
            camera,
            size_px,
            settings: state.render,
            transfer_generation: self.renderer.transfer_generation(),
            volume_generation: self.volume_generation,
            stats: state.statistics,
        };
        if !self.redraw.needs_render(&inputs) {
            return self.refine_step(&inputs, interacting);
        }
        let request = FrameRequest {
            camera: &inputs.camera,
            size: size_px,
            settings: &inputs.settings,
            stats: inputs.stats,
        };
        if !inputs.stats {
            self.counters = None;
        }
        self.last_pixels = u64::from(size_px[0]) * u64::from(size_px[1]);
        let submit_started = Instant::now();
        // A full frame of a view that may be refined starts the mean (a cheap pass in the same
        // submission) and is shown from it; previews and statistics frames are shown as they
        // are.
        let refine = scale == 1.0 && !state.statistics && state.refine_frames > 1;
        self.refined = (0, state.refine_frames);
        // `auto` is timed on the first frame that asks for it (a few frames, once).
        let result = auto_path::choose(&mut self.renderer, inputs.settings.path).and_then(|_| {
            if refine {
                self.renderer
                    .render_accumulated(&request, true)
                    .map(|(frame, n)| {
                        self.refined.0 = n.unwrap_or(0);
                        frame
                    })
            } else {
                self.renderer.render(&request)
            }
        });
        let submit_ms = submit_started.elapsed().as_secs_f64() * 1e3;
        // Marked even on failure, so a failing frame is not retried on every pass.
        self.redraw.mark_rendered(inputs);
        let submitted = result.map_err(render_error)?;
        self.lod.submitted(submitted.frame, self.last_pixels);
        self.last_plain_frame = submitted.frame;
        self.preview_of = (size_px != view_px).then_some(view_px);
        self.frames_rendered += 1;
        self.quiet_passes = 0;
        self.fps.record(Instant::now());
        self.path_used = Some(submitted.key.path);
        self.show_frame(size_px);
        log::debug!(
            "rendered volume frame {} at {size_px:?} ({submit_ms:.0} ms to submit)",
            self.frames_rendered
        );
        Ok(true)
    }

    /// Points the view at the refinement mean when it holds frames, else at the plain frame.
    fn show_frame(&mut self, size_px: [u32; 2]) {
        let view = if self.refined.0 > 0 {
            self.renderer.refined_view()
        } else {
            self.renderer.output_view()
        };
        if let Some(view) = view {
            self.texture.sync(
                &self.egui_renderer,
                &self.device,
                view,
                size_px,
                self.preview_of.is_some(),
            );
        }
    }

    /// With the view unchanged (`inputs` already on screen) and still: renders the next frame of
    /// the refinement at its shifted sample grid and adds it to the mean on screen. Returns
    /// whether a frame was rendered.
    fn refine_step(&mut self, inputs: &FrameInputs, interacting: bool) -> Result<bool, String> {
        let (done, target) = self.refined;
        if interacting || done == 0 || done >= target || self.preview_of.is_some() {
            return Ok(false);
        }
        let settings = crate::settings::RenderSettings {
            sample_offset: crate::render::raycast::refine::offset(done),
            ..inputs.settings
        };
        let request = FrameRequest {
            camera: &inputs.camera,
            size: inputs.size_px,
            settings: &settings,
            stats: false,
        };
        let added = self
            .renderer
            .render_accumulated(&request, false)
            .map_err(render_error)
            .map(|(_, n)| n);
        match added {
            Ok(Some(n)) => self.refined.0 = n,
            Ok(None) => self.refined = (0, 0),
            Err(e) => {
                // Not retried: the plain frame stays on screen.
                self.refined = (0, 0);
                self.show_frame(inputs.size_px);
                return Err(e);
            }
        }
        self.show_frame(inputs.size_px);
        self.quiet_passes = 0;
        log::debug!(
            "refined volume frame {} to a mean of {}/{target}",
            self.frames_rendered,
            self.refined.0
        );
        Ok(true)
    }

    /// Whether the GPU timings can be shown: the adapter has timestamp queries, and it is not a
    /// CPU driver that has run a refinement (lavapipe, Mesa 22.3, reports ~0.1 ms for every frame
    /// from the first accumulation on; the H100 reports the same times with and without).
    fn timestamps_reliable(&self) -> bool {
        let ctx = self.renderer.context();
        ctx.has_timestamps()
            && !(ctx.adapter_info.device_type == wgpu::DeviceType::Cpu
                && self.renderer.has_accumulated())
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
            fps: self.fps.fps(now),
            gpu_ms: self.gpu_ms.filter(|_| self.timestamps_reliable()),
            has_timestamps: self.timestamps_reliable(),
            adapter: &self.adapter_label,
            path: self.path_used,
            strategy: state.render.strategy.label(),
            volume: self.volume.as_ref(),
            counters: self.counters,
            rebuild_ms: self.rebuild_ms.filter(|_| state.render.strategy.leaps()),
            tf_latency_ms: self.tf_latency_ms,
            preview_scale: self.preview_scale(),
            refined: Some(self.refined).filter(|(n, _)| *n > 0),
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

    /// The frame on screen, read back from the GPU (waits for it).
    pub fn read_image(&self) -> Result<ImageF32, RenderError> {
        if self.refined.0 > 0 {
            self.renderer.read_refined()
        } else {
            self.renderer.read_image()
        }
    }

    /// Whether GPU timings are still on their way.
    pub fn results_pending(&self) -> bool {
        self.renderer.results_pending()
    }
}

/// A render error as the one-line message the window shows.
fn render_error(e: RenderError) -> String {
    format!("Cannot render the volume: {e}")
}
