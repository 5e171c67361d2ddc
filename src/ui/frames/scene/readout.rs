//! What the scene tells the readout over the view: the volume, the look, frame rate and GPU
//! time where they can be trusted, what `auto` chose, the refinement's and the frame's progress.

use std::time::{Duration, Instant};

use super::Scene;
use crate::settings::{ConcretePath, Strategy};
use crate::ui::ViewerState;
use crate::ui::view::overlay::Readout;

impl Scene {
    /// Whether the GPU timings can be shown: the adapter has timestamp queries, and it is not a
    /// CPU driver that has run a refinement (lavapipe, Mesa 22.3, reports ~0.1 ms for every frame
    /// from the first accumulation on; a data-centre GPU reports the same times with and without).
    fn timestamps_reliable(&self) -> bool {
        self.has_timestamps && !(self.cpu_adapter && self.busy.accumulated)
    }

    /// What the readout shows now.
    pub fn readout(&mut self, state: &ViewerState, now: Instant) -> Readout<'_> {
        Readout {
            developer: state.developer_readout || state.statistics,
            look: Some(state.look()),
            frame_ms: self.stats.frame_ms,
            orientation_note: self.framing.volume().and_then(|v| {
                (v.orientation_or_assumed().source == crate::volume::OrientationSource::Assumed)
                    .then_some("no orientation in the file: RAS assumed (side panel › View)")
            }),
            fps: self.stats.fps.fps(now),
            gpu_ms: self.stats.gpu_ms.filter(|_| self.timestamps_reliable()),
            has_timestamps: self.timestamps_reliable(),
            adapter: &self.adapter_label,
            path: self.stats.path_used,
            strategy: self
                .stats
                .strategy_used
                .unwrap_or(state.render.strategy)
                .label(),
            volume: self.framing.volume(),
            counters: self.stats.counters,
            rebuild_ms: self.stats.rebuild_ms.filter(|_| {
                self.stats
                    .strategy_used
                    .unwrap_or(state.render.strategy)
                    .leaps()
            }),
            tf_latency_ms: self.stats.tf_latency_ms,
            preview_scale: self.preview_scale(),
            refined: Some(self.shown.refinement).filter(|r| r.done > 0),
            rendering: self.busy.frame.filter(|f| f.sent_band).map(|f| f.submitted),
            preparing: self.busy.preparing,
            blank: self.framing.volume().and_then(|v| {
                crate::transfer::blank::why_blank_in(v.range, state.editor.tf(), &state.render)
            }),
        }
    }

    /// When the frame rate shown changes by itself (down to idle), if it will.
    pub(crate) fn fps_next_change(&self, now: Instant) -> Option<Duration> {
        self.stats.fps_next_change(now)
    }

    /// The path the last frame used (what `auto` chose).
    pub fn path_used(&self) -> Option<ConcretePath> {
        self.stats.path_used
    }

    /// The strategy the last frame ran with (what `auto` chose).
    pub fn strategy_used(&self) -> Option<Strategy> {
        self.stats.strategy_used
    }
}
