//! What the window measured of its frames: frames per second, the GPU time of the last plain
//! frame (added up over its bands as their timings arrive), sample counters, the leaping
//! structures' rebuild time, the transfer-function edit latency, and what `auto` chose.

use std::time::{Duration, Instant};

use crate::counters::FrameCounters;
use crate::render::probe::FrameResults;
use crate::settings::{ConcretePath, Strategy};
use crate::ui::view::overlay::FpsCounter;

/// What a statistics frame counted, and over how many pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CountedFrame {
    /// The frame's sample counters.
    pub counters: FrameCounters,
    /// Its pixels (for samples per pixel).
    pub pixels: u64,
}

/// The GPU time of a frame's bands as their timings arrive.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct GpuSum {
    /// Milliseconds of the bands back so far.
    ms: f64,
    /// Bands whose results are back.
    bands_back: usize,
}

/// The window's measurements of its frames.
#[derive(Default)]
pub struct FrameStats {
    /// Frames per second over the last moments.
    pub fps: FpsCounter,
    /// GPU time of the last complete plain frame, once all its bands are timed.
    pub gpu_ms: Option<f64>,
    /// What the last statistics frame counted.
    pub counters: Option<CountedFrame>,
    /// GPU time of the last rebuild of the leaping structures.
    pub rebuild_ms: Option<f64>,
    /// The path the last frame used.
    pub path_used: Option<ConcretePath>,
    /// The strategy the last frame ran with (what `auto` stood for).
    pub strategy_used: Option<Strategy>,
    /// Whether that strategy is final for the last frame's inputs (false: `auto` carried its
    /// last choice over while the user was busy).
    pub strategy_settled: bool,
    /// Volume frames rendered so far.
    pub frames_rendered: u64,
    /// Pixels of the last frame (for samples per pixel).
    pub last_pixels: u64,
    /// Predicted milliseconds of a full-resolution frame of the view, once bands were timed.
    pub frame_ms: Option<f64>,
    /// Whether the renderer has been given the editor's function yet (the first one is not an
    /// edit whose latency is measured).
    transfer_given: bool,
    /// When the renderer got a new transfer function whose frame has not come back yet.
    tf_edit_at: Option<Instant>,
    /// Milliseconds from the last transfer-function change to its frame's completion.
    pub tf_latency_ms: Option<f64>,
    /// Renderer frame numbers of the last complete plain frame's bands.
    plain_bands: Vec<u64>,
    plain_gpu: GpuSum,
}

impl FrameStats {
    /// Measurements before any frame.
    pub fn new() -> Self {
        Self {
            strategy_settled: true,
            ..Self::default()
        }
    }

    /// Notes that the renderer was given the editor's function, `changed` or not.
    pub(crate) fn transfer_given(&mut self, changed: bool) {
        if changed && self.transfer_given {
            self.tf_edit_at = Some(Instant::now());
        }
        self.transfer_given = true;
    }

    /// A plain frame of `bands` (renderer frame numbers) and `pixels` pixels is on screen: its
    /// GPU time adds up from now on; `stats`: whether it counted samples.
    pub(crate) fn plain_frame(&mut self, bands: Vec<u64>, pixels: u64, stats: bool) {
        self.frames_rendered += 1;
        self.fps.record(Instant::now());
        self.last_pixels = pixels;
        self.plain_bands = bands;
        self.plain_gpu = GpuSum::default();
        if !stats {
            self.counters = None;
        }
    }

    /// Bands of the plain frame on screen.
    pub(crate) fn plain_band_count(&self) -> usize {
        self.plain_bands.len()
    }

    /// Takes the GPU timings of a finished band.
    pub fn take(&mut self, result: FrameResults) {
        if let Some(c) = result.counters
            && self.plain_bands.last() == Some(&result.frame)
        {
            // The counters add up over a frame's bands: the last band's are the frame's.
            self.counters = Some(CountedFrame {
                counters: c,
                pixels: self.last_pixels,
            });
        }
        if result.rebuild_ms.is_some() {
            self.rebuild_ms = result.rebuild_ms;
        }
        if self.plain_bands.contains(&result.frame) {
            if let Some(ms) = result.gpu_ms {
                self.plain_gpu.ms += ms;
            }
            self.plain_gpu.bands_back += 1;
            if self.plain_gpu.bands_back == self.plain_bands.len() {
                self.gpu_ms = Some(self.plain_gpu.ms);
            }
        }
        // The first frame back after a transfer-function change carries it (frames complete in
        // order): from the change to that frame's completion on the GPU.
        if let Some(at) = self.tf_edit_at.take() {
            self.tf_latency_ms = Some(at.elapsed().as_secs_f64() * 1e3);
        }
    }

    /// When the frame rate shown changes by itself (down to idle), if it will.
    pub(crate) fn fps_next_change(&self, now: Instant) -> Option<Duration> {
        self.fps.next_change(now)
    }
}
