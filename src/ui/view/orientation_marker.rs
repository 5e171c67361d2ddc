//! The orientation marker: a small triad in the view's bottom-left corner whose arms point to
//! the patient's right, anterior and superior (R, A, S, drawn strong) and left, posterior and
//! inferior (L, P, I, drawn faint), turned with the camera, as the orientation axes of 3D Slicer
//! and ParaView. It follows the file's orientation (RAS where the file has none).

use egui::{Color32, FontId, Pos2, Rect, Stroke, Vec2, pos2, vec2};

use crate::camera::Camera;
use crate::volume::{Direction, Orientation};

/// Length of an arm seen side on, in points.
const ARM: f32 = 30.0;
/// Distance of the marker's centre from the view's bottom-left corner, in points.
const INSET: f32 = 48.0;

/// One arm of the marker as the camera sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arm {
    /// The anatomical direction the arm points to.
    pub direction: Direction,
    /// The arm's tip on screen relative to the centre, for an arm of length 1 (x right, y down).
    pub screen: Vec2,
    /// How far the tip comes towards the viewer (−1 … 1).
    pub depth: f64,
}

/// The six arms for `camera`, farthest first (the drawing order).
fn arms(camera: &Camera, orientation: &Orientation) -> Vec<Arm> {
    let view = camera.view_from_world();
    let mut arms: Vec<Arm> = Direction::VIEWS
        .iter()
        .map(|&direction| {
            // View space: x right, y up, the viewer on +z.
            let v = view.transform_vector3(orientation.world(direction));
            Arm {
                direction,
                screen: vec2(v.x as f32, -v.y as f32),
                depth: v.z,
            }
        })
        .collect();
    arms.sort_by(|a, b| a.depth.total_cmp(&b.depth));
    arms
}

/// The colour of a direction's RAS axis: right–left red, anterior–posterior green,
/// superior–inferior blue (x, y, z in RAS).
fn colour(direction: Direction) -> Color32 {
    match direction {
        Direction::Right | Direction::Left => Color32::from_rgb(230, 80, 70),
        Direction::Anterior | Direction::Posterior => Color32::from_rgb(90, 200, 90),
        Direction::Superior | Direction::Inferior => Color32::from_rgb(90, 140, 240),
    }
}

/// Whether `direction` is the positive end of its RAS axis (R, A or S).
fn positive(direction: Direction) -> bool {
    matches!(
        direction,
        Direction::Right | Direction::Anterior | Direction::Superior
    )
}

/// Draws the marker in the bottom-left corner of `view` and returns the square it may cover
/// (nothing on a view too small for it).
pub fn draw(ui: &egui::Ui, view: Rect, camera: &Camera, orientation: &Orientation) -> Option<Rect> {
    if view.width() < 3.0 * INSET || view.height() < 3.0 * INSET {
        return None;
    }
    let centre = pos2(view.left() + INSET, view.bottom() - INSET);
    let painter = ui.painter_at(view);
    painter.circle_filled(centre, ARM + 12.0, Color32::from_black_alpha(90));
    for arm in arms(camera, orientation) {
        let strong = positive(arm.direction);
        let base = colour(arm.direction);
        let colour = if strong {
            base
        } else {
            base.gamma_multiply(0.55)
        };
        let tip: Pos2 = centre + arm.screen * ARM;
        painter.line_segment(
            [centre, tip],
            Stroke::new(if strong { 2.5 } else { 1.5 }, colour),
        );
        // The letter just beyond the tip, or on the centre when the arm points at the viewer.
        let label = tip + arm.screen.normalized() * 8.0 * arm.screen.length().min(1.0);
        painter.text(
            label,
            egui::Align2::CENTER_CENTER,
            arm.direction.letter(),
            FontId::monospace(if strong { 13.0 } else { 11.0 }),
            colour,
        );
    }
    Some(Rect::from_center_size(centre, Vec2::splat(2.0 * INSET)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{Aabb, ProjectionKind};

    fn seen_from(side: Direction, orientation: Orientation) -> Vec<Arm> {
        let bounds = Aabb::of_volume([10, 20, 30], [1.0, 0.5, 2.0]);
        let (direction, up) = orientation.view_from(side);
        let camera = Camera::framing(&bounds, direction, up, ProjectionKind::Perspective);
        arms(&camera, &orientation)
    }

    fn arm(arms: &[Arm], d: Direction) -> Arm {
        *arms.iter().find(|a| a.direction == d).expect("all six")
    }

    #[test]
    fn from_the_front_the_patients_right_is_on_the_viewers_left_and_superior_up() {
        for o in [
            Orientation::ASSUMED,
            Orientation::from_lps_columns([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
                .expect("LPS"),
            Orientation::from_ras_columns([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
                .expect("SRA"),
        ] {
            let a = seen_from(Direction::Anterior, o);
            let right = arm(&a, Direction::Right);
            assert!(
                (right.screen - vec2(-1.0, 0.0)).length() < 1e-6,
                "{right:?}"
            );
            let up = arm(&a, Direction::Superior);
            assert!((up.screen - vec2(0.0, -1.0)).length() < 1e-6, "{up:?}");
            let front = arm(&a, Direction::Anterior);
            assert!(front.screen.length() < 1e-6 && (front.depth - 1.0).abs() < 1e-9);
            // Drawn last: nearest the viewer.
            assert_eq!(a.last().map(|x| x.direction), Some(Direction::Anterior));
            assert_eq!(a.first().map(|x| x.direction), Some(Direction::Posterior));
        }
    }

    #[test]
    fn from_above_anterior_is_up_and_right_is_right() {
        let a = seen_from(Direction::Superior, Orientation::ASSUMED);
        let right = arm(&a, Direction::Right);
        assert!((right.screen - vec2(1.0, 0.0)).length() < 1e-6, "{right:?}");
        let front = arm(&a, Direction::Anterior);
        assert!(
            (front.screen - vec2(0.0, -1.0)).length() < 1e-6,
            "{front:?}"
        );
        assert!((arm(&a, Direction::Superior).depth - 1.0).abs() < 1e-9);
    }

    #[test]
    fn opposite_arms_are_opposite() {
        let bounds = Aabb::of_volume([8, 8, 8], [1.0; 3]);
        let dir = crate::camera::orbit_direction(37.0, 21.0);
        let camera = Camera::framing(&bounds, dir, glam::DVec3::Z, ProjectionKind::Perspective);
        let a = arms(&camera, &Orientation::ASSUMED);
        for d in Direction::VIEWS {
            let (p, q) = (arm(&a, d), arm(&a, d.opposite()));
            assert!((p.screen + q.screen).length() < 1e-6);
            assert!((p.depth + q.depth).abs() < 1e-9);
            assert!((p.screen.length_sq() as f64 + p.depth * p.depth - 1.0).abs() < 1e-5);
        }
    }
}
