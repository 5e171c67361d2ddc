//! A volume frame rendered in bands of rows, one band per submission, so that the window never
//! waits long for the GPU: the window's own drawing shares the queue with the ray caster, so a
//! frame that keeps the GPU busy for a second (a CPU driver, a large view, a dense volume) would
//! hold every click and key press for that second and deliver them late in one batch. A band is
//! sized from the measured cost of its rows ([`crate::ui::frames::lod::Lod::band_end`]) to take about
//! [`BAND_BUDGET_MS`] while the user is active; the next band is
//! submitted only once the last has finished, so the queue never holds more than one band ahead
//! of the window. A frame whose inputs change, or a refinement frame when the user does anything,
//! is dropped between two bands.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::settings::RenderSettings;

use crate::ui::frames::redraw::FrameInputs;

/// Time one band should take from submission to completion while the user is active: a 60 Hz
/// refresh. A click waits for at most about one band.
pub const BAND_BUDGET_MS: f64 = 16.0;

/// Time one band may take when the user has been idle for [`IDLE_AFTER_MS`]: every band costs a
/// few milliseconds of its own (the submission, the driver's hand-over, the pump noticing it has
/// finished), so bands of 16 ms make a long frame slower (seen on lavapipe: the phantom at
/// 892×775, 1.0 s in one piece, 1.27 s in 51 bands); the first click after a pause waits for at
/// most one band of this length.
pub const IDLE_BAND_BUDGET_MS: f64 = 50.0;

/// Milliseconds without input after which bands grow to [`IDLE_BAND_BUDGET_MS`].
pub const IDLE_AFTER_MS: f64 = 1000.0;

/// The time a band may take when the user's last input was `since_input_ms` ago (`None`:
/// never).
pub(crate) fn band_budget_ms(since_input_ms: Option<f64>) -> f64 {
    match since_input_ms {
        Some(ms) if ms < IDLE_AFTER_MS => BAND_BUDGET_MS,
        _ => IDLE_BAND_BUDGET_MS,
    }
}

/// What a frame is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JobKind {
    /// A frame for new inputs; `refine`: it starts the refinement mean.
    Plain {
        /// Whether the frame starts the refinement mean.
        refine: bool,
    },
    /// The next frame of the refinement mean, at its shifted sample grid (in the job's settings).
    Refinement,
}

/// Set when the GPU has finished a submission (wgpu calls back from its poll).
#[derive(Clone, Debug, Default)]
pub struct Completion(Arc<AtomicBool>);

impl Completion {
    /// Marks it done (what the queue's callback does).
    pub fn finish(&self) {
        self.0.store(true, Ordering::Release);
    }

    /// Whether the GPU has finished.
    pub(crate) fn is_done(&self) -> bool {
        self.0.load(Ordering::Acquire)
    }
}

/// A band on the GPU.
#[derive(Clone, Debug)]
pub struct BandInFlight {
    /// When it was submitted.
    pub submitted_at: Instant,
    /// The frame's size.
    pub size: [u32; 2],
    /// Its rows, `[first, end)`.
    pub rows: [u32; 2],
    /// Set once it has finished.
    pub done: Completion,
}

/// A frame being rendered band by band.
#[derive(Clone, Debug)]
pub struct FrameJob {
    /// What the frame shows.
    pub inputs: FrameInputs,
    /// The settings it renders with (the inputs' own, or shifted for a refinement frame).
    pub settings: RenderSettings,
    /// What it is for.
    pub kind: JobKind,
    /// The view's size when the frame is a reduced preview of it.
    pub preview_of: Option<[u32; 2]>,
    /// The first row not yet submitted.
    pub next_row: u32,
    /// Renderer frame numbers of the bands submitted so far.
    pub bands: Vec<u64>,
    /// When the first band was submitted.
    pub started: Option<Instant>,
}

impl FrameJob {
    /// A frame for `inputs` rendered with `settings`.
    pub fn new(
        inputs: FrameInputs,
        settings: RenderSettings,
        kind: JobKind,
        preview_of: Option<[u32; 2]>,
    ) -> Self {
        Self {
            inputs,
            settings,
            kind,
            preview_of,
            next_row: 0,
            bands: Vec::new(),
            started: None,
        }
    }

    /// The rows of the next band, up to row `end` (at least one row, at most the image's);
    /// `None` once all are submitted.
    pub(crate) fn next_band(&self, end: u32) -> Option<[u32; 2]> {
        let height = self.inputs.size_px[1];
        (self.next_row < height).then(|| [self.next_row, end.clamp(self.next_row + 1, height)])
    }

    /// Records that `rows` went to the GPU as renderer frame `frame`.
    pub fn submitted(&mut self, rows: [u32; 2], frame: u64) {
        self.next_row = rows[1];
        self.bands.push(frame);
        self.started.get_or_insert_with(Instant::now);
    }

    /// Whether every row was submitted.
    pub(crate) fn is_complete(&self) -> bool {
        self.next_row >= self.inputs.size_px[1]
    }

    /// Share of the rows submitted.
    pub fn progress(&self) -> f64 {
        f64::from(self.next_row) / f64::from(self.inputs.size_px[1].max(1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{Aabb, Camera, ProjectionKind, ViewPreset};

    fn inputs(size: [u32; 2]) -> FrameInputs {
        let b = Aabb::of_volume([8; 3], [1.0; 3]);
        let (dir, up) = ViewPreset::Oblique.direction_and_up();
        FrameInputs {
            camera: Camera::framing(&b, dir, up, ProjectionKind::Perspective),
            size_px: size,
            settings: RenderSettings::default(),
            transfer_generation: 0,
            volume_generation: 0,
            bricks_generation: 0,
            labels_generation: 0,
            slices_generation: 0,
            stats: false,
        }
    }

    #[test]
    fn bands_are_short_while_the_user_is_active() {
        assert_eq!(band_budget_ms(Some(10.0)), BAND_BUDGET_MS);
        assert_eq!(
            band_budget_ms(Some(IDLE_AFTER_MS + 1.0)),
            IDLE_BAND_BUDGET_MS
        );
        assert_eq!(band_budget_ms(None), IDLE_BAND_BUDGET_MS);
    }

    #[test]
    fn a_job_walks_its_rows_once_in_order() {
        let mut job = FrameJob::new(
            inputs([30, 20]),
            RenderSettings::default(),
            JobKind::Plain { refine: true },
            None,
        );
        let mut seen = Vec::new();
        let mut frame = 10;
        while let Some(rows) = job.next_band(job.next_row + 8) {
            assert!(!job.is_complete());
            job.submitted(rows, frame);
            seen.push(rows);
            frame += 1;
        }
        assert_eq!(seen, [[0, 8], [8, 16], [16, 20]]);
        assert!(job.is_complete());
        assert_eq!(job.progress(), 1.0);
        assert_eq!(job.bands, [10, 11, 12]);
        assert!(job.started.is_some());
    }

    #[test]
    fn completion_is_shared_with_the_callback() {
        let done = Completion::default();
        let callback = done.clone();
        assert!(!done.is_done());
        callback.finish();
        assert!(done.is_done());
    }
}
