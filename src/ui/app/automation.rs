//! Screenshot and exit for scripts and the window smoke test (see [`crate::ui::screenshot`]):
//! the screenshot is taken once the view has settled, and compared with the renderer's own image.

use egui::ViewportCommand;

use crate::ui::screenshot::{self, ShotEvent};

use super::LeapViewApp;

/// Passes without a new frame before the view counts as settled for the screenshot: egui needs
/// a pass or two to settle its layout (panel widths), which can resize the view.
const SETTLED_AFTER_PASSES: u32 = 3;

impl LeapViewApp {
    /// Screenshot and exit for scripts; see [`crate::ui::screenshot`].
    pub(super) fn automate(&mut self, ctx: &egui::Context) {
        let quiet_passes = self.scene.note_pass();
        // A 2D image alone shows no 3D frames: its slice view is drawn in the pass that shows
        // it, so a shown volume counts as one frame.
        let frames = if self.state.layout.has_3d() {
            self.scene.frames_rendered()
        } else {
            u64::from(self.scene.volume().is_some())
        };
        let ready = frames >= 1
            && quiet_passes > SETTLED_AFTER_PASSES
            && !self.scene.results_pending()
            && self.scene.preview_scale().is_none()
            && !self.scene.refining()
            && self.scene.rendering().is_none()
            && self.loader.busy().is_none();
        match self.automation.poll_screenshot(ctx, ready) {
            ShotEvent::Requested => self.shot_inputs = self.scene.last_inputs().cloned(),
            ShotEvent::Arrived(path, image) => {
                match screenshot::save(&image, &path) {
                    Ok(()) => log::info!("saved the window to {}", path.display()),
                    Err(e) => log::error!("cannot save the screenshot to {}: {e}", path.display()),
                }
                self.check_screenshot(&image, ctx.pixels_per_point());
            }
            ShotEvent::None => {}
        }
        if frames >= 1 && self.automation.screenshot_waiting() && self.scene.rendering().is_none() {
            // Keep passes coming until the view has settled (while a frame renders, the band
            // pump asks for the pass that follows it).
            ctx.request_repaint();
        }
        if self.automation.should_close(frames) {
            ctx.send_viewport_cmd(ViewportCommand::Close);
        }
    }

    /// Logs how the view in the screenshot differs from the renderer's own image: it must not.
    fn check_screenshot(&self, image: &egui::ColorImage, ppp: f32) {
        if !self.state.layout.has_3d() {
            log::info!("the layout shows no 3D view: nothing to compare");
            return;
        }
        if self.shot_inputs.as_ref() != self.scene.last_inputs() {
            log::info!("a new frame was rendered after the screenshot; not compared");
            return;
        }
        let rendered = match self.scene.read_image() {
            Ok(img) => img.to_rgba8(),
            Err(e) => return log::warn!("cannot read the rendered image back: {e}"),
        };
        let px = |v: f32| (v * ppp).round().max(0.0) as usize;
        let origin = [px(self.view_rect.min.x), px(self.view_rect.min.y)];
        let skip = screenshot::Overdrawn {
            rects: [self.readout_rect, self.marker_rect]
                .into_iter()
                .flatten()
                .map(|r| [px(r.min.x), px(r.min.y), px(r.max.x), px(r.max.y)])
                .collect(),
            lines: self
                .plane_lines
                .iter()
                .map(|[a, b]| [[a.x * ppp, a.y * ppp], [b.x * ppp, b.y * ppp]])
                .collect(),
        };
        let c = screenshot::compare_view(image, origin, &rendered, &skip);
        log::info!(
            "window vs rendered image: {} pixels compared, {} differ, largest difference {} levels",
            c.pixels,
            c.differing,
            c.max_levels
        );
    }
}
