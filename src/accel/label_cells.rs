//! Which labels each cell of a segmentation holds: the volume cut into cells of
//! [`CELL_VOX`]³ voxels (the finest pyramid blocks), each with the sorted list of the distinct
//! non-zero labels of its voxels, over every layer, as a CSR pair (offsets per cell, values).
//! Built once per label map on all cores; the GPU turns it into one flag per pyramid node
//! (`build/labels.wgsl`): whether the node holds a shown label. A pyramid node owns the samples
//! whose nearest voxel is one of its own (`accel::pyramid`), so a node none of whose labels is
//! shown holds only samples a cut view takes away.

use rayon::prelude::*;

use crate::labels::LabelMap;

/// Edge of a cell in voxels: the finest pyramid block (`pyramid::FINEST_BRICK`).
pub const CELL_VOX: u32 = super::pyramid::FINEST_BRICK;

/// The labels of every cell.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LabelCells {
    /// Cells per axis.
    pub cells: [u32; 3],
    /// Cell `c`'s labels are `labels[offsets[c]..offsets[c + 1]]` (cells x fastest).
    pub offsets: Vec<u32>,
    /// Every cell's labels, sorted within a cell.
    pub labels: Vec<u32>,
}

impl LabelCells {
    /// The cells of `map`.
    pub fn of(map: &LabelMap) -> Self {
        let dims = map.dims();
        let cells = dims.map(|d| d.div_ceil(CELL_VOX).max(1));
        let layers = map.layers();
        let voxel = |x: u32, y: u32, z: u32| {
            x as usize + dims[0] as usize * (y as usize + dims[1] as usize * z as usize)
        };
        // One row of cells (fixed y, z) per task: its lists, in order.
        let rows: Vec<Vec<Vec<u32>>> = (0..cells[1] * cells[2])
            .into_par_iter()
            .map(|row| {
                let (cy, cz) = (row % cells[1], row / cells[1]);
                let span = |c: u32, a: usize| c * CELL_VOX..((c + 1) * CELL_VOX).min(dims[a]);
                (0..cells[0])
                    .map(|cx| {
                        let mut found = Vec::new();
                        for z in span(cz, 2) {
                            for y in span(cy, 1) {
                                for x in span(cx, 0) {
                                    let i = voxel(x, y, z);
                                    found.extend(
                                        layers
                                            .iter()
                                            .map(|layer| u32::from(layer[i]))
                                            .filter(|&l| l != 0),
                                    );
                                }
                            }
                        }
                        found.sort_unstable();
                        found.dedup();
                        found
                    })
                    .collect()
            })
            .collect();
        let mut offsets =
            Vec::with_capacity(cells.iter().map(|&c| c as usize).product::<usize>() + 1);
        let mut labels = Vec::new();
        offsets.push(0);
        for cell in rows.iter().flatten() {
            labels.extend_from_slice(cell);
            // A label map's voxels, times its few layers, stay far below 2³² on any GPU.
            offsets.push(labels.len() as u32);
        }
        Self {
            cells,
            offsets,
            labels,
        }
    }

    /// Cell `[x, y, z]`'s labels.
    pub fn at(&self, [x, y, z]: [u32; 3]) -> &[u32] {
        let c = x as usize
            + self.cells[0] as usize * (y as usize + self.cells[1] as usize * z as usize);
        &self.labels[self.offsets[c] as usize..self.offsets[c + 1] as usize]
    }

    /// Each label's box of voxels (first, end: half open), to the cell on a grid of `dims`:
    /// every voxel of the label lies inside it, and so does at most a cell's edge more.
    pub fn boxes(&self, dims: [u32; 3]) -> std::collections::BTreeMap<u16, VoxelBox> {
        let mut boxes = std::collections::BTreeMap::<u16, VoxelBox>::new();
        let [nx, ny, _] = self.cells.map(|c| c as usize);
        for c in 0..self.offsets.len().saturating_sub(1) {
            let cell = [c % nx, c / nx % ny, c / (nx * ny)].map(|v| v as u32);
            let first = cell.map(|v| v * CELL_VOX);
            let end = std::array::from_fn(|a| ((cell[a] + 1) * CELL_VOX).min(dims[a]));
            for &l in &self.labels[self.offsets[c] as usize..self.offsets[c + 1] as usize] {
                // Labels are u16 values widened for the GPU's buffers.
                let b = boxes.entry(l as u16).or_insert(VoxelBox { first, end });
                b.first = std::array::from_fn(|a| b.first[a].min(first[a]));
                b.end = std::array::from_fn(|a| b.end[a].max(end[a]));
            }
        }
        boxes
    }
}

/// A box of voxels: `first` to `end` (past the last) on each axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VoxelBox {
    /// Its first voxel.
    pub first: [u32; 3],
    /// Past its last voxel.
    pub end: [u32; 3],
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against a brute-force walk of every voxel: a grid not a multiple of the cell, two
    /// layers, labels up to 65535.
    #[test]
    fn every_cell_lists_exactly_the_labels_of_its_voxels() {
        let dims = [13, 9, 7];
        let n = dims.iter().product::<u32>() as usize;
        let mut state = 12345u32;
        let mut next = || {
            state = state.wrapping_mul(1_103_515_245).wrapping_add(12_345);
            state >> 16
        };
        let layer = |next: &mut dyn FnMut() -> u32, values: &[u16]| -> Vec<u16> {
            (0..n)
                .map(|_| values[next() as usize % values.len()])
                .collect()
        };
        let first = layer(&mut next, &[0, 0, 0, 1, 2, 7, 65535]);
        let second = layer(&mut next, &[0, 0, 0, 0, 0, 0, 300]);
        let map = LabelMap::bare(dims, vec![first.clone(), second.clone()]);
        let cells = LabelCells::of(&map);
        assert_eq!(cells.cells, [4, 3, 2]);
        for cz in 0..2 {
            for cy in 0..3 {
                for cx in 0..4 {
                    let mut want = std::collections::BTreeSet::new();
                    for z in 0..dims[2] {
                        for y in 0..dims[1] {
                            for x in 0..dims[0] {
                                if [x / 4, y / 4, z / 4] != [cx, cy, cz] {
                                    continue;
                                }
                                let i = (x + dims[0] * (y + dims[1] * z)) as usize;
                                for l in [first[i], second[i]] {
                                    if l != 0 {
                                        want.insert(u32::from(l));
                                    }
                                }
                            }
                        }
                    }
                    let want: Vec<u32> = want.into_iter().collect();
                    assert_eq!(
                        cells.at([cx, cy, cz]),
                        want.as_slice(),
                        "cell {cx} {cy} {cz}"
                    );
                }
            }
        }
        assert!(cells.labels.contains(&65535) && cells.labels.contains(&300));
    }

    /// Each label's box holds all its voxels and reaches no further than the cells they lie in.
    #[test]
    fn each_labels_box_holds_its_voxels_to_the_cell() {
        let dims = [21, 10, 9];
        let n = dims.iter().product::<u32>() as usize;
        let mut layer = vec![0u16; n];
        let at = |x: u32, y: u32, z: u32| (x + dims[0] * (y + dims[1] * z)) as usize;
        layer[at(1, 2, 3)] = 5;
        layer[at(17, 9, 8)] = 5;
        layer[at(20, 0, 0)] = 9;
        let mut second = vec![0u16; n];
        second[at(6, 6, 6)] = 9;
        let map = LabelMap::bare(dims, vec![layer, second]);
        let boxes = LabelCells::of(&map).boxes(dims);
        assert_eq!(boxes.len(), 2);
        // Voxels 1..=17, 2..=9, 3..=8 widened to their cells (4 voxels), clipped to the grid.
        assert_eq!(
            boxes[&5],
            VoxelBox {
                first: [0, 0, 0],
                end: [20, 10, 9]
            }
        );
        assert_eq!(
            boxes[&9],
            VoxelBox {
                first: [4, 0, 0],
                end: [21, 8, 8]
            }
        );
    }
}
