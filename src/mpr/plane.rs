//! Slice planes in the patient frame (LPS millimetres) and the patient directions at their
//! edges. The standard planes are shown as radiology viewers show them: axial from the feet
//! (the patient's right on the screen's left, anterior up), coronal from the front (right on the
//! left, superior up), sagittal from the patient's left (anterior on the left, superior up).

use glam::{DQuat, DVec3};

use crate::volume::Direction;

use super::frame::lps;

/// Which plane a view shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum PlaneKind {
    /// Perpendicular to the head–feet axis.
    Axial,
    /// Perpendicular to the front–back axis.
    Coronal,
    /// Perpendicular to the left–right axis.
    Sagittal,
    /// Any other orientation.
    Oblique,
}

impl PlaneKind {
    /// The three standard planes.
    pub const STANDARD: [Self; 3] = [Self::Axial, Self::Coronal, Self::Sagittal];

    /// Its name, for labels and the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Axial => "axial",
            Self::Coronal => "coronal",
            Self::Sagittal => "sagittal",
            Self::Oblique => "oblique",
        }
    }
}

/// A plane through the patient: a point on it and the screen's right and up directions (unit,
/// orthogonal, LPS). Its normal `right × up` points towards the viewer.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Plane {
    /// Which plane this is (oblique once tilted).
    pub kind: PlaneKind,
    /// A point on the plane (mm, LPS).
    pub point: DVec3,
    /// The screen's +x direction (unit, LPS).
    pub right: DVec3,
    /// The screen's +y (upward) direction (unit, LPS).
    pub up: DVec3,
}

/// Why a plane's normal was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("a plane's normal must be three finite numbers, not all zero (got {0:?})")]
pub struct BadNormal(pub [f64; 3]);

impl Plane {
    /// A standard plane through `point` (an oblique kind gives the axial plane).
    pub fn standard(kind: PlaneKind, point: DVec3) -> Self {
        use Direction::{Anterior, Left, Posterior, Superior};
        let (right, up) = match kind {
            PlaneKind::Axial | PlaneKind::Oblique => (lps(Left), lps(Anterior)),
            PlaneKind::Coronal => (lps(Left), lps(Superior)),
            PlaneKind::Sagittal => (lps(Posterior), lps(Superior)),
        };
        Self {
            kind: if kind == PlaneKind::Oblique {
                PlaneKind::Axial
            } else {
                kind
            },
            point,
            right,
            up,
        }
    }

    /// The plane through `point` with normal `normal` (LPS, towards the viewer), its screen axes
    /// those of the standard plane whose normal is closest, turned onto it by the smallest
    /// rotation, so a slightly tilted axial plane still looks axial.
    pub fn with_normal(normal: [f64; 3], point: DVec3) -> Result<Self, BadNormal> {
        let n = DVec3::from(normal);
        if !n.is_finite() || n.length() == 0.0 {
            return Err(BadNormal(normal));
        }
        let n = n.normalize();
        let closest = PlaneKind::STANDARD
            .into_iter()
            .map(|k| Self::standard(k, point))
            .max_by(|a, b| a.normal().dot(n).abs().total_cmp(&b.normal().dot(n).abs()))
            .unwrap_or_else(|| Self::standard(PlaneKind::Axial, point));
        // Facing the viewer the same way as the standard plane.
        let n = if closest.normal().dot(n) < 0.0 { -n } else { n };
        let turn = DQuat::from_rotation_arc(closest.normal(), n);
        let mut plane = Self {
            kind: closest.kind,
            point,
            right: (turn * closest.right).normalize(),
            up: (turn * closest.up).normalize(),
        };
        if closest.normal().dot(n) < 1.0 - 1e-12 {
            plane.kind = PlaneKind::Oblique;
        }
        Ok(plane)
    }

    /// The normal, towards the viewer.
    pub fn normal(&self) -> DVec3 {
        self.right.cross(self.up)
    }

    /// The same plane through `point` (the crosshair moved).
    pub fn through(mut self, point: DVec3) -> Self {
        self.point = point;
        self
    }

    #[cfg(test)] // Only the tests ask.
    /// The plane moved `mm` along its normal.
    pub(crate) fn stepped(mut self, mm: f64) -> Self {
        self.point += self.normal() * mm;
        self
    }

    /// The plane turned by `angle` radians about the line through its point along `axis` (a
    /// direction in the plane: a crosshair line): an oblique plane.
    pub fn tilted(mut self, axis: DVec3, angle: f64) -> Self {
        let axis = axis.normalize_or_zero();
        if axis == DVec3::ZERO || angle == 0.0 {
            return self;
        }
        let turn = DQuat::from_axis_angle(axis, angle);
        self.right = (turn * self.right).normalize();
        self.up = (turn * self.up).normalize();
        self.kind = PlaneKind::Oblique;
        self
    }

    /// Signed distance of `p` from the plane, positive towards the viewer.
    pub fn distance(&self, p: DVec3) -> f64 {
        (p - self.point).dot(self.normal())
    }

    /// The patient directions at the view's edges: `[left, right, top, bottom]`.
    pub fn edge_labels(&self) -> [String; 4] {
        [
            direction_label(-self.right),
            direction_label(self.right),
            direction_label(self.up),
            direction_label(-self.up),
        ]
    }
}

/// The patient directions a screen direction `d` (unit, LPS) points to, as radiology viewers
/// write them: the main one first, then any other with at least a third of its weight (an
/// oblique edge reads e.g. "LA").
fn direction_label(d: DVec3) -> String {
    let mut parts: Vec<(f64, char)> = (0..3)
        .filter_map(|a| {
            let v = d[a];
            let letter = match (a, v > 0.0) {
                (0, true) => 'L',
                (0, false) => 'R',
                (1, true) => 'P',
                (1, false) => 'A',
                (_, true) => 'S',
                (_, false) => 'I',
            };
            (v.abs() > 1e-9).then_some((v.abs(), letter))
        })
        .collect();
    parts.sort_by(|a, b| b.0.total_cmp(&a.0));
    let main = parts.first().map_or(0.0, |p| p.0);
    parts
        .iter()
        .filter(|p| p.0 >= main / 3.0)
        .map(|p| p.1)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(p: &Plane) -> [String; 4] {
        p.edge_labels()
    }

    #[test]
    fn standard_planes_read_as_radiology_viewers_show_them() {
        let a = Plane::standard(PlaneKind::Axial, DVec3::ZERO);
        assert_eq!(labels(&a), ["R", "L", "A", "P"].map(String::from));
        assert_eq!(a.normal(), lps(Direction::Inferior), "seen from the feet");
        let c = Plane::standard(PlaneKind::Coronal, DVec3::ZERO);
        assert_eq!(labels(&c), ["R", "L", "S", "I"].map(String::from));
        assert_eq!(c.normal(), lps(Direction::Anterior), "seen from the front");
        let s = Plane::standard(PlaneKind::Sagittal, DVec3::ZERO);
        assert_eq!(labels(&s), ["A", "P", "S", "I"].map(String::from));
        assert_eq!(s.normal(), lps(Direction::Left), "seen from the left");
    }

    #[test]
    fn a_tilted_plane_is_oblique_with_mixed_labels() {
        let a = Plane::standard(PlaneKind::Axial, DVec3::ZERO);
        // Tilt 30° about the left–right line: the top edge now leans towards the head.
        let t = a.tilted(a.right, 30f64.to_radians());
        assert_eq!(t.kind, PlaneKind::Oblique);
        assert!((t.right.dot(t.up)).abs() < 1e-12);
        let [l, r, top, bottom] = labels(&t);
        assert_eq!((l.as_str(), r.as_str()), ("R", "L"));
        assert!(top.starts_with('A') && top.len() == 2, "{top}");
        assert!(bottom.starts_with('P'), "{bottom}");
        // 45° about the up axis: right and left edges mix L/R with A/P.
        let t = a.tilted(a.up, 45f64.to_radians());
        assert_eq!(labels(&t)[1].len(), 2);
    }

    #[test]
    fn planes_from_a_normal_keep_the_nearest_standard_layout() {
        let p = Plane::with_normal([0.0, 0.0, 1.0], DVec3::ZERO).expect("axial");
        assert_eq!(p.kind, PlaneKind::Axial);
        assert_eq!(labels(&p), ["R", "L", "A", "P"].map(String::from));
        let p = Plane::with_normal([1.0, 0.0, 0.0], DVec3::ZERO).expect("sagittal");
        assert_eq!(p.kind, PlaneKind::Sagittal);
        let p = Plane::with_normal([0.1, 0.0, 1.0], DVec3::ZERO).expect("oblique");
        assert_eq!(p.kind, PlaneKind::Oblique);
        assert_eq!(labels(&p)[2], "A", "still reads as axial");
        assert!((p.normal().dot(DVec3::new(0.1, 0.0, 1.0).normalize()).abs() - 1.0).abs() < 1e-12);
        assert!(Plane::with_normal([0.0, 0.0, 0.0], DVec3::ZERO).is_err());
        assert!(Plane::with_normal([f64::NAN, 0.0, 1.0], DVec3::ZERO).is_err());
    }

    #[test]
    fn stepping_moves_along_the_normal() {
        let a = Plane::standard(PlaneKind::Axial, DVec3::new(1.0, 2.0, 3.0));
        let b = a.stepped(2.0);
        assert_eq!(
            b.point,
            DVec3::new(1.0, 2.0, 1.0),
            "towards the feet (the viewer)"
        );
        assert_eq!(a.distance(DVec3::new(9.0, 9.0, 1.0)), 2.0);
    }
}
