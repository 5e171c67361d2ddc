//! Boxes assembled from tiles: a cache of decoded tiles (a Zarr store's chunks, a TIFF page's
//! strips), least recently used first out under a byte budget, and the copy of a tile's part
//! inside a box. A brick and its apron straddle several tiles, each read by its neighbours too.

use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

use super::samples::{Samples, ScalarType};

/// A decoded tile: its samples (x fastest) and voxels per axis.
pub(crate) struct Tile {
    /// Its samples, x fastest.
    pub(crate) samples: Samples,
    /// Its voxels along x, y, z.
    pub(crate) dims: [u32; 3],
}

/// The decoded tiles held, least recently used first out under a byte budget.
pub(crate) struct Cache<K> {
    tiles: HashMap<K, (Arc<Tile>, u64)>,
    by_use: BTreeMap<u64, K>,
    bytes: u64,
    clock: u64,
}

impl<K> Default for Cache<K> {
    fn default() -> Self {
        Self {
            tiles: HashMap::new(),
            by_use: BTreeMap::new(),
            bytes: 0,
            clock: 0,
        }
    }
}

impl<K: std::hash::Hash + Eq + Copy> Cache<K> {
    /// The tile of `key`, if held (now the most recently used).
    pub(crate) fn get(&mut self, key: &K) -> Option<Arc<Tile>> {
        self.clock += 1;
        let clock = self.clock;
        let (tile, used) = self.tiles.get_mut(key)?;
        self.by_use.remove(used);
        *used = clock;
        self.by_use.insert(clock, *key);
        Some(Arc::clone(tile))
    }

    /// Holds `tile` as `key`, letting the least recently used go until the cache is within
    /// `budget` bytes (a tile larger than the budget is not held).
    pub(crate) fn put(&mut self, key: K, tile: Arc<Tile>, budget: u64) {
        let bytes = tile_bytes(&tile);
        if self.tiles.contains_key(&key) || bytes > budget {
            return;
        }
        while self.bytes + bytes > budget {
            let Some((_, oldest)) = self.by_use.pop_first() else {
                break;
            };
            if let Some((gone, _)) = self.tiles.remove(&oldest) {
                self.bytes -= tile_bytes(&gone);
            }
        }
        self.clock += 1;
        self.by_use.insert(self.clock, key);
        self.tiles.insert(key, (tile, self.clock));
        self.bytes += bytes;
    }
}

/// Bytes the samples of `tile` take.
fn tile_bytes(tile: &Tile) -> u64 {
    (tile.samples.len() * tile.samples.scalar_type().size_bytes()) as u64
}

impl<K> Cache<K> {
    /// Bytes of the tiles held.
    pub(crate) fn bytes(&self) -> u64 {
        self.bytes
    }
}

/// `n` samples of `scalar`, zero.
pub(crate) fn empty(scalar: ScalarType, n: usize) -> Samples {
    match scalar {
        ScalarType::U8 => Samples::U8(vec![0; n]),
        ScalarType::I8 => Samples::I8(vec![0; n]),
        ScalarType::U16 => Samples::U16(vec![0; n]),
        ScalarType::I16 => Samples::I16(vec![0; n]),
        ScalarType::U32 => Samples::U32(vec![0; n]),
        ScalarType::I32 => Samples::I32(vec![0; n]),
        ScalarType::F32 => Samples::F32(vec![0.0; n]),
        ScalarType::F64 => Samples::F64(vec![0.0; n]),
    }
}

/// Copies the part of `tile` (whose first voxel is `origin` of its level) inside the box
/// `(lo, dims)` into `out`, the box's samples (x fastest).
pub(crate) fn copy_overlap(
    tile: &Tile,
    origin: [u32; 3],
    out: &mut Samples,
    (lo, dims): ([u32; 3], [u32; 3]),
) {
    let start: [u32; 3] = std::array::from_fn(|a| origin[a].max(lo[a]));
    let end: [u32; 3] = std::array::from_fn(|a| (origin[a] + tile.dims[a]).min(lo[a] + dims[a]));
    if (0..3).any(|a| start[a] >= end[a]) {
        return;
    }
    let width = (end[0] - start[0]) as usize;
    macro_rules! copy {
        ($src:expr, $dst:expr) => {
            for z in start[2]..end[2] {
                for y in start[1]..end[1] {
                    let s = ((z - origin[2]) * tile.dims[1] + (y - origin[1])) as usize
                        * tile.dims[0] as usize
                        + (start[0] - origin[0]) as usize;
                    let d = ((z - lo[2]) * dims[1] + (y - lo[1])) as usize * dims[0] as usize
                        + (start[0] - lo[0]) as usize;
                    $dst[d..d + width].copy_from_slice(&$src[s..s + width]);
                }
            }
        };
    }
    match (&tile.samples, out) {
        (Samples::U8(s), Samples::U8(d)) => copy!(s, d),
        (Samples::I8(s), Samples::I8(d)) => copy!(s, d),
        (Samples::U16(s), Samples::U16(d)) => copy!(s, d),
        (Samples::I16(s), Samples::I16(d)) => copy!(s, d),
        (Samples::U32(s), Samples::U32(d)) => copy!(s, d),
        (Samples::I32(s), Samples::I32(d)) => copy!(s, d),
        (Samples::F32(s), Samples::F32(d)) => copy!(s, d),
        (Samples::F64(s), Samples::F64(d)) => copy!(s, d),
        // Tiles are decoded in the source's one type.
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cache_lets_the_least_recently_used_tile_go_first() {
        let tile = |n: usize| {
            Arc::new(Tile {
                samples: Samples::U8(vec![0; n]),
                dims: [n as u32, 1, 1],
            })
        };
        let mut cache = Cache::<(usize, [u32; 3])>::default();
        cache.put((0, [0; 3]), tile(40), 100);
        cache.put((0, [1, 0, 0]), tile(40), 100);
        assert!(cache.get(&(0, [0; 3])).is_some());
        // Room for one more 40 only if [1, 0, 0], used least recently, goes.
        cache.put((0, [2, 0, 0]), tile(40), 100);
        assert!(cache.get(&(0, [1, 0, 0])).is_none());
        assert!(cache.get(&(0, [0; 3])).is_some());
        assert!(cache.get(&(0, [2, 0, 0])).is_some());
        assert_eq!(cache.bytes, 80);
        // A tile larger than the budget is not kept.
        cache.put((1, [0; 3]), tile(200), 100);
        assert!(cache.get(&(1, [0; 3])).is_none());
    }
}
