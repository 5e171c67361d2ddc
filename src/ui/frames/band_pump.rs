//! The band pump: a thread that feeds the frame in progress to the GPU one band at a time
//! ([`crate::ui::frames::frame_job`]), so that the window's thread never waits for long GPU work and never
//! has to run a pass (on a CPU driver, about 50 ms of drawing the whole window) just to submit
//! the next band. The renderer and the frame in progress live in [`Shared`], behind a mutex; the
//! window's thread only ever `try_lock`s it in a pass, so the slow CPU work the pump may do
//! first — compiling a shader variant, timing the `auto` path or the `auto` strategy — shows as
//! "preparing" instead of a frozen window. The `auto` strategy is timed only once the user is
//! still ([`STILL_AFTER`]); while they drag, it keeps its last choice (no frame waits for it).
//!
//! The pump submits a band once the GPU has finished the last one (it polls every millisecond):
//! the queue never holds more than one band ahead of the window's own drawing, which therefore
//! waits at most one band ([`crate::ui::frames::frame_job::band_budget_ms`]).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, TryLockError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::render::gpu_data::WORKGROUP;
use crate::render::raycast::{auto_path, auto_strategy};
use crate::render::{Accumulate, FrameRequest, RefineRun, RenderError, VolumeRenderer};
use crate::settings::{ConcretePath, Strategy};

use crate::ui::frames::frame_job::{BandInFlight, Completion, FrameJob, JobKind, band_budget_ms};
use crate::ui::frames::lod::{Lod, STILL_AFTER};

/// How long the pump lets the window draw "preparing" before slow work holds the renderer.
const PREPARE_NOTICE: Duration = Duration::from_millis(30);
/// How often the pump looks whether the GPU has finished a band.
const POLL: Duration = Duration::from_millis(1);
/// How long the pump sleeps when there is nothing to do (it is woken for new work).
const IDLE: Duration = Duration::from_millis(250);
/// How often the pump asks the window to draw while a long frame is in progress (its overlay
/// shows how far the frame has come); each such pass costs the window's drawing.
const PROGRESS_EVERY: Duration = Duration::from_millis(2000);

/// A frame whose last band went to the GPU, for the window to show.
pub struct Finished {
    /// The frame.
    pub job: FrameJob,
    /// Frames in the refinement mean after it, where it joined the mean.
    pub mean: Option<u32>,
    /// The path its bands ran on.
    pub path: ConcretePath,
    /// The strategy its bands ran with (what `auto` stood for).
    pub strategy: Strategy,
    /// Whether that strategy is final for the frame's inputs: false where `auto` carried its
    /// last choice over while the user was busy, to be timed once they are quiet (never on a
    /// CPU driver, which does not time).
    pub strategy_settled: bool,
}

/// What the window's thread and the pump share.
pub struct Shared {
    /// The renderer (all of the window's GPU work goes through it).
    pub renderer: VolumeRenderer,
    /// The frame being rendered.
    pub job: Option<FrameJob>,
    /// The last band submitted, until the GPU has finished it.
    pub in_flight: Option<BandInFlight>,
    /// Frames finished since the window last looked.
    pub finished: Vec<Finished>,
    /// The cost per pixel, from the wall time of finished bands.
    pub lod: Lod,
    /// Why the frame in progress failed, for the window to show.
    pub error: Option<String>,
    /// The slow CPU work the pump is doing before the next band, if any.
    pub preparing: Option<&'static str>,
    /// When the user last did anything in the window: bands are short while they are active.
    pub last_input: Option<Instant>,
}

/// What the window knows of the pump's work, from the last pass that could look.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Busy {
    /// The frame in progress.
    pub frame: Option<InProgress>,
    /// Whether a band is on the GPU.
    pub in_flight: bool,
    /// Slow CPU work before the next band.
    pub preparing: Option<&'static str>,
    /// Whether a frame was ever added to a refinement mean (lavapipe's timestamps go wrong
    /// after one).
    pub accumulated: bool,
}

/// The frame in progress, as the window sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InProgress {
    /// What it is for.
    pub kind: JobKind,
    /// The share of its rows submitted, 0 to 1.
    pub submitted: f64,
    /// Whether it has sent out a band yet.
    pub sent_band: bool,
}

impl Shared {
    /// What the window needs to know of the pump's state.
    pub fn busy(&self) -> Busy {
        Busy {
            frame: self.job.as_ref().map(|j| InProgress {
                kind: j.kind,
                submitted: j.progress(),
                sent_band: !j.bands.is_empty(),
            }),
            in_flight: self.in_flight.is_some(),
            preparing: self.preparing,
            accumulated: self.renderer.has_accumulated(),
        }
    }

    /// Notes a finished band (its wall time feeds the cost model), then submits the frame's next
    /// band if the GPU is free. `may_prepare`: whether slow CPU work (compiling the frame's shader
    /// variant, timing the `auto` path) may be done first (the pump's thread: yes; the window's:
    /// no, it leaves such frames to the pump). Returns whether a band was submitted.
    pub fn step(&mut self, may_prepare: bool) -> bool {
        self.renderer
            .context()
            .device
            .poll(wgpu::PollType::Poll)
            .ok();
        if let Some(band) = self.in_flight.take_if(|b| b.done.is_done()) {
            let ms = band.submitted_at.elapsed().as_secs_f64() * 1e3;
            log::trace!("band {:?} done in {ms:.1} ms", band.rows);
            self.lod.observe(band.size, band.rows, ms);
        }
        if self.in_flight.is_some() {
            return false;
        }
        let Some(job) = self.job.as_ref() else {
            return false;
        };
        let (settings, stats, size) = (job.settings, job.inputs.stats, job.inputs.size_px);
        let camera = job.inputs.camera;
        // A frame's first band: `auto` keeps the choice made for these inputs, or carries the last
        // one over until it can be timed (instant: this never renders).
        if job.next_row == 0
            && let Err(e) =
                auto_strategy::choose(&mut self.renderer, &settings, size, &camera, false)
        {
            return self.fail(e);
        }
        if !self.ready() {
            if !may_prepare {
                return false;
            }
            self.preparing = Some(self.preparation());
            let may_time = self.user_still();
            let prepared = auto_path::choose(&mut self.renderer, settings.path)
                .and_then(|_| {
                    auto_strategy::choose(&mut self.renderer, &settings, size, &camera, may_time)
                })
                .and_then(|_| self.renderer.prepare_pipeline(&settings, stats, size));
            self.preparing = None;
            if let Err(e) = prepared {
                return self.fail(e);
            }
        }
        self.submit_next()
    }

    /// Whether the frame in progress can go out without slow CPU work first.
    fn ready(&self) -> bool {
        self.job.as_ref().is_none_or(|j| {
            !self.wants_strategy_timing()
                && self
                    .renderer
                    .ready_for(&j.settings, j.inputs.stats, j.inputs.size_px)
        })
    }

    /// Whether the user has been still long enough for the `auto` strategy to be timed.
    fn user_still(&self) -> bool {
        self.last_input.is_none_or(|t| t.elapsed() >= STILL_AFTER)
    }

    /// Whether the frame in progress, not yet begun, waits for the `auto` strategy to be timed.
    fn wants_strategy_timing(&self) -> bool {
        self.job.as_ref().is_some_and(|j| {
            j.next_row == 0
                && auto_strategy::wants_timing(
                    &self.renderer,
                    &j.settings,
                    j.inputs.size_px,
                    self.user_still(),
                )
        })
    }

    /// What the slow work before the frame in progress is.
    fn preparation(&self) -> &'static str {
        if self.renderer.auto_path().is_none() {
            "timing the fragment and compute ray loops on this GPU"
        } else if self.wants_strategy_timing() {
            "timing RC-t against leaping for these settings"
        } else {
            "compiling the ray caster for these settings"
        }
    }

    /// Submits the job's next band (the GPU is free and the renderer ready).
    fn submit_next(&mut self) -> bool {
        let Some(job) = self.job.as_mut() else {
            return false;
        };
        let size = job.inputs.size_px;
        let since_input = self.last_input.map(|t| t.elapsed().as_secs_f64() * 1e3);
        let budget = band_budget_ms(since_input);
        // A preview is as cheap as the interaction level of detail could make it, and the user
        // is waiting to see it move: it goes out whole.
        let end = if job.preview_of.is_some() {
            size[1]
        } else {
            self.lod.band_end(size, job.next_row, budget, WORKGROUP)
        };
        let Some(band) = job.next_band(end) else {
            self.job = None;
            return false;
        };
        let request = FrameRequest {
            camera: &job.inputs.camera,
            size,
            settings: &job.settings,
            stats: job.inputs.stats,
        };
        let accumulate = match job.kind {
            JobKind::Plain { refine } => refine.then_some(Accumulate::Restart),
            JobKind::Refinement => Some(Accumulate::Add),
        };
        let submitted_at = Instant::now();
        let (submitted, mean) = match self.renderer.render_band(&request, band, accumulate) {
            Ok(ok) => ok,
            Err(e) => return self.fail(e),
        };
        log::trace!(
            "band {band:?} of {size:?} submitted as frame {}",
            submitted.frame
        );
        let done = Completion::default();
        let callback = done.clone();
        self.renderer
            .context()
            .queue
            .on_submitted_work_done(move || callback.finish());
        self.in_flight = Some(BandInFlight {
            submitted_at,
            size,
            rows: band,
            done,
        });
        job.submitted(band, submitted.frame);
        if job.is_complete()
            && let Some(job) = self.job.take()
        {
            // Settled unless `auto` would still time these inputs once the user is quiet.
            let strategy_settled = !auto_strategy::wants_timing(
                &self.renderer,
                &job.settings,
                job.inputs.size_px,
                true,
            );
            self.finished.push(Finished {
                job,
                mean,
                path: submitted.key.path,
                strategy: submitted.key.strategy,
                strategy_settled,
            });
        }
        true
    }

    /// Drops the frame in progress with `e` for the window to show; returns false.
    fn fail(&mut self, e: RenderError) -> bool {
        self.job = None;
        self.error = Some(format!("Cannot render the volume: {e}"));
        false
    }
}

/// The shared state, waiting for the pump if it holds it (only for rare, user-started work: a
/// new volume, saving an image).
pub fn lock(shared: &Mutex<Shared>) -> MutexGuard<'_, Shared> {
    // A panic on the pump thread leaves the state as it was between two steps: usable.
    shared.lock().unwrap_or_else(|p| p.into_inner())
}

/// The shared state, unless the pump holds it (it is preparing a frame): a window's pass never
/// waits.
pub(crate) fn try_lock(shared: &Mutex<Shared>) -> Option<MutexGuard<'_, Shared>> {
    match shared.try_lock() {
        Ok(guard) => Some(guard),
        Err(TryLockError::Poisoned(p)) => Some(p.into_inner()),
        Err(TryLockError::WouldBlock) => None,
    }
}

/// The pump's thread and the state it shares with the window.
pub struct BandPump {
    shared: Arc<Mutex<Shared>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl BandPump {
    /// Starts the pump over `renderer`; `ctx` is asked to draw when a frame is finished.
    pub fn start(renderer: VolumeRenderer, ctx: egui::Context) -> Result<Self, std::io::Error> {
        let shared = Arc::new(Mutex::new(Shared {
            renderer,
            job: None,
            in_flight: None,
            finished: Vec::new(),
            lod: Lod::default(),
            error: None,
            preparing: None,
            last_input: None,
        }));
        let stop = Arc::new(AtomicBool::new(false));
        let thread = {
            let (shared, stop) = (Arc::clone(&shared), Arc::clone(&stop));
            std::thread::Builder::new()
                .name("band pump".into())
                .spawn(move || run(&shared, &stop, &ctx))?
        };
        Ok(Self {
            shared,
            stop,
            thread: Some(thread),
        })
    }

    /// The shared state (lock it with [`lock`] or [`try_lock`]); a handle of its own, so that
    /// its guard does not borrow the caller.
    pub fn handle(&self) -> Arc<Mutex<Shared>> {
        Arc::clone(&self.shared)
    }

    /// Wakes the pump for new work.
    pub(crate) fn wake(&self) {
        if let Some(t) = &self.thread {
            t.thread().unpark();
        }
    }
}

impl Drop for BandPump {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            t.thread().unpark();
            let _ = t.join();
        }
    }
}

/// The pump's loop: a step whenever there is work, a wake-up for the window when a frame is
/// finished (and now and then while a long one is in progress).
fn run(shared: &Mutex<Shared>, stop: &AtomicBool, ctx: &egui::Context) {
    let mut last_progress = Instant::now();
    let mut was_busy = false;
    while !stop.load(Ordering::Acquire) {
        let (busy, finished, failed) = {
            let mut s = lock(shared);
            if s.job.is_some() && s.in_flight.is_none() && !s.ready() {
                // About to do slow work: let the window say so first.
                s.preparing = Some(s.preparation());
                drop(s);
                ctx.request_repaint();
                std::thread::sleep(PREPARE_NOTICE);
                s = lock(shared);
            }
            s.step(true);
            (
                s.job.is_some() || s.in_flight.is_some(),
                !s.finished.is_empty(),
                s.error.is_some(),
            )
        };
        // The last band done: its timings can be read now.
        let drained = was_busy && !busy;
        was_busy = busy;
        if finished || failed || drained {
            ctx.request_repaint();
        } else if busy && last_progress.elapsed() >= PROGRESS_EVERY {
            last_progress = Instant::now();
            ctx.request_repaint();
        }
        if busy {
            std::thread::sleep(POLL);
        } else {
            std::thread::park_timeout(IDLE);
        }
    }
}

/// An image to render at full quality for saving (File › Save image…).
pub struct Still {
    /// The camera.
    pub camera: crate::camera::Camera,
    /// Image size in pixels.
    pub size: [u32; 2],
    /// What the frame renders with.
    pub settings: crate::settings::RenderSettings,
    /// The transfer function.
    pub transfer: crate::transfer::TransferFunction,
    /// Frames of the refinement mean (1: one plain frame).
    pub frames: u32,
    /// Where to write it (`.png`, `.exr`).
    pub path: std::path::PathBuf,
}

/// Renders `still` on a thread of its own, in bands, waiting for each, and writes it: the window
/// keeps drawing (its passes find the renderer busy and leave it alone) and its own drawing waits
/// for at most one band. The outcome arrives on the returned channel as a line for the user, and
/// `ctx` is asked to draw when it does.
pub(crate) fn save_still(
    shared: Arc<Mutex<Shared>>,
    still: Still,
    ctx: egui::Context,
) -> Result<std::sync::mpsc::Receiver<Result<String, String>>, String> {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::Builder::new()
        .name("save image".into())
        .spawn(move || {
            let [w, h] = still.size;
            let started = Instant::now();
            let outcome = {
                let mut s = lock(&shared);
                render_still(&mut s, &still)
                    .map_err(|e| format!("Cannot render a {w}×{h} image: {e}"))
            }
            .and_then(|image| image.save(&still.path).map_err(|e| e.to_string()))
            .map(|()| {
                format!(
                    "saved {w}×{h} to {} ({:.1} s)",
                    still.path.display(),
                    started.elapsed().as_secs_f64()
                )
            });
            match &outcome {
                Ok(line) => log::info!("{line}"),
                Err(e) => log::error!("{e}"),
            }
            let _ = tx.send(outcome);
            ctx.request_repaint();
        })
        .map_err(|e| format!("cannot start saving: {e}"))?;
    Ok(rx)
}

/// The frames of `still` in bands sized by the learnt cost of their rows, each waited for.
fn render_still(s: &mut Shared, still: &Still) -> Result<crate::imaging::ImageF32, RenderError> {
    s.job = None;
    let Shared { renderer, lod, .. } = s;
    renderer.set_transfer_function(&still.transfer);
    auto_path::choose(renderer, still.settings.path)?;
    let size = still.size;
    auto_strategy::choose(renderer, &still.settings, size, &still.camera, true)?;
    let run = RefineRun {
        frames: still.frames,
        band_end: Some(&mut |first| lod.band_end(size, first, band_budget_ms(None), WORKGROUP)),
        done: None,
    };
    renderer.render_refined(&still.camera, size, &still.settings, run)
}
