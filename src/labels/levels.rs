//! Coarser levels of a segmentation's layers, for labels that travel in the volume's bricks:
//! each level halves every axis as the image's levels do
//! ([`crate::volume::downsample::level_dims`]), a voxel the most frequent label of the
//! 2 × 2 × 2 it covers (ties: the smaller value; the last voxel of an odd axis repeated, as the
//! image's levels repeat it). Never a mean: a coarse voxel holds a label that its block of the
//! finest level holds, so what leaps by the finest cells' label lists stays exact within a
//! block's reach.

use rayon::prelude::*;

use crate::volume::downsample::level_dims;

/// The next coarser level of `layer`, a label per voxel of a grid of `dims` (x fastest).
pub(crate) fn halved(layer: &[u16], dims: [u32; 3]) -> Vec<u16> {
    let half = level_dims(dims, 1);
    let [w, h, d] = dims.map(|n| n.max(1) as usize);
    let [hw, hh, hd] = half.map(|n| n as usize);
    let mut out = vec![0u16; hw * hh * hd];
    out.par_chunks_mut(hw * hh)
        .enumerate()
        .for_each(|(z, plane)| {
            let zs = [2 * z, (2 * z + 1).min(d - 1)];
            for y in 0..hh {
                let ys = [2 * y, (2 * y + 1).min(h - 1)];
                for x in 0..hw {
                    let xs = [2 * x, (2 * x + 1).min(w - 1)];
                    let eight: [u16; 8] = std::array::from_fn(|k| {
                        layer[xs[k & 1] + w * (ys[(k >> 1) & 1] + h * zs[k >> 2])]
                    });
                    plane[x + hw * y] = mode(eight);
                }
            }
        });
    out
}

/// The most frequent of eight labels; of those as frequent, the smallest.
fn mode(mut eight: [u16; 8]) -> u16 {
    if eight.iter().all(|&l| l == eight[0]) {
        return eight[0];
    }
    eight.sort_unstable();
    let (mut best, mut most) = (eight[0], 0);
    let mut i = 0;
    while i < eight.len() {
        let run = eight[i..].iter().take_while(|&&l| l == eight[i]).count();
        // Ascending order: a later run as long is of a larger label.
        if run > most {
            (best, most) = (eight[i], run);
        }
        i += run;
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_coarse_voxel_takes_its_blocks_most_frequent_label_and_the_smaller_of_a_tie() {
        assert_eq!(mode([3, 3, 3, 3, 3, 3, 3, 3]), 3);
        assert_eq!(mode([0, 5, 5, 0, 5, 7, 7, 7]), 5);
        assert_eq!(mode([9, 2, 9, 2, 9, 2, 9, 2]), 2);
        assert_eq!(mode([0, 0, 0, 0, 0, 0, 0, 1]), 0);
        assert_eq!(mode([6, 0, 0, 1, 1, 6, 6, 1]), 1);
        // Against counting by brute force, on an odd grid (the last voxel repeated).
        let dims = [7u32, 5, 3];
        let n = (dims[0] * dims[1] * dims[2]) as usize;
        let layer: Vec<u16> = (0..n).map(|i| ((i * 7919) % 13 % 4) as u16).collect();
        let half = halved(&layer, dims);
        let hd = level_dims(dims, 1);
        assert_eq!(half.len(), (hd[0] * hd[1] * hd[2]) as usize);
        for (i, &got) in half.iter().enumerate() {
            let v = [
                i as u32 % hd[0],
                i as u32 / hd[0] % hd[1],
                i as u32 / (hd[0] * hd[1]),
            ];
            let mut counts = [0usize; 4];
            for k in 0..8u32 {
                let c: [u32; 3] =
                    std::array::from_fn(|a| (2 * v[a] + (k >> a & 1)).min(dims[a] - 1));
                counts[layer[(c[0] + dims[0] * (c[1] + dims[1] * c[2])) as usize] as usize] += 1;
            }
            let most = counts.iter().max().copied().unwrap_or(0);
            let want = counts.iter().position(|&c| c == most).unwrap_or(0) as u16;
            assert_eq!(got, want, "coarse voxel {v:?}");
        }
    }
}
