//! The min/max pyramid over a volume (Liang et al.'s octree of blocks), geometry and CPU build.
//!
//! Level 0 cuts the volume into bricks of [`FINEST_BRICK`]³ voxels; each coarser level doubles
//! the brick edge, with `ceil(n / 2)` nodes per axis, until one node covers an axis; an axis that
//! is covered stops splitting while the others go on (the paper's per-axis depth: the octree of
//! the volume padded to `2^L_i ≥ size_i` voxels per axis, with the padding never stored). The
//! leaping block size B is a level of this pyramid (B = 4·2^level), so changing it needs no
//! rebuild.
//!
//! A node owns the region of samples whose continuous voxel coordinate `x` (voxel centre `i` at
//! `x = i`) lies in `[i0·b − ½, (i0+1)·b − ½)` per axis. Trilinear interpolation there reads voxels
//! `floor(x)` and `floor(x) + 1`, i.e. `[i0·b − 1, (i0+1)·b]`: the brick extended by one voxel on
//! each side, as in the paper, so no interpolated value can escape the node's range. Extension
//! commutes with union, so a parent's range is the union of its children's.

use crate::volume::Volume;

/// Edge of the finest bricks, in voxels.
pub const FINEST_BRICK: u32 = 4;

/// Block sizes the renderer accepts (edge in voxels).
pub const BLOCK_SIZES: [u32; 6] = [4, 8, 16, 32, 64, 128];

/// One level of the pyramid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Level {
    /// Edge of this level's bricks in voxels (4 · 2^level).
    pub brick_vox: u32,
    /// Nodes per axis.
    pub nodes: [u32; 3],
    /// Index of this level's first node in the flat node arrays.
    pub offset: u32,
}

impl Level {
    /// Number of nodes.
    pub fn count(&self) -> u32 {
        self.nodes.iter().product()
    }

    /// Flat index of node `n` (within the level's nodes).
    pub fn index(&self, n: [u32; 3]) -> u32 {
        self.offset + n[0] + self.nodes[0] * (n[1] + self.nodes[1] * n[2])
    }
}

/// The pyramid's layout for a volume.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pyramid {
    /// Volume dimensions.
    pub dims: [u32; 3],
    /// Levels, finest first; the last has one node and bricks of at least 128 voxels.
    pub levels: Vec<Level>,
}

impl Pyramid {
    /// The layout for a volume of `dims` voxels.
    pub fn new(dims: [u32; 3]) -> Self {
        Self::with_finest(dims, FINEST_BRICK)
    }

    /// The layout with the finest blocks that keep the node min/max array (8 bytes a node, the
    /// largest of the structures) within `max_bytes`, the most a shader can bind: 4³ blocks
    /// where they fit (a 1024³ volume's pyramid of them is 153 MB, past lavapipe's 128 MiB),
    /// and all the structures on the GPU ([`Self::gpu_bytes`]) within `most`, where given.
    pub fn within(dims: [u32; 3], max_bytes: u64, most: Option<u64>) -> Self {
        let fits = |b: &u32| {
            let p = Self::with_finest(dims, *b);
            u64::from(p.node_count()) * 8 <= max_bytes && most.is_none_or(|m| p.gpu_bytes() <= m)
        };
        let finest = BLOCK_SIZES.iter().copied().find(|b| fits(b));
        Self::with_finest(dims, finest.unwrap_or(BLOCK_SIZES[BLOCK_SIZES.len() - 1]))
    }

    /// Bytes the leaping structures of this layout take on the GPU: per node its min/max (8)
    /// and its flags (4), per block of the finest level its distance twice (4 each).
    pub fn gpu_bytes(&self) -> u64 {
        let leaves = self.levels.first().map_or(0, |l| u64::from(l.count()));
        u64::from(self.node_count()) * 12 + leaves * 8
    }

    /// The layout whose finest blocks are `finest` voxels (one of [`BLOCK_SIZES`]).
    fn with_finest(dims: [u32; 3], finest: u32) -> Self {
        let mut levels = Vec::new();
        let mut brick = finest;
        let mut offset = 0u32;
        loop {
            let nodes = dims.map(|d| d.div_ceil(brick).max(1));
            let level = Level {
                brick_vox: brick,
                nodes,
                offset,
            };
            offset += level.count();
            levels.push(level);
            if nodes == [1, 1, 1] && brick >= BLOCK_SIZES[BLOCK_SIZES.len() - 1] {
                break;
            }
            brick *= 2;
        }
        Self { dims, levels }
    }

    /// Total number of nodes over all levels.
    pub fn node_count(&self) -> u32 {
        self.levels.last().map_or(0, |l| l.offset + l.count())
    }

    /// The level whose bricks are `block_vox` voxels (a power of two from 4 to 128).
    pub fn level_of_block(&self, block_vox: u32) -> Option<usize> {
        self.levels.iter().position(|l| l.brick_vox == block_vox)
    }

    /// The voxels (inclusive, clamped to the volume) that samples in node `i0` of `level` can
    /// read along `axis`.
    fn voxel_range(&self, level: &Level, i0: u32, axis: usize) -> (u32, u32) {
        let b = level.brick_vox as i64;
        let lo = (i0 as i64 * b - 1).max(0);
        let hi = ((i0 as i64 + 1) * b).min(self.dims[axis] as i64 - 1);
        (lo as u32, hi.max(lo) as u32)
    }
}

/// Min and max of the normalised values (0 = volume minimum, 1 = maximum) a node's samples can
/// interpolate from; `min > max` for a node with no finite voxel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MinMax {
    /// Smallest value.
    pub min: f32,
    /// Largest value.
    pub max: f32,
}

impl MinMax {
    /// The empty range (no finite voxel).
    pub const NONE: Self = Self {
        min: f32::MAX,
        max: f32::MIN,
    };

    /// The union of two ranges.
    pub(crate) fn union(self, other: Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }
}

/// Normalised values of every voxel (NaN where not finite), as the shader decodes them; none
/// for a volume read from its store as needed (it holds no whole grid).
pub fn normalized_values(volume: &Volume) -> Vec<f32> {
    let range = volume.normalization_range();
    let mapping = volume.mapping();
    let Some(samples) = volume.samples() else {
        return Vec::new();
    };
    let mut out = Vec::with_capacity(volume.sample_count() as usize);
    samples.for_each_f64(|s| {
        let v = mapping.apply(s);
        out.push(if v.is_finite() {
            range.normalize(v) as f32
        } else {
            f32::NAN
        });
    });
    out
}

/// Builds all levels on the CPU: level 0 from the voxels, the others by reduction.
pub fn build_cpu(pyramid: &Pyramid, values: &[f32]) -> Vec<MinMax> {
    let mut out = vec![MinMax::NONE; pyramid.node_count() as usize];
    let [nx, ny, _] = pyramid.dims.map(|d| d as usize);
    let base = pyramid.levels[0];
    for_each_node(&base, |n| {
        let r = |a: usize| pyramid.voxel_range(&base, n[a], a);
        let ((x0, x1), (y0, y1), (z0, z1)) = (r(0), r(1), r(2));
        let mut m = MinMax::NONE;
        for z in z0..=z1 {
            for y in y0..=y1 {
                let row = (z as usize * ny + y as usize) * nx;
                for &v in &values[row + x0 as usize..=row + x1 as usize] {
                    if !v.is_nan() {
                        m = m.union(MinMax { min: v, max: v });
                    }
                }
            }
        }
        out[base.index(n) as usize] = m;
    });
    for w in 1..pyramid.levels.len() {
        let (child, parent) = (pyramid.levels[w - 1], pyramid.levels[w]);
        for_each_node(&parent, |n| {
            let mut m = MinMax::NONE;
            for c in 0..8u32 {
                let k = [0, 1, 2].map(|a| 2 * n[a] + (c >> a & 1));
                if (0..3).all(|a| k[a] < child.nodes[a]) {
                    m = m.union(out[child.index(k) as usize]);
                }
            }
            out[parent.index(n) as usize] = m;
        });
    }
    out
}

/// Calls `f` with every node coordinate of `level`.
fn for_each_node(level: &Level, mut f: impl FnMut([u32; 3])) {
    for z in 0..level.nodes[2] {
        for y in 0..level.nodes[1] {
            for x in 0..level.nodes[0] {
                f([x, y, z]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finest_blocks_grow_until_the_min_max_array_fits_the_binding_limit() {
        let dims = [1024, 1024, 1024];
        let fine = Pyramid::new(dims);
        assert_eq!(fine.levels[0].brick_vox, FINEST_BRICK);
        let bytes = u64::from(fine.node_count()) * 8;
        assert!(bytes > 128 << 20, "{bytes}");
        assert_eq!(Pyramid::within(dims, bytes, None), fine);
        let coarser = Pyramid::within(dims, 128 << 20, None);
        assert_eq!(coarser.levels[0].brick_vox, 8);
        assert!(u64::from(coarser.node_count()) * 8 <= 128 << 20);
        // Every level above the finest is the finer pyramid's level of the same block size.
        for level in &coarser.levels {
            let same = fine.levels[fine.level_of_block(level.brick_vox).unwrap()];
            assert_eq!(level.nodes, same.nodes);
        }
        assert_eq!(Pyramid::within(dims, 8, None).levels[0].brick_vox, 128);
    }

    #[test]
    fn finest_blocks_grow_until_all_the_structures_fit_their_share_of_the_budget() {
        // 2048 × 2048 × 1024: 4³ blocks take 1.46 GB (min/max, flags, two distance fields).
        let dims = [2048, 2048, 1024];
        let fine = Pyramid::within(dims, u64::MAX, None);
        assert_eq!(fine.levels[0].brick_vox, 4);
        let leaves = 512u64 * 512 * 256;
        let nodes = u64::from(fine.node_count());
        assert!(nodes > leaves && nodes < leaves * 8 / 7 + 64, "{nodes}");
        assert_eq!(fine.gpu_bytes(), nodes * 12 + leaves * 8);
        // A quarter of a 1 GB budget: 8³ blocks (182 MB).
        let share = Pyramid::within(dims, u64::MAX, Some(250_000_000));
        assert_eq!(share.levels[0].brick_vox, 8);
        assert!(share.gpu_bytes() <= 250_000_000, "{}", share.gpu_bytes());
        assert!(
            Pyramid::within(dims, u64::MAX, Some(share.gpu_bytes() - 1)).levels[0].brick_vox > 8
        );
    }

    #[test]
    fn levels_split_each_axis_until_covered() {
        let p = Pyramid::new([37, 50, 13]);
        let nodes: Vec<[u32; 3]> = p.levels.iter().map(|l| l.nodes).collect();
        assert_eq!(
            nodes,
            vec![
                [10, 13, 4],
                [5, 7, 2],
                [3, 4, 1],
                [2, 2, 1],
                [1, 1, 1],
                [1, 1, 1]
            ]
        );
        assert_eq!(p.levels.last().map(|l| l.brick_vox), Some(128));
        assert_eq!(p.level_of_block(16), Some(2));
        assert_eq!(p.node_count(), 520 + 70 + 12 + 4 + 1 + 1);
    }

    #[test]
    fn brick_ranges_are_extended_by_one_voxel_and_clamped() {
        let p = Pyramid::new([37, 50, 13]);
        let l = p.levels[1]; // 8-voxel bricks
        assert_eq!(p.voxel_range(&l, 0, 0), (0, 8));
        assert_eq!(p.voxel_range(&l, 1, 0), (7, 16));
        assert_eq!(p.voxel_range(&l, 4, 0), (31, 36));
    }

    /// Every node of every level against a brute-force min/max over its extended voxel range.
    #[test]
    fn cpu_build_equals_brute_force_on_odd_sizes() {
        let dims = [37u32, 50, 13];
        let n = dims.iter().product::<u32>() as usize;
        let mut values: Vec<f32> = (0..n)
            .map(|i| ((i * 7919) % 1009) as f32 / 1009.0)
            .collect();
        values[5 + 37 * (7 + 50 * 3)] = f32::NAN;
        let p = Pyramid::new(dims);
        let built = build_cpu(&p, &values);
        for level in &p.levels {
            for_each_node(level, |node| {
                let r = |a: usize| p.voxel_range(level, node[a], a);
                let mut m = MinMax::NONE;
                for z in r(2).0..=r(2).1 {
                    for y in r(1).0..=r(1).1 {
                        for x in r(0).0..=r(0).1 {
                            let v = values[(x + 37 * (y + 50 * z)) as usize];
                            if !v.is_nan() {
                                m = m.union(MinMax { min: v, max: v });
                            }
                        }
                    }
                }
                assert_eq!(
                    built[level.index(node) as usize],
                    m,
                    "level {} node {node:?}",
                    level.brick_vox
                );
            });
        }
    }
}
