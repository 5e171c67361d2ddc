//! One slice pane: its view (zoom and pan) of the plane through the crosshair, its GPU buffers
//! and the texture egui shows, redrawn only when what it shows changed; the crosshair lines and
//! the patient directions at its edges; its gestures.

use egui::{
    Align2, Color32, CursorIcon, FontId, PointerButton, Pos2, Rect, Sense, Stroke, pos2, vec2,
};
use glam::{DVec2, DVec3};

use crate::mpr::frame::lps;
use crate::mpr::{Plane, PlaneKind, Slab, SliceView};
use crate::render::gpu_data::SliceParams;
use crate::render::labels::GpuLabels;
use crate::render::slice::{
    DisplayTarget, LabelLook, Output, SliceLook, SliceSource, slice_params,
};
use crate::render::table_texture::TableTexture;
use crate::ui::gestures::window_level::window_drag;
use crate::volume::Direction;

use super::{SliceGpu, Source, crop_edit};
use crate::settings::CropBox;

/// What a pane shows this pass.
#[derive(Clone, Copy)]
pub struct PaneLook<'a> {
    /// The crosshair (mm, LPS).
    pub crosshair: DVec3,
    /// This pane's plane (through the crosshair; tilted when oblique).
    pub plane: Plane,
    /// The other two panes (their slots) and planes, whose lines cross this one at the
    /// crosshair.
    pub others: [(PlaneKind, Plane); 2],
    /// The grey window.
    pub window: [f64; 2],
    /// Grey inverted (white at the window's low end).
    pub invert: bool,
    /// Nearest-voxel sampling.
    pub nearest: bool,
    /// A thick slab.
    pub slab: Option<Slab>,
    /// The cropping box, when it is shown (drawn and edited here too).
    pub crop: Option<CropBox>,
    /// The transfer function's colour table and its generation, when the slices are coloured.
    pub colours: Option<(&'a TableTexture, u64)>,
    /// A segmentation over the slice: its textures, their generation and its look.
    pub labels: Option<(&'a GpuLabels, u64, LabelLook)>,
    /// A 2D image alone in its layout: no other planes' lines cross it.
    pub alone: bool,
    /// Whether the patient's directions are known (not a 2D image shown as stored), so that
    /// the edges name them.
    pub directions: bool,
}

/// What a pane's texture shows: the volume's and its bricks' generations, the colour table's
/// and the labels' (where shown), and the pass's parameters.
type Drawn = ((u64, u64), (Option<u64>, Option<u64>), SliceParams);

/// The point under the pointer in a slice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Probe {
    /// Which pane (`None`: the 3D view).
    pub kind: Option<PlaneKind>,
    /// Patient position (mm, LPS).
    pub patient: DVec3,
    /// The nearest voxel (stored indices), `None` outside the volume.
    pub voxel: Option<[u32; 3]>,
    /// Its value in data units (the nearest voxel's), `None` outside or where it is missing.
    pub value: Option<f64>,
    /// Of a volume read from its store brick by brick, the preview level the value is the
    /// mean of (`None`: the voxel's own).
    pub preview_level: Option<u32>,
}

/// What a pane's gestures asked for this pass.
#[derive(Default)]
pub struct Outcome {
    /// Move the crosshair here.
    pub crosshair: Option<DVec3>,
    /// The new window.
    pub window: Option<[f64; 2]>,
    /// The pointer's point, when over the pane.
    pub hover: Option<Probe>,
    /// Turn the other planes about this pane's normal through the crosshair by this many
    /// radians (Ctrl + drag).
    pub tilt: Option<f64>,
    /// The cropping box as a drag of one of its faces left it.
    pub crop: Option<CropBox>,
}

/// A pane's GPU side for one image size: the texture the pass writes and egui shows.
struct PaneGpu {
    target: DisplayTarget,
    id: egui::TextureId,
}

/// One slice pane.
pub struct SlicePane {
    kind: PlaneKind,
    view: Option<SliceView>,
    gpu: Option<PaneGpu>,
    /// What the texture shows: the volume's generation and its bricks', the colour table's and
    /// the labels' generations, and the pass's parameters.
    drawn: Option<Drawn>,
    /// A distance ruler's ends (patient mm), drawn while the plane passes through them.
    ruler: Option<(DVec3, DVec3)>,
    /// The cropping box's face being dragged.
    crop_face: Option<crop_edit::Face>,
}

/// The direction Up, Page Up and the wheel step a plane in: the patient's head, front and right
/// (RAS positive, as 3D Slicer's slice offsets).
fn forward(kind: PlaneKind) -> DVec3 {
    match kind {
        PlaneKind::Axial | PlaneKind::Oblique => lps(Direction::Superior),
        PlaneKind::Coronal => lps(Direction::Anterior),
        PlaneKind::Sagittal => lps(Direction::Right),
    }
}

impl SlicePane {
    /// A pane of `kind`, not yet drawn.
    pub fn new(kind: PlaneKind) -> Self {
        Self {
            kind,
            view: None,
            gpu: None,
            drawn: None,
            ruler: None,
            crop_face: None,
        }
    }

    /// The plane it shows.
    pub fn kind(&self) -> PlaneKind {
        self.kind
    }

    /// Forgets zoom and pan (a new volume): the next pass fits the slice to the pane.
    pub(crate) fn forget_view(&mut self) {
        self.view = None;
        self.drawn = None;
    }

    /// Draws the pane in `rect` and reads its gestures.
    pub fn ui(
        &mut self,
        ui: &mut egui::Ui,
        rect: Rect,
        gpu: &SliceGpu,
        source: &Source,
        look: PaneLook<'_>,
    ) -> Outcome {
        let ppp = ui.ctx().pixels_per_point();
        let (rect, size_px) = crate::ui::view::viewport::pixel_aligned(rect, ppp);
        let size_px = size_px.map(|n| n.max(1));
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        let plane = look.plane;
        let mut view = match self.view {
            Some(v) if v.size == size_px => v.with_plane(plane),
            _ => SliceView::fit(plane, &source.frame, Some(size_px)),
        };
        let to_px = |p: Pos2| {
            DVec2::new(
                f64::from((p.x - rect.min.x) * ppp),
                f64::from((p.y - rect.min.y) * ppp),
            )
        };
        let mut outcome = Outcome::default();
        let pointer = response.hover_pos().or(response.interact_pointer_pos());
        let (shift, ctrl, alt) =
            ui.input(|i| (i.modifiers.shift, i.modifiers.command, i.modifiers.alt));
        // A press on a face of the shown cropping box takes that face.
        if response.drag_started_by(PointerButton::Primary) && !(alt || ctrl || shift) {
            let origin = ui.input(|i| i.pointer.press_origin());
            self.crop_face = match (look.crop, origin) {
                (Some(crop), Some(o)) => crop_edit::face_at(
                    &view.voxel_grid(&source.frame),
                    &source.frame,
                    &crop,
                    to_px(o),
                ),
                _ => None,
            };
        }
        if !response.dragged() {
            self.crop_face = None;
        }
        if let (Some(face), Some(crop), Some(p)) = (self.crop_face, look.crop, pointer) {
            let grid = view.voxel_grid(&source.frame);
            outcome.crop = crop_edit::moved(&grid, &source.frame, &crop, face, to_px(p));
            ui.ctx().set_cursor_icon(CursorIcon::ResizeColumn);
        } else if alt && (response.dragged_by(PointerButton::Primary) || response.clicked()) {
            // Alt + drag measures; Alt + click takes the ruler away.
            if response.clicked() {
                self.ruler = None;
            } else if let Some(p) = pointer {
                let end = view.to_patient(to_px(p));
                let pressed = ui.input(|i| i.pointer.press_origin());
                let start = match (self.ruler, pressed) {
                    (Some((start, _)), _) if !response.drag_started() => start,
                    (_, Some(origin)) => view.to_patient(to_px(origin)),
                    _ => end,
                };
                self.ruler = Some((start, end));
            }
            ui.ctx().set_cursor_icon(CursorIcon::Crosshair);
        } else if response.dragged_by(PointerButton::Primary)
            && ctrl
            && let Some(p) = pointer
        {
            // The turn of the pointer about the crosshair, counter-clockwise on screen.
            let c = view.to_pixel(look.crosshair);
            let now = to_px(p) - c;
            let d = response.drag_delta() * ppp;
            let before = now - DVec2::new(f64::from(d.x), f64::from(d.y));
            let angle = |v: DVec2| (-v.y).atan2(v.x);
            if now.length() > 4.0 && before.length() > 4.0 {
                let mut turn = angle(now) - angle(before);
                if turn > std::f64::consts::PI {
                    turn -= std::f64::consts::TAU;
                } else if turn < -std::f64::consts::PI {
                    turn += std::f64::consts::TAU;
                }
                outcome.tilt = Some(turn);
            }
            ui.ctx().set_cursor_icon(CursorIcon::Alias);
        } else if response.dragged_by(PointerButton::Middle)
            || (response.dragged_by(PointerButton::Primary) && shift)
        {
            let d = response.drag_delta() * ppp;
            view = view.panned(DVec2::new(f64::from(d.x), f64::from(d.y)));
            ui.ctx().set_cursor_icon(CursorIcon::Move);
        } else if (response.dragged_by(PointerButton::Primary) || response.clicked())
            && let Some(p) = pointer
        {
            outcome.crosshair = Some(view.to_patient(to_px(p)));
            ui.ctx().set_cursor_icon(CursorIcon::Crosshair);
        }
        if response.dragged_by(PointerButton::Secondary)
            && let Some(range) = source.volume.value_range()
        {
            let d = response.drag_delta();
            outcome.window = Some(window_drag(look.window, range, [d.x, d.y]));
        }
        if response.hovered() {
            let (zoom, scroll, up, down) = ui.input(|i| {
                let key = |k: &[egui::Key]| k.iter().filter(|k| i.key_pressed(**k)).count() as i32;
                (
                    i.zoom_delta(),
                    i.events
                        .iter()
                        .map(|e| match e {
                            egui::Event::MouseWheel {
                                delta, modifiers, ..
                            } if !modifiers.ctrl && !modifiers.command => delta.y.signum() as i32,
                            _ => 0,
                        })
                        .sum::<i32>(),
                    key(&[egui::Key::ArrowUp, egui::Key::PageUp]),
                    key(&[egui::Key::ArrowDown, egui::Key::PageDown]),
                )
            });
            if zoom != 1.0
                && let Some(p) = pointer
            {
                view = view.zoomed(f64::from(zoom), to_px(p));
            } else {
                let steps = up - down + scroll;
                if steps != 0 {
                    // Along the plane's normal (tilted or not), the way of `forward`.
                    let n = look.plane.normal();
                    let dir = if n.dot(forward(self.kind)) >= 0.0 {
                        n
                    } else {
                        -n
                    };
                    let mm = source.frame.step_along(dir) * f64::from(steps);
                    outcome.crosshair = Some(look.crosshair + dir * mm);
                }
            }
            if let Some(p) = pointer {
                let patient = view.to_patient(to_px(p));
                let voxel = source.frame.voxel_index(source.frame.to_voxel(patient));
                let value = voxel
                    .map(|[i, j, k]| source.volume.value(i, j, k))
                    .filter(|v| v.is_finite());
                outcome.hover = Some(Probe {
                    kind: Some(self.kind),
                    patient,
                    voxel,
                    value,
                    preview_level: source.volume.streaming().map(|s| s.preview_level()),
                });
            }
        }
        self.view = Some(view);
        self.draw(gpu, source, look, view);
        self.paint(ui, rect, &view, &look);
        if let Some(crop) = &look.crop {
            crop_edit::draw(ui, rect, &view, &source.frame, crop);
        }
        if let Some((a, b)) = self.ruler {
            let near = source.frame.step_along(view.plane.normal()) / 2.0;
            if view.plane.distance(a).abs() <= near && view.plane.distance(b).abs() <= near {
                draw_ruler(ui, rect, &view, a, b);
            }
        }
        outcome
    }

    /// Renders the slice into the pane's texture when what it shows changed.
    fn draw(&mut self, gpu: &SliceGpu, source: &Source, look: PaneLook<'_>, view: SliceView) {
        if self.gpu.as_ref().is_none_or(|g| g.target.size != view.size) {
            self.gpu = new_pane_gpu(gpu, view.size, self.gpu.as_ref().map(|g| g.id));
            self.drawn = None;
        }
        let Some(pane) = &self.gpu else { return };
        let slice_look = SliceLook {
            window: look.window,
            nearest: look.nearest,
            slab: look.slab,
            leap: true,
            colour: look.colours.is_some(),
            invert: look.invert,
            labels: look.labels.map_or_else(LabelLook::default, |(_, _, l)| l),
        };
        let params = slice_params(
            &view,
            &source.frame,
            &source.volume,
            source.format,
            slice_look,
            view.size[0],
        );
        let drawn = Some((
            (source.generation, source.contents),
            (look.colours.map(|(_, g)| g), look.labels.map(|(_, g, _)| g)),
            params,
        ));
        if self.drawn == drawn {
            return;
        }
        let bricks = look.slab.and_then(|_| source.bricks(gpu));
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("slice view"),
            });
        gpu.renderer.encode(
            &gpu.device,
            &gpu.queue,
            &mut encoder,
            SliceSource {
                texture: &source.texture,
                bricks,
                colours: look.colours.map(|(table, _)| table),
                labels: look.labels.map(|(labels, _, _)| labels),
            },
            Output::Display(&pane.target),
            &params,
        );
        gpu.queue.submit([encoder.finish()]);
        self.drawn = drawn;
        let p = view.plane.point;
        log::debug!(
            "{} slice drawn through {:.2}, {:.2}, {:.2} mm",
            self.kind.name(),
            p.x,
            p.y,
            p.z
        );
    }

    /// The image, the other planes' lines through the crosshair (in their colours), the patient
    /// directions at the edges and the plane's name.
    fn paint(&self, ui: &egui::Ui, rect: Rect, view: &SliceView, look: &PaneLook<'_>) {
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 0.0, Color32::BLACK);
        if let Some(pane) = &self.gpu {
            let uv = Rect::from_min_max(pos2(0.0, 0.0), pos2(1.0, 1.0));
            painter.image(pane.id, rect, uv, Color32::WHITE);
        }
        let ppp = ui.ctx().pixels_per_point();
        let c = view.to_pixel(look.crosshair);
        let at = pos2(rect.min.x + c.x as f32 / ppp, rect.min.y + c.y as f32 / ppp);
        let reach = rect.width().hypot(rect.height());
        let others: &[(PlaneKind, crate::mpr::Plane)] = if look.alone { &[] } else { &look.others };
        for (slot, other) in others {
            // Where the other plane cuts this one: a line through the crosshair.
            let d = view.plane.normal().cross(other.normal());
            let screen = egui::vec2(d.dot(view.plane.right) as f32, -d.dot(view.plane.up) as f32);
            if screen.length() < 1e-6 {
                continue;
            }
            let screen = screen.normalized() * reach;
            let colour = super::planes_3d::colour(*slot).gamma_multiply(0.75);
            painter.line_segment([at - screen, at + screen], Stroke::new(1.0, colour));
        }
        let font = FontId::proportional(14.0);
        let text = Color32::from_rgb(255, 220, 120);
        let [left, right, top, bottom] = if look.directions {
            view.plane.edge_labels()
        } else {
            Default::default()
        };
        let m = 4.0;
        painter.text(
            pos2(rect.min.x + m, rect.center().y),
            Align2::LEFT_CENTER,
            left,
            font.clone(),
            text,
        );
        painter.text(
            pos2(rect.max.x - m, rect.center().y),
            Align2::RIGHT_CENTER,
            right,
            font.clone(),
            text,
        );
        painter.text(
            pos2(rect.center().x, rect.min.y + m),
            Align2::CENTER_TOP,
            top,
            font.clone(),
            text,
        );
        painter.text(
            pos2(rect.center().x, rect.max.y - m),
            Align2::CENTER_BOTTOM,
            bottom,
            font.clone(),
            text,
        );
        let name = if !look.directions {
            "as stored (no patient orientation)".to_string()
        } else if view.plane.kind == PlaneKind::Oblique {
            format!("{} (oblique)", self.kind.name())
        } else {
            self.kind.name().to_string()
        };
        painter.text(
            rect.min + vec2(m, m),
            Align2::LEFT_TOP,
            name,
            FontId::proportional(13.0),
            super::planes_3d::colour(self.kind),
        );
    }
}

/// A pane's buffers and texture for `size`, registered with egui (reusing `id`).
fn new_pane_gpu(gpu: &SliceGpu, size: [u32; 2], id: Option<egui::TextureId>) -> Option<PaneGpu> {
    let target = match DisplayTarget::new(&gpu.device, size) {
        Ok(t) => t,
        Err(e) => {
            log::warn!("slice view: {e}");
            return None;
        }
    };
    let mut renderer = gpu.egui_renderer.write();
    let id = match id {
        Some(id) => {
            renderer.update_egui_texture_from_wgpu_texture(
                &gpu.device,
                &target.view,
                wgpu::FilterMode::Nearest,
                id,
            );
            id
        }
        None => {
            renderer.register_native_texture(&gpu.device, &target.view, wgpu::FilterMode::Nearest)
        }
    };
    Some(PaneGpu { target, id })
}

/// A pane that cannot show a slice: its reason, centred.
pub(crate) fn draw_message(ui: &mut egui::Ui, rect: Rect, text: &str) {
    ui.allocate_rect(rect, Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 0.0, Color32::from_gray(20));
    painter.text(
        rect.center(),
        Align2::CENTER_CENTER,
        text,
        FontId::proportional(14.0),
        Color32::from_gray(180),
    );
}

/// A ruler from `a` to `b` (patient mm) over the pane, labelled with its length.
fn draw_ruler(ui: &egui::Ui, rect: Rect, view: &SliceView, a: DVec3, b: DVec3) {
    let ppp = ui.ctx().pixels_per_point();
    let at = |p: DVec3| {
        let px = view.to_pixel(p);
        pos2(
            rect.min.x + px.x as f32 / ppp,
            rect.min.y + px.y as f32 / ppp,
        )
    };
    let (pa, pb) = (at(a), at(b));
    let painter = ui.painter_at(rect);
    let colour = Color32::from_rgb(120, 220, 255);
    painter.line_segment([pa, pb], Stroke::new(1.5, colour));
    for p in [pa, pb] {
        painter.circle_stroke(p, 3.0, Stroke::new(1.5, colour));
    }
    painter.text(
        pb + vec2(6.0, -6.0),
        Align2::LEFT_BOTTOM,
        format!("{:.1} mm", (b - a).length()),
        FontId::proportional(14.0),
        colour,
    );
}
