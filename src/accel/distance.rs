//! The distance field over blocks (beyond the paper): for each block, the Chebyshev distance in
//! blocks to the nearest non-empty block, so that one step clears a whole cube of empty blocks.
//!
//! A block at distance `d > 0` is the centre of a `(2d − 1)`-block cube that holds only empty
//! blocks; a ray inside it can jump to the cube's exit. Distances are capped at [`MAX_DISTANCE`];
//! blocks outside the volume count as empty (rays end at the volume's faces anyway). The L∞
//! distance transform is separable: three 1D passes, each `g(x) = min over x' of max(|x − x'|,
//! f(x'))`, give the 3D distance; the GPU runs the same passes.

/// Largest distance stored, in blocks (also the window of each 1D pass).
pub const MAX_DISTANCE: u32 = 31;

/// Chebyshev distances for a grid of `nodes` blocks where `empty[i]` says block `i` (x fastest)
/// is empty.
pub fn chebyshev(nodes: [u32; 3], empty: &[bool]) -> Vec<u32> {
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

#[cfg(test)]
mod tests {
    use super::*;

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
