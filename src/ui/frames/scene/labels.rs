//! The segmentation the 3D view shows: what the app offers each pass (the slices' labels and
//! how many times their visibility changed), handed to the renderer before the next frame.

use std::sync::Arc;

use crate::render::VolumeRenderer;
use crate::render::labels::GpuLabels;

/// The labels offered to the 3D view and whether the renderer holds them.
#[derive(Default)]
pub(super) struct SceneLabels {
    /// The labels offered last, and the visibility generation they came with.
    offered: Option<(Arc<GpuLabels>, u64)>,
    /// Labels the renderer refused (on another grid): not offered again.
    refused: Option<Arc<GpuLabels>>,
    /// Whether the renderer holds what was offered.
    applied: bool,
    /// Bumped whenever what the labels show changes (other labels, none, a toggle): a frame
    /// input.
    pub(super) generation: u64,
}

impl SceneLabels {
    /// The app's labels this pass (`None`: none shown), with their visibility generation.
    pub(super) fn offer(&mut self, labels: Option<(Arc<GpuLabels>, u64)>) {
        let labels = labels.filter(|(l, _)| {
            self.refused
                .as_ref()
                .is_none_or(|refused| !Arc::ptr_eq(l, refused))
        });
        let same = |a: &(Arc<GpuLabels>, u64), b: &(Arc<GpuLabels>, u64)| Arc::ptr_eq(&a.0, &b.0);
        match (&self.offered, &labels) {
            (None, None) => return,
            (Some(a), Some(b)) if same(a, b) => {
                if a.1 != b.1 {
                    self.generation += 1;
                    self.offered = labels;
                }
                return;
            }
            _ => {}
        }
        self.offered = labels;
        self.applied = false;
        self.generation += 1;
    }

    /// A new volume was uploaded: it holds no labels until they are given again.
    pub(super) fn volume_changed(&mut self) {
        self.applied = false;
    }

    /// Gives the renderer the labels offered, where it does not hold them yet; the reason where
    /// it cannot show them (they are then dropped, and not offered again).
    pub(super) fn apply(&mut self, renderer: &mut VolumeRenderer) -> Result<(), String> {
        if self.applied || !renderer.has_volume() {
            return Ok(());
        }
        self.applied = true;
        let labels = self.offered.as_ref().map(|(l, _)| Arc::clone(l));
        if let Err(e) = renderer.set_labels(labels) {
            self.refused = self.offered.take().map(|(l, _)| l);
            self.generation += 1;
            return Err(format!("Cannot show the segmentation in 3D: {e}"));
        }
        Ok(())
    }
}
