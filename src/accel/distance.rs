//! The distance field over blocks (beyond the paper): for each block, the Chebyshev distance in
//! blocks to the nearest non-empty block, so that one step clears a whole cube of empty blocks.
//!
//! A block at distance `d > 0` is the centre of a `(2d − 1)`-block cube that holds only empty
//! blocks; a ray inside it can jump to the cube's exit. Distances are capped at [`MAX_DISTANCE`];
//! blocks outside the volume count as empty (rays end at the volume's faces anyway). The L∞
//! distance transform is separable: three 1D passes, each `g(x) = min over x' of max(|x − x'|,
//! f(x'))`, give the 3D distance; the GPU runs the same passes.
//!
//! The GPU field is two-sided ([`two_sided`]): beside the distance to the nearest non-empty
//! block it holds, for a non-empty block, the distance to the nearest empty one, so that a ray in
//! a cube of non-empty blocks takes all its samples up to the cube's exit without asking about
//! each block. Blocks outside the volume count as non-empty there (rays end at the faces anyway).

/// Largest distance stored, in blocks (also the window of each 1D pass).
pub const MAX_DISTANCE: u32 = 31;

/// Chebyshev distances for a grid of `nodes` blocks where `empty[i]` says block `i` (x fastest)
/// is empty.
fn chebyshev(nodes: [u32; 3], empty: &[bool]) -> Vec<u32> {
    let [nx, ny, nz] = nodes.map(|n| n as usize);
    let mut d: Vec<u32> = empty
        .iter()
        .map(|&e| if e { MAX_DISTANCE } else { 0 })
        .collect();
    let strides = [1, nx, nx * ny];
    let lens = [nx, ny, nz];
    for axis in 0..3 {
        let mut next = d.clone();
        for (i, out) in next.iter_mut().enumerate() {
            let coord = (i / strides[axis]) % lens[axis];
            let base = i - coord * strides[axis];
            let w = MAX_DISTANCE as usize;
            let from = coord.saturating_sub(w);
            let to = (coord + w).min(lens[axis] - 1);
            let mut best = d[i];
            for c in from..=to {
                let dist = coord.abs_diff(c) as u32;
                best = best.min(dist.max(d[base + c * strides[axis]]));
            }
            *out = best.min(MAX_DISTANCE);
        }
        d = next;
    }
    d
}

/// Bit where the full side of a [`two_sided`] entry starts.
pub const FULL_SHIFT: u32 = 16;

/// The two-sided field the GPU builds from emptiness flags (`shaders/build/distance.wgsl`), one
/// `u32` per block: the low bits hold [`chebyshev`]'s distance to the nearest non-empty block (0
/// for a non-empty block), the bits from [`FULL_SHIFT`] on the distance to the nearest empty
/// block (0 for an empty block), both capped at [`MAX_DISTANCE`]. A non-empty block at full
/// distance `f` is the centre of a `(2f − 1)`-block cube of non-empty blocks (clipped to the
/// volume).
pub fn two_sided(nodes: [u32; 3], empty: &[bool]) -> Vec<u32> {
    let full: Vec<bool> = empty.iter().map(|&e| !e).collect();
    sides(nodes, empty, &full)
}

/// A field of two sides packed as the GPU packs them: the low bits the distance from each block
/// to the nearest block not in `low` (0 for such a block), the bits from [`FULL_SHIFT`] on the
/// distance to the nearest not in `high`. Isosurfaces build it with `low` the blocks wholly below
/// the iso value and `high` those wholly at or above it.
pub fn sides(nodes: [u32; 3], low: &[bool], high: &[bool]) -> Vec<u32> {
    chebyshev(nodes, low)
        .into_iter()
        .zip(chebyshev(nodes, high))
        .map(|(l, h)| l | (h << FULL_SHIFT))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_sided_fields_hold_both_distances() {
        // One empty block in the middle of a 5×4×3 grid.
        let nodes = [5u32, 4, 3];
        let empty: Vec<bool> = (0..60).map(|i| i == 5 * (4 + 2) + 2).collect();
        let d = two_sided(nodes, &empty);
        let at = |x: usize, y: usize, z: usize| d[x + 5 * (y + 4 * z)];
        assert_eq!(
            at(2, 2, 1),
            1,
            "the empty block: one to the nearest non-empty"
        );
        assert_eq!(at(3, 2, 1), 1 << FULL_SHIFT, "its neighbour: one to it");
        assert_eq!(at(0, 0, 0), 2 << FULL_SHIFT);
        assert_eq!(at(4, 3, 2), 2 << FULL_SHIFT);
        // No empty block: every block reaches the cap.
        let none = two_sided(nodes, &[false; 60]);
        assert!(none.iter().all(|&v| v == MAX_DISTANCE << FULL_SHIFT));
    }

    #[test]
    fn separable_passes_equal_brute_force() {
        let nodes = [9u32, 7, 5];
        let n = 9 * 7 * 5;
        let full: Vec<bool> = (0..n).map(|i| (i * 37) % 11 != 0).collect();
        let sparse: Vec<bool> = (0..n).map(|i| i != 100).collect();
        for empty in [full, sparse, vec![true; n], vec![false; n]] {
            let d = chebyshev(nodes, &empty);
            for (i, &got) in d.iter().enumerate() {
                let p = [i % 9, (i / 9) % 7, i / 63];
                let brute = (0..n)
                    .filter(|&j| !empty[j])
                    .map(|j| {
                        let q = [j % 9, (j / 9) % 7, j / 63];
                        (0..3)
                            .map(|a| p[a].abs_diff(q[a]) as u32)
                            .max()
                            .unwrap_or(0)
                    })
                    .min()
                    .unwrap_or(MAX_DISTANCE)
                    .min(MAX_DISTANCE);
                assert_eq!(got, brute, "block {p:?}");
            }
        }
    }
}
