//! A store's levels written from level-0 slabs, a shard row at a time, so that no level is ever
//! whole in memory: each row of shards of a level is written once its slices have come, then
//! halved into the next level's pending row (a row's depth is even but for a level's last, so
//! pairs of slices never straddle two rows). Memory is about 1.33 rows of level 0 plus the
//! shards being compressed: writing 2048 × 2048 × 4096 uint16 peaked at 3.1 GB resident on 2
//! cores and 3.9 GB on 16 (`/usr/bin/time -v leapview generate dense-head --dims 2048,2048,4096
//! --type uint16`, docs/benchmarks/out-of-core).

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use rayon::prelude::*;
use zarrs::array::codec::ZstdCodec;
use zarrs::array::{Array, ArrayBuilder, Element, FillValue, data_type};
use zarrs::storage::{ReadableWritableListableStorage, ReadableWritableListableStorageTraits};

use super::write::{CHUNK_EDGE, SHARD_EDGE, WriteError, zarr_error};
use crate::volume::downsample::{halve, level_dims};
use crate::volume::error::VolumeError;
use crate::volume::samples::{Samples, ScalarType, ValueMapping};
use crate::volume::stats::{Counts, Histogram, ValueRange};

/// The zstd level: 3 is zstd's default, a third of the raw size for CT at about 300 MB/s a core.
const ZSTD_LEVEL: i32 = 3;

/// The level-0 samples a store is written from, a slab of z-slices at a time.
pub trait Slabs: Sync {
    /// Voxels along x, y, z.
    fn dims(&self) -> [u32; 3];
    /// The stored type.
    fn scalar_type(&self) -> ScalarType;
    /// Slices `z0..z1`, x fastest.
    fn read(&self, z0: u32, z1: u32) -> Result<Samples, VolumeError>;
}

type LevelArray = Array<dyn ReadableWritableListableStorageTraits>;

/// One level being written: its array, voxels, shard depth, and the slices come and not yet
/// written (from slice `first`).
struct Pending {
    array: LevelArray,
    path: String,
    dims: [u32; 3],
    depth: u32,
    first: u32,
    slices: Vec<Samples>,
}

/// The levels of a volume of `dims`: halved until every axis fits one chunk.
fn level_count(dims: [u32; 3]) -> u32 {
    let mut n = 1;
    while level_dims(dims, n - 1).iter().any(|&d| d > CHUNK_EDGE) {
        n += 1;
    }
    n
}

/// Writes every level of `slabs` into `store` (arrays `/0`, `/1`, …), calling `progress` with
/// the share of voxels written; returns the levels' dimensions and, for 8- and 16-bit
/// integers, every voxel's statistics under `mapping`.
#[allow(clippy::type_complexity)]
pub(super) fn write_levels(
    store: &ReadableWritableListableStorage,
    slabs: &dyn Slabs,
    mapping: ValueMapping,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<(Vec<[u32; 3]>, Option<(Option<ValueRange>, Histogram, u64)>), WriteError> {
    let dims0 = slabs.dims();
    let scalar = slabs.scalar_type();
    let levels: Vec<[u32; 3]> = (0..level_count(dims0))
        .map(|k| level_dims(dims0, k))
        .collect();
    let total: f64 = levels
        .iter()
        .map(|d| d.iter().map(|&n| f64::from(n)).product::<f64>())
        .sum();
    let done = AtomicU64::new(0);
    let report = |voxels: u64| {
        let so_far = done.fetch_add(voxels, Ordering::Relaxed) + voxels;
        progress(so_far as f64 / total);
    };
    let mut pending = Vec::new();
    for (k, &dims) in levels.iter().enumerate() {
        let path = format!("/{k}");
        let array = level_array(store, &path, dims, scalar)?;
        array
            .store_metadata()
            .map_err(|e| zarr_error(&path)(e.to_string()))?;
        let depth = array
            .chunk_shape(&[0, 0, 0])
            .map_err(|e| zarr_error(&path)(e.to_string()))?[0]
            .get() as u32;
        pending.push(Pending {
            array,
            path,
            dims,
            depth,
            first: 0,
            slices: Vec::new(),
        });
    }
    let mut counts = Counts::for_type(scalar);
    let depth0 = pending[0].depth;
    for z0 in (0..dims0[2]).step_by(depth0 as usize) {
        let z1 = (z0 + depth0).min(dims0[2]);
        let slab = slabs
            .read(z0, z1)
            .map_err(|e| WriteError::Read(e.to_string()))?;
        if let Some(c) = counts.as_mut() {
            c.add(&slab);
        }
        push(&mut pending, 0, slab, &report)?;
    }
    let statistics = counts.map(|c| c.statistics(mapping));
    Ok((levels, statistics))
}

/// Adds `slab` (whole slices of level `k`) to the level's pending row; writes the row once it
/// holds the shard depth or the level's last slice, and hands its halving to level `k + 1`.
fn push(
    pending: &mut [Pending],
    k: usize,
    slab: Samples,
    report: &(dyn Fn(u64) + Sync),
) -> Result<(), WriteError> {
    let level = &mut pending[k];
    let plane = level.dims[0] as usize * level.dims[1] as usize;
    level.slices.push(slab);
    let held: usize = level.slices.iter().map(|s| s.len() / plane).sum();
    let end = level.first + held as u32;
    if held < level.depth as usize && end < level.dims[2] {
        return Ok(());
    }
    let row = Samples::concat(std::mem::take(&mut level.slices));
    let row_dims = [level.dims[0], level.dims[1], held as u32];
    write_row(level, &row, row_dims, report).map_err(zarr_error(&level.path))?;
    level.first = end;
    if k + 1 < pending.len() {
        push(pending, k + 1, halve(&row, row_dims), report)?;
    }
    Ok(())
}

/// The sharded array of one level.
fn level_array(
    store: &ReadableWritableListableStorage,
    path: &str,
    [x, y, z]: [u32; 3],
    scalar: ScalarType,
) -> Result<LevelArray, WriteError> {
    let chunk = [z, y, x].map(|d| d.min(CHUNK_EDGE));
    let shard: Vec<u64> = [z, y, x]
        .iter()
        .zip(chunk)
        .map(|(&d, c)| u64::from(d.div_ceil(c) * c).min(u64::from(SHARD_EDGE)))
        .collect();
    // The zero of each type: its own bytes (as bytes, zarrs would take them for a list).
    let (data_type, fill): (_, FillValue) = match scalar {
        ScalarType::U8 => (data_type::uint8(), 0u8.into()),
        ScalarType::I8 => (data_type::int8(), 0i8.into()),
        ScalarType::U16 => (data_type::uint16(), 0u16.into()),
        ScalarType::I16 => (data_type::int16(), 0i16.into()),
        ScalarType::U32 => (data_type::uint32(), 0u32.into()),
        ScalarType::I32 => (data_type::int32(), 0i32.into()),
        ScalarType::F32 => (data_type::float32(), 0f32.into()),
        ScalarType::F64 => (data_type::float64(), 0f64.into()),
    };
    ArrayBuilder::new(
        vec![u64::from(z), u64::from(y), u64::from(x)],
        shard,
        data_type,
        fill,
    )
    .subchunk_shape(chunk.map(u64::from).to_vec())
    .bytes_to_bytes_codecs(vec![Arc::new(ZstdCodec::new(ZSTD_LEVEL, false))])
    .dimension_names(["z", "y", "x"].into())
    .build(store.clone(), path)
    .map_err(|e| zarr_error(path)(e.to_string()))
}

/// Writes `row` (`dims`: the level's x and y, the row's slices) as the level's row of shards
/// that starts at slice `level.first`.
fn write_row(
    level: &Pending,
    row: &Samples,
    dims: [u32; 3],
    report: &(dyn Fn(u64) + Sync),
) -> Result<(), String> {
    let shard_z = u64::from(level.first / level.depth);
    match row {
        Samples::U8(v) => write_typed(&level.array, v, dims, shard_z, report),
        Samples::I8(v) => write_typed(&level.array, v, dims, shard_z, report),
        Samples::U16(v) => write_typed(&level.array, v, dims, shard_z, report),
        Samples::I16(v) => write_typed(&level.array, v, dims, shard_z, report),
        Samples::U32(v) => write_typed(&level.array, v, dims, shard_z, report),
        Samples::I32(v) => write_typed(&level.array, v, dims, shard_z, report),
        Samples::F32(v) => write_typed(&level.array, v, dims, shard_z, report),
        Samples::F64(v) => write_typed(&level.array, v, dims, shard_z, report),
    }
}

/// Every shard of row `sz` of the level from `values` (the row's slices), on all cores (each
/// shard a file of its own), padded past the volume's edge with zeros as the shard shape
/// requires.
fn write_typed<T: Element + Copy + Default + Send + Sync>(
    array: &LevelArray,
    values: &[T],
    [nx, ny, nz]: [u32; 3],
    sz: u64,
    report: &(dyn Fn(u64) + Sync),
) -> Result<(), String> {
    let grid = array.chunk_grid_shape().to_vec();
    let shard = array
        .chunk_shape(&[0, 0, 0])
        .map_err(|e| e.to_string())?
        .iter()
        .map(|n| n.get() as usize)
        .collect::<Vec<_>>();
    let (nx, ny, nz) = (nx as usize, ny as usize, nz as usize);
    let count = grid[1] * grid[2];
    (0..count).into_par_iter().try_for_each(|index| {
        let (sx, sy) = (index % grid[2], index / grid[2]);
        let [dz, dy, dx] = [shard[0], shard[1], shard[2]];
        let (y0, x0) = (sy as usize * dy, sx as usize * dx);
        let mut data = vec![T::default(); dz * dy * dx];
        let width = dx.min(nx - x0);
        let mut voxels = 0u64;
        for z in 0..dz.min(nz) {
            for y in y0..(y0 + dy).min(ny) {
                let from = (z * ny + y) * nx + x0;
                let to = (z * dy + (y - y0)) * dx;
                data[to..to + width].copy_from_slice(&values[from..from + width]);
                voxels += width as u64;
            }
        }
        array
            .store_chunk(&[sz, sy, sx], data)
            .map_err(|e| e.to_string())?;
        report(voxels);
        Ok(())
    })
}
