//! A view of a plane in pixels: which patient point each pixel shows, with the view's zoom
//! (millimetres per pixel, square pixels) and pan (the patient point at its centre). Pixel
//! coordinates run from the image's top-left corner, pixel `(x, y)` covering `[x, x+1) × [y, y+1)`
//! with its centre at `(x + 0.5, y + 0.5)`.

use glam::{DVec2, DVec3};

use super::frame::PatientFrame;
use super::plane::Plane;

/// Largest side of an image [`SliceView::fit`] chooses by itself.
pub const MAX_AUTO_SIDE: u32 = 4096;

/// A plane as an image of `size` pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SliceView {
    /// The plane shown.
    pub plane: Plane,
    /// Image size in pixels.
    pub size: [u32; 2],
    /// Millimetres per pixel, both ways.
    pub mm_per_pixel: f64,
    /// The patient point at the image's centre (on the plane).
    pub centre: DVec3,
}

/// Where a view's pixel grid lies in a volume's voxel coordinates: pixel `(x, y)`'s centre is at
/// `first + x·step_x + y·step_y`. What the GPU samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoxelGrid {
    /// Voxel coordinates of pixel (0, 0)'s centre.
    pub first: DVec3,
    /// One pixel to the right.
    pub step_x: DVec3,
    /// One pixel down.
    pub step_y: DVec3,
}

impl SliceView {
    /// The view of `plane` whose image is filled by the slice's extent through the volume of
    /// `frame`, with square pixels: `size` pixels when given (the extent centred, letterboxed
    /// along one side), else one pixel per voxel at the volume's finest spacing (at most
    /// [`MAX_AUTO_SIDE`] pixels a side).
    pub fn fit(plane: Plane, frame: &PatientFrame, size: Option<[u32; 2]>) -> Self {
        let (lo, hi) = slice_extent(&plane, frame);
        let extent = hi - lo;
        let mid = (lo + hi) / 2.0;
        let centre = plane.point + plane.right * mid.x + plane.up * mid.y;
        let finest = [
            frame.axes().x_axis,
            frame.axes().y_axis,
            frame.axes().z_axis,
        ]
        .iter()
        .map(|c| c.length())
        .fold(f64::INFINITY, f64::min);
        let (size, mm_per_pixel) = match size {
            Some([w, h]) => {
                let (w, h) = (w.max(1), h.max(1));
                let mpp = (extent.x / f64::from(w)).max(extent.y / f64::from(h));
                ([w, h], if mpp > 0.0 { mpp } else { finest })
            }
            None => {
                let mut mpp = finest;
                let longest = extent.x.max(extent.y);
                if longest / mpp > f64::from(MAX_AUTO_SIDE) {
                    mpp = longest / f64::from(MAX_AUTO_SIDE);
                }
                let side = |e: f64| ((e / mpp).round() as u32).clamp(1, MAX_AUTO_SIDE);
                ([side(extent.x), side(extent.y)], mpp)
            }
        };
        Self {
            plane,
            size,
            mm_per_pixel,
            centre,
        }
    }

    /// The patient point (mm, LPS) under pixel coordinates `px`.
    pub fn to_patient(&self, px: DVec2) -> DVec3 {
        let [w, h] = self.size.map(f64::from);
        self.centre
            + self.plane.right * ((px.x - w / 2.0) * self.mm_per_pixel)
            + self.plane.up * ((h / 2.0 - px.y) * self.mm_per_pixel)
    }

    /// The pixel coordinates of patient point `p` projected on the plane.
    pub(crate) fn to_pixel(self, p: DVec3) -> DVec2 {
        let [w, h] = self.size.map(f64::from);
        let d = p - self.centre;
        DVec2::new(
            w / 2.0 + d.dot(self.plane.right) / self.mm_per_pixel,
            h / 2.0 - d.dot(self.plane.up) / self.mm_per_pixel,
        )
    }

    /// The view zoomed by `factor` (> 1 magnifies) about pixel coordinates `about`, which keep
    /// showing the same point.
    pub fn zoomed(mut self, factor: f64, about: DVec2) -> Self {
        if !(factor.is_finite() && factor > 0.0) {
            return self;
        }
        let fixed = self.to_patient(about);
        self.mm_per_pixel /= factor;
        let moved = self.to_patient(about);
        self.centre += fixed - moved;
        self
    }

    /// The view panned by `pixels` (the picture follows the mouse).
    pub fn panned(mut self, pixels: DVec2) -> Self {
        self.centre -= self.plane.right * (pixels.x * self.mm_per_pixel);
        self.centre += self.plane.up * (pixels.y * self.mm_per_pixel);
        self
    }

    /// The same view of another plane position or tilt: the centre follows onto the new plane.
    pub(crate) fn with_plane(mut self, plane: Plane) -> Self {
        let moved = self.centre - plane.normal() * plane.distance(self.centre);
        self.plane = plane;
        self.centre = moved;
        self
    }

    /// The pixel grid in `frame`'s voxel coordinates, for sampling.
    pub fn voxel_grid(&self, frame: &PatientFrame) -> VoxelGrid {
        let first = frame.to_voxel(self.to_patient(DVec2::splat(0.5)));
        let inverse = frame.axes().inverse();
        VoxelGrid {
            first,
            step_x: inverse * (self.plane.right * self.mm_per_pixel),
            step_y: inverse * (-self.plane.up * self.mm_per_pixel),
        }
    }
}

/// The bounds of the plane's cut through the volume's box, in the plane's (right, up)
/// coordinates from its point (mm): the polygon where the plane crosses the box's edges; the
/// whole box projected when the plane misses it.
fn slice_extent(plane: &Plane, frame: &PatientFrame) -> (DVec2, DVec2) {
    let mut points = cut_polygon(plane, frame);
    if points.is_empty() {
        points.extend(frame.corners());
    }
    let project = |p: &DVec3| {
        let d = *p - plane.point;
        DVec2::new(d.dot(plane.right), d.dot(plane.up))
    };
    let lo = points
        .iter()
        .map(project)
        .fold(DVec2::splat(f64::INFINITY), DVec2::min);
    let hi = points
        .iter()
        .map(project)
        .fold(DVec2::splat(f64::NEG_INFINITY), DVec2::max);
    (lo, hi)
}

/// The polygon where the plane cuts the volume's box (patient mm), its corners in order around
/// the cut; empty when the plane misses the box.
pub fn cut_polygon(plane: &Plane, frame: &PatientFrame) -> Vec<DVec3> {
    let dims = frame.dims().map(|n| f64::from(n) - 0.5);
    cut_polygon_of(plane, frame, DVec3::splat(-0.5), DVec3::from(dims))
}

/// The polygon where the plane cuts the box from `lo` to `hi` in voxel coordinates (a cropping
/// box), in patient mm, in order around the cut; empty when the plane misses it.
pub(crate) fn cut_polygon_of(
    plane: &Plane,
    frame: &PatientFrame,
    lo: DVec3,
    hi: DVec3,
) -> Vec<DVec3> {
    let corners: [DVec3; 8] = std::array::from_fn(|c| {
        let pick = |a: usize| if c >> a & 1 == 1 { hi[a] } else { lo[a] };
        frame.to_patient(DVec3::new(pick(0), pick(1), pick(2)))
    });
    let mut points: Vec<DVec3> = Vec::with_capacity(12);
    for a in 0..8usize {
        for axis in 0..3 {
            let b = a | 1 << axis;
            if b == a {
                continue;
            }
            let (pa, pb) = (corners[a], corners[b]);
            let (da, db) = (plane.distance(pa), plane.distance(pb));
            let hit = if da == 0.0 {
                Some(pa)
            } else if db == 0.0 {
                Some(pb)
            } else if da * db < 0.0 {
                Some(pa + (pb - pa) * (da / (da - db)))
            } else {
                None
            };
            if let Some(p) = hit
                && !points.iter().any(|q| (*q - p).length() < 1e-9)
            {
                points.push(p);
            }
        }
    }
    if points.len() < 3 {
        return Vec::new();
    }
    let centre = points.iter().copied().sum::<DVec3>() / points.len() as f64;
    let angle = |p: &DVec3| {
        let d = *p - centre;
        d.dot(plane.up).atan2(d.dot(plane.right))
    };
    points.sort_by(|a, b| angle(a).total_cmp(&angle(b)));
    points
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mpr::plane::PlaneKind;
    use crate::volume::Orientation;

    fn frame(code: &str) -> PatientFrame {
        let o = Orientation::parse_code(code).expect("code");
        PatientFrame::new(o, [0.5, 1.0, 2.0], [40, 30, 20], DVec3::ZERO, false)
    }

    #[test]
    fn a_fitted_axial_view_shows_the_whole_slice_with_square_pixels() {
        let f = frame("LPS");
        let plane = Plane::standard(PlaneKind::Axial, f.centre());
        let v = SliceView::fit(plane, &f, None);
        // 20 mm (L–R) x 30 mm (A–P) at 0.5 mm per pixel.
        assert_eq!(v.size, [40, 60]);
        assert_eq!(v.mm_per_pixel, 0.5);
        // Pixel (0, 0) is the patient's right-anterior corner: i = 0 (an LPS file's i runs to
        // the left) and j a quarter voxel inside the box's front face (j runs to the back).
        let g = v.voxel_grid(&f);
        assert!((g.first - DVec3::new(0.0, -0.25, f.to_voxel(f.centre()).z)).length() < 1e-9);
        assert!((g.step_x - DVec3::new(1.0, 0.0, 0.0)).length() < 1e-12);
        assert!((g.step_y - DVec3::new(0.0, 0.5, 0.0)).length() < 1e-12);
        // A given size letterboxes: 100 x 100 for 20 x 30 mm: 0.3 mm per pixel.
        let v = SliceView::fit(plane, &f, Some([100, 100]));
        assert!((v.mm_per_pixel - 0.3).abs() < 1e-12);
    }

    #[test]
    fn pixels_and_patient_points_invert_each_other() {
        let f = frame("RAI");
        let plane =
            Plane::standard(PlaneKind::Sagittal, f.centre()).tilted(DVec3::new(0.0, 0.6, 0.8), 0.4);
        let v = SliceView::fit(plane, &f, Some([321, 123]));
        for px in [
            DVec2::new(0.5, 0.5),
            DVec2::new(300.25, 17.0),
            DVec2::new(-3.0, 500.0),
        ] {
            let back = v.to_pixel(v.to_patient(px));
            assert!((back - px).length() < 1e-9, "{px} -> {back}");
            assert!(
                v.plane.distance(v.to_patient(px)).abs() < 1e-9,
                "on the plane"
            );
        }
    }

    #[test]
    fn zoom_keeps_the_point_under_the_mouse_and_pan_follows_it() {
        let f = frame("LPS");
        let v = SliceView::fit(Plane::standard(PlaneKind::Coronal, f.centre()), &f, None);
        let about = DVec2::new(7.0, 11.0);
        let z = v.zoomed(2.5, about);
        assert!((z.to_patient(about) - v.to_patient(about)).length() < 1e-9);
        assert!((z.mm_per_pixel - v.mm_per_pixel / 2.5).abs() < 1e-12);
        let p = v.panned(DVec2::new(3.0, -2.0));
        assert!(
            (p.to_patient(DVec2::new(10.0, 9.0)) - v.to_patient(DVec2::new(7.0, 11.0))).length()
                < 1e-9
        );
    }

    #[test]
    fn the_cut_polygon_is_the_box_section_in_order() {
        let f = frame("LPS");
        let axial = Plane::standard(PlaneKind::Axial, f.centre());
        let cut = cut_polygon(&axial, &f);
        assert_eq!(cut.len(), 4, "an axial cut of a box is a rectangle");
        for w in 0..4 {
            let edge = cut[(w + 1) % 4] - cut[w];
            assert!(edge.length() == 20.0 || edge.length() == 30.0, "{edge}");
        }
        // Tilted about two axes: a polygon of up to six corners, all on the plane.
        let tilted = axial.tilted(DVec3::new(1.0, 1.0, 0.0), 0.6);
        let cut = cut_polygon(&tilted, &f);
        assert!((3..=6).contains(&cut.len()));
        assert!(cut.iter().all(|p| tilted.distance(*p).abs() < 1e-9));
        assert!(cut_polygon(&axial.through(DVec3::Z * 1e3), &f).is_empty());
    }

    #[test]
    fn an_oblique_cut_is_bounded_by_where_it_crosses_the_box() {
        let f = frame("LPS");
        let axial = Plane::standard(PlaneKind::Axial, f.centre());
        let (lo, hi) = slice_extent(&axial, &f);
        assert!((hi - lo - DVec2::new(20.0, 30.0)).length() < 1e-9);
        // Tilted 45° about L–R: the cut is longer along A–P than the box is deep.
        let tilted = axial.tilted(axial.right, std::f64::consts::FRAC_PI_4);
        let (lo, hi) = slice_extent(&tilted, &f);
        assert!((hi.x - lo.x - 20.0).abs() < 1e-9);
        assert!(hi.y - lo.y > 30.0f64.min(40.0 * 2f64.sqrt()) - 1e-9);
        // A plane missing the box: the box's projection.
        let away = axial.through(f.centre() + DVec3::Z * 1000.0);
        let (lo, hi) = slice_extent(&away, &f);
        assert!((hi - lo - DVec2::new(20.0, 30.0)).length() < 1e-9);
    }
}
