//! Mouse gestures to camera motion, as pure functions of the pointer deltas (in points) so that
//! the feel can be tested without a window: orbit about the target, pan in the view plane, zoom
//! towards the target, and switching projection without a jump in size.

use crate::camera::{Aabb, Camera, DEFAULT_FOV_Y_DEG, Projection, ProjectionKind, ViewPreset};

/// Orbit speed: degrees per point of pointer motion (a 450-point drag turns 180°).
pub const ORBIT_DEG_PER_POINT: f64 = 0.4;

/// Zoom speed: the zoom factor is `exp(ZOOM_PER_POINT * scrolled points)`; one wheel notch
/// (about 50 points in egui) zooms by about 13 %.
pub const ZOOM_PER_POINT: f64 = 0.0025;

/// Orbits for a drag of `delta` points: horizontal motion turns about the up axis (azimuth),
/// vertical motion tilts (elevation). The surface under the pointer follows it.
pub(crate) fn orbit_drag(camera: &mut Camera, delta: [f32; 2]) {
    camera.orbit(
        f64::from(delta[0]) * ORBIT_DEG_PER_POINT,
        f64::from(delta[1]) * ORBIT_DEG_PER_POINT,
    );
}

/// Pans for a drag of `delta` points in a view `view_height_points` tall: what lies at the
/// target's depth moves with the pointer.
pub(crate) fn pan_drag(camera: &mut Camera, delta: [f32; 2], view_height_points: f32) {
    if view_height_points <= 0.0 {
        return;
    }
    let h = f64::from(view_height_points);
    let height_mm = camera.view_height_at_target_mm();
    // Moving the camera left makes the scene move right, hence the minus on x; screen y grows
    // downwards while the camera's up grows upwards, so y keeps its sign.
    camera.pan(-f64::from(delta[0]) / h, f64::from(delta[1]) / h, height_mm);
}

/// Zooms for `scrolled` points of wheel motion (positive = away from the user = closer) and a
/// pinch or Ctrl+wheel factor `pinch` (1 = none).
pub(crate) fn zoom_scroll(camera: &mut Camera, scrolled: f32, pinch: f32) {
    let factor = (ZOOM_PER_POINT * f64::from(scrolled)).exp() * f64::from(pinch);
    if factor != 1.0 {
        camera.zoom(factor);
    }
}

/// A camera looking along `preset` that frames the whole volume.
pub(crate) fn framed(bounds: &Aabb, preset: ViewPreset, kind: ProjectionKind) -> Camera {
    let (dir, up) = preset.direction_and_up();
    Camera::framing(bounds, dir, up, kind)
}

/// `camera` with projection `kind`, keeping the height of the view at the target: the volume
/// does not jump in size when the projection changes.
pub(crate) fn with_projection(camera: &Camera, kind: ProjectionKind) -> Camera {
    let mut out = *camera;
    let height_mm = camera.view_height_at_target_mm();
    match (camera.projection, kind) {
        (Projection::Perspective { .. }, ProjectionKind::Orthographic) => {
            out.projection = Projection::Orthographic { height_mm };
        }
        (Projection::Orthographic { .. }, ProjectionKind::Perspective) => {
            let fov_y_deg = DEFAULT_FOV_Y_DEG;
            let distance = 0.5 * height_mm / (0.5 * fov_y_deg.to_radians()).tan();
            out.eye = camera.target - camera.forward() * distance;
            out.projection = Projection::Perspective { fov_y_deg };
        }
        _ => {}
    }
    out
}

#[cfg(test)] // Only the tests ask.
/// The kind of `camera`'s projection.
fn projection_kind(camera: &Camera) -> ProjectionKind {
    match camera.projection {
        Projection::Perspective { .. } => ProjectionKind::Perspective,
        Projection::Orthographic { .. } => ProjectionKind::Orthographic,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn bounds() -> Aabb {
        Aabb::of_volume([100, 100, 50], [1.0, 1.0, 2.0])
    }

    /// Where `point` lands on screen (NDC) for a `size` viewport.
    fn ndc(camera: &Camera, point: DVec3, size: [u32; 2]) -> glam::DVec2 {
        let p = camera.clip_from_world(size, &bounds()) * point.extend(1.0);
        (p.truncate() / p.w).truncate()
    }

    #[test]
    fn pan_moves_the_target_with_the_pointer() {
        for kind in [ProjectionKind::Perspective, ProjectionKind::Orthographic] {
            let camera = framed(&bounds(), ViewPreset::MinusY, kind);
            let probe = camera.target;
            let mut moved = camera;
            // Dragging a quarter of the view height to the right and down.
            pan_drag(&mut moved, [100.0, 100.0], 400.0);
            let before = ndc(&camera, probe, [400, 400]);
            let after = ndc(&moved, probe, [400, 400]);
            // A quarter of the height is half an NDC unit; NDC y grows upwards. 1e-9: rounding.
            assert!(
                (after.x - before.x - 0.5).abs() < 1e-9,
                "{kind:?} x {after}"
            );
            assert!(
                (after.y - before.y + 0.5).abs() < 1e-9,
                "{kind:?} y {after}"
            );
        }
    }

    #[test]
    fn orbit_right_turns_the_eye_to_the_left() {
        let mut camera = framed(&bounds(), ViewPreset::PlusY, ProjectionKind::Perspective);
        let right_before = camera.forward().cross(camera.up);
        let eye_before = camera.eye - camera.target;
        orbit_drag(&mut camera, [50.0, 0.0]);
        let eye_after = camera.eye - camera.target;
        // The eye moved towards the old left, so the front surface moved right on screen.
        assert!((eye_after - eye_before).dot(right_before) < 0.0);
        // Dragging down lifts the eye: the top of the volume comes into view.
        let z_before = camera.eye.z;
        orbit_drag(&mut camera, [0.0, 50.0]);
        assert!(camera.eye.z > z_before);
    }

    #[test]
    fn wheel_away_zooms_in_and_pinch_multiplies() {
        let mut camera = framed(&bounds(), ViewPreset::Oblique, ProjectionKind::Perspective);
        let d0 = (camera.eye - camera.target).length();
        zoom_scroll(&mut camera, 50.0, 1.0);
        let d1 = (camera.eye - camera.target).length();
        // exp(0.0025 * 50) = 1.133; 1e-9: rounding.
        assert!((d0 / d1 - (0.125f64).exp()).abs() < 1e-9);
        zoom_scroll(&mut camera, 0.0, 0.5);
        let d2 = (camera.eye - camera.target).length();
        assert!((d2 / d1 - 2.0).abs() < 1e-9);
    }

    #[test]
    fn projection_switch_keeps_the_size_at_the_target() {
        let mut camera = framed(&bounds(), ViewPreset::Oblique, ProjectionKind::Perspective);
        zoom_scroll(&mut camera, 120.0, 1.0);
        let h = camera.view_height_at_target_mm();
        let ortho = with_projection(&camera, ProjectionKind::Orthographic);
        assert_eq!(projection_kind(&ortho), ProjectionKind::Orthographic);
        // 1e-9 relative: rounding of tan and the distance.
        assert!((ortho.view_height_at_target_mm() / h - 1.0).abs() < 1e-9);
        let back = with_projection(&ortho, ProjectionKind::Perspective);
        assert_eq!(projection_kind(&back), ProjectionKind::Perspective);
        assert!((back.view_height_at_target_mm() / h - 1.0).abs() < 1e-9);
        assert!((back.forward() - camera.forward()).length() < 1e-12);
        assert_eq!(with_projection(&back, ProjectionKind::Perspective), back);
    }
}
