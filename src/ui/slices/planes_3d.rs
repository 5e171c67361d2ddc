//! The slice planes drawn over the 3D view: where each plane through the crosshair cuts the
//! volume's box, projected by the 3D view's camera, in the colour 3D Slicer gives it (axial red,
//! coronal green, sagittal yellow).

use egui::{Color32, Rect, Stroke};
use glam::DVec3;

use crate::camera::{Aabb, Camera};
use crate::mpr::view::cut_polygon;
use crate::mpr::{PatientFrame, Plane, PlaneKind};
use crate::ui::view::crop::Projector;

/// A plane's colour in every view that shows it.
pub fn colour(kind: PlaneKind) -> Color32 {
    match kind {
        PlaneKind::Axial => Color32::from_rgb(230, 80, 70),
        PlaneKind::Coronal => Color32::from_rgb(90, 200, 90),
        PlaneKind::Sagittal | PlaneKind::Oblique => Color32::from_rgb(240, 210, 70),
    }
}

/// Draws `planes` (each with its pane's kind, for its colour) over the 3D view; returns the
/// segments drawn.
pub fn draw(
    ui: &egui::Ui,
    rect: Rect,
    size_px: [u32; 2],
    camera: &Camera,
    bounds: &Aabb,
    frame: &PatientFrame,
    planes: &[(PlaneKind, Plane)],
) -> Vec<[egui::Pos2; 2]> {
    let projector = Projector {
        clip_from_world: camera.clip_from_world(size_px, bounds),
        rect,
    };
    // The renderer's world: voxel coordinates times the spacing.
    let spacing = DVec3::new(
        frame.axes().x_axis.length(),
        frame.axes().y_axis.length(),
        frame.axes().z_axis.length(),
    );
    let painter = ui.painter_at(rect);
    let mut segments = Vec::new();
    for (kind, plane) in planes {
        let kind = *kind;
        let cut = cut_polygon(plane, frame);
        let screen: Option<Vec<egui::Pos2>> = cut
            .iter()
            .map(|p| projector.screen(frame.to_voxel(*p) * spacing))
            .collect();
        if let Some(mut points) = screen
            && points.len() >= 3
        {
            points.push(points[0]);
            segments.extend(points.windows(2).map(|w| [w[0], w[1]]));
            painter.line(points, Stroke::new(1.5, colour(kind)));
        }
    }
    segments
}
