//! Labels put on the image's voxel grid by patient coordinates: each image voxel takes the label
//! of the label voxel nearest its centre (labels are never interpolated), 0 outside the labels'
//! grid.

use glam::{DMat3, DVec3};
use rayon::prelude::*;

use crate::mpr::frame::PatientFrame;

/// Where a grid lies in the patient frame: one step along each axis (mm, LPS; the matrix's
/// columns), the position of voxel (0, 0, 0), and its dimensions.
#[derive(Clone, Copy, Debug)]
pub(super) struct Placement {
    /// One voxel's step along each axis.
    pub axes: DMat3,
    /// Where voxel (0, 0, 0) is.
    pub origin: DVec3,
    /// Voxels along each axis.
    pub dims: [u32; 3],
}

impl Placement {
    /// The placement of a volume's grid.
    pub(super) fn of(frame: &PatientFrame) -> Self {
        Self {
            axes: frame.axes(),
            origin: frame.to_patient(DVec3::ZERO),
            dims: frame.dims(),
        }
    }

    /// The patient-frame box of the grid's voxels (their outer faces), as text.
    pub(super) fn span(&self) -> String {
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for c in 0..8 {
            let corner = DVec3::new(
                if c & 1 == 1 {
                    f64::from(self.dims[0]) - 0.5
                } else {
                    -0.5
                },
                if c & 2 == 2 {
                    f64::from(self.dims[1]) - 0.5
                } else {
                    -0.5
                },
                if c & 4 == 4 {
                    f64::from(self.dims[2]) - 0.5
                } else {
                    -0.5
                },
            );
            let p = self.origin + self.axes * corner;
            (lo, hi) = (lo.min(p), hi.max(p));
        }
        format!(
            "x {:.1} … {:.1}, y {:.1} … {:.1}, z {:.1} … {:.1}",
            lo.x, hi.x, lo.y, hi.y, lo.z, hi.z
        )
    }
}

/// How one grid's voxel coordinates map into another's: `u = matrix · v + offset`.
#[derive(Clone, Copy, Debug)]
pub(super) struct GridMap {
    matrix: DMat3,
    offset: DVec3,
}

/// Largest difference, in voxels across the grid, at which two grids count as the same.
const SAME_GRID: f64 = 1e-3;

impl GridMap {
    /// From the image's voxels (`to`) into the labels' (`from`).
    pub(super) fn between(from: &Placement, to: &Placement) -> Self {
        let inverse = from.axes.inverse();
        Self {
            matrix: inverse * to.axes,
            offset: inverse * (to.origin - from.origin),
        }
    }

    /// Voxel for voxel: the same matrix (to within [`SAME_GRID`] over `dims`) and no offset.
    pub(super) fn is_identity(&self, dims: [u32; 3]) -> bool {
        self.same_steps(dims) && self.offset.abs().max_element() < SAME_GRID
    }

    /// The same voxel steps (to within [`SAME_GRID`] over `dims`), shifted by whole voxels: one
    /// grid cut from the other.
    pub(super) fn is_shift(&self, dims: [u32; 3]) -> bool {
        let whole = (self.offset - self.offset.round()).abs().max_element() < SAME_GRID;
        self.same_steps(dims) && whole
    }

    fn same_steps(&self, dims: [u32; 3]) -> bool {
        let extent = f64::from(dims.into_iter().max().unwrap_or(1));
        let m = (self.matrix - DMat3::IDENTITY).to_cols_array();
        m.iter().all(|d| d.abs() * extent < SAME_GRID)
    }

    /// Where image voxel `v` falls in the labels' grid.
    fn apply(&self, v: DVec3) -> DVec3 {
        self.matrix * v + self.offset
    }
}

/// `layers` (on a grid of `from_dims`) on the image's grid of `to_dims` through `map`, and how
/// many image voxels fall inside the labels' grid.
pub(super) fn onto(
    layers: &[Vec<u16>],
    from_dims: [u32; 3],
    to_dims: [u32; 3],
    map: &GridMap,
) -> (Vec<Vec<u16>>, u64) {
    let [nx, ny, nz] = to_dims.map(|d| d as usize);
    let index = |v: DVec3| -> Option<usize> {
        let u = (v + DVec3::splat(0.5)).floor();
        let inside = (0..3).all(|a| u[a] >= 0.0 && u[a] < f64::from(from_dims[a]));
        inside.then(|| {
            // Inside the grid, so each coordinate is a whole number below its dimension.
            let [i, j, k] = [u.x, u.y, u.z].map(|c| c as usize);
            i + from_dims[0] as usize * (j + from_dims[1] as usize * k)
        })
    };
    // Where each image voxel lands, slice by slice (a slice of indices at a time).
    let mut sources = vec![u32::MAX; nx * ny * nz];
    sources
        .par_chunks_mut((nx * ny).max(1))
        .enumerate()
        .for_each(|(z, slice)| {
            for y in 0..ny {
                let start = map.apply(DVec3::new(0.0, y as f64, z as f64));
                for (x, source) in slice[y * nx..(y + 1) * nx].iter_mut().enumerate() {
                    let v = start + map.matrix.x_axis * x as f64;
                    // A label grid holds under 2³² voxels (checked by the loader's limits).
                    *source = index(v).map_or(u32::MAX, |i| i as u32);
                }
            }
        });
    let inside = sources.par_iter().filter(|&&s| s != u32::MAX).count() as u64;
    let out = layers
        .iter()
        .map(|layer| {
            sources
                .par_iter()
                .map(|&s| if s == u32::MAX { 0 } else { layer[s as usize] })
                .collect()
        })
        .collect();
    (out, inside)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::Orientation;

    fn frame(spacing: [f64; 3], dims: [u32; 3], origin: [f64; 3]) -> PatientFrame {
        PatientFrame::new(
            Orientation::ASSUMED,
            spacing,
            dims,
            DVec3::from(origin),
            false,
        )
    }

    #[test]
    fn the_same_grid_maps_voxel_for_voxel() {
        let f = Placement::of(&frame([1.0, 1.0, 2.0], [4, 3, 2], [-1.0, 2.0, 3.0]));
        let map = GridMap::between(&f, &f);
        assert!(map.is_identity([4, 3, 2]));
        let layer: Vec<u16> = (0..24).collect();
        let (out, inside) = onto(std::slice::from_ref(&layer), [4, 3, 2], [4, 3, 2], &map);
        assert_eq!(out[0], layer);
        assert_eq!(inside, 24);
    }

    #[test]
    fn a_coarser_shifted_grid_gives_the_nearest_label_and_zero_outside() {
        // Both along R (LPS −x): labels every 2 mm from 1 mm right of the image's first voxel
        // (LPS x = −1), the image every 1 mm from LPS x = 0.
        let labels = Placement::of(&frame([2.0, 1.0, 1.0], [3, 1, 1], [-1.0, 0.0, 0.0]));
        let image = Placement::of(&frame([1.0, 1.0, 1.0], [8, 1, 1], [0.0, 0.0, 0.0]));
        let map = GridMap::between(&labels, &image);
        assert!(!map.is_identity([8, 1, 1]));
        let (out, inside) = onto(&[vec![10, 20, 30]], [3, 1, 1], [8, 1, 1], &map);
        // Image voxels 0 … 7 mm along R; label centres at 1, 3, 5 mm, each covering ±1 mm:
        // voxel 0 is at the edge (−0.5 label voxels rounds to 0), 6 and 7 past the last.
        assert_eq!(out[0], vec![10, 10, 20, 20, 30, 30, 0, 0]);
        assert_eq!(inside, 6);
    }
}
