//! The central panel: the view's gestures (window/level included), its frame, the image and what
//! is drawn over it.

use std::time::{Duration, Instant};

use egui::Color32;

use crate::ui::Action;
use crate::ui::frames::lod::STILL_AFTER;
use crate::ui::gestures::window_level::{self, WindowLevelEdit};
use crate::ui::layout::{Pane, panes};
use crate::ui::screenshot::TURN_DEG_PER_FRAME;
use crate::ui::view::crop::{crop_handles, hint as crop_hint};
use crate::ui::view::orientation_marker;
use crate::ui::view::overlay::{draw_first_frame_status, draw_loading, draw_readout};
use crate::ui::view::viewport::{ViewArea, view_ui};

use super::LeapViewApp;

impl LeapViewApp {
    /// The central panel, divided by the layout between the 3D view and the slice views.
    pub(super) fn view(&mut self, ui: &mut egui::Ui) {
        self.slices.begin_pass();
        self.slices.alone = !self.state.layout.has_3d();
        self.slices.set_transfer_function(self.state.editor.tf());
        let area = ui.available_rect_before_wrap();
        let has_volume = self.scene.volume().is_some();
        let layout = panes(self.state.layout, area, 2.0);
        // The slices shown keep their bricks on the GPU, and draw again when bricks arrive.
        let slices_shown = layout.iter().any(|(p, _)| matches!(p, Pane::Slice(_)));
        self.scene.set_slice_planes(if slices_shown {
            self.slices.planes_in_voxels()
        } else {
            Vec::new()
        });
        self.slices.set_contents(self.scene.pages_generation());
        for (pane, rect) in layout {
            let mut child = ui.new_child(egui::UiBuilder::new().max_rect(rect));
            match pane {
                Pane::ThreeD => self.view_3d(&mut child),
                Pane::Slice(kind) if has_volume => {
                    let crop = self
                        .state
                        .show_crop_box
                        .then_some(&mut self.state.render.crop);
                    self.slices.pane_ui(&mut child, kind, rect, crop);
                }
                Pane::Slice(_) => {}
            }
        }
        let probe = match self.slices.hover() {
            Some(probe) if self.state.layout.has_slices() => Some(*probe),
            _ => self.hover_3d,
        };
        if let Some(probe) = &probe {
            let label = probe
                .voxel
                .and_then(|v| self.slices.labels()?.segment_at(v))
                .map(|s| match s.name == format!("label {}", s.value) {
                    true => s.name.clone(),
                    false => format!("{} (label {})", s.name, s.value),
                });
            draw_probe(
                ui,
                area,
                probe,
                self.scene.volume().map(|v| &v.kind),
                label.as_deref(),
            );
        }
        // Without the 3D view (a 2D image alone), loading shows over the whole area.
        if !self.state.layout.has_3d() {
            if let Some(status) = self.loader.busy()
                && draw_loading(ui, area, &status)
            {
                self.loader.cancel();
                self.untitle_if_empty(ui.ctx());
            }
            draw_drop_hint(ui, area);
        }
    }

    /// The 3D view: gestures, the frame, the image and what is drawn over it.
    fn view_3d(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        let area = view_ui(ui, self.scene.framing_mut().camera_mut());
        self.view_gestures(&area, &ctx);
        self.render_view(&area, &ctx);
        self.view_rect = area.rect;
        self.view_px = area.size_px;
        let [r, g, b] = self.state.background_rgb8();
        ui.painter()
            .rect_filled(area.rect, 0.0, Color32::from_rgb(r, g, b));
        self.scene.paint(ui, area.rect.min);
        if self.scene.frames_rendered() == 0 && self.scene.volume().is_some() {
            draw_first_frame_status(
                ui,
                area.rect,
                self.scene.preparing(),
                self.scene.rendering(),
            );
        }
        self.draw_over_view(ui, &area);
        if let Some(status) = self.loader.busy()
            && draw_loading(ui, area.rect, &status)
        {
            self.loader.cancel();
            self.untitle_if_empty(&ctx);
        }
        draw_drop_hint(ui, area.rect);
    }

    /// What the view's gestures ask of the app: reset, window/level, the scripted turn; and
    /// what lies under the pointer, where a segmentation is shown (its label in the readout).
    fn view_gestures(&mut self, area: &ViewArea, ctx: &egui::Context) {
        self.hover_3d = None;
        if self.slices.labels().is_some()
            && let Some([x, y]) = area.hover_px
            && let Some((camera, _)) = self.scene.framing().camera_and_bounds()
        {
            let tf = self.state.editor.tf();
            let px = glam::DVec2::new(x, y);
            self.hover_3d =
                (self.slices).probe_3d(&self.state.render, tf, &camera, area.size_px, px);
        }
        // With slices shown, a click on the 3D view moves the crosshair to what it points at.
        if self.state.layout.has_slices()
            && let Some([x, y]) = area.clicked_px
            && let Some((camera, _)) = self.scene.framing().camera_and_bounds()
        {
            let tf = self.state.editor.tf().clone();
            self.slices.pick(
                &self.state.render,
                &tf,
                &camera,
                area.size_px,
                glam::DVec2::new(x, y),
            );
        }
        if area.reset_requested {
            self.apply(Action::ResetView, ctx);
        }
        if let Some(deg) = area.roll_deg {
            self.apply(Action::Roll(deg), ctx);
        }
        if let Some(delta) = area.window_drag {
            self.window_level(delta);
        }
        if area.window_drag_ended {
            self.state.editor.end_gesture();
        }
        // The next turn once the last frame is done (a turn drops a frame in progress).
        if self
            .automation
            .wants_another_frame(self.scene.frames_rendered())
            && !self.scene.rendering_new_frame()
        {
            if let Some(camera) = self.scene.framing_mut().camera_mut() {
                camera.orbit(TURN_DEG_PER_FRAME, 0.0);
            }
            ctx.request_repaint();
        }
    }

    /// Renders the view's frame when its inputs changed, and asks for the passes that
    /// refinement and the full-resolution frame after a preview need.
    fn render_view(&mut self, area: &ViewArea, ctx: &egui::Context) {
        let interacting = self.interacting(ctx);
        if user_input(ctx) {
            self.scene.note_input();
        }
        self.scene.offer_labels(self.slices.labels_3d());
        if let Err(message) =
            self.scene
                .render_if_changed(&mut self.state, area.size_px, interacting)
        {
            self.dialogs.show_error(message);
        }
        if self.scene.refining() && self.scene.rendering().is_none() {
            // Refinement paused for input: it goes on once the user has been quiet for a
            // moment. (While a refinement frame renders, the pump asks for the pass that starts
            // the next one.)
            ctx.request_repaint_after(STILL_AFTER);
        }
        if self.scene.strategy_untimed() {
            // `auto` carried its last choice over while the user was busy: it is timed (the
            // view rendered again) once they have been quiet for a moment.
            ctx.request_repaint_after(STILL_AFTER);
        }
        if self.scene.preview_scale().is_some() && self.scene.rendering().is_none() {
            // Refine once the pointer has been still long enough (or at once, if it is).
            let still_in = self
                .last_motion
                .map_or(Duration::ZERO, |t| STILL_AFTER.saturating_sub(t.elapsed()));
            ctx.request_repaint_after(still_in + Duration::from_millis(1));
        }
    }

    /// The orientation marker, the cropping box and the readout, over the image.
    fn draw_over_view(&mut self, ui: &mut egui::Ui, area: &ViewArea) {
        self.marker_rect = None;
        if self.state.show_orientation_marker
            && let Some((camera, _)) = self.scene.framing().camera_and_bounds()
            && let Some(volume) = self.scene.volume()
        {
            self.marker_rect =
                orientation_marker::draw(ui, area.rect, &camera, &volume.orientation_or_assumed());
        }
        self.plane_lines.clear();
        if self.state.layout.has_slices()
            && self.state.show_slice_planes
            && let Some((camera, bounds)) = self.scene.framing().camera_and_bounds()
        {
            self.plane_lines =
                self.slices
                    .draw_planes_3d(ui, area.rect, area.size_px, &camera, &bounds);
        }
        if self.state.show_crop_box
            && let Some((camera, bounds)) = self.scene.framing().camera_and_bounds()
        {
            let crop = &mut self.state.render.crop;
            // Moved faces render in the next pass.
            if crop_handles(ui, area.rect, area.size_px, &camera, &bounds, crop) {
                ui.ctx().request_repaint();
            }
            crop_hint(ui, area.rect);
        }
        self.readout_rect = None;
        if self.state.show_readout {
            let now = Instant::now();
            let readout = self.scene.readout(&self.state, now);
            self.readout_rect = Some(draw_readout(ui, area.rect, &readout));
            // Refresh when the frame rate changes by itself (down to "idle"); no GPU work.
            if let Some(wait) = self.scene.fps_next_change(now) {
                ui.ctx()
                    .request_repaint_after(wait + Duration::from_millis(1));
            }
        }
    }

    /// Whether the user is dragging or zooming: the pointer moved with a button held, or the
    /// wheel turned, less than [`STILL_AFTER`] ago.
    fn interacting(&mut self, ctx: &egui::Context) -> bool {
        let moving = ctx.input(|i| {
            (i.pointer.any_down() && i.pointer.delta() != egui::Vec2::ZERO)
                || i.smooth_scroll_delta != egui::Vec2::ZERO
                || i.zoom_delta() != 1.0
        });
        if moving {
            self.last_motion = Some(Instant::now());
        }
        self.last_motion.is_some_and(|t| t.elapsed() < STILL_AFTER)
    }

    /// A right-drag in the view: the window of MIP, MinIP and X-ray, or the transfer function
    /// shifted and scaled (DVR, isosurface), as 3D Slicer's window/level.
    fn window_level(&mut self, delta: [f32; 2]) {
        let Some(range) = self.scene.volume().and_then(|v| v.range) else {
            return;
        };
        let render = &mut self.state.render;
        let tf = self.state.editor.tf();
        match window_level::drag(render.mode, render.window, tf, range, delta) {
            Some(WindowLevelEdit::Window(window)) => render.window = Some(window),
            Some(WindowLevelEdit::Transfer(map)) => self.state.editor.remap(|x| map.apply(x)),
            None => {}
        }
    }
}

/// Whether the user did anything this pass: moved the pointer, pressed a button or a key, typed,
/// turned the wheel or pinched.
fn user_input(ctx: &egui::Context) -> bool {
    ctx.input(|i| {
        i.events.iter().any(|e| {
            matches!(
                e,
                egui::Event::PointerMoved(_)
                    | egui::Event::MouseMoved(_)
                    | egui::Event::PointerButton { .. }
                    | egui::Event::Key { .. }
                    | egui::Event::Text(_)
                    | egui::Event::MouseWheel { .. }
                    | egui::Event::Zoom(_)
                    | egui::Event::Touch { .. }
            )
        })
    })
}

/// "Drop to open NAME" over the view while a file is dragged over the window.
fn draw_drop_hint(ui: &egui::Ui, rect: egui::Rect) {
    let hovered = ui
        .ctx()
        .input(|i| i.raw.hovered_files.first().and_then(|f| f.path.clone()));
    let Some(path) = hovered else { return };
    let name = path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into());
    ui.painter()
        .rect_filled(rect, 0.0, Color32::from_black_alpha(140));
    ui.painter().text(
        rect.center(),
        egui::Align2::CENTER_CENTER,
        format!("Drop to open {name}"),
        egui::FontId::proportional(22.0),
        Color32::WHITE,
    );
}

/// The point under the pointer in a slice: patient millimetres, voxel, value, the label shown
/// there, at the bottom of the central area.
fn draw_probe(
    ui: &egui::Ui,
    area: egui::Rect,
    probe: &crate::ui::slices::Probe,
    kind: Option<&crate::transfer::fit::DataKind>,
    label: Option<&str>,
) {
    let p = probe.patient;
    let mut text = format!("{:.1}, {:.1}, {:.1} mm (LPS)", p.x, p.y, p.z);
    if let Some([i, j, k]) = probe.voxel {
        text.push_str(&format!("   voxel {i}, {j}, {k}"));
    }
    match probe.value {
        Some(v) => {
            use crate::transfer::fit::DataKind;
            match probe.preview_level {
                // A streamed volume's value is its preview's: the mean of 2^level voxels a side.
                Some(level) => text.push_str(&format!(
                    "   value ≈ {} (level {level})",
                    crate::text::number_to(v, 5)
                )),
                None => text.push_str(&format!("   value {}", crate::text::number_to(v, 5))),
            }
            // CT: in Hounsfield units, or the calibration's HU beside scanner units.
            match kind {
                Some(DataKind::CtHounsfield { .. }) => text.push_str(" HU"),
                Some(DataKind::CtCalibrated { to_hu, .. }) => text.push_str(&format!(
                    " (about {:.0} HU)",
                    to_hu.offset + to_hu.scale * v
                )),
                _ => {}
            }
        }
        None if probe.voxel.is_some() => text.push_str("   no value"),
        None => text.push_str("   outside the volume"),
    }
    if let Some(label) = label {
        text.push_str(&format!("   {label}"));
    }
    let at = egui::pos2(area.min.x + 6.0, area.max.y - 6.0);
    let font = egui::FontId::monospace(13.0);
    let galley = ui.painter().layout_no_wrap(text, font, Color32::WHITE);
    let rect = egui::Align2::LEFT_BOTTOM
        .anchor_size(at, galley.size())
        .expand(3.0);
    ui.painter()
        .rect_filled(rect, 3.0, Color32::from_black_alpha(180));
    ui.painter()
        .galley(rect.min + egui::vec2(3.0, 3.0), galley, Color32::WHITE);
}
