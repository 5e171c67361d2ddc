//! What a frame's rays and slices leave unseen, for the bricks' residency: the rule a mode's
//! samples are unseen by (the transfer function's transparency, one side of the iso value), how
//! far a brick's values reach the samples that read it, the view frustum and the slice planes.

use std::sync::Arc;

use rayon::prelude::*;

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
    /// The image's size in pixels where each brick need be held no finer than its footprint on
    /// it needs (a voxel about a pixel: the window, while bricks stream under a time budget);
    /// `None`: at full resolution wherever the budget allows (`render`, whose output is
    /// exact). Read with `frustum`.
    pub footprint: Option<[u32; 2]>,
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

/// Where a box lies against a view frustum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    /// All its corners outside one of the six planes.
    Outside,
    /// All its corners inside all six.
    Inside,
    /// Neither: it may be in view.
    Across,
}

/// Where the box `[lo, hi]` (continuous voxel coordinates) lies against the view of `clip`
/// (exact for a convex box, whatever the corners' w: each plane is a half-space).
fn side(clip: &glam::DMat4, lo: [f64; 3], hi: [f64; 3]) -> Side {
    let corners: [glam::DVec4; 8] = std::array::from_fn(|i| {
        let pick = |a: usize| if i >> a & 1 == 1 { hi[a] } else { lo[a] };
        *clip * glam::DVec4::new(pick(0), pick(1), pick(2), 1.0)
    });
    let planes: [fn(&glam::DVec4) -> f64; 6] = [
        |c| c.x + c.w,
        |c| c.w - c.x,
        |c| c.y + c.w,
        |c| c.w - c.y,
        |c| c.z,
        |c| c.w - c.z,
    ];
    let mut inside = true;
    for plane in planes {
        let out = corners.iter().filter(|c| plane(c) < 0.0).count();
        if out == corners.len() {
            return Side::Outside;
        }
        inside &= out == 0;
    }
    if inside { Side::Inside } else { Side::Across }
}

/// Whether the box `[lo, hi]` (continuous voxel coordinates) may be in the view of `clip`: not
/// all its corners outside one of the frustum's six planes.
#[cfg(test)]
fn in_frustum(clip: &glam::DMat4, lo: [f64; 3], hi: [f64; 3]) -> bool {
    side(clip, lo, hi) != Side::Outside
}

/// Per brick of a `grid` of bricks of `brick` voxels (x fastest): whether it may be in the view
/// of `clip`, its box grown by `reach` voxels. The same answer as testing each brick, found by
/// halving the grid where a part lies across the frustum's planes: a part wholly inside or
/// outside is answered at once (an orbit around the whole volume tests one box, not 131 072).
pub(super) fn in_view(clip: &glam::DMat4, grid: [u32; 3], brick: f64, reach: f64) -> Vec<bool> {
    let mut seen = vec![false; grid.iter().map(|&g| g as usize).product()];
    let mut parts = vec![([0u32; 3], grid)];
    while let Some((lo, hi)) = parts.pop() {
        let low = lo.map(|v| f64::from(v) * brick - reach);
        let high = hi.map(|v| f64::from(v) * brick + reach);
        let single = (0..3).all(|a| hi[a] - lo[a] == 1);
        match side(clip, low, high) {
            Side::Outside => {}
            Side::Across if !single => {
                let mid: [u32; 3] = std::array::from_fn(|a| lo[a] + (hi[a] - lo[a]).div_ceil(2));
                for octant in 0..8 {
                    let upper = |a: usize| octant >> a & 1 == 1;
                    let p: [u32; 3] =
                        std::array::from_fn(|a| if upper(a) { mid[a] } else { lo[a] });
                    let q: [u32; 3] =
                        std::array::from_fn(|a| if upper(a) { hi[a] } else { mid[a] });
                    if (0..3).all(|a| p[a] < q[a]) {
                        parts.push((p, q));
                    }
                }
            }
            _ => {
                for z in lo[2]..hi[2] {
                    for y in lo[1]..hi[1] {
                        let row = (grid[0] * (y + grid[1] * z)) as usize;
                        seen[row + lo[0] as usize..row + hi[0] as usize].fill(true);
                    }
                }
            }
        }
    }
    seen
}

/// Per brick of level 0 of a `grid` of bricks of `brick` voxels (x fastest): the coarsest of
/// `levels` levels whose voxels the view of `clip` shows no larger than a pixel of an image of
/// `size` pixels anywhere in the brick; 0 where level 0's are larger, or where the brick reaches
/// the eye's plane. A voxel step along axis `a` moves a point by `∂(X/W)/∂a` in normalised
/// device coordinates, at most `(|M_xa| + |M_wa|) / W` where the point is on screen (|X/W| ≤ 1):
/// so a pixel holds at most `K / W` voxels' width, K the largest of those numerators in pixels,
/// and the brick's nearest W bounds it (exact for orthographic views, where `M_wa` is 0).
pub(super) fn footprint_levels(
    clip: &glam::DMat4,
    size: [u32; 2],
    grid: [u32; 3],
    brick: f64,
    levels: u32,
) -> Vec<u8> {
    let half = [f64::from(size[0]) / 2.0, f64::from(size[1]) / 2.0];
    let cols = [clip.x_axis, clip.y_axis, clip.z_axis];
    let k = cols
        .iter()
        .map(|c| (half[0] * (c.x.abs() + c.w.abs())).max(half[1] * (c.y.abs() + c.w.abs())))
        .fold(0.0, f64::max);
    // How far W falls from a brick's centre to its nearest corner.
    let spread: f64 = cols.iter().map(|c| c.w.abs() * brick / 2.0).sum();
    let last = levels.saturating_sub(1).min(u32::from(u8::MAX - 1));
    let plane = grid[0] as usize * grid[1] as usize;
    let mut out = vec![0u8; plane * grid[2] as usize];
    // A plane of bricks per task: an orbit asks every frame, and deciding (this, the frustum
    // and the decision) took 2.3-4.5 ms a frame over 131 072 bricks on one core of the H100
    // machine (docs/benchmarks/nvidia-h100-bricks-stream §9).
    out.par_chunks_mut(plane.max(1))
        .enumerate()
        .for_each(|(z, levels_of)| {
            let z = z as u32;
            for (i, out) in levels_of.iter_mut().enumerate() {
                let (x, y) = (i as u32 % grid[0], i as u32 / grid[0]);
                let centre = [x, y, z].map(|v| (f64::from(v) + 0.5) * brick);
                let w = clip.x_axis.w * centre[0]
                    + clip.y_axis.w * centre[1]
                    + clip.z_axis.w * centre[2]
                    + clip.w_axis.w
                    - spread;
                // Pixels a voxel of level 0 spans at most: a level of 2^l voxels spans 2^l times.
                let level = if w <= 0.0 || k <= 0.0 {
                    0
                } else {
                    ((w / k).log2().floor().max(0.0) as u32).min(last)
                };
                *out = level as u8;
            }
        });
    out
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
        footprint: None,
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
    fn the_bricks_in_view_are_those_each_brick_s_own_test_finds() {
        let grid = [13u32, 9, 6];
        let (brick, reach) = (32.0, 4.0);
        let centre = glam::DVec3::new(208.0, 144.0, 96.0);
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut unit = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut kinds = [0usize; 3];
        for view in 0..60 {
            // Eyes around the volume, near it and inside it, looking somewhere near its centre
            // (every third away from it).
            let eye = centre
                + glam::DVec3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5) * 900.0 * unit();
            let mut target =
                centre + glam::DVec3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5) * 300.0;
            if view % 3 == 0 {
                target = eye + (eye - target);
            }
            let fov = 0.2 + 1.2 * unit();
            let clip = glam::DMat4::perspective_rh(fov, 0.5 + unit(), 1.0, 5000.0)
                * glam::DMat4::look_at_rh(eye, target, glam::DVec3::Z);
            let fast = in_view(&clip, grid, brick, reach);
            let each: Vec<bool> = (0..fast.len())
                .map(|i| {
                    let (lo, hi) = brick_box(i, grid, brick);
                    in_frustum(&clip, lo.map(|v| v - reach), hi.map(|v| v + reach))
                })
                .collect();
            assert_eq!(fast, each);
            let count = fast.iter().filter(|&&f| f).count();
            kinds[if count == 0 {
                0
            } else if count == fast.len() {
                1
            } else {
                2
            }] += 1;
        }
        // The views cover all three cases: none, all and some of the bricks in view.
        assert!(kinds.iter().all(|&k| k > 0), "{kinds:?}");
    }

    #[test]
    fn a_brick_s_footprint_level_never_shows_a_voxel_larger_than_a_pixel() {
        let grid = [16u32, 16, 8];
        let (brick, levels, size) = (32.0, 6, [1920u32, 1080]);
        let centre = glam::DVec3::new(256.0, 256.0, 128.0);
        // Pixels the step from p along axis a spans in the image (p on screen).
        let pixels = |clip: &glam::DMat4, p: glam::DVec3, a: usize| -> Option<f64> {
            let ndc = |q: glam::DVec3| {
                let c = *clip * q.extend(1.0);
                (c.w > 0.0).then(|| glam::DVec2::new(c.x / c.w, c.y / c.w))
            };
            let (u, v) = (ndc(p)?, ndc(p + glam::DVec3::AXES[a] * 1e-3)?);
            let on_screen = u.x.abs() <= 1.0 && u.y.abs() <= 1.0;
            let d = (v - u) * glam::DVec2::new(f64::from(size[0]), f64::from(size[1])) / 2.0;
            on_screen.then(|| d.x.abs().max(d.y.abs()) * 1e3)
        };
        let mut coarse = 0;
        for distance in [300.0, 900.0, 3000.0, 12000.0] {
            let eye = centre + glam::DVec3::new(0.6, -0.7, 0.4).normalize() * distance;
            let clip = glam::DMat4::perspective_rh(0.6, 16.0 / 9.0, 1.0, 1e5)
                * glam::DMat4::look_at_rh(eye, centre, glam::DVec3::Z);
            let found = footprint_levels(&clip, size, grid, brick, levels);
            for (i, &level) in found.iter().enumerate() {
                let (lo, _) = brick_box(i, grid, brick);
                coarse += usize::from(level > 0);
                for corner in 0..27 {
                    let p = glam::DVec3::new(
                        lo[0] + f64::from(corner % 3) * brick / 2.0,
                        lo[1] + f64::from(corner / 3 % 3) * brick / 2.0,
                        lo[2] + f64::from(corner / 9) * brick / 2.0,
                    );
                    for a in 0..3 {
                        // Level 0 is the finest there is, whatever it spans.
                        if let Some(px) = pixels(&clip, p, a).filter(|_| level > 0) {
                            let span = px * f64::from(1u32 << level);
                            assert!(span <= 1.0 + 1e-9, "brick {i} at level {level}: {span} px");
                        }
                    }
                }
            }
        }
        assert!(coarse > 0, "the far views hold some bricks coarser");
        // Orthographic: exactly the level at which a voxel first spans at most a pixel.
        let clip = glam::DMat4::orthographic_rh(-1024.0, 1024.0, -576.0, 576.0, -1e4, 1e4)
            * glam::DMat4::look_at_rh(centre + glam::DVec3::Z * 1000.0, centre, glam::DVec3::Y);
        let found = footprint_levels(&clip, size, grid, brick, levels);
        // 1920 pixels over 2048 voxels: 0.94 px a voxel, so level 0.
        assert!(found.iter().all(|&l| l == 0));
        let zoomed_out = glam::DMat4::from_scale(glam::DVec3::new(0.25, 0.25, 1.0)) * clip;
        // 0.23 px a voxel: two levels coarser (4 voxels: 0.94 px).
        assert!(
            footprint_levels(&zoomed_out, size, grid, brick, levels)
                .iter()
                .all(|&l| l == 2)
        );
    }

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
