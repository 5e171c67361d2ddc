//! What a frame's rays and slices leave unseen, for the bricks' residency: the rule a mode's
//! samples are unseen by (the transfer function's transparency, one side of the iso value), how
//! far a brick's values reach the samples that read it, the view frustum and the slice planes.

use std::sync::Arc;

use crate::accel::emptiness::OpacityIndex;

/// Voxels around a brick whose values its range includes. A brick is served by a constant only
/// where those values are all unseen (transparent, or on one side of the iso value); then any
/// sample within `REACH - ½` voxels of the brick is unseen too, and no seen sample reads the
/// brick: a gradient reads two voxels on (fourth order), a pre-integrated segment or an
/// isosurface's refinement one step, and the gradient at an isosurface's hit two voxels past
/// that step. Four voxels cover steps up to 1.5 voxels ([`REACH_STEP_VOX`] takes 1); a frame
/// with longer steps keeps every brick beside a seen one too.
pub const REACH: u32 = 4;

/// The longest step (voxels) a frame may take for [`REACH`] to cover it (1.5 would do).
pub const REACH_STEP_VOX: f64 = 1.0;

/// Which bricks of level 0 a frame's rays cannot see, and so may read a constant.
#[derive(Clone, Debug)]
pub enum Cull {
    /// Every brick's data (MIP, MinIP, X-ray, slices).
    Nothing,
    /// DVR: bricks whose every value the transfer function makes transparent (the index of
    /// its baked table, and the table's generation, which names it).
    Transparent(Arc<OpacityIndex>, u64),
    /// Isosurfaces: bricks whose values all lie on one side of the iso value (normalised).
    OneSide(f32),
}

/// What a frame leaves unseen, and what it shows besides its rays: the rule, whether its step
/// is longer than [`REACH_STEP_VOX`] (every brick beside a seen one is then kept too), the
/// view frustum, the eye (to upload nearest first) and the slice planes.
#[derive(Clone, Debug)]
pub struct Unseen {
    /// Which bricks the rule empties.
    pub cull: Cull,
    /// Whether the frame's step is longer than [`REACH`] covers.
    pub long_steps: bool,
    /// The eye in continuous voxel coordinates (voxel `i`'s centre at `i + ½`): missing
    /// bricks nearest it are uploaded first.
    pub eye: Option<[f64; 3]>,
    /// Slice planes shown beside the rays: the bricks they cross hold data, whatever the rays
    /// leave unseen.
    pub slices: Vec<SlicePlane>,
    /// Continuous voxel coordinates → clip space of the frame (wgpu's: depth 0…1): bricks
    /// outside the view frustum (by more than [`REACH`]) are seen by no ray. `None`: all are in
    /// view.
    pub frustum: Option<glam::DMat4>,
}

/// A slice (or slab) through the volume, in continuous voxel coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlicePlane {
    /// A point on the plane.
    pub point: [f64; 3],
    /// Its unit normal.
    pub normal: [f64; 3],
    /// How far the slab reaches either side of the plane (0 for a thin slice).
    pub half_thickness: f64,
}

/// The box of brick `index` (x fastest) of a `grid` of bricks of `brick` voxels, in continuous
/// voxel coordinates.
pub(super) fn brick_box(index: usize, grid: [u32; 3], brick: f64) -> ([f64; 3], [f64; 3]) {
    let i = index as u32;
    let at = [
        i % grid[0],
        (i / grid[0]) % grid[1],
        i / (grid[0] * grid[1]),
    ];
    (
        at.map(|v| f64::from(v) * brick),
        at.map(|v| f64::from(v + 1) * brick),
    )
}

/// Whether the box `[lo, hi]` (continuous voxel coordinates) may be in the view of `clip`: not
/// all its corners outside one of the frustum's six planes (exact for a convex box, whatever
/// the corners' w).
pub(super) fn in_frustum(clip: &glam::DMat4, lo: [f64; 3], hi: [f64; 3]) -> bool {
    let corners: [glam::DVec4; 8] = std::array::from_fn(|i| {
        let pick = |a: usize| if i >> a & 1 == 1 { hi[a] } else { lo[a] };
        *clip * glam::DVec4::new(pick(0), pick(1), pick(2), 1.0)
    });
    let outside = |f: &dyn Fn(&glam::DVec4) -> f64| corners.iter().all(|c| f(c) < 0.0);
    !(outside(&|c| c.x + c.w)
        || outside(&|c| c.w - c.x)
        || outside(&|c| c.y + c.w)
        || outside(&|c| c.w - c.y)
        || outside(&|c| c.z)
        || outside(&|c| c.w - c.z))
}

impl SlicePlane {
    /// Whether the plane (its slab) comes within `margin` voxels of the box `[lo, hi]`.
    pub(super) fn meets(&self, lo: [f64; 3], hi: [f64; 3], margin: f64) -> bool {
        let mut distance = 0.0;
        let mut extent = 0.0;
        for a in 0..3 {
            let centre = 0.5 * (lo[a] + hi[a]);
            distance += self.normal[a] * (centre - self.point[a]);
            extent += self.normal[a].abs() * (0.5 * (hi[a] - lo[a]) + margin);
        }
        distance.abs() <= extent + self.half_thickness
    }
}

impl Unseen {
    /// Nothing unseen: every brick's data, in brick order.
    pub const NOTHING: Self = Self {
        cull: Cull::Nothing,
        long_steps: false,
        eye: None,
        slices: Vec::new(),
        frustum: None,
    };
}

impl Cull {
    /// What the decision depends on, to tell whether it must be made again.
    pub(super) fn key(&self) -> (u8, u64) {
        match self {
            Self::Nothing => (0, 0),
            Self::Transparent(_, generation) => (1, *generation),
            Self::OneSide(iso) => (2, u64::from(iso.to_bits())),
        }
    }

    /// Whether it empties nothing.
    pub(super) fn is_nothing(&self) -> bool {
        matches!(self, Self::Nothing)
    }

    /// Whether a brick whose samples (normalised) lie in `[lo, hi]` contributes nothing.
    pub(super) fn is_empty(&self, lo: f32, hi: f32) -> bool {
        match self {
            Self::Nothing => false,
            Self::Transparent(index, _) => index.is_empty(lo, hi),
            Self::OneSide(iso) => lo > *iso || hi < *iso,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plane_meets_the_bricks_it_crosses_and_a_slab_those_it_reaches() {
        let axial = SlicePlane {
            point: [0.0, 0.0, 40.0],
            normal: [0.0, 0.0, 1.0],
            half_thickness: 0.0,
        };
        let brick = |z: f64| ([0.0, 0.0, z], [32.0, 32.0, z + 32.0]);
        let (lo, hi) = brick(32.0);
        assert!(axial.meets(lo, hi, 0.0));
        let (lo, hi) = brick(64.0);
        assert!(!axial.meets(lo, hi, 4.0));
        let slab = SlicePlane {
            half_thickness: 30.0,
            ..axial
        };
        assert!(slab.meets(lo, hi, 0.0));
        let (lo, hi) = brick(0.0);
        assert!(!axial.meets(lo, hi, 4.0) && axial.meets(lo, hi, 8.0));
        let oblique = SlicePlane {
            point: [16.0, 16.0, 16.0],
            normal: [0.0, 0.6, 0.8],
            half_thickness: 0.0,
        };
        // The box (0, 0, 32)…(32, 32, 64): its nearest corner (0, 0, 32) is 3.2 voxels off
        // the plane (0.6·(0 − 16) + 0.8·(32 − 16)).
        let (lo, hi) = brick(32.0);
        assert!(!oblique.meets(lo, hi, 0.0) && oblique.meets(lo, hi, 4.0));
    }
}
