//! Where each voxel lies in the patient's frame: millimetres in LPS (x to the patient's left, y
//! to the back, z to the head: DICOM's frame, the one `leapview info` reports). Voxel
//! coordinates are continuous stored indices, voxel centre `(i, j, k)` at `(i, j, k)`; the
//! volume's box runs from −0.5 to `n − 0.5` along each axis.
//!
//! The orientation model is the one the renderer uses: each index axis points along one patient
//! direction (`volume::Orientation`; files without one are taken as RAS), the header's origin
//! (`Provenance::origin_lps`, else 0 at the first voxel) and the spacing place it. A volume the
//! loader reversed along i to undo a mirrored file ([`Volume::unmirrored`]) keeps the file's
//! positions: stored voxel `i` is file voxel `n − 1 − i`.

use glam::{DMat3, DVec3};

use crate::volume::{Direction, Orientation, Volume};

/// The patient-frame (LPS) unit vector of an anatomical direction.
pub fn lps(direction: Direction) -> DVec3 {
    match direction {
        Direction::Left => DVec3::X,
        Direction::Right => -DVec3::X,
        Direction::Posterior => DVec3::Y,
        Direction::Anterior => -DVec3::Y,
        Direction::Superior => DVec3::Z,
        Direction::Inferior => -DVec3::Z,
    }
}

/// The standard plane a 2D image (a volume one voxel thick along some axis) lies in: the one
/// whose normal is nearest that axis in the patient frame; `None` for a volume.
pub fn image_plane(volume: &Volume) -> Option<crate::mpr::PlaneKind> {
    image_plane_of(
        volume.dims(),
        volume.orientation().unwrap_or(Orientation::ASSUMED),
    )
}

/// [`image_plane`] of a volume of `dims` in `orientation`.
pub(crate) fn image_plane_of(
    dims: [u32; 3],
    orientation: Orientation,
) -> Option<crate::mpr::PlaneKind> {
    use crate::mpr::PlaneKind;
    let thin = (0..3)
        .rev()
        .find(|&a| dims[a] == 1 && dims.iter().filter(|&&d| d > 1).count() == 2)?;
    let along = lps(orientation.axes[thin]).abs();
    Some(if along.z >= along.x && along.z >= along.y {
        PlaneKind::Axial
    } else if along.y >= along.x {
        PlaneKind::Coronal
    } else {
        PlaneKind::Sagittal
    })
}

/// The affine map between a volume's stored voxel coordinates and patient millimetres (LPS).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatientFrame {
    /// Patient position of voxel centre (0, 0, 0) as stored.
    origin: DVec3,
    /// Patient step (mm) of one voxel along each stored index axis: the matrix's columns.
    axes: DMat3,
    /// Stored dimensions.
    dims: [u32; 3],
    /// The orientation used (the volume's, or RAS assumed).
    orientation: Orientation,
}

impl PatientFrame {
    /// The frame of `volume` as stored.
    pub fn of(volume: &Volume) -> Self {
        let orientation = volume.orientation().unwrap_or(Orientation::ASSUMED);
        let origin = volume
            .provenance()
            .origin_lps
            .map_or(DVec3::ZERO, DVec3::from);
        Self::new(
            orientation,
            volume.spacing_mm(),
            volume.dims(),
            origin,
            volume.reversed_i(),
        )
    }

    /// A frame from its parts: `orientation` and `spacing` of the stored axes, the file's
    /// `origin` (patient position of the file's first voxel), and whether the samples were
    /// reversed along i after reading (then the file's first voxel is stored at `i = n − 1`).
    pub fn new(
        orientation: Orientation,
        spacing: [f64; 3],
        dims: [u32; 3],
        origin: DVec3,
        reversed_i: bool,
    ) -> Self {
        let axes = DMat3::from_cols(
            lps(orientation.axes[0]) * spacing[0],
            lps(orientation.axes[1]) * spacing[1],
            lps(orientation.axes[2]) * spacing[2],
        );
        // Reversed: the file's voxel 0 is stored at n − 1, and stored +i steps the other way
        // from the file's +i (the orientation already says so).
        let origin = if reversed_i {
            origin - axes.x_axis * f64::from(dims[0].saturating_sub(1))
        } else {
            origin
        };
        Self {
            origin,
            axes,
            dims,
            orientation,
        }
    }

    /// Patient position (mm, LPS) of voxel coordinates `v`.
    pub fn to_patient(&self, v: DVec3) -> DVec3 {
        self.origin + self.axes * v
    }

    /// Voxel coordinates of patient position `p` (mm, LPS).
    pub fn to_voxel(&self, p: DVec3) -> DVec3 {
        self.axes.inverse() * (p - self.origin)
    }

    /// The patient-frame step of one voxel along each stored axis (mm).
    pub fn axes(&self) -> DMat3 {
        self.axes
    }

    /// The stored dimensions.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// The orientation the frame uses.
    pub fn orientation(&self) -> Orientation {
        self.orientation
    }

    /// The patient position of the volume's centre.
    pub fn centre(&self) -> DVec3 {
        let d = self.dims.map(|n| (f64::from(n) - 1.0) / 2.0);
        self.to_patient(DVec3::from(d))
    }

    /// The eight corners of the volume's box (voxel boxes included), in patient millimetres.
    pub fn corners(&self) -> [DVec3; 8] {
        std::array::from_fn(|c| {
            let pick = |a: usize| {
                if c >> a & 1 == 1 {
                    f64::from(self.dims[a]) - 0.5
                } else {
                    -0.5
                }
            };
            self.to_patient(DVec3::new(pick(0), pick(1), pick(2)))
        })
    }

    /// Whether voxel coordinates `v` lie in the volume's box.
    pub fn contains(&self, v: DVec3) -> bool {
        (0..3).all(|a| v[a] >= -0.5 && v[a] <= f64::from(self.dims[a]) - 0.5)
    }

    /// The nearest voxel centre to `v`, `None` outside the box.
    pub fn voxel_index(&self, v: DVec3) -> Option<[u32; 3]> {
        if !self.contains(v) {
            return None;
        }
        Some(std::array::from_fn(|a| {
            (v[a] + 0.5)
                .floor()
                .clamp(0.0, f64::from(self.dims[a]) - 1.0) as u32
        }))
    }

    /// The spacing along the patient direction `d` (unit vector): the length of one voxel step
    /// of the axis closest to it, for stepping a slice "one voxel" along its normal.
    pub(crate) fn step_along(&self, d: DVec3) -> f64 {
        let cols = [self.axes.x_axis, self.axes.y_axis, self.axes.z_axis];
        cols.iter()
            .map(|c| (c.normalize_or_zero().dot(d).abs(), c.length()))
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map_or(1.0, |(_, len)| len)
    }
}

#[cfg(test)]
mod image_tests {
    use super::*;
    use crate::mpr::PlaneKind;

    #[test]
    fn a_2d_image_lies_in_the_plane_across_its_thin_axis() {
        let lps = Orientation::AS_STORED;
        assert_eq!(image_plane_of([64, 32, 1], lps), Some(PlaneKind::Axial));
        let coronal = Orientation::parse_code("LIP").expect("code");
        assert_eq!(
            image_plane_of([64, 32, 1], coronal),
            Some(PlaneKind::Coronal)
        );
        assert_eq!(image_plane_of([1, 64, 32], lps), Some(PlaneKind::Sagittal));
        assert_eq!(image_plane_of([64, 32, 2], lps), None);
        assert_eq!(image_plane_of([64, 1, 1], lps), None);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(code: &str, spacing: [f64; 3], reversed: bool) -> PatientFrame {
        let o = Orientation::parse_code(code).expect("code");
        PatientFrame::new(
            o,
            spacing,
            [10, 20, 30],
            DVec3::new(5.0, -7.0, 100.0),
            reversed,
        )
    }

    #[test]
    fn lps_and_ras_files_place_voxels_where_their_headers_say() {
        // LPS: +i to the left, +j to the back, +k to the head.
        let f = frame("LPS", [0.5, 0.7, 2.0], false);
        assert_eq!(f.to_patient(DVec3::ZERO), DVec3::new(5.0, -7.0, 100.0));
        assert_eq!(
            f.to_patient(DVec3::new(2.0, 10.0, 3.0)),
            DVec3::new(5.0 + 1.0, -7.0 + 7.0, 100.0 + 6.0)
        );
        // RAS: +i to the right (−x in LPS), +j to the front (−y).
        let f = frame("RAS", [0.5, 0.7, 2.0], false);
        assert_eq!(
            f.to_patient(DVec3::new(2.0, 10.0, 3.0)),
            DVec3::new(5.0 - 1.0, -7.0 - 7.0, 106.0)
        );
        // Slices running from the head down (LPI).
        let f = frame("LPI", [1.0, 1.0, 2.0], false);
        assert_eq!(f.to_patient(DVec3::new(0.0, 0.0, 3.0)).z, 94.0);
    }

    #[test]
    fn voxel_and_patient_coordinates_invert_each_other_with_anisotropic_spacing() {
        for code in ["RAS", "LPS", "LPI", "ASR", "SAL"] {
            let f = frame(code, [0.3, 1.7, 4.0], false);
            for v in [
                DVec3::ZERO,
                DVec3::new(9.0, 19.0, 29.0),
                DVec3::new(-0.5, 3.25, 12.75),
            ] {
                let back = f.to_voxel(f.to_patient(v));
                assert!((back - v).length() < 1e-12, "{code}: {v} -> {back}");
            }
        }
    }

    #[test]
    fn a_reversed_mirrored_file_keeps_its_patient_positions() {
        // LAS is mirrored: the loader stores it reversed along i as RAS. The file's voxel
        // (0, j, k) is stored at (9, j, k) and must stay where the file put it.
        let file = frame("LAS", [2.0, 1.0, 1.0], false);
        let stored = frame("RAS", [2.0, 1.0, 1.0], true);
        for (i, j, k) in [(0.0, 0.0, 0.0), (3.0, 4.0, 5.0), (9.0, 19.0, 29.0)] {
            assert_eq!(
                stored.to_patient(DVec3::new(9.0 - i, j, k)),
                file.to_patient(DVec3::new(i, j, k))
            );
        }
    }

    #[test]
    fn the_box_centre_corners_and_nearest_voxel() {
        let f = frame("LPS", [1.0, 1.0, 1.0], false);
        assert_eq!(f.centre(), DVec3::new(5.0 + 4.5, -7.0 + 9.5, 100.0 + 14.5));
        let c = f.corners();
        assert_eq!(c[0], DVec3::new(4.5, -7.5, 99.5));
        assert_eq!(c[7], DVec3::new(5.0 + 9.5, -7.0 + 19.5, 100.0 + 29.5));
        assert_eq!(
            f.voxel_index(DVec3::new(0.49, 0.51, 29.4)),
            Some([0, 1, 29])
        );
        assert_eq!(f.voxel_index(DVec3::new(-0.6, 0.0, 0.0)), None);
        assert_eq!(
            f.voxel_index(DVec3::new(9.5, 19.5, 29.5)),
            Some([9, 19, 29])
        );
        let f = frame("LPS", [0.5, 0.7, 2.0], false);
        assert_eq!(f.step_along(DVec3::Z), 2.0);
        assert_eq!(f.step_along(-DVec3::Y), 0.7);
    }
}
