//! Reading one time point and channel of a Zarr array's three space axes into LeapView's samples
//! (x fastest), a chunk (a shard's inner chunk) at a time on all cores: a chunk that fails to
//! read is left at the fill value and counted, so one bad chunk costs that chunk, not the image.

use std::ops::Range;
use std::sync::Mutex;

use rayon::prelude::*;
use zarrs::array::{
    Array, ArrayShardedExt, ArrayShardedReadableExt, ArrayShardedReadableExtCache, CodecOptions,
    ElementOwned, data_type,
};
use zarrs::storage::ReadableStorageTraits;

use crate::volume::error::VolumeError;
use crate::volume::error::zarr::ZarrError;
use crate::volume::progress::LoadProgress;
use crate::volume::samples::{Samples, ScalarType};

/// A Zarr array as this reader takes it.
pub(super) type ZarrArray = Array<dyn ReadableStorageTraits>;

/// The largest chunk (or a shard's inner chunk) decoded at once: 2 GiB.
pub(super) const MAX_CHUNK_BYTES: u64 = 2 << 30;

/// Which part of the array is the volume: the array axes of k, j, i (slowest to fastest), and an
/// index for every other axis.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct Selection {
    /// The array axes that are the volume's k, j, i.
    pub space: [usize; 3],
    /// The index taken along every other axis, by array axis.
    pub fixed: Vec<(usize, u64)>,
}

/// Chunks that could not be read: how many, of how many, and the first failure.
#[derive(Debug, Default)]
pub(super) struct Faults {
    /// Chunks left at the fill value because they failed to read.
    pub failed: u64,
    /// Chunks read in all.
    pub total: u64,
    /// The first failure, in words.
    pub first: Option<String>,
}

/// The scalar type of a Zarr data type, if LeapView stores it.
pub(super) fn scalar_type(array: &ZarrArray) -> Result<ScalarType, ZarrError> {
    let t = array.data_type();
    let known = [
        (data_type::uint8(), ScalarType::U8),
        (data_type::int8(), ScalarType::I8),
        (data_type::uint16(), ScalarType::U16),
        (data_type::int16(), ScalarType::I16),
        (data_type::uint32(), ScalarType::U32),
        (data_type::int32(), ScalarType::I32),
        (data_type::float32(), ScalarType::F32),
        (data_type::float64(), ScalarType::F64),
    ];
    known
        .into_iter()
        .find(|(d, _)| d == t)
        .map(|(_, s)| s)
        .ok_or_else(|| ZarrError::DataType {
            name: t.to_string(),
        })
}

/// The shape of the pieces reads are made in: a shard's inner chunk, else the chunk (the first
/// chunk's shape: NGFF stores use regular grids).
pub(super) fn tile_shape(array: &ZarrArray) -> Result<Vec<u64>, ZarrError> {
    let zeros = vec![0; array.dimensionality()];
    let shape = match array.effective_subchunk_shape() {
        Some(s) => s,
        None => array.chunk_shape(&zeros).map_err(|e| ZarrError::Open {
            what: "array",
            path: array.path().to_string(),
            reason: e.to_string(),
        })?,
    };
    Ok(shape.iter().map(|n| n.get()).collect())
}

/// Refuses chunks (and inner chunks) whose decoded size passes [`MAX_CHUNK_BYTES`]: zarrs decodes
/// a whole one at a time, so a hostile shape would otherwise allocate without bound.
pub(super) fn check_chunks(array: &ZarrArray, scalar: ScalarType) -> Result<(), ZarrError> {
    let zeros = vec![0; array.dimensionality()];
    let mut shapes = vec![tile_shape(array)?];
    if let Ok(chunk) = array.chunk_shape(&zeros) {
        shapes.push(chunk.iter().map(|n| n.get()).collect());
    }
    for shape in shapes {
        let bytes = shape
            .iter()
            .try_fold(scalar.size_bytes() as u64, |a, &n| a.checked_mul(n));
        if bytes.is_none_or(|b| b > MAX_CHUNK_BYTES) {
            return Err(ZarrError::ChunkTooLarge {
                shape,
                limit_bytes: MAX_CHUNK_BYTES,
            });
        }
    }
    Ok(())
}

/// Reads the selection of `array`, `dims` (x, y, z) voxels of `scalar`, reporting bytes to
/// `progress` and stopping when it is cancelled.
pub(super) fn read(
    array: &ZarrArray,
    selection: &Selection,
    dims: [u32; 3],
    scalar: ScalarType,
    progress: Option<&LoadProgress>,
) -> Result<(Samples, Faults), VolumeError> {
    macro_rules! typed {
        ($t:ty, $variant:ident) => {{
            let (values, faults) = read_typed::<$t>(array, selection, dims, progress)?;
            (Samples::$variant(values), faults)
        }};
    }
    Ok(match scalar {
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

fn read_typed<T>(
    array: &ZarrArray,
    selection: &Selection,
    dims: [u32; 3],
    progress: Option<&LoadProgress>,
) -> Result<(Vec<T>, Faults), VolumeError>
where
    T: ElementOwned + bytemuck::Pod + Send + Sync,
{
    let [nx, ny, nz] = dims.map(|d| d as usize);
    let fill: T = fill_value(array);
    let count = nx * ny * nz;
    let mut values: Vec<T> = Vec::new();
    values
        .try_reserve_exact(count)
        .map_err(|_| VolumeError::OutOfMemory {
            bytes: (count * size_of::<T>()) as u64,
        })?;
    values.resize(count, fill);
    let tile = tile_shape(array)?;
    let [tk, tj, ti] = selection.space.map(|a| tile[a] as usize);
    if let Some(p) = progress {
        p.start((count * size_of::<T>()) as u64);
    }
    let cache = ArrayShardedReadableExtCache::new(array);
    // One reader a tile at a time inside each thread: zarrs would otherwise spread every tile's
    // codecs over the same cores again.
    let options = CodecOptions::default().with_concurrent_target(1);
    let faults = Mutex::new(Faults::default());
    let slab = tk * nx * ny;
    // Slabs of one tile row along k each belong to one task: disjoint writes, no locks.
    values.par_chunks_mut(slab).enumerate().try_for_each(
        |(row, out)| -> Result<(), VolumeError> {
            let k0 = row * tk;
            let k1 = (k0 + tk).min(nz);
            for j0 in (0..ny).step_by(tj) {
                for i0 in (0..nx).step_by(ti) {
                    if progress.is_some_and(LoadProgress::is_cancelled) {
                        return Err(VolumeError::Cancelled);
                    }
                    let box_ = [k0..k1, j0..(j0 + tj).min(ny), i0..(i0 + ti).min(nx)];
                    let subset = subset_of(array.dimensionality(), selection, &box_);
                    let read = array
                        .retrieve_array_subset_sharded_opt::<Vec<T>>(&cache, &subset, &options);
                    let mut f = faults.lock().unwrap_or_else(|e| e.into_inner());
                    f.total += 1;
                    match read {
                        Ok(tile) => {
                            drop(f);
                            place(out, &tile, &box_, k0, [nx, ny]);
                        }
                        Err(e) => {
                            f.failed += 1;
                            f.first.get_or_insert_with(|| {
                                format!("the chunk at {:?}: {e}", [&box_[0], &box_[1], &box_[2]])
                            });
                        }
                    }
                    if let Some(p) = progress {
                        let voxels = box_.iter().map(|r| r.len()).product::<usize>();
                        p.advance((voxels * size_of::<T>()) as u64);
                    }
                }
            }
            Ok(())
        },
    )?;
    let faults = faults.into_inner().unwrap_or_else(|e| e.into_inner());
    if faults.total > 0 && faults.failed == faults.total {
        return Err(ZarrError::Unreadable {
            path: array.path().to_string(),
            first: faults.first.unwrap_or_default(),
        }
        .into());
    }
    Ok((values, faults))
}

/// The array's fill value as `T` (zero where it is no `T`).
pub(super) fn fill_value<T: bytemuck::Pod>(array: &ZarrArray) -> T {
    bytemuck::try_pod_read_unaligned(array.fill_value().as_ne_bytes())
        .unwrap_or_else(|_| T::zeroed())
}

/// The array subset of a box of k, j, i ranges, every other axis at its fixed index.
pub(super) fn subset_of(
    ndim: usize,
    selection: &Selection,
    box_: &[Range<usize>; 3],
) -> Vec<Range<u64>> {
    let mut subset = vec![0..1; ndim];
    for &(axis, index) in &selection.fixed {
        subset[axis] = index..index + 1;
    }
    for (axis, r) in selection.space.iter().zip(box_) {
        subset[*axis] = r.start as u64..r.end as u64;
    }
    subset
}

/// Copies a tile read in C order of the array's axes into the slab `out` that starts at slice
/// `k0`, x fastest. The space axes are in the array's order k, j, i, so the tile's order is
/// k, j, i too (the fixed axes have one entry each).
fn place<T: Copy>(
    out: &mut [T],
    tile: &[T],
    box_: &[Range<usize>; 3],
    k0: usize,
    [nx, ny]: [usize; 2],
) {
    let width = box_[2].len();
    for (n, k) in box_[0].clone().enumerate() {
        for (m, j) in box_[1].clone().enumerate() {
            let from = (n * box_[1].len() + m) * width;
            let to = ((k - k0) * ny + j) * nx + box_[2].start;
            out[to..to + width].copy_from_slice(&tile[from..from + width]);
        }
    }
}
