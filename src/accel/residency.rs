//! Which bricks of which levels the atlas holds (the Residency Octree's idea on our page table):
//! a fixed number of slots, the coarsest level (one brick) always resident, and for the rest the
//! finest level whose wanted bricks fit, or the coarser one a brick's footprint on screen needs.
//! A brick of level 0 that the frame cannot see (empty under the transfer function, and not
//! beside one that is not) is served by a constant instead of data, so it costs no slot, no
//! upload and no sample; every other brick of level 0 reads the finest resident level among its
//! ancestors, so a brick still on its way shows a coarser one, never a hole. Slots not wanted
//! for the longest time are given first (least recently used).
//!
//! Pure bookkeeping: what to upload where, and the page tables that follow. The GPU side is
//! `render::volume_texture`.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;
use rustc_hash::{FxHashMap, FxHashSet};

use super::bricks::{BrickLayout, level_count, level_dims};

/// A brick of one level: its level and its coordinates in that level's brick grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BrickKey {
    /// The level (0: full resolution).
    pub level: u32,
    /// Brick coordinates within the level.
    pub brick: [u32; 3],
}

/// Levels coarser than the wanted one that a preview streams first (each brick of it stands for
/// 64 of the wanted level's).
const PREVIEW_LEVELS: u32 = 2;

/// In [`Residency::decide_levels`]'s levels: a brick of level 0 whose data the rays do not need.
pub const NOT_NEEDED: u8 = u8::MAX;

/// Levels that want each brick `marked` marks at level 0, and no other.
pub fn at_level_0(marked: &[bool]) -> Vec<u8> {
    (marked.iter())
        .map(|&m| if m { 0 } else { NOT_NEEDED })
        .collect()
}

/// Page-table bit of an entry that holds a constant instead of a slot.
pub const CONSTANT: u32 = 1 << 31;
/// Page-table bit of a constant entry whose low 16 bits are an f16 (else a unorm16).
pub const CONSTANT_F16: u32 = 1 << 30;

/// The bricks a frame wants resident.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Wanted {
    /// The level the data bricks are wanted at (0: full resolution).
    pub level: u32,
    /// The finest level at which every brick the rays need fits the atlas: `level` is coarser
    /// than this where the footprints on screen ask for no finer.
    pub fits: u32,
    /// The bricks, coarsest level first.
    pub bricks: Vec<BrickKey>,
    /// Per brick of level 0 (x fastest): whether the rays read its constant, not data.
    pub constant: Vec<bool>,
}

/// The atlas's slots and what each holds.
#[derive(Clone, Debug)]
pub struct Residency {
    dims: [u32; 3],
    brick_vox: u32,
    levels: u32,
    slots: [u32; 3],
    capacity: u32,
    resident: FxHashMap<BrickKey, u32>,
    held: Vec<Option<BrickKey>>,
    last_wanted: Vec<u64>,
    frame: u64,
    /// Bricks admitted or evicted since the page tables were last refreshed.
    dirty: Vec<BrickKey>,
    /// The slots this frame may give, in the order it gives them, from the first admission
    /// after [`Self::want`] on (what is given meanwhile is wanted: the rest keep their order).
    givable: Option<std::vec::IntoIter<u32>>,
}

impl Residency {
    /// The slots of an atlas of `slots` per axis, `capacity` of them used, for a volume of
    /// `dims` in bricks of `brick_vox`; nothing resident.
    pub fn new(dims: [u32; 3], brick_vox: u32, slots: [u32; 3], capacity: u32) -> Self {
        let capacity = capacity.clamp(1, slots.iter().product());
        Self {
            dims,
            brick_vox,
            levels: level_count(dims, brick_vox).min(super::bricks::MAX_LEVELS),
            slots,
            capacity,
            resident: FxHashMap::default(),
            held: vec![None; capacity as usize],
            last_wanted: vec![0; capacity as usize],
            frame: 0,
            dirty: Vec::new(),
            givable: None,
        }
    }

    /// Bricks per axis of `level`.
    pub fn grid(&self, level: u32) -> [u32; 3] {
        level_dims(self.dims, level).map(|d| d.div_ceil(self.brick_vox))
    }

    /// Number of levels (the last is one brick).
    pub fn levels(&self) -> u32 {
        self.levels
    }

    /// Slots the atlas gives.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Bricks resident now.
    pub fn resident_count(&self) -> usize {
        self.resident.len()
    }

    /// Whether `key` is resident.
    pub fn is_resident(&self, key: &BrickKey) -> bool {
        self.resident.contains_key(key)
    }

    /// Every slot holding a brick, and which.
    pub fn held_slots(&self) -> impl Iterator<Item = (u32, BrickKey)> + '_ {
        (self.held.iter().enumerate()).filter_map(|(s, k)| k.map(|k| (s as u32, k)))
    }

    /// Whether every brick of level 0 fits beside the coarsest (then all are held, whatever
    /// the view).
    pub fn holds_everything(&self) -> bool {
        self.page_count() as u64 + u64::from(self.levels > 1) <= u64::from(self.capacity)
    }

    /// Bricks of level 0.
    pub fn page_count(&self) -> usize {
        self.grid(0).iter().map(|&b| b as usize).product()
    }

    fn coarsest(&self) -> BrickKey {
        BrickKey {
            level: self.levels - 1,
            brick: [0; 3],
        }
    }

    /// What to hold, given which bricks of level 0 the rays need the data of (`needs_data`,
    /// x fastest; the others are served by a constant) and which others the slices show
    /// (`also`; empty for none): every brick of level 0 where they all fit beside the coarsest
    /// (no constants then: the slices and any later transfer function find their data there);
    /// else the coarsest and, at the finest level whose bricks fit, the ancestors of the bricks
    /// the rays need; then, where they fit, the same bricks' ancestors two levels coarser (a
    /// preview that streams first); then the slices' bricks at that level, or the finest coarser
    /// one that still fits beside them (the rays' level is never given up for the slices').
    pub fn decide(&self, needs_data: &[bool], also: &[bool]) -> Wanted {
        self.decide_levels(&at_level_0(needs_data), also)
    }

    /// [`Self::decide`], each brick of level 0 that the rays need wanted no finer than `finest`
    /// says (x fastest; the level its footprint on screen needs, a voxel about a pixel, or
    /// [`NOT_NEEDED`]): each at the finest level at which all fit, or the coarser one it needs;
    /// `Wanted::level` is then the finest level any brick is wanted at.
    pub fn decide_levels(&self, finest: &[u8], also: &[bool]) -> Wanted {
        let pages = self.grid(0);
        let coarsest = self.coarsest();
        let all = self.page_count() as u64;
        if self.holds_everything() {
            let mut bricks = vec![coarsest];
            if self.levels > 1 {
                bricks.extend(grid_keys(pages, 0));
            }
            return Wanted {
                level: 0,
                fits: 0,
                bricks,
                constant: vec![false; all as usize],
            };
        }
        let constant: Vec<bool> = finest.iter().map(|&f| f == NOT_NEEDED).collect();
        let capacity = self.capacity as usize;
        for level in 0..self.levels {
            let mut bricks = vec![coarsest];
            bricks.extend(self.ancestors_at(finest, level).filter(|k| *k != coarsest));
            if bricks.len() > capacity {
                continue;
            }
            let mut held: FxHashSet<BrickKey> = bricks.iter().copied().collect();
            // A preview two levels coarser, where it fits, streams first: the coarsest alone
            // (a mean over the whole volume's bricks) hides thin structures while the rest comes.
            let preview_level = level + PREVIEW_LEVELS;
            if preview_level + 1 < self.levels {
                let preview: Vec<BrickKey> = self
                    .ancestors_at(finest, preview_level)
                    .filter(|k| !held.contains(k))
                    .collect();
                if bricks.len() + preview.len() <= capacity {
                    held.extend(preview.iter().copied());
                    bricks.splice(1..1, preview);
                }
            }
            if also.iter().any(|a| *a) {
                let also = at_level_0(also);
                for coarser in level..self.levels {
                    let more: Vec<BrickKey> = self
                        .ancestors_at(&also, coarser)
                        .filter(|k| !held.contains(k))
                        .collect();
                    if bricks.len() + more.len() <= capacity {
                        bricks.extend(more);
                        break;
                    }
                }
            }
            // Where footprints ask for coarser levels than fit, the finest actually wanted.
            let finest_wanted = bricks[1..].iter().map(|k| k.level).min().unwrap_or(level);
            return Wanted {
                level: finest_wanted.max(level),
                fits: level,
                bricks,
                constant,
            };
        }
        // The coarsest alone always fits one slot.
        Wanted {
            level: self.levels - 1,
            fits: self.levels - 1,
            bricks: vec![coarsest],
            constant,
        }
    }

    /// The distinct ancestors of the bricks of level 0 that `finest` wants, each at its level
    /// there or at `level` where that is coarser: coarser levels first, each in brick order.
    /// On all cores, a plane of bricks per task: a frame of an orbit decides again wherever a
    /// brick's footprint crosses a level, and 131 072 bricks took 0.6 ms a pass on one core.
    fn ancestors_at(&self, finest: &[u8], level: u32) -> impl Iterator<Item = BrickKey> {
        let last = self.levels - 1;
        let grids: Vec<[u32; 3]> = (0..self.levels).map(|l| self.grid(l)).collect();
        let marks: Vec<Vec<AtomicBool>> = (grids.iter())
            .map(|g| {
                (0..g.iter().map(|&v| v as usize).product::<usize>())
                    .map(|_| AtomicBool::new(false))
                    .collect()
            })
            .collect();
        let pages = grids[0];
        let plane = (pages[0] * pages[1]) as usize;
        finest
            .par_chunks(plane.max(1))
            .enumerate()
            .for_each(|(z, wants)| {
                let z = z as u32;
                for (i, &f) in wants.iter().enumerate() {
                    if f == NOT_NEEDED {
                        continue;
                    }
                    let (x, y) = (i as u32 % pages[0], i as u32 / pages[0]);
                    let l = u32::from(f).max(level).min(last);
                    let g = grids[l as usize];
                    let (bx, by, bz) = (x >> l, y >> l, z >> l);
                    marks[l as usize][(bx + g[0] * (by + g[1] * bz)) as usize]
                        .store(true, Ordering::Relaxed);
                }
            });
        let keys: Vec<Vec<BrickKey>> = (0..self.levels)
            .rev()
            .map(|l| {
                let g = grids[l as usize];
                (marks[l as usize].par_iter())
                    .enumerate()
                    .filter(|(_, m)| m.load(Ordering::Relaxed))
                    .map(|(i, _)| BrickKey {
                        level: l,
                        brick: index_to_brick(i as u32, g),
                    })
                    .collect()
            })
            .collect();
        keys.into_iter().flatten()
    }

    /// How many of `wanted` are not resident.
    pub fn missing(&self, wanted: &Wanted) -> usize {
        wanted
            .bricks
            .iter()
            .filter(|k| !self.resident.contains_key(k))
            .count()
    }

    /// Starts a frame wanting `wanted`: its resident bricks are marked used now, so no admission
    /// of this frame gives their slots away.
    pub fn want(&mut self, wanted: &Wanted) {
        self.frame += 1;
        self.givable = None;
        for key in &wanted.bricks {
            if let Some(&slot) = self.resident.get(key) {
                self.last_wanted[slot as usize] = self.frame;
            }
        }
    }

    /// Gives slots to at most `limit` of `bricks` that are not resident, in their order (a
    /// frame's wanted bricks, or those of them missing), taking free slots first and then those
    /// wanted least recently (never one wanted by this frame); returns each brick with its slot
    /// index, for the caller to upload.
    pub fn admit(&mut self, bricks: &[BrickKey], limit: usize) -> Vec<(BrickKey, u32)> {
        let missing: Vec<BrickKey> = bricks
            .iter()
            .filter(|k| !self.resident.contains_key(k))
            .take(limit)
            .copied()
            .collect();
        if missing.is_empty() {
            return Vec::new();
        }
        // Free slots first, then the least recently wanted; none this frame wants. Sorted once
        // a frame: a frame admits a batch at a time, and the atlas may have 10⁵ slots.
        let givable = self.givable.get_or_insert_with(|| {
            let mut order: Vec<u32> = (0..self.capacity)
                .filter(|&s| {
                    self.last_wanted[s as usize] < self.frame || self.held[s as usize].is_none()
                })
                .collect();
            order.sort_by_key(|&s| {
                (
                    self.held[s as usize].is_some(),
                    self.last_wanted[s as usize],
                )
            });
            order.into_iter()
        });
        let mut given = Vec::with_capacity(missing.len());
        for (key, slot) in missing.into_iter().zip(givable.by_ref()) {
            if let Some(old) = self.held[slot as usize].take() {
                self.resident.remove(&old);
                self.dirty.push(old);
            }
            self.dirty.push(key);
            self.held[slot as usize] = Some(key);
            self.last_wanted[slot as usize] = self.frame;
            self.resident.insert(key, slot);
            given.push((key, slot));
        }
        given
    }

    /// Slot `index`'s coordinates in the atlas.
    pub fn slot_coords(&self, index: u32) -> [u32; 3] {
        let [sx, sy, _] = self.slots;
        [index % sx, (index / sx) % sy, index / (sx * sy)]
    }

    /// The finest resident level holding each brick of level 0 (x fastest), with its slot:
    /// every level's answer from the one above it, coarsest first, over dense grids filled
    /// from the resident bricks (no lookup per brick and level: 2048 × 2048 × 1024 has 131 072
    /// bricks and eight levels).
    fn finest_resident_all(&self) -> Vec<Option<(u32, u32)>> {
        let grids: Vec<[u32; 3]> = (0..self.levels).map(|l| self.grid(l)).collect();
        let count = |g: &[u32; 3]| g.iter().map(|&v| v as usize).product::<usize>();
        let mut own: Vec<Vec<Option<u32>>> = grids.iter().map(|g| vec![None; count(g)]).collect();
        for (key, &slot) in &self.resident {
            let g = grids[key.level as usize];
            let [x, y, z] = key.brick;
            own[key.level as usize][(x + g[0] * (y + g[1] * z)) as usize] = Some(slot);
        }
        let mut above: Vec<Option<(u32, u32)>> = Vec::new();
        for level in (0..self.levels).rev() {
            let g = grids[level as usize];
            let up = grids.get(level as usize + 1).copied().unwrap_or([1; 3]);
            let own = &own[level as usize];
            let finest = |i: usize| {
                own[i].map(|s| (level, s)).or_else(|| {
                    let [x, y, z] = index_to_brick(i as u32, g).map(|c| c >> 1);
                    above
                        .get((x + up[0] * (y + up[1] * z)) as usize)
                        .copied()
                        .flatten()
                })
            };
            above = (0..count(&g)).into_par_iter().map(finest).collect();
        }
        above
    }

    /// Brick `i` of level 0's (rays', slices') entries, its finest resident ancestor being
    /// `finest` (level, slot).
    fn entries_of(
        &self,
        i: usize,
        finest: Option<(u32, u32)>,
        wanted: &Wanted,
        constants: &[Option<u32>],
    ) -> (u32, u32) {
        let entry = finest
            .map(|(level, slot)| BrickLayout::page_entry(self.slot_coords(slot), level))
            .unwrap_or(0);
        let constant = wanted.constant.get(i).copied().unwrap_or(false);
        match constants.get(i).copied().flatten().filter(|_| constant) {
            Some(c) => (CONSTANT | c, entry),
            None => (entry, entry),
        }
    }

    /// The finest resident level holding brick `b` of level 0, with its slot.
    fn finest_resident(&self, b: [u32; 3]) -> Option<(u32, u32)> {
        (0..self.levels).find_map(|level| {
            let key = BrickKey {
                level,
                brick: b.map(|c| c >> level),
            };
            self.resident.get(&key).map(|&slot| (level, slot))
        })
    }

    /// Brings `tables`, the page tables of this residency as it stood at their last refresh
    /// with `before` as the constant flags, up to `wanted` (and `constants`, as then): only the
    /// bricks of level 0 under a brick admitted or evicted since, or whose flag changed, are
    /// looked at again, or the whole table where they are more than a quarter of it (a
    /// 2048 × 2048 × 1024 volume's tables have 131 072 entries; a frame while bricks stream
    /// changes some hundreds).
    pub fn refresh_page_tables(
        &mut self,
        tables: &mut PageTables,
        before: &[bool],
        wanted: &Wanted,
        constants: &[Option<u32>],
    ) -> Refreshed {
        let dirty = std::mem::take(&mut self.dirty);
        let n = self.page_count();
        let whole = |r: &Self, tables: &mut PageTables| {
            let new = r.page_tables(wanted, constants);
            let rays_changed = (tables.rays.len() == n).then(|| {
                (tables.rays.iter().zip(&new.rays).enumerate())
                    .filter(|(_, (a, b))| a != b)
                    .map(|(i, _)| i)
                    .collect()
            });
            *tables = new;
            Refreshed {
                looked_at: None,
                rays_changed,
            }
        };
        if before.len() != wanted.constant.len() || tables.rays.len() != n {
            return whole(self, tables);
        }
        let grid = self.grid(0);
        let mut marked = vec![false; n];
        let mut touched: Vec<usize> = (before.iter().zip(&wanted.constant).enumerate())
            .filter(|(_, (a, b))| a != b)
            .map(|(i, _)| i)
            .collect();
        // A lookup per level and entry costs more than the whole table's dense pass past this.
        if touched.len() > n / 4 {
            return whole(self, tables);
        }
        for &i in &touched {
            marked[i] = true;
        }
        for key in dirty {
            let l = key.level;
            let lo = key.brick.map(|c| c << l);
            let hi: [u32; 3] = std::array::from_fn(|a| ((key.brick[a] + 1) << l).min(grid[a]));
            let count: usize = (0..3)
                .map(|a| hi[a].saturating_sub(lo[a]) as usize)
                .product();
            if touched.len() + count > n / 4 {
                return whole(self, tables);
            }
            for z in lo[2]..hi[2] {
                for y in lo[1]..hi[1] {
                    for x in lo[0]..hi[0] {
                        let i = (x + grid[0] * (y + grid[1] * z)) as usize;
                        if !marked[i] {
                            marked[i] = true;
                            touched.push(i);
                        }
                    }
                }
            }
        }
        touched.sort_unstable();
        let mut rays_changed = Vec::new();
        for &i in &touched {
            let finest = self.finest_resident(index_to_brick(i as u32, grid));
            let (ray, slice) = self.entries_of(i, finest, wanted, constants);
            if ray != tables.rays[i] {
                rays_changed.push(i);
            }
            (tables.rays[i], tables.slices[i]) = (ray, slice);
        }
        tables.levels = levels_read(&tables.rays);
        Refreshed {
            looked_at: Some(touched),
            rays_changed: Some(rays_changed),
        }
    }

    /// The page tables (x fastest, one entry per brick of level 0): the rays' (a constant where
    /// `wanted` says so and `constants` has one, else the finest resident ancestor) and the
    /// slices' (always the finest resident ancestor: slices show data, never a constant), and
    /// the levels the rays' entries read (bit `k` for level `k`).
    pub fn page_tables(&self, wanted: &Wanted, constants: &[Option<u32>]) -> PageTables {
        let (rays, slices): (Vec<u32>, Vec<u32>) = (self.finest_resident_all().into_par_iter())
            .enumerate()
            .map(|(i, finest)| self.entries_of(i, finest, wanted, constants))
            .unzip();
        PageTables {
            levels: levels_read(&rays),
            rays,
            slices,
        }
    }
}

/// The page tables a frame binds.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PageTables {
    /// The rays' table.
    pub rays: Vec<u32>,
    /// The slices' table.
    pub slices: Vec<u32>,
    /// Levels the rays read data from (bit `k` for level `k`).
    pub levels: u32,
}

/// What [`Residency::refresh_page_tables`] did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refreshed {
    /// The entries it looked at again, ascending (`None`: it rebuilt the tables whole).
    pub looked_at: Option<Vec<usize>>,
    /// The entries of the rays' table that changed (`None`: the tables were new).
    pub rays_changed: Option<Vec<usize>>,
}

/// The levels a rays' page table reads data from (bit `k` for level `k`).
fn levels_read(rays: &[u32]) -> u32 {
    (rays.iter())
        .filter(|&&e| e & CONSTANT == 0)
        .fold(0, |levels, &e| levels | 1 << BrickLayout::decode_entry(e).1)
}

/// Brick `index` (x fastest) of a grid of `grid` bricks per axis.
pub(crate) fn index_to_brick(index: u32, grid: [u32; 3]) -> [u32; 3] {
    [
        index % grid[0],
        (index / grid[0]) % grid[1],
        index / (grid[0] * grid[1]),
    ]
}

/// Every brick of a `grid` at `level`, x fastest.
fn grid_keys(grid: [u32; 3], level: u32) -> impl Iterator<Item = BrickKey> {
    let n = grid.iter().product::<u32>();
    (0..n).map(move |i| BrickKey {
        level,
        brick: index_to_brick(i, grid),
    })
}

/// `marked` (x fastest over a grid of `grid`) grown by one brick in every direction, diagonals
/// included: the bricks whose data a sample of a marked brick can reach (its trilinear apron,
/// a gradient, a pre-integrated segment).
pub fn dilate(marked: &[bool], grid: [u32; 3]) -> Vec<bool> {
    let mut out = marked.to_vec();
    let g = grid.map(i64::from);
    for (i, _) in marked.iter().enumerate().filter(|(_, m)| **m) {
        let b = index_to_brick(i as u32, grid).map(i64::from);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let n = [b[0] + dx, b[1] + dy, b[2] + dz];
                    if (0..3).all(|a| (0..g[a]).contains(&n[a])) {
                        out[(n[0] + g[0] * (n[1] + g[1] * n[2])) as usize] = true;
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A volume of 4 × 2 × 1 bricks of 8³ (levels: 4×2×1, 2×1×1, 1×1×1).
    /// A seeded coin of `n` sides (an LCG): random residencies that repeat.
    fn coin(mut seed: u64) -> impl FnMut(u64) -> u64 {
        move |n| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 33) % n
        }
    }

    fn residency(capacity: u32) -> Residency {
        Residency::new([32, 16, 8], 8, [4, 4, 4], capacity)
    }

    #[test]
    fn a_volume_that_fits_is_held_whole_without_constants() {
        let r = residency(9);
        let wanted = r.decide(&[false; 8], &[]);
        assert_eq!(wanted.level, 0);
        assert_eq!(wanted.bricks.len(), 9);
        assert!(wanted.constant.iter().all(|c| !c));
        assert_eq!(wanted.bricks[0].level, 2);
    }

    #[test]
    fn each_brick_is_held_no_finer_than_its_footprint_needs_and_coarser_where_all_do_not_fit() {
        // 8 × 8 × 4 bricks of 8 voxels: levels of 8, 4, 2 and 1 brick per axis (x).
        let r = Residency::new([64, 64, 32], 8, [8, 8, 8], 40);
        let key = |level, brick| BrickKey { level, brick };
        let mut finest = vec![NOT_NEEDED; 256];
        // The near bricks (x < 2, y < 2, z = 0) at level 0, the far half (x ≥ 4) at level 1.
        for y in 0..2 {
            for x in 0..2 {
                finest[x + 8 * y] = 0;
            }
        }
        for z in 0..4 {
            for y in 0..8 {
                for x in 4..8 {
                    finest[x + 8 * (y + 8 * z)] = 1;
                }
            }
        }
        let wanted = r.decide_levels(&finest, &[]);
        assert_eq!(wanted.level, 0);
        let at = |l: u32| wanted.bricks.iter().filter(|k| k.level == l).count();
        // The coarsest; the preview, two levels coarser than level 0 (level 2: the near four's
        // one brick and the far half's two); the far half's 4 × 8 × 4 at level 1 (2 × 4 × 2);
        // the near four at level 0.
        assert_eq!((at(3), at(2), at(1), at(0)), (1, 3, 16, 4));
        assert!(wanted.bricks.contains(&key(0, [1, 1, 0])));
        assert!(wanted.bricks.contains(&key(1, [3, 3, 1])));
        assert!(
            !wanted
                .bricks
                .iter()
                .any(|k| k.level == 0 && k.brick[0] >= 4)
        );
        // With 12 slots the far half does not fit at level 1: all go one level coarser.
        let tight = Residency::new([64, 64, 32], 8, [8, 8, 8], 12).decide_levels(&finest, &[]);
        assert_eq!(tight.level, 2);
        assert!(tight.bricks.iter().all(|k| k.level >= 2));
        assert_eq!(
            tight.fits, 2,
            "the budget, not the footprints, chose level 2"
        );
        // Where only the far half is needed, the footprints alone ask for level 1: it fits at 0.
        let far: Vec<u8> = (finest.iter())
            .map(|&f| if f == 1 { 1 } else { NOT_NEEDED })
            .collect();
        let by_footprint = r.decide_levels(&far, &[]);
        assert_eq!((by_footprint.level, by_footprint.fits), (1, 0));
        // Footprints of level 0 everywhere decide as `decide` does.
        let everywhere: Vec<bool> = finest.iter().map(|&f| f != NOT_NEEDED).collect();
        let zero: Vec<u8> = (finest.iter())
            .map(|&f| if f == NOT_NEEDED { f } else { 0 })
            .collect();
        assert_eq!(r.decide(&everywhere, &[]), r.decide_levels(&zero, &[]));
    }

    #[test]
    fn over_capacity_only_bricks_that_need_data_are_held_at_the_finest_level_that_fits() {
        let mut needs = [false; 8];
        needs[0] = true;
        needs[5] = true;
        // Capacity 3: the coarsest and both level-0 bricks.
        let r = residency(3);
        let wanted = r.decide(&needs, &[]);
        assert_eq!(wanted.level, 0);
        assert_eq!(
            wanted.bricks,
            vec![
                BrickKey {
                    level: 2,
                    brick: [0; 3]
                },
                BrickKey {
                    level: 0,
                    brick: [0, 0, 0]
                },
                BrickKey {
                    level: 0,
                    brick: [1, 1, 0]
                },
            ]
        );
        assert_eq!(wanted.constant.iter().filter(|c| **c).count(), 6);
        // Capacity 2: bricks 0 and 5 have one ancestor at level 1 ([0, 0, 0]).
        let wanted = residency(2).decide(&needs, &[]);
        assert_eq!(wanted.level, 1);
        assert_eq!(wanted.bricks.len(), 2);
        // Capacity 1: the coarsest alone.
        let wanted = residency(1).decide(&needs, &[]);
        assert_eq!(wanted.level, 2);
        assert_eq!(wanted.bricks.len(), 1);
    }

    #[test]
    fn a_missing_brick_reads_its_finest_resident_ancestor_and_the_least_recently_wanted_go_first() {
        let mut r = residency(3);
        // Nothing needs data: the coarsest alone.
        let coarse = r.decide(&[false; 8], &[]);
        assert_eq!(
            coarse.bricks,
            vec![BrickKey {
                level: 2,
                brick: [0; 3]
            }]
        );
        r.want(&coarse);
        assert_eq!(r.admit(&coarse.bricks, usize::MAX).len(), 1);
        // Brick 5 needs data: it is admitted one at a time; until then it reads level 2.
        let mut needs = [false; 8];
        needs[5] = true;
        needs[6] = true;
        let fine = r.decide(&needs, &[]);
        assert_eq!(fine.level, 0);
        r.want(&fine);
        let constants: Vec<Option<u32>> = (0..8).map(Some).collect();
        let before = r.page_tables(&fine, &constants);
        assert_eq!(BrickLayout::decode_entry(before.rays[5]).1, 2);
        assert_eq!(before.rays[0], CONSTANT);
        assert_eq!(BrickLayout::decode_entry(before.slices[0]).1, 2);
        assert_eq!(before.levels, 1 << 2);
        let first = r.admit(&fine.bricks, 1);
        assert_eq!(first.len(), 1);
        let after = r.page_tables(&fine, &constants);
        assert_eq!(BrickLayout::decode_entry(after.rays[5]).1, 0);
        assert_eq!(r.missing(&fine), 1);
        r.admit(&fine.bricks, usize::MAX);
        assert_eq!(r.missing(&fine), 0);
        // Another frame wants bricks 1 and 2: the slots of 5 and 6 (unwanted now) are reused,
        // the coarsest (wanted by every frame) stays.
        let mut needs = [false; 8];
        needs[1] = true;
        needs[2] = true;
        let other = r.decide(&needs, &[]);
        r.want(&other);
        let given = r.admit(&other.bricks, usize::MAX);
        assert_eq!(given.len(), 2);
        assert!(r.is_resident(&BrickKey {
            level: 2,
            brick: [0; 3]
        }));
        assert!(!r.is_resident(&BrickKey {
            level: 0,
            brick: [1, 1, 0]
        }));
        assert_eq!(r.resident_count(), 3);
    }

    #[test]
    fn every_page_reads_its_finest_resident_ancestor_as_a_search_level_by_level_finds() {
        // An uneven grid (odd bricks per axis) and bricks of every level resident at random.
        let mut r = Residency::new([200, 130, 70], 16, [64, 64, 64], 4096);
        let mut coin = coin(7);
        let bricks: Vec<BrickKey> = (0..r.levels())
            .rev()
            .flat_map(|level| grid_keys(r.grid(level), level).collect::<Vec<_>>())
            .filter(|k| k.level + 1 == r.levels() || coin(3) == 0)
            .collect();
        let wanted = Wanted {
            level: 0,
            fits: 0,
            bricks,
            constant: vec![false; r.page_count()],
        };
        r.want(&wanted);
        r.admit(&wanted.bricks, usize::MAX);
        let tables = r.page_tables(&wanted, &[]);
        for (i, &entry) in tables.slices.iter().enumerate() {
            let b = index_to_brick(i as u32, r.grid(0));
            let (level, slot) = (0..r.levels())
                .find_map(|level| {
                    let key = BrickKey {
                        level,
                        brick: b.map(|c| c >> level),
                    };
                    r.resident.get(&key).map(|&s| (level, s))
                })
                .expect("the coarsest brick is resident");
            assert_eq!(
                entry,
                BrickLayout::page_entry(r.slot_coords(slot), level),
                "brick {b:?}"
            );
        }
    }

    #[test]
    fn refreshed_page_tables_equal_tables_made_whole_as_bricks_come_and_go() {
        // Capacity for a fraction of the bricks: admissions evict, flags change between frames.
        let mut r = Residency::new([200, 130, 70], 16, [8, 8, 8], 60);
        let mut coin = coin(11);
        let n = r.page_count();
        let constants: Vec<Option<u32>> = (0..n as u32).map(|i| Some(i % 7)).collect();
        let mut tables = PageTables::default();
        let mut before: Vec<bool> = Vec::new();
        let mut partial = 0;
        let mut needs: Vec<bool> = (0..n).map(|_| coin(4) == 0).collect();
        for frame in 0..40 {
            // Some flags change each frame (past a quarter of them the table is made whole).
            for need in needs.iter_mut() {
                *need ^= coin(20) == 0;
            }
            let wanted = r.decide(&needs, &[]);
            r.want(&wanted);
            r.admit(&wanted.bricks, 1 + coin(20) as usize);
            let old = tables.rays.clone();
            let refreshed = r.refresh_page_tables(&mut tables, &before, &wanted, &constants);
            partial += usize::from(refreshed.looked_at.is_some());
            before.clone_from(&wanted.constant);
            assert_eq!(tables, r.page_tables(&wanted, &constants), "frame {frame}");
            let differ: Vec<usize> = (0..n)
                .filter(|&i| old.get(i) != Some(&tables.rays[i]))
                .collect();
            let mut changed = refreshed.rays_changed.unwrap_or_else(|| (0..n).collect());
            changed.sort_unstable();
            assert_eq!(changed, differ, "frame {frame}");
        }
        assert!(partial > 20, "{partial} of 40 refreshes were partial");
    }

    #[test]
    fn least_recently_wanted_is_evicted_before_more_recent() {
        // Capacity 4: the coarsest and three bricks; frames want {0,1,2}, then {3}, then {4}.
        let mut r = residency(4);
        let want = |r: &mut Residency, bricks: &[usize]| {
            let mut needs = [false; 8];
            bricks.iter().for_each(|&b| needs[b] = true);
            let w = r.decide(&needs, &[]);
            assert_eq!(w.level, 0);
            r.want(&w);
            r.admit(&w.bricks, usize::MAX);
        };
        want(&mut r, &[0, 1, 2]);
        want(&mut r, &[1, 2]);
        want(&mut r, &[3]);
        // Brick 0 was wanted least recently: it went for brick 3.
        let key = |b: [u32; 3]| BrickKey { level: 0, brick: b };
        assert!(!r.is_resident(&key([0, 0, 0])));
        assert!(r.is_resident(&key([1, 0, 0])) && r.is_resident(&key([2, 0, 0])));
        assert!(r.is_resident(&key([3, 0, 0])));
    }

    #[test]
    fn dilation_reaches_every_neighbour_and_stays_inside() {
        let grid = [3, 3, 2];
        let mut marked = vec![false; 18];
        marked[0] = true;
        let grown = dilate(&marked, grid);
        let expect: Vec<usize> = vec![0, 1, 3, 4, 9, 10, 12, 13];
        let got: Vec<usize> = (0..18).filter(|&i| grown[i]).collect();
        assert_eq!(got, expect);
    }

    #[test]
    fn the_finest_level_whose_bricks_and_the_coarsest_fit_is_chosen() {
        // 300 × 200 × 100 in 32³: 10 × 7 × 4 = 280 bricks at level 0, 5 × 4 × 2 = 40 at 1,
        // 3 × 2 × 1 = 6 at 2, 2 × 1 × 1 at 3, 1 at 4 (the coarsest).
        let dims = [300, 200, 100];
        assert_eq!(level_count(dims, 32), 5);
        for (capacity, level) in [
            (281, 0),
            (280, 1),
            (41, 1),
            (40, 2),
            (7, 2),
            (6, 3),
            (3, 3),
            (2, 4),
        ] {
            let r = Residency::new(dims, 32, [20, 20, 20], capacity);
            let wanted = r.decide(&[true; 280], &[]);
            assert_eq!(wanted.level, level, "{capacity} slots");
            assert!(wanted.bricks.len() <= capacity as usize);
        }
    }

    #[test]
    fn a_coarser_levels_pages_send_each_brick_to_its_ancestors_slot() {
        let dims = [300, 200, 100];
        let mut r = Residency::new(dims, 32, [4, 4, 4], 7);
        let wanted = r.decide(&[true; 280], &[]);
        assert_eq!(wanted.level, 2);
        r.want(&wanted);
        let given = r.admit(&wanted.bricks, usize::MAX);
        assert_eq!(given.len(), 7);
        let tables = r.page_tables(&wanted, &[]);
        assert_eq!(tables.rays, tables.slices);
        assert_eq!(tables.levels, 1 << 2);
        let pages = r.grid(0);
        for (i, &e) in tables.rays.iter().enumerate() {
            let b = index_to_brick(i as u32, pages);
            let key = BrickKey {
                level: 2,
                brick: b.map(|v| v >> 2),
            };
            let slot = given.iter().find(|(k, _)| *k == key).map(|(_, s)| *s);
            let (at, level) = BrickLayout::decode_entry(e);
            assert_eq!(level, 2);
            assert_eq!(Some(at), slot.map(|s| r.slot_coords(s)), "{b:?}");
        }
    }

    #[test]
    fn the_slices_bricks_come_at_the_rays_level_where_they_fit_else_coarser() {
        // 4 × 2 × 1 bricks: the rays need brick 0, the slices bricks 3 and 7.
        let mut needs = [false; 8];
        needs[0] = true;
        let mut also = [false; 8];
        also[3] = true;
        also[7] = true;
        let full = Residency::new([32, 16, 8], 8, [4, 4, 4], 4).decide(&needs, &also);
        assert_eq!(full.level, 0);
        assert_eq!(full.bricks.len(), 4);
        assert!(
            full.constant[3] && full.constant[7],
            "the rays still read constants there"
        );
        // Capacity 3: the slices' two bricks do not fit beside the rays' at level 0; their
        // ancestor at level 1 ([1, 0, 0]) does.
        let tight = Residency::new([32, 16, 8], 8, [4, 4, 4], 3).decide(&needs, &also);
        assert_eq!(tight.level, 0);
        assert_eq!(
            tight.bricks[2..],
            [BrickKey {
                level: 1,
                brick: [1, 0, 0]
            }]
        );
    }

    #[test]
    fn a_preview_two_levels_coarser_streams_first_where_it_fits() {
        // 300 × 200 × 100 in 32³ (levels 0…4): the rays need one brick of level 0; its ancestor
        // at level 2 comes right after the coarsest.
        let mut needs = [false; 280];
        needs[0] = true;
        let r = Residency::new([300, 200, 100], 32, [4, 4, 4], 3);
        let wanted = r.decide(&needs, &[]);
        assert_eq!(
            wanted.bricks,
            vec![
                BrickKey {
                    level: 4,
                    brick: [0; 3]
                },
                BrickKey {
                    level: 2,
                    brick: [0; 3]
                },
                BrickKey {
                    level: 0,
                    brick: [0; 3]
                },
            ]
        );
        // No room: no preview.
        let wanted = Residency::new([300, 200, 100], 32, [4, 4, 4], 2).decide(&needs, &[]);
        assert_eq!(wanted.bricks.len(), 2);
        assert_eq!(wanted.level, 0);
    }
}
