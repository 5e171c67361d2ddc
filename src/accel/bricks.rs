//! The volume cut into bricks for the GPU: a grid of `brick_vox`³ bricks, each stored with an
//! apron of one voxel on every side in a slot of an atlas texture, and a page table that gives
//! each brick's slot. With the apron, the texture unit's trilinear filter inside a slot reads
//! exactly the eight voxels it would read in one texture of the whole volume, so samples,
//! gradients and the leaping structures are exact across brick borders.
//!
//! A point at continuous texel coordinate `c` (voxel `i`'s centre at `c = i + ½`) lies in brick
//! `floor(c / brick_vox)`; trilinear there reads voxels `floor(c − ½)` and `floor(c − ½) + 1`,
//! all within the brick extended by one voxel: the apron. Voxels outside the volume repeat the
//! nearest edge voxel (clamp to edge, as the sampler does).
//!
//! The atlas holds the bricks of one level of the volume (`volume::downsample`: level `k` halves
//! every axis `k` times), the finest whose bricks fit the GPU memory budget. The page table has
//! one entry per brick of level 0; each names the slot and level of the brick that holds its
//! voxels (at level `k`, its ancestor: brick `b >> k`), so the shaders sample any level through
//! the same lookup, at continuous coordinate `c / 2^k`.

/// Voxels of apron on every side of a brick in its slot.
pub const APRON: u32 = 1;

/// The brick edge in voxels when none is asked for (BigVolumeViewer's and the Residency
/// Octree's 32³; with the apron a slot is 34³, 1.2× the payload).
pub const DEFAULT_BRICK_VOX: u32 = 32;

/// Bits of one slot coordinate in a page-table entry (three of them, then four of the level).
const SLOT_BITS: u32 = 9;

/// Slots an atlas may have along one axis (what nine bits of an entry can name).
pub const MAX_SLOTS_PER_AXIS: u32 = (1 << SLOT_BITS) - 1;

/// Levels a page-table entry can name.
pub const MAX_LEVELS: u32 = 16;

/// Why a volume cannot be bricked within the adapter's limits.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BrickError {
    /// The atlas would need more slots than a texture of the limit holds.
    #[error(
        "{bricks} bricks of {brick_vox}³ voxels do not fit an atlas of at most {max} texels per \
         axis"
    )]
    AtlasFull {
        /// Bricks of the volume.
        bricks: u64,
        /// Their edge.
        brick_vox: u32,
        /// The adapter's 3D texture limit.
        max: u32,
    },
    /// A brick edge that is not a power of two from 4 to 256 (bricks nest in the leaping
    /// pyramid's nodes).
    #[error("a brick edge of {0} voxels is not a power of two from 4 to 256")]
    Edge(u32),
    /// Not even the coarsest level fits the GPU memory budget.
    #[error(
        "a GPU memory budget of {} is smaller than the volume's coarsest level ({})",
        crate::text::bytes(*budget_bytes),
        crate::text::bytes(*coarsest_bytes)
    )]
    Budget {
        /// The budget.
        budget_bytes: u64,
        /// What the coarsest level's bricks take.
        coarsest_bytes: u64,
    },
}

pub use crate::volume::downsample::level_dims;

/// Levels of a volume of `dims` in bricks of `brick_vox`: halving until one brick holds a level.
pub fn level_count(dims: [u32; 3], brick_vox: u32) -> u32 {
    let mut level = 0;
    while level_dims(dims, level).iter().any(|&d| d > brick_vox) {
        level += 1;
    }
    level + 1
}

/// How a volume is cut into bricks and where each brick of the level held lives in the atlas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BrickLayout {
    /// Volume voxels per axis (level 0).
    pub dims: [u32; 3],
    /// Brick edge in voxels (without the apron).
    pub brick_vox: u32,
    /// The level the atlas holds (0: full resolution).
    pub level: u32,
    /// Bricks of that level per axis.
    pub bricks: [u32; 3],
    /// Atlas slots per axis.
    pub slots: [u32; 3],
}

impl BrickLayout {
    /// The layout of a volume of `dims` in bricks of `brick_vox`, in an atlas of at most
    /// `max_texels` per axis, its slots about as many along each axis.
    pub fn new(dims: [u32; 3], brick_vox: u32, max_texels: u32) -> Result<Self, BrickError> {
        Self::at_level(dims, brick_vox, 0, max_texels)
    }

    /// The bricks of level `level` of a volume of `dims`, without an atlas (one slot): where
    /// each brick's voxels are.
    pub fn geometry(dims: [u32; 3], brick_vox: u32, level: u32) -> Self {
        Self {
            dims,
            brick_vox,
            level,
            bricks: level_dims(dims, level).map(|d| d.div_ceil(brick_vox)),
            slots: [1; 3],
        }
    }

    /// The layout of level `level` of a volume of `dims`.
    pub fn at_level(
        dims: [u32; 3],
        brick_vox: u32,
        level: u32,
        max_texels: u32,
    ) -> Result<Self, BrickError> {
        if !brick_vox.is_power_of_two() || !(4..=256).contains(&brick_vox) {
            return Err(BrickError::Edge(brick_vox));
        }
        let bricks = level_dims(dims, level).map(|d| d.div_ceil(brick_vox));
        let count: u64 = bricks.iter().map(|&b| u64::from(b)).product();
        let per_axis = u64::from((max_texels / (brick_vox + 2 * APRON)).min(MAX_SLOTS_PER_AXIS));
        let full = || BrickError::AtlasFull {
            bricks: count,
            brick_vox,
            max: max_texels,
        };
        if per_axis == 0 {
            return Err(full());
        }
        let cube = (count as f64).cbrt().ceil() as u64;
        let sx = cube.clamp(1, per_axis);
        let sy = ((count.div_ceil(sx) as f64).sqrt().ceil() as u64).clamp(1, per_axis);
        let sz = count.div_ceil(sx * sy);
        if sz > per_axis {
            return Err(full());
        }
        Ok(Self {
            dims,
            brick_vox,
            level: level.min(MAX_LEVELS - 1),
            bricks,
            slots: [sx as u32, sy as u32, sz as u32],
        })
    }

    /// Voxels per axis of the level held.
    pub fn level_dims(&self) -> [u32; 3] {
        level_dims(self.dims, self.level)
    }

    /// Entries of the page table per axis: the bricks of level 0.
    pub fn pages(&self) -> [u32; 3] {
        self.dims.map(|d| d.max(1).div_ceil(self.brick_vox))
    }

    /// Bytes of the atlas's slots that hold bricks, at `bytes_per_texel`.
    pub fn brick_bytes(&self, bytes_per_texel: u64) -> u64 {
        u64::from(self.count()) * u64::from(self.slot_vox()).pow(3) * bytes_per_texel
    }

    /// Edge of a slot: the brick and its apron.
    pub fn slot_vox(&self) -> u32 {
        self.brick_vox + 2 * APRON
    }

    /// Number of bricks.
    pub fn count(&self) -> u32 {
        self.bricks.iter().product()
    }

    /// Texels of the atlas per axis.
    #[cfg(test)] // The atlas the tests build by hand.
    pub fn atlas_texels(&self) -> [u32; 3] {
        self.slots.map(|s| s * self.slot_vox())
    }

    /// Brick `index` (x fastest) as grid coordinates.
    pub fn brick_at(&self, index: u32) -> [u32; 3] {
        let [bx, by, _] = self.bricks;
        [index % bx, (index / bx) % by, index / (bx * by)]
    }

    /// The slot of brick `index` while every brick is resident: slots in brick order, x fastest.
    #[cfg(test)] // The atlas the tests build by hand.
    pub fn slot_of(&self, index: u32) -> [u32; 3] {
        let [sx, sy, _] = self.slots;
        [index % sx, (index / sx) % sy, index / (sx * sy)]
    }

    /// The page-table entry that sends a brick to `slot` of a brick of `level`: its
    /// coordinates nine bits each, then the level in four.
    pub fn page_entry(slot: [u32; 3], level: u32) -> u32 {
        slot[0] | (slot[1] << SLOT_BITS) | (slot[2] << (2 * SLOT_BITS)) | (level << (3 * SLOT_BITS))
    }

    /// The slot and level a page-table entry names.
    pub fn decode_entry(entry: u32) -> ([u32; 3], u32) {
        let mask = (1 << SLOT_BITS) - 1;
        (
            [
                entry & mask,
                (entry >> SLOT_BITS) & mask,
                (entry >> (2 * SLOT_BITS)) & mask,
            ],
            entry >> (3 * SLOT_BITS),
        )
    }

    /// The voxel of the level held at texel `t` of brick `brick`'s slot (t in `0..slot_vox` per
    /// axis; the apron's and the overhang's texels repeat the nearest voxel inside the level).
    pub fn voxel_of(&self, brick: [u32; 3], t: [u32; 3]) -> [u32; 3] {
        let dims = self.level_dims();
        std::array::from_fn(|a| {
            let v = i64::from(brick[a] * self.brick_vox) + i64::from(t[a]) - i64::from(APRON);
            v.clamp(0, i64::from(dims[a] - 1)) as u32
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Trilinear interpolation of `f` at continuous texel coordinate `c` of a grid of `dims`,
    /// clamped to the edge, as the texture unit computes it (without its fixed-point weights).
    fn trilinear(dims: [u32; 3], c: [f64; 3], f: impl Fn([u32; 3]) -> f64) -> f64 {
        let x = c.map(|c| c - 0.5);
        let base = x.map(f64::floor);
        let mut sum = 0.0;
        for corner in 0..8 {
            let mut w = 1.0;
            let mut i = [0u32; 3];
            for a in 0..3 {
                let hi = (corner >> a) & 1 == 1;
                let frac = x[a] - base[a];
                w *= if hi { frac } else { 1.0 - frac };
                let v = base[a] as i64 + i64::from(hi);
                i[a] = v.clamp(0, i64::from(dims[a]) - 1) as u32;
            }
            sum += w * f(i);
        }
        sum
    }

    #[test]
    fn a_sample_in_a_slot_reads_what_it_reads_in_the_whole_volume() {
        // An odd size: partial bricks at the far ends of every axis.
        let dims = [37, 9, 70];
        let layout = BrickLayout::new(dims, 8, 64).expect("fits");
        let value = |v: [u32; 3]| f64::from(v[0] * 7 + v[1] * 131 + v[2] * 1009);
        // The atlas as the upload fills it.
        let atlas = layout.atlas_texels();
        let mut texels = vec![0.0; atlas.iter().map(|&a| a as usize).product()];
        let s = layout.slot_vox();
        for index in 0..layout.count() {
            let (brick, slot) = (layout.brick_at(index), layout.slot_of(index));
            for z in 0..s {
                for y in 0..s {
                    for x in 0..s {
                        let a = [slot[0] * s + x, slot[1] * s + y, slot[2] * s + z];
                        texels[(a[0] + atlas[0] * (a[1] + atlas[1] * a[2])) as usize] =
                            value(layout.voxel_of(brick, [x, y, z]));
                    }
                }
            }
        }
        let pages: Vec<u32> = (0..layout.count())
            .map(|i| BrickLayout::page_entry(layout.slot_of(i), 0))
            .collect();
        // Points all over the volume and past its faces (clamped as the renderer clamps).
        let mut state = 12345u64;
        for _ in 0..5000 {
            let c: [f64; 3] = std::array::from_fn(|a| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 11) as f64 / (1u64 << 53) as f64) * (f64::from(dims[a]) + 2.0) - 1.0
            });
            let c = std::array::from_fn(|a| c[a].clamp(0.5, f64::from(dims[a]) - 0.5));
            let want = trilinear(dims, c, value);
            // The shader's lookup: the brick, its page entry, the texel in the atlas.
            let b: [u32; 3] = std::array::from_fn(|a| (c[a] / 8.0).floor() as u32);
            let entry =
                pages[(b[0] + layout.bricks[0] * (b[1] + layout.bricks[1] * b[2])) as usize];
            let (slot, level) = BrickLayout::decode_entry(entry);
            assert_eq!(level, 0);
            let at: [f64; 3] = std::array::from_fn(|a| {
                f64::from(slot[a] * s + APRON) + c[a] - f64::from(b[a] * 8)
            });
            let got = trilinear(atlas, at, |i| {
                texels[(i[0] + atlas[0] * (i[1] + atlas[1] * i[2])) as usize]
            });
            assert!((got - want).abs() < 1e-6, "{c:?}: {got} vs {want}");
        }
    }

    #[test]
    fn an_axis_past_the_texture_limit_packs_into_an_atlas_within_it() {
        for dims in [[4200, 16, 16], [64, 48, 4500], [2048, 2048, 1024]] {
            let layout = BrickLayout::new(dims, 32, 4096).expect("fits");
            assert!(layout.atlas_texels().iter().all(|&t| t <= 4096), "{dims:?}");
            let slots: u32 = layout.slots.iter().product();
            assert!(slots >= layout.count());
            // At most one layer of slots is left over.
            assert!(slots - layout.count() < layout.slots[0] * layout.slots[1]);
        }
        let layout = BrickLayout::new([1, 1, 1], 32, 2048).expect("fits");
        assert_eq!((layout.count(), layout.slots), (1, [1, 1, 1]));
    }

    #[test]
    fn refusals_name_what_does_not_fit() {
        assert_eq!(
            BrickLayout::new([16; 3], 24, 4096),
            Err(BrickError::Edge(24))
        );
        // 8 slots of 34 per axis: 512 bricks at most.
        let err = BrickLayout::new([32 * 9, 32 * 8, 32 * 8], 32, 8 * 34).expect_err("full");
        assert!(
            matches!(err, BrickError::AtlasFull { bricks: 576, .. }),
            "{err}"
        );
        assert!(BrickLayout::new([32 * 8; 3], 32, 8 * 34).is_ok());
    }

    #[test]
    fn page_entries_round_trip_their_slots_and_levels() {
        for slot in [[0, 0, 0], [510, 3, 77], [511, 511, 511]] {
            for level in [0, 1, 7, 15] {
                let e = BrickLayout::page_entry(slot, level);
                assert_eq!(BrickLayout::decode_entry(e), (slot, level));
                assert_eq!(e & (1 << 31), 0, "bit 31 marks constants");
            }
        }
    }
}
