//! Redraw only when something changed: the inputs of the last rendered frame are kept, and a new
//! frame is rendered only when the current inputs differ. egui runs a pass on every input event
//! (a mouse move, a key); none of those touch the GPU unless they changed what the volume looks
//! like.

use crate::camera::Camera;
use crate::settings::RenderSettings;

/// Everything a volume frame depends on.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameInputs {
    /// The camera in world millimetres.
    pub camera: Camera,
    /// Image size in physical pixels.
    pub size_px: [u32; 2],
    /// Mode, strategy, path, step, termination, background.
    pub settings: RenderSettings,
    /// Bumped whenever the transfer function given to the renderer changes.
    pub transfer_generation: u64,
    /// Bumped whenever a new volume is uploaded.
    pub volume_generation: u64,
    /// Bumped by every frame that some wanted brick was missing from: the next shows more.
    pub bricks_generation: u64,
    /// Bumped whenever the segmentation shown changes (another, none, a label toggled).
    pub labels_generation: u64,
    /// Bumped when the slice planes moved while the rays leave bricks out (their bricks are
    /// decided again in the next frame).
    pub slices_generation: u64,
    /// Whether the frame counts samples (the statistics variant).
    pub stats: bool,
}

/// Remembers the inputs of the last frame.
#[derive(Clone, Debug, Default)]
pub struct RedrawTracker {
    last: Option<FrameInputs>,
}

impl RedrawTracker {
    /// Whether a frame with `inputs` would differ from the last one.
    pub(crate) fn needs_render(&self, inputs: &FrameInputs) -> bool {
        self.last.as_ref() != Some(inputs)
    }

    /// Records that a frame with `inputs` was rendered — or was attempted and failed, so that a
    /// failing frame is not retried on every pass until something changes.
    pub(crate) fn mark_rendered(&mut self, inputs: FrameInputs) {
        self.last = Some(inputs);
    }

    /// Forgets the last frame, so the next pass renders even if nothing changed (after the
    /// renderer's output was used for something else, such as an image of another size).
    pub(crate) fn invalidate(&mut self) {
        self.last = None;
    }

    /// The inputs of the last frame, if any.
    pub fn last(&self) -> Option<&FrameInputs> {
        self.last.as_ref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{Aabb, ProjectionKind, ViewPreset};
    use crate::settings::Strategy;

    fn inputs() -> FrameInputs {
        let bounds = Aabb::of_volume([64, 64, 32], [1.0, 1.0, 2.0]);
        let (dir, up) = ViewPreset::Oblique.direction_and_up();
        FrameInputs {
            camera: Camera::framing(&bounds, dir, up, ProjectionKind::Perspective),
            size_px: [640, 480],
            settings: RenderSettings::default(),
            transfer_generation: 1,
            volume_generation: 1,
            bricks_generation: 0,
            labels_generation: 0,
            slices_generation: 0,
            stats: false,
        }
    }

    #[test]
    fn first_frame_renders_and_identical_inputs_do_not() {
        let mut tracker = RedrawTracker::default();
        let a = inputs();
        assert!(tracker.needs_render(&a));
        tracker.mark_rendered(a.clone());
        // A pass with the same inputs (a mouse move over the window, a repaint for the overlay)
        // must not render again, however often it happens.
        for _ in 0..100 {
            assert!(!tracker.needs_render(&inputs()));
        }
        assert_eq!(tracker.last(), Some(&a));
    }

    /// Changes one input of a frame.
    type Change = fn(&mut FrameInputs);

    #[test]
    fn every_input_triggers_a_frame() {
        let mut tracker = RedrawTracker::default();
        tracker.mark_rendered(inputs());
        let changes: [(&str, Change); 11] = [
            ("orbit", |f| f.camera.orbit(0.5, 0.0)),
            ("pan", |f| f.camera.pan(0.01, 0.0, 100.0)),
            ("zoom", |f| f.camera.zoom(1.1)),
            ("width", |f| f.size_px[0] += 1),
            ("height", |f| f.size_px[1] -= 1),
            ("strategy", |f| f.settings.strategy = Strategy::Rc),
            ("step", |f| f.settings.step_vox *= 2.0),
            ("termination", |f| f.settings.termination_alpha = 0.9),
            ("background", |f| f.settings.background[1] = 0.5),
            ("transfer", |f| f.transfer_generation += 1),
            ("volume", |f| f.volume_generation += 1),
        ];
        for (what, change) in changes {
            let mut changed = inputs();
            change(&mut changed);
            assert!(tracker.needs_render(&changed), "{what} did not trigger");
        }
    }

    #[test]
    fn a_failed_frame_is_not_retried_until_something_changes() {
        let mut tracker = RedrawTracker::default();
        let a = inputs();
        // The caller marks a frame even when rendering it failed.
        tracker.mark_rendered(a.clone());
        assert!(!tracker.needs_render(&a));
        let mut b = a;
        b.size_px = [320, 240];
        assert!(tracker.needs_render(&b));
    }
}
