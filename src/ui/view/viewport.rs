//! The view: the area the volume is shown in, its mouse gestures, and the renderer's output
//! texture registered once with egui-wgpu and drawn 1:1 in physical pixels, with nearest
//! filtering, so the window shows exactly the values the PNG output holds.

use egui::mutex::RwLock;
use egui::{Color32, CursorIcon, PointerButton, Pos2, Rect, Sense, TextureId, pos2, vec2};

use crate::camera::Camera;

use crate::ui::gestures::interaction::{orbit_drag, pan_drag, zoom_scroll};

/// The area allocated for the view this pass.
pub struct ViewArea {
    /// In points, aligned to physical pixels.
    pub rect: Rect,
    /// Where a left click (not a drag) landed this pass, in physical pixels from the corner.
    pub clicked_px: Option<[f64; 2]>,
    /// Where the pointer rests over the view (not dragging), in physical pixels from the corner.
    pub hover_px: Option<[f64; 2]>,
    /// In physical pixels (what the renderer renders at).
    pub size_px: [u32; 2],
    /// Whether R was pressed (reset view) while the view had the keyboard.
    pub reset_requested: bool,
    /// Degrees to roll the view by (`[` and `]`: 90° anticlockwise and clockwise), when asked.
    pub roll_deg: Option<f64>,
    /// Pointer motion of a right-drag this pass (window/level), in points.
    pub window_drag: Option<[f32; 2]>,
    /// Whether a right-drag ended this pass.
    pub window_drag_ended: bool,
}

/// `rect` with its corner on a physical pixel and a whole number of pixels wide and high (at
/// `ppp` pixels per point), and that size in pixels: what makes texels map 1:1 onto the screen.
pub(crate) fn pixel_aligned(rect: Rect, ppp: f32) -> (Rect, [u32; 2]) {
    let min = pos2(
        (rect.min.x * ppp).round() / ppp,
        (rect.min.y * ppp).round() / ppp,
    );
    let size_px = [
        ((rect.max.x - min.x) * ppp).floor().max(0.0) as u32,
        ((rect.max.y - min.y) * ppp).floor().max(0.0) as u32,
    ];
    let aligned = Rect::from_min_size(min, vec2(size_px[0] as f32 / ppp, size_px[1] as f32 / ppp));
    (aligned, size_px)
}

/// Allocates all remaining space for the view and applies the pointer gestures to `camera`.
pub(crate) fn view_ui(ui: &mut egui::Ui, camera: Option<&mut Camera>) -> ViewArea {
    let ppp = ui.ctx().pixels_per_point();
    let (rect, size_px) = pixel_aligned(ui.available_rect_before_wrap(), ppp);
    let response = ui.allocate_rect(rect, Sense::click_and_drag());
    // Clicking the view gives it egui's focus, so only a text field blocks the shortcut.
    let keys = !ui.ctx().text_edit_focused();
    let pressed = |key| keys && ui.input(|i| i.key_pressed(key) && i.modifiers.is_none());
    let reset_requested = pressed(egui::Key::R);
    let roll_deg = if pressed(egui::Key::OpenBracket) {
        Some(-90.0)
    } else if pressed(egui::Key::CloseBracket) {
        Some(90.0)
    } else {
        None
    };
    if let Some(camera) = camera {
        let shift = ui.input(|i| i.modifiers.shift);
        let delta = response.drag_delta();
        let panning = response.dragged_by(PointerButton::Middle)
            || (response.dragged_by(PointerButton::Primary) && shift);
        if panning {
            pan_drag(camera, [delta.x, delta.y], rect.height());
            ui.ctx().set_cursor_icon(CursorIcon::Move);
        } else if response.dragged_by(PointerButton::Primary) {
            orbit_drag(camera, [delta.x, delta.y]);
            ui.ctx().set_cursor_icon(CursorIcon::Grabbing);
        }
        if response.hovered() {
            let (scrolled, pinch) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
            zoom_scroll(camera, scrolled, pinch);
        }
    }
    let window_drag = response
        .dragged_by(PointerButton::Secondary)
        .then(|| response.drag_delta())
        .filter(|d| *d != egui::Vec2::ZERO)
        .map(|d| [d.x, d.y]);
    if window_drag.is_some() {
        ui.ctx().set_cursor_icon(CursorIcon::ResizeColumn);
    }
    ViewArea {
        rect,
        clicked_px: response
            .clicked()
            .then(|| response.interact_pointer_pos())
            .flatten()
            .map(|p| {
                [
                    f64::from((p.x - rect.min.x) * ppp),
                    f64::from((p.y - rect.min.y) * ppp),
                ]
            }),
        hover_px: (!response.dragged())
            .then(|| response.hover_pos())
            .flatten()
            .map(|p| {
                [
                    f64::from((p.x - rect.min.x) * ppp),
                    f64::from((p.y - rect.min.y) * ppp),
                ]
            }),
        size_px,
        reset_requested,
        roll_deg,
        window_drag,
        window_drag_ended: response.drag_stopped_by(PointerButton::Secondary),
    }
}

/// The renderer's output image as an egui texture: registered once, re-pointed when the renderer
/// replaces its output texture (on a size change).
#[derive(Default)]
pub struct ViewTexture {
    id: Option<TextureId>,
    view: Option<wgpu::TextureView>,
    size_px: [u32; 2],
    filter: Option<wgpu::FilterMode>,
}

impl ViewTexture {
    /// Makes the texture id show `view` (of `size_px` pixels); `stretched` when the image is a
    /// reduced-resolution preview drawn over a larger view.
    pub fn sync(
        &mut self,
        egui_renderer: &RwLock<egui_wgpu::Renderer>,
        device: &wgpu::Device,
        view: &wgpu::TextureView,
        size_px: [u32; 2],
        stretched: bool,
    ) {
        self.size_px = size_px;
        // Nearest at 1:1: it reads each texel exactly, where linear could blend neighbours when
        // the panel edge is not exactly on a pixel. Linear for a stretched preview (no blocks).
        let filter = if stretched {
            wgpu::FilterMode::Linear
        } else {
            wgpu::FilterMode::Nearest
        };
        if self.view.as_ref() == Some(view) && self.filter == Some(filter) {
            return;
        }
        self.filter = Some(filter);
        let mut renderer = egui_renderer.write();
        match self.id {
            Some(id) => renderer.update_egui_texture_from_wgpu_texture(device, view, filter, id),
            None => self.id = Some(renderer.register_native_texture(device, view, filter)),
        }
        self.view = Some(view.clone());
    }

    /// Size of the image on display, in physical pixels.
    pub(crate) fn size_px(&self) -> [u32; 2] {
        self.size_px
    }

    /// Draws the image with its top-left corner at `origin`, one texel per physical pixel, or,
    /// for a reduced preview, stretched over `view_px` physical pixels.
    pub(crate) fn paint(
        &self,
        ui: &egui::Ui,
        origin: Pos2,
        view_px: Option<[u32; 2]>,
    ) -> Option<Rect> {
        let id = self.id?;
        let ppp = ui.ctx().pixels_per_point();
        let size = view_px.unwrap_or(self.size_px);
        let rect = Rect::from_min_size(origin, vec2(size[0] as f32 / ppp, size[1] as f32 / ppp));
        let uv = Rect::from_min_max(pos2(0.0, 0.0), pos2(1.0, 1.0));
        ui.painter().image(id, rect, uv, Color32::WHITE);
        Some(rect)
    }
}
