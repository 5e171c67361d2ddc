//! The view layouts: the 3D view alone, a 2×2 grid (axial, coronal, sagittal, 3D) as radiology
//! viewers arrange them, the 3D view large with the three slices in a column beside it, or, for a
//! 2D image (a radiograph, a photograph, one slice), that image alone in its own plane. Pure:
//! rectangles in, rectangles out.

use egui::{Rect, pos2};

use crate::mpr::PlaneKind;

/// How the central area is divided.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Layout {
    /// The 3D view only.
    ThreeD,
    /// Axial and coronal on top, sagittal and 3D below.
    Grid,
    /// The 3D view large, the three slices in a column on its right: what a volume opens in, as
    /// a reader of CT and MR expects the slices beside the rendering.
    #[default]
    OnePlusThree,
    /// A 2D image alone, as a slice view of the plane it lies in: what a single image opens in.
    Image(PlaneKind),
}

impl Layout {
    /// Every layout, in menu order.
    pub const ALL: [Self; 3] = [Self::ThreeD, Self::Grid, Self::OnePlusThree];

    /// Its name in the menu and the toolbar.
    pub fn label(self) -> &'static str {
        match self {
            Self::ThreeD => "3D only",
            Self::Grid => "2 × 2",
            Self::OnePlusThree => "1 + 3",
            Self::Image(_) => "Image",
        }
    }

    /// Whether it shows the 3D view.
    pub(crate) fn has_3d(self) -> bool {
        !matches!(self, Self::Image(_))
    }

    /// Whether it shows slice views.
    pub(crate) fn has_slices(self) -> bool {
        self != Self::ThreeD
    }
}

/// What a pane of the layout shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pane {
    /// The 3D rendering.
    ThreeD,
    /// A slice view of one standard plane.
    Slice(PlaneKind),
}

/// The panes of `layout` over `area`, `gap` points apart.
pub fn panes(layout: Layout, area: Rect, gap: f32) -> Vec<(Pane, Rect)> {
    let (x0, y0, x1, y1) = (area.min.x, area.min.y, area.max.x, area.max.y);
    let rect = |a: f32, b: f32, c: f32, d: f32| Rect::from_min_max(pos2(a, b), pos2(c, d));
    match layout {
        Layout::ThreeD => vec![(Pane::ThreeD, area)],
        Layout::Image(kind) => vec![(Pane::Slice(kind), area)],
        Layout::Grid => {
            let xm = ((x0 + x1) / 2.0).round();
            let ym = ((y0 + y1) / 2.0).round();
            let h = gap / 2.0;
            vec![
                (Pane::Slice(PlaneKind::Axial), rect(x0, y0, xm - h, ym - h)),
                (
                    Pane::Slice(PlaneKind::Coronal),
                    rect(xm + h, y0, x1, ym - h),
                ),
                (
                    Pane::Slice(PlaneKind::Sagittal),
                    rect(x0, ym + h, xm - h, y1),
                ),
                (Pane::ThreeD, rect(xm + h, ym + h, x1, y1)),
            ]
        }
        Layout::OnePlusThree => {
            // The column is a third of the width, at most as wide as a third of the height
            // allows for square slices.
            let column = ((x1 - x0) / 3.0).min((y1 - y0) / 3.0).max(0.0).round();
            let xs = x1 - column;
            let third = (y1 - y0) / 3.0;
            let mut out = vec![(Pane::ThreeD, rect(x0, y0, xs - gap, y1))];
            for (i, kind) in PlaneKind::STANDARD.into_iter().enumerate() {
                let top = (y0 + third * i as f32).round();
                let bottom = if i == 2 {
                    y1
                } else {
                    (y0 + third * (i + 1) as f32).round() - gap
                };
                out.push((Pane::Slice(kind), rect(xs, top, x1, bottom)));
            }
            out
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area() -> Rect {
        Rect::from_min_max(pos2(10.0, 20.0), pos2(1210.0, 820.0))
    }

    #[test]
    fn the_3d_layout_is_one_pane_and_an_image_one_slice() {
        assert_eq!(
            panes(Layout::ThreeD, area(), 2.0),
            vec![(Pane::ThreeD, area())]
        );
        let image = Layout::Image(PlaneKind::Coronal);
        assert_eq!(
            panes(image, area(), 2.0),
            vec![(Pane::Slice(PlaneKind::Coronal), area())]
        );
        assert!(image.has_slices() && !image.has_3d());
    }

    #[test]
    fn the_grid_has_four_panes_that_tile_the_area_without_overlap() {
        let p = panes(Layout::Grid, area(), 2.0);
        assert_eq!(p.len(), 4);
        assert_eq!(p[0].0, Pane::Slice(PlaneKind::Axial));
        assert_eq!(p[3].0, Pane::ThreeD);
        for (i, (_, a)) in p.iter().enumerate() {
            assert!(area().contains_rect(*a));
            for (_, b) in &p[i + 1..] {
                assert!(!a.intersects(*b) || a.intersect(*b).area() == 0.0);
            }
        }
        let covered: f32 = p.iter().map(|(_, r)| r.area()).sum();
        assert!(covered > 0.99 * area().area() - 2.0 * 1200.0 - 2.0 * 800.0);
    }

    #[test]
    fn one_plus_three_puts_a_column_of_slices_beside_a_large_3d_view() {
        let p = panes(Layout::OnePlusThree, area(), 2.0);
        assert_eq!(p.len(), 4);
        let (pane, big) = p[0];
        assert_eq!(pane, Pane::ThreeD);
        for (pane, r) in &p[1..] {
            assert!(matches!(pane, Pane::Slice(_)));
            assert!(r.min.x > big.max.x);
            assert!(r.area() < big.area() / 3.0);
        }
        assert_eq!(p[3].1.max.y, area().max.y);
    }
}
