//! Cropping in the window: six sliders (each face of the box, in voxels) in the side panel, and
//! the box drawn over the view with a handle on each face that drags that face along its axis.
//! Both edit the [`CropBox`] the renderer clips rays to (src/settings/crop.rs).

use egui::{Color32, Pos2, Rect, Sense, Stroke, Vec2, pos2, vec2};
use glam::{DMat4, DVec3};

use crate::camera::{Aabb, Camera};
use crate::settings::CropBox;
use crate::settings::crop::MIN_CROP_FRACTION;

/// Radius of a face handle, in points.
const HANDLE_RADIUS: f32 = 6.0;

/// Axis names, for the slider labels.
const AXES: [&str; 3] = ["x", "y", "z"];

/// Six sliders (low and high face per axis, in voxel edges of a volume of `dims`) and a reset
/// button; `show_box` toggles the box and its handles over the view. Returns whether the box
/// changed.
pub(crate) fn crop_ui(
    ui: &mut egui::Ui,
    crop: &mut CropBox,
    show_box: &mut bool,
    dims: [u32; 3],
) -> bool {
    let before = *crop;
    let (mut lo, mut hi) = crop.voxels(dims);
    egui::Grid::new("crop sliders")
        .num_columns(3)
        .spacing([6.0, 4.0])
        .show(ui, |ui| {
            for a in 0..3 {
                let n = f64::from(dims[a]);
                ui.label(AXES[a]);
                // Whole voxels: the cut falls on voxel edges, as in the CLI's --crop. The box
                // keeps at least one voxel on each axis.
                ui.add(
                    egui::Slider::new(&mut lo[a], 0.0..=n - 1.0)
                        .step_by(1.0)
                        .custom_formatter(voxel_text),
                )
                .on_hover_text(format!("Lowest {} voxel kept", AXES[a]));
                ui.add(
                    egui::Slider::new(&mut hi[a], 1.0..=n)
                        .step_by(1.0)
                        .custom_formatter(voxel_text),
                )
                .on_hover_text(format!("Voxel edge the box ends at on {}", AXES[a]));
                ui.end_row();
                // The face moved last pushes the other one rather than crossing it.
                if hi[a] <= lo[a] {
                    if lo[a] != before.voxels(dims).0[a] {
                        hi[a] = (lo[a] + 1.0).min(n);
                    } else {
                        lo[a] = (hi[a] - 1.0).max(0.0);
                    }
                }
            }
        });
    let moved = CropBox::from_voxels(dims, lo, hi);
    // Only a slider the user moved replaces the box: a handle may have left it between voxels.
    if moved.voxels(dims) != before.voxels(dims) && moved.validate().is_ok() {
        *crop = moved;
    }
    ui.horizontal(|ui| {
        ui.checkbox(show_box, "show box and handles")
            .on_hover_text("Drag a face's handle in the view to move that face");
        if ui
            .add_enabled(!crop.is_full(), egui::Button::new("Reset"))
            .clicked()
        {
            *crop = CropBox::FULL;
        }
    });
    *crop != before
}

/// A voxel edge as the sliders show it: whole voxels as integers, a face a handle left between
/// voxels to a tenth.
fn voxel_text(v: f64, _: std::ops::RangeInclusive<usize>) -> String {
    if v.fract() == 0.0 {
        format!("{v:.0}")
    } else {
        format!("{v:.1}")
    }
}

/// Projects world points onto the view (in points).
pub struct Projector {
    /// The camera's world → clip transform for the view's image.
    pub clip_from_world: DMat4,
    /// The view's rectangle on screen.
    pub rect: Rect,
}

impl Projector {
    /// Screen position of `p`, or `None` behind the eye.
    pub fn screen(&self, p: DVec3) -> Option<Pos2> {
        let h = self.clip_from_world * p.extend(1.0);
        if h.w <= 1e-9 {
            return None;
        }
        let (x, y) = (h.x / h.w, h.y / h.w);
        Some(pos2(
            self.rect.min.x + (0.5 + 0.5 * x as f32) * self.rect.width(),
            self.rect.min.y + (0.5 - 0.5 * y as f32) * self.rect.height(),
        ))
    }
}

/// The twelve edges of a box as index pairs into [`Aabb::corners`] (corner c has bit a set for
/// the max on axis a).
const EDGES: [(usize, usize); 12] = [
    (0, 1),
    (2, 3),
    (4, 5),
    (6, 7),
    (0, 2),
    (1, 3),
    (4, 6),
    (5, 7),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

/// Draws the cropping box over the view `rect` (showing `camera`'s image of `size_px` pixels of
/// a volume with bounding box `bounds`) with a handle at each face's centre; dragging a handle
/// moves its face along its axis, following the pointer's motion along the axis's image on
/// screen. Returns whether the box changed.
pub(crate) fn crop_handles(
    ui: &mut egui::Ui,
    rect: Rect,
    size_px: [u32; 2],
    camera: &Camera,
    bounds: &Aabb,
    crop: &mut CropBox,
) -> bool {
    let projector = Projector {
        clip_from_world: camera.clip_from_world(size_px, bounds),
        rect,
    };
    let world = crop.world(bounds);
    let corners = world.corners();
    let painter = ui.painter_at(rect);
    let line = Stroke::new(1.5, Color32::from_rgb(255, 200, 60));
    for (a, b) in EDGES {
        if let (Some(p), Some(q)) = (projector.screen(corners[a]), projector.screen(corners[b])) {
            painter.line_segment([p, q], line);
        }
    }
    let mut changed = false;
    let size = bounds.size();
    for axis in 0..3 {
        for high in [false, true] {
            let mut centre = world.center();
            centre[axis] = if high {
                world.max[axis]
            } else {
                world.min[axis]
            };
            let Some(at) = projector.screen(centre) else {
                continue;
            };
            // Screen motion per millimetre along the axis, from a step of 1 % of the extent.
            let step = size[axis] * 0.01;
            let mut ahead = centre;
            ahead[axis] += step;
            let Some(ahead) = projector.screen(ahead) else {
                continue;
            };
            let per_mm = (ahead - at) / step as f32;
            let id = ui.scope_id().with(("crop handle", axis, high));
            let hit = Rect::from_center_size(at, Vec2::splat(3.0 * HANDLE_RADIUS));
            let response = ui.interact(hit, id, Sense::drag());
            let active = response.hovered() || response.dragged();
            painter.circle(
                at,
                HANDLE_RADIUS,
                if active {
                    Color32::WHITE
                } else {
                    Color32::from_rgb(255, 200, 60)
                },
                Stroke::new(1.0, Color32::BLACK),
            );
            if response.dragged() && per_mm.length_sq() > 1e-6 {
                let mm = drag_mm(response.drag_delta(), per_mm);
                changed |= move_face(crop, axis, high, mm / size[axis]);
            }
            if active {
                ui.ctx().set_cursor_icon(egui::CursorIcon::Grab);
            }
        }
    }
    changed
}

/// Pointer motion `delta` (points) projected on an axis whose image moves `per_mm` points per
/// millimetre: the millimetres along the axis that follow the pointer.
fn drag_mm(delta: Vec2, per_mm: Vec2) -> f64 {
    f64::from(delta.dot(per_mm) / per_mm.length_sq())
}

/// Moves the low or high face of `axis` by `delta` (box units), keeping the box inside the
/// volume and at least [`MIN_CROP_FRACTION`]·4 thick. Returns whether it moved.
fn move_face(crop: &mut CropBox, axis: usize, high: bool, delta: f64) -> bool {
    if !delta.is_finite() || delta == 0.0 {
        return false;
    }
    let gap = 4.0 * MIN_CROP_FRACTION;
    let before = *crop;
    if high {
        crop.max[axis] = (crop.max[axis] + delta).clamp(crop.min[axis] + gap, 1.0);
    } else {
        crop.min[axis] = (crop.min[axis] + delta).clamp(0.0, crop.max[axis] - gap);
    }
    *crop != before
}

/// Marks a drag hint in the view's corner while the box is shown.
pub fn hint(ui: &egui::Ui, rect: Rect) {
    ui.painter_at(rect).text(
        rect.right_bottom() + vec2(-8.0, -8.0),
        egui::Align2::RIGHT_BOTTOM,
        "drag a handle to move a face of the cropping box",
        egui::FontId::proportional(12.0),
        Color32::from_rgb(255, 200, 60),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_move_within_the_volume_and_never_cross() {
        let mut crop = CropBox::FULL;
        assert!(move_face(&mut crop, 0, false, 0.25));
        assert_eq!(crop.min[0], 0.25);
        assert!(move_face(&mut crop, 0, true, -0.9));
        assert!(crop.max[0] > crop.min[0]);
        assert_eq!(crop.validate(), Ok(()));
        // Pushing past the volume's edge stops at the edge.
        assert!(move_face(&mut crop, 2, true, 5.0) || crop.max[2] == 1.0);
        assert_eq!(crop.max[2], 1.0);
        assert!(!move_face(&mut crop, 1, false, -1.0), "already at 0");
        assert!(!move_face(&mut crop, 1, false, f64::NAN));
    }

    #[test]
    fn a_handle_drag_follows_the_axis_on_screen() {
        // Looking along −y with +z up, the x axis lies horizontal on screen and z vertical.
        let bounds = Aabb::of_volume([32, 32, 32], [1.0; 3]);
        let (dir, up) = crate::camera::ViewPreset::MinusY.direction_and_up();
        let camera = Camera::framing(
            &bounds,
            dir,
            up,
            crate::camera::ProjectionKind::Orthographic,
        );
        let projector = Projector {
            clip_from_world: camera.clip_from_world([400, 400], &bounds),
            rect: Rect::from_min_size(Pos2::ZERO, vec2(400.0, 400.0)),
        };
        let c = bounds.center();
        let centre = projector.screen(c).expect("in front");
        let along_x = projector.screen(c + DVec3::X).expect("in front") - centre;
        let along_z = projector.screen(c + DVec3::Z).expect("in front") - centre;
        assert!(
            along_x.x.abs() > 1.0 && along_x.y.abs() < 1e-3,
            "{along_x:?}"
        );
        assert!(
            along_z.y < -1.0 && along_z.x.abs() < 1e-3,
            "up is up: {along_z:?}"
        );
        // Dragging ten millimetres' worth along the axis's image moves the face 10 mm; across
        // it, not at all.
        assert!((drag_mm(along_x * 10.0, along_x) - 10.0).abs() < 1e-4);
        assert!(drag_mm(vec2(-along_x.y, along_x.x) * 10.0, along_x).abs() < 1e-4);
    }
}
