//! The cropping box on a slice: its cut through the plane drawn over the pane, and its faces
//! dragged there (a face whose line crosses the pane moves with the pointer along its axis).

use egui::{Color32, Rect, Stroke, pos2};
use glam::{DVec2, DVec3};

use crate::mpr::view::{VoxelGrid, cut_polygon_of};
use crate::mpr::{PatientFrame, SliceView};
use crate::settings::CropBox;

/// How close (physical pixels) the pointer must come to a face's line to take it.
const GRAB_PX: f64 = 6.0;

/// A face of the cropping box: its axis and which end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Face {
    /// 0, 1 or 2.
    pub axis: usize,
    /// The high end (`max`) or the low end (`min`).
    pub high: bool,
}

/// The crop box's corners in voxel coordinates.
fn voxel_box(crop: &CropBox, dims: [u32; 3]) -> (DVec3, DVec3) {
    let n = DVec3::from(dims.map(f64::from));
    (
        DVec3::from(crop.min) * n - 0.5,
        DVec3::from(crop.max) * n - 0.5,
    )
}

/// Draws the box's cut through the pane's plane.
pub fn draw(ui: &egui::Ui, rect: Rect, view: &SliceView, frame: &PatientFrame, crop: &CropBox) {
    let (lo, hi) = voxel_box(crop, frame.dims());
    let cut = cut_polygon_of(&view.plane, frame, lo, hi);
    if cut.len() < 3 {
        return;
    }
    let ppp = ui.ctx().pixels_per_point();
    let mut points: Vec<egui::Pos2> = cut
        .iter()
        .map(|p| {
            let px = view.to_pixel(*p);
            pos2(
                rect.min.x + px.x as f32 / ppp,
                rect.min.y + px.y as f32 / ppp,
            )
        })
        .collect();
    points.push(points[0]);
    ui.painter_at(rect)
        .line(points, Stroke::new(1.5, Color32::from_rgb(255, 200, 60)));
}

/// The face whose line on the pane passes within [`GRAB_PX`] of pixel `px`, inside the box's
/// extent along the other axes.
pub(crate) fn face_at(
    grid: &VoxelGrid,
    frame: &PatientFrame,
    crop: &CropBox,
    px: DVec2,
) -> Option<Face> {
    let (lo, hi) = voxel_box(crop, frame.dims());
    // Pixel centres sit at +0.5.
    let v = grid.first + grid.step_x * (px.x - 0.5) + grid.step_y * (px.y - 0.5);
    let slack = |a: usize| (grid.step_x[a].abs() + grid.step_y[a].abs()) * GRAB_PX;
    let mut best: Option<(f64, Face)> = None;
    for axis in 0..3 {
        let per_px = grid.step_x[axis].hypot(grid.step_y[axis]);
        if per_px < 1e-9 {
            continue;
        }
        let inside = (0..3)
            .filter(|b| *b != axis)
            .all(|b| v[b] >= lo[b] - slack(b) && v[b] <= hi[b] + slack(b));
        if !inside {
            continue;
        }
        for (high, at) in [(false, lo[axis]), (true, hi[axis])] {
            let distance_px = (v[axis] - at).abs() / per_px;
            if distance_px <= GRAB_PX && best.is_none_or(|(d, _)| distance_px < d) {
                best = Some((distance_px, Face { axis, high }));
            }
        }
    }
    best.map(|(_, f)| f)
}

/// The box with `face` moved to the pointer at pixel `px` (along the face's axis, within the
/// volume, never past the opposite face); `None` when that would not be a valid box.
pub fn moved(
    grid: &VoxelGrid,
    frame: &PatientFrame,
    crop: &CropBox,
    face: Face,
    px: DVec2,
) -> Option<CropBox> {
    let v = grid.first + grid.step_x * (px.x - 0.5) + grid.step_y * (px.y - 0.5);
    let n = f64::from(frame.dims()[face.axis]);
    let fraction = ((v[face.axis] + 0.5) / n).clamp(0.0, 1.0);
    let mut out = *crop;
    let gap = 2.0 * crate::settings::crop::MIN_CROP_FRACTION;
    if face.high {
        out.max[face.axis] = fraction.max(out.min[face.axis] + gap);
    } else {
        out.min[face.axis] = fraction.min(out.max[face.axis] - gap);
    }
    out.validate().ok().map(|()| out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mpr::{Plane, PlaneKind};
    use crate::volume::Orientation;

    #[test]
    fn a_face_is_taken_near_its_line_and_follows_the_pointer() {
        let frame = PatientFrame::new(
            Orientation::parse_code("LPS").expect("code"),
            [1.0, 1.0, 1.0],
            [100, 80, 60],
            DVec3::ZERO,
            false,
        );
        let view = SliceView::fit(
            Plane::standard(PlaneKind::Axial, frame.centre()),
            &frame,
            Some([100, 80]),
        );
        let grid = view.voxel_grid(&frame);
        let crop = CropBox::from_voxels([100, 80, 60], [10.0, 0.0, 0.0], [90.0, 80.0, 60.0]);
        // One pixel per voxel, i to the right: the low-x face is the column near x = 10.
        let face = face_at(&grid, &frame, &crop, DVec2::new(10.5, 40.0)).expect("a face");
        assert_eq!(
            face,
            Face {
                axis: 0,
                high: false
            }
        );
        assert_eq!(face_at(&grid, &frame, &crop, DVec2::new(50.0, 40.0)), None);
        let dragged = moved(&grid, &frame, &crop, face, DVec2::new(30.5, 40.0)).expect("valid");
        assert!(
            (dragged.min[0] - 30.5 / 100.0).abs() < 1e-9,
            "{:?}",
            dragged.min
        );
        // Never past the opposite face.
        let far = moved(&grid, &frame, &crop, face, DVec2::new(99.5, 40.0)).expect("valid");
        assert!(far.min[0] < far.max[0]);
    }
}
