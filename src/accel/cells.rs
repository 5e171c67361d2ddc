//! The finer occupancy: each finest block (4³ voxels) of the pyramid split into eight cells of
//! 2³ voxels, with the range of values each cell's samples can interpolate from. A DVR ray
//! inside a block that can be visible leaps over its cells that cannot (vessels: a 4³ block
//! that a thin vessel touches is mostly transparent).
//!
//! Cell `c = x + 2y + 4z` of block `i` owns, along each axis, the samples whose continuous voxel
//! coordinate lies in `[4i + 2c_a − ½, 4i + 2c_a + 1½)` (half of the block's region, see
//! [`super::pyramid`]); trilinear interpolation there reads voxels `[4i + 2c_a − 1, 4i + 2c_a + 2]`,
//! clamped to the volume. The GPU stores each cell's range as the emptiness table's bins and
//! builds the mask of visible cells with the node flags (`shaders/build/`); these are the
//! brute-force references.

use super::pyramid::{FINEST_BRICK, MinMax, Pyramid, for_each_node};

/// Edge of a cell in voxels.
pub const CELL_VOX: u32 = FINEST_BRICK / 2;

/// The voxels (inclusive, clamped to the volume) that samples in cell `c` (0 or 1) of finest
/// block `i` can read along an axis of `dim` voxels; `None` where the cell holds no voxel.
pub fn cell_voxel_range(i: u32, c: u32, dim: u32) -> Option<(u32, u32)> {
    let start = i64::from(i * FINEST_BRICK + c * CELL_VOX);
    let lo = (start - 1).max(0);
    let hi = (start + i64::from(CELL_VOX)).min(i64::from(dim) - 1);
    // A cell past the end of the volume reads at most the voxel before it; its samples never
    // exist, so what it holds does not matter, but the GPU keeps the same rule.
    (lo <= hi).then_some((lo as u32, hi as u32))
}

/// Per finest block (in the pyramid's order for level 0), the value range of each of its eight
/// cells (`MinMax::NONE` for a cell without finite voxels), by visiting every voxel each reads.
pub fn cell_ranges(pyramid: &Pyramid, values: &[f32]) -> Vec<[MinMax; 8]> {
    let base = pyramid.levels[0];
    let [nx, ny, _] = pyramid.dims.map(|d| d as usize);
    let mut out = vec![[MinMax::NONE; 8]; base.count() as usize];
    for_each_node(&base, |n| {
        let block = &mut out[base.index(n) as usize];
        for (c, range) in block.iter_mut().enumerate() {
            let axis = |a: usize| cell_voxel_range(n[a], (c as u32 >> a) & 1, pyramid.dims[a]);
            let (Some((x0, x1)), Some((y0, y1)), Some((z0, z1))) = (axis(0), axis(1), axis(2))
            else {
                continue;
            };
            for z in z0..=z1 {
                for y in y0..=y1 {
                    let row = (z as usize * ny + y as usize) * nx;
                    for &v in &values[row + x0 as usize..=row + x1 as usize] {
                        if !v.is_nan() {
                            *range = range.union(MinMax { min: v, max: v });
                        }
                    }
                }
            }
        }
    });
    out
}

/// The mask of a block's cells that can be visible (bit `c` set), given whether the block is
/// empty as a whole and a test for each cell's range: none where the block is empty.
pub fn cell_mask(ranges: &[MinMax; 8], block_empty: bool, empty: impl Fn(MinMax) -> bool) -> u8 {
    if block_empty {
        return 0;
    }
    ranges
        .iter()
        .enumerate()
        .filter(|(_, m)| !empty(**m))
        .fold(0, |mask, (c, _)| mask | (1 << c))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_read_their_half_of_the_block_extended_by_one_voxel() {
        assert_eq!(cell_voxel_range(0, 0, 37), Some((0, 2)));
        assert_eq!(cell_voxel_range(0, 1, 37), Some((1, 4)));
        assert_eq!(cell_voxel_range(1, 0, 37), Some((3, 6)));
        // The last block of 37 voxels holds voxel 36 only: its second cell holds none.
        assert_eq!(cell_voxel_range(9, 0, 37), Some((35, 36)));
        assert_eq!(cell_voxel_range(9, 1, 37), None);
        assert_eq!(cell_voxel_range(9, 1, 38), Some((37, 37)));
    }

    #[test]
    fn the_cells_of_a_block_cover_its_range() {
        let pyramid = Pyramid::new([9, 6, 5]);
        let values: Vec<f32> = (0..9 * 6 * 5).map(|i| ((i * 37) % 101) as f32).collect();
        let blocks = super::super::pyramid::build_cpu(&pyramid, &values);
        for (i, cells) in cell_ranges(&pyramid, &values).iter().enumerate() {
            let union = cells.iter().fold(MinMax::NONE, |a, b| a.union(*b));
            assert_eq!(union, blocks[i], "block {i}");
        }
    }

    #[test]
    fn a_mask_holds_the_cells_that_are_not_empty() {
        let mut ranges = [MinMax { min: 0.0, max: 0.1 }; 8];
        ranges[3] = MinMax { min: 0.0, max: 0.9 };
        ranges[6] = MinMax { min: 0.7, max: 0.8 };
        let empty = |m: MinMax| m.max < 0.5;
        assert_eq!(cell_mask(&ranges, false, empty), 0b0100_1000);
        assert_eq!(cell_mask(&ranges, true, empty), 0);
    }
}
