//! An OME-Zarr image read box by box as the GPU's bricks ask ([`BrickSource`]): a box of
//! LeapView's level `k` comes from the coarsest store level that is no coarser along any axis,
//! halved along each axis as often as that level is finer (a store written by `leapview
//! convert` holds every level as LeapView halves it, so nothing is halved). Decoded tiles (a
//! shard's inner chunks, else chunks) are kept in a [`Cache`] of bounded bytes.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use zarrs::array::{ArrayShardedReadableExt, ArrayShardedReadableExtCache, CodecOptions};

use super::read::{Selection, ZarrArray, fill_value, subset_of, tile_shape};
use crate::volume::downsample::{halve_axes, halved_dims, level_dims};
use crate::volume::error::VolumeError;
use crate::volume::error::zarr::ZarrError;
use crate::volume::samples::{Samples, ScalarType};
use crate::volume::streamed::BrickSource;
use crate::volume::tiles::{Cache, Tile, copy_overlap, empty};

/// One level of the store as the source reads it.
struct StoreLevel {
    array: ZarrArray,
    /// Its voxels along x, y, z.
    dims: [u32; 3],
    /// How many times each axis (x, y, z) of level 0 was halved to make it.
    halvings: [u32; 3],
    /// Its tiles' voxels along x, y, z.
    tile: [u32; 3],
    /// zarrs' shard indexes, read once a shard (emptied past [`MOST_SHARD_INDEXES`]).
    shards: ArrayShardedReadableExtCache,
}

/// Shard indexes kept per level at most: a 256³ shard of 32³ chunks has an index of 8 KiB, so
/// 32 MiB at most.
const MOST_SHARD_INDEXES: usize = 4096;

/// Which tile: the store level and its index along x, y, z.
type TileKey = (usize, [u32; 3]);

/// An OME-Zarr image's time point and channel, read a box at a time.
pub(super) struct ZarrSource {
    levels: Vec<StoreLevel>,
    selection: Selection,
    dims: [u32; 3],
    scalar: ScalarType,
    budget: u64,
    cache: Mutex<Cache<TileKey>>,
    /// Tiles decoded, those that failed to read (left at the fill value), and the first
    /// failure in words.
    decoded: AtomicU64,
    failed: AtomicU64,
    first_failure: Mutex<Option<String>>,
    /// Whether the store is remote (reads wait on the network, not the cores).
    remote: bool,
}

impl ZarrSource {
    /// The source over `arrays` (the store's levels, finest first) of which `selection` is the
    /// volume, of `dims` voxels (level 0) of `scalar`, caching up to `budget` bytes of tiles.
    /// Levels whose shape is not level 0's halved along each axis some number of times are
    /// left out.
    pub(super) fn new(
        arrays: Vec<ZarrArray>,
        selection: Selection,
        scalar: ScalarType,
        budget: u64,
    ) -> Result<Self, ZarrError> {
        let dims_of = |a: &ZarrArray| {
            let shape = a.shape();
            let [k, j, i] = selection.space;
            [shape[i], shape[j], shape[k]].map(|n| u32::try_from(n).unwrap_or(u32::MAX))
        };
        let mut levels = Vec::new();
        let dims = arrays.first().map(dims_of).unwrap_or([1; 3]);
        for array in arrays {
            let d = dims_of(&array);
            let Some(halvings) = halvings_of(dims, d) else {
                log::debug!(
                    "store level {} left out: {d:?} is no halving of {dims:?}",
                    array.path()
                );
                continue;
            };
            let shape = tile_shape(&array)?;
            let [k, j, i] = selection.space;
            let tile = [shape[i], shape[j], shape[k]].map(|n| u32::try_from(n).unwrap_or(u32::MAX));
            let shards = ArrayShardedReadableExtCache::new(&array);
            levels.push(StoreLevel {
                array,
                dims: d,
                halvings,
                tile,
                shards,
            });
        }
        Ok(Self {
            levels,
            selection,
            dims,
            scalar,
            budget,
            cache: Mutex::new(Cache::default()),
            decoded: AtomicU64::new(0),
            failed: AtomicU64::new(0),
            first_failure: Mutex::new(None),
            remote: false,
        })
    }

    /// The source, said to read from a remote store (`remote`): more readers at once.
    pub(super) fn remote(mut self, remote: bool) -> Self {
        self.remote = remote;
        self
    }

    /// Voxels of level 0 along x, y, z.
    pub(super) fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// The tiles that failed to read so far.
    pub(super) fn faults(&self) -> super::read::Faults {
        let failed = self.failed.load(Ordering::Relaxed);
        super::read::Faults {
            failed,
            total: self.decoded.load(Ordering::Relaxed),
            first: self.first_failure.lock().ok().and_then(|f| f.clone()),
        }
    }

    /// The store level a box of LeapView's `level` is read from: the coarsest no coarser along
    /// any axis (level 0 always qualifies).
    fn level_for(&self, level: u32) -> usize {
        (0..self.levels.len())
            .filter(|&j| self.levels[j].halvings.iter().all(|&h| h <= level))
            .max_by_key(|&j| self.levels[j].halvings.iter().sum::<u32>())
            .unwrap_or(0)
    }

    /// Tile `at` of store level `j`, from the cache or decoded.
    fn tile(&self, j: usize, at: [u32; 3]) -> Result<Arc<Tile>, VolumeError> {
        let key = (j, at);
        if let Some(tile) = self.lock().get(&key) {
            return Ok(tile);
        }
        let level = &self.levels[j];
        let lo: [u32; 3] = std::array::from_fn(|a| at[a] * level.tile[a]);
        let hi: [u32; 3] = std::array::from_fn(|a| (lo[a] + level.tile[a]).min(level.dims[a]));
        let dims = std::array::from_fn(|a| hi[a] - lo[a]);
        let samples = self.decode(level, lo, hi)?;
        let tile = Arc::new(Tile { samples, dims });
        self.lock().put(key, Arc::clone(&tile), self.budget);
        Ok(tile)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Cache<TileKey>> {
        self.cache.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Decodes the box `lo..hi` (x, y, z) of `level` from the store; a tile that fails to read
    /// is the fill value (logged once: the rest still renders).
    fn decode(
        &self,
        level: &StoreLevel,
        lo: [u32; 3],
        hi: [u32; 3],
    ) -> Result<Samples, VolumeError> {
        let box_ = [2, 1, 0].map(|a| lo[a] as usize..hi[a] as usize);
        let subset = subset_of(level.array.dimensionality(), &self.selection, &box_);
        if level.shards.len() > MOST_SHARD_INDEXES {
            level.shards.clear();
        }
        let cache = &level.shards;
        // Bricks are read on every core at once: no threads inside a read.
        let options = CodecOptions::default().with_concurrent_target(1);
        macro_rules! typed {
            ($t:ty, $variant:ident) => {{
                self.decoded.fetch_add(1, Ordering::Relaxed);
                match level
                    .array
                    .retrieve_array_subset_sharded_opt::<Vec<$t>>(cache, &subset, &options)
                {
                    Ok(v) => Samples::$variant(v),
                    Err(e) => {
                        if self.failed.fetch_add(1, Ordering::Relaxed) == 0 {
                            if let Ok(mut first) = self.first_failure.lock() {
                                *first = Some(format!(
                                    "the chunk at {:?}..{:?} of '{}': {e}",
                                    lo,
                                    hi,
                                    level.array.path()
                                ));
                            }
                            log::warn!(
                                "a chunk of the Zarr array '{}' could not be read and shows \
                                 the fill value ({e}); the rest still renders",
                                level.array.path()
                            );
                        }
                        let n = (0..3).map(|a| (hi[a] - lo[a]) as usize).product::<usize>();
                        Samples::$variant(vec![fill_value::<$t>(&level.array); n])
                    }
                }
            }};
        }
        Ok(match self.scalar {
            ScalarType::U8 => typed!(u8, U8),
            ScalarType::I8 => typed!(i8, I8),
            ScalarType::U16 => typed!(u16, U16),
            ScalarType::I16 => typed!(i16, I16),
            ScalarType::U32 => typed!(u32, U32),
            ScalarType::I32 => typed!(i32, I32),
            ScalarType::F32 => typed!(f32, F32),
            ScalarType::F64 => typed!(f64, F64),
        })
    }

    /// The box `lo..hi` (x, y, z) of store level `j`, assembled from its tiles.
    fn read_store_box(&self, j: usize, lo: [u32; 3], hi: [u32; 3]) -> Result<Samples, VolumeError> {
        let level = &self.levels[j];
        let dims: [u32; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
        let mut out = empty(self.scalar, dims.iter().map(|&d| d as usize).product());
        let first: [u32; 3] = std::array::from_fn(|a| lo[a] / level.tile[a]);
        let last: [u32; 3] = std::array::from_fn(|a| (hi[a] - 1) / level.tile[a]);
        for tz in first[2]..=last[2] {
            for ty in first[1]..=last[1] {
                for tx in first[0]..=last[0] {
                    let at = [tx, ty, tz];
                    let tile = self.tile(j, at)?;
                    let origin: [u32; 3] = std::array::from_fn(|a| at[a] * level.tile[a]);
                    copy_overlap(&tile, origin, &mut out, (lo, dims));
                }
            }
        }
        Ok(out)
    }
}

impl BrickSource for ZarrSource {
    fn read_box(&self, level: u32, lo: [u32; 3], hi: [u32; 3]) -> Result<Samples, VolumeError> {
        let j = self.level_for(level);
        let store = &self.levels[j];
        // Halvings still to make along each axis, and the store's box that covers the box.
        let rounds: [u32; 3] = std::array::from_fn(|a| level - store.halvings[a]);
        let from: [u32; 3] = std::array::from_fn(|a| lo[a] << rounds[a]);
        let to: [u32; 3] = std::array::from_fn(|a| {
            (u64::from(hi[a]) << rounds[a]).min(u64::from(store.dims[a])) as u32
        });
        if (0..3).any(|a| from[a] >= to[a]) {
            return Err(ZarrError::Metadata(format!(
                "a box of level {level} past the store level's {:?} voxels",
                store.dims
            ))
            .into());
        }
        let mut samples = self.read_store_box(j, from, to)?;
        let mut dims: [u32; 3] = std::array::from_fn(|a| to[a] - from[a]);
        for round in 0..rounds.iter().copied().max().unwrap_or(0) {
            let axes = rounds.map(|r| r > round);
            samples = halve_axes(&samples, dims, axes);
            dims = halved_dims(dims, axes);
        }
        let want: [u32; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
        if dims != want {
            return Err(ZarrError::Metadata(format!(
                "a box of level {level} came out {dims:?} voxels for {want:?}"
            ))
            .into());
        }
        Ok(samples)
    }

    fn held_bytes(&self) -> u64 {
        self.lock().bytes()
    }

    fn budget_bytes(&self) -> u64 {
        self.budget
    }

    fn readers(&self) -> usize {
        let cores = crate::parallel::cores();
        // A remote store's reads wait on round trips: many at once hide them.
        if self.remote {
            cores.max(REMOTE_READERS)
        } else {
            cores
        }
    }
}

/// Readers of a remote store at once, at least.
const REMOTE_READERS: usize = 16;

/// How many times each axis of `dims` (level 0) was halved (`ceil(n / 2)`) to give `level`;
/// `None` where an axis is no such halving.
fn halvings_of(dims: [u32; 3], level: [u32; 3]) -> Option<[u32; 3]> {
    let mut out = [0; 3];
    for a in 0..3 {
        out[a] = (0..32).find(|&h| level_dims([dims[a], 1, 1], h)[0] == level[a])?;
        // An axis of one voxel halves to itself: count no halving.
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_level_is_matched_to_the_halvings_of_each_axis() {
        assert_eq!(halvings_of([100, 64, 7], [50, 32, 4]), Some([1, 1, 1]));
        // ome-zarr-py keeps z whole by default.
        assert_eq!(halvings_of([100, 64, 7], [25, 16, 7]), Some([2, 2, 0]));
        // Floor instead of ceil is no LeapView halving.
        assert_eq!(halvings_of([101, 64, 8], [50, 32, 4]), None);
        assert_eq!(halvings_of([1, 64, 8], [1, 32, 4]), Some([0, 1, 1]));
    }
}
