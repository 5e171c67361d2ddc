//! Writing a volume as a multiscale OME-Zarr store (NGFF 0.5 on Zarr v3): levels halved as
//! LeapView halves them (`downsample::halve`) down to one chunk, each a sharded array of 32³
//! inner chunks compressed with zstd, spacing and the voxel-centre shift of each level in its
//! `scale` and `translation` (millimetres), and what NGFF has no field for (patient orientation,
//! origin, value mapping, modality, display window, source) under the `leapview` attribute, which
//! LeapView reads back. The store is written under a hidden name beside `out` and renamed to it
//! only once complete, so an interrupted or failed write leaves no store that looks valid.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use rayon::prelude::*;
use serde_json::{Value, json};
use zarrs::array::codec::ZstdCodec;
use zarrs::array::{Array, ArrayBuilder, Element, FillValue, data_type};
use zarrs::filesystem::FilesystemStore;
use zarrs::group::GroupBuilder;
use zarrs::storage::ReadableWritableListableStorage;

use crate::volume::downsample::{halve, level_dims};
use crate::volume::model::Volume;
use crate::volume::samples::{Samples, ScalarType, ValueMapping};

/// Edge of an inner chunk (a shard's unit of reading and decoding).
pub const CHUNK_EDGE: u32 = 32;

/// Largest edge of a shard (a file of the store), a multiple of [`CHUNK_EDGE`].
pub const SHARD_EDGE: u32 = 256;

/// The zstd level: 3 is zstd's default, a third of the raw size for CT at about 300 MB/s a core.
const ZSTD_LEVEL: i32 = 3;

/// Why a store could not be written.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// The output exists already.
    #[error("{0} exists already; give a new name (LeapView does not write over a store)")]
    Exists(PathBuf),
    /// The folder it goes into does not exist.
    #[error("{0}: the folder to write into does not exist")]
    NoFolder(PathBuf),
    /// The file system refused (a full disk, no permission).
    #[error("writing {path}: {reason}")]
    Io {
        /// What was being written.
        path: PathBuf,
        /// What the system said.
        reason: String,
    },
    /// The volume is read from its store as needed, not held whole.
    #[error(transparent)]
    Streamed(crate::volume::error::VolumeError),
    /// zarrs refused an array or its metadata.
    #[error("writing the Zarr array '{path}': {reason}")]
    Zarr {
        /// The array's path in the store.
        path: String,
        /// What zarrs said.
        reason: String,
    },
}

/// What was written: the levels' dimensions (x, y, z), finest first, and the bytes on disk.
#[derive(Debug, Clone, PartialEq)]
pub struct Written {
    /// Each level's voxels along x, y, z.
    pub levels: Vec<[u32; 3]>,
    /// Bytes the store's files take.
    pub bytes: u64,
}

/// Writes `volume` to a new store at `out`, calling `progress` with the share done (0 to 1)
/// after each shard. `source` is said in the store's attributes (the file it came from).
pub fn write_ome_zarr(
    volume: &Volume,
    out: &Path,
    source: &str,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<Written, WriteError> {
    if out.exists() {
        return Err(WriteError::Exists(out.to_path_buf()));
    }
    volume
        .whole_samples("converting")
        .map_err(WriteError::Streamed)?;
    let parent = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !parent.is_dir() {
        return Err(WriteError::NoFolder(parent.to_path_buf()));
    }
    let name = out
        .file_name()
        .map_or_else(|| "store".into(), |n| n.to_string_lossy().into_owned());
    let partial = parent.join(format!(".{name}.partial-{}", std::process::id()));
    let result = write_all(volume, &partial, source, progress).and_then(|written| {
        std::fs::rename(&partial, out).map_err(|e| WriteError::Io {
            path: out.to_path_buf(),
            reason: e.to_string(),
        })?;
        Ok(written)
    });
    if result.is_err() {
        // Nothing half-written stays behind (a failure to remove it changes nothing said).
        let _ = std::fs::remove_dir_all(&partial);
    }
    result
}

fn io(path: &Path) -> impl Fn(std::io::Error) -> WriteError + '_ {
    move |e| WriteError::Io {
        path: path.to_path_buf(),
        reason: e.to_string(),
    }
}

fn zarr_error(path: &str) -> impl Fn(String) -> WriteError + '_ {
    move |reason| WriteError::Zarr {
        path: path.to_string(),
        reason,
    }
}

/// The levels of a volume of `dims`: halved until every axis fits one chunk.
pub fn level_count(dims: [u32; 3]) -> u32 {
    let mut n = 1;
    while level_dims(dims, n - 1).iter().any(|&d| d > CHUNK_EDGE) {
        n += 1;
    }
    n
}

fn write_all(
    volume: &Volume,
    dir: &Path,
    source: &str,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<Written, WriteError> {
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    zarrs::config::global_config_mut().set_include_zarrs_metadata(false);
    let store: ReadableWritableListableStorage =
        Arc::new(FilesystemStore::new(dir).map_err(|e| WriteError::Io {
            path: dir.to_path_buf(),
            reason: e.to_string(),
        })?);
    let dims0 = volume.dims();
    let count = level_count(dims0);
    let levels: Vec<[u32; 3]> = (0..count).map(|k| level_dims(dims0, k)).collect();
    let total: f64 = levels
        .iter()
        .map(|d| d.iter().map(|&n| f64::from(n)).product::<f64>())
        .sum();
    let done = std::sync::atomic::AtomicU64::new(0);
    let mut coarser: Option<Samples> = None;
    let whole = volume
        .whole_samples("converting")
        .map_err(WriteError::Streamed)?;
    for (k, &dims) in levels.iter().enumerate() {
        let samples = coarser.as_ref().unwrap_or(whole);
        let path = format!("/{k}");
        let array = level_array(&store, &path, dims, volume.scalar_type())?;
        array
            .store_metadata()
            .map_err(|e| zarr_error(&path)(e.to_string()))?;
        let report = |voxels: u64| {
            let so_far = done.fetch_add(voxels, std::sync::atomic::Ordering::Relaxed) + voxels;
            progress(so_far as f64 / total);
        };
        write_level(&array, samples, dims, &report).map_err(zarr_error(&path))?;
        if k + 1 < levels.len() {
            coarser = Some(halve(samples, dims));
        }
    }
    let attributes = attributes(volume, &levels, source);
    GroupBuilder::new()
        .attributes(attributes)
        .build(store.clone(), "/")
        .map_err(|e| zarr_error("/")(e.to_string()))?
        .store_metadata()
        .map_err(|e| zarr_error("/")(e.to_string()))?;
    Ok(Written {
        levels,
        bytes: folder_bytes(dir),
    })
}

/// The sharded array of one level.
fn level_array(
    store: &ReadableWritableListableStorage,
    path: &str,
    [x, y, z]: [u32; 3],
    scalar: ScalarType,
) -> Result<Array<dyn zarrs::storage::ReadableWritableListableStorageTraits>, WriteError> {
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

fn write_level(
    array: &Array<dyn zarrs::storage::ReadableWritableListableStorageTraits>,
    samples: &Samples,
    dims: [u32; 3],
    report: &(dyn Fn(u64) + Sync),
) -> Result<(), String> {
    match samples {
        Samples::U8(v) => write_typed(array, v, dims, report),
        Samples::I8(v) => write_typed(array, v, dims, report),
        Samples::U16(v) => write_typed(array, v, dims, report),
        Samples::I16(v) => write_typed(array, v, dims, report),
        Samples::U32(v) => write_typed(array, v, dims, report),
        Samples::I32(v) => write_typed(array, v, dims, report),
        Samples::F32(v) => write_typed(array, v, dims, report),
        Samples::F64(v) => write_typed(array, v, dims, report),
    }
}

/// Every shard of the level, on all cores (each shard a file of its own), padded past the
/// volume's edge with zeros as the shard shape requires.
fn write_typed<T: Element + Copy + Default + Send + Sync>(
    array: &Array<dyn zarrs::storage::ReadableWritableListableStorageTraits>,
    values: &[T],
    [nx, ny, nz]: [u32; 3],
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
    let count = grid.iter().product::<u64>();
    (0..count).into_par_iter().try_for_each(|index| {
        let (sx, sy, sz) = (
            index % grid[2],
            (index / grid[2]) % grid[1],
            index / (grid[2] * grid[1]),
        );
        let [dz, dy, dx] = [shard[0], shard[1], shard[2]];
        let (z0, y0, x0) = (sz as usize * dz, sy as usize * dy, sx as usize * dx);
        let mut data = vec![T::default(); dz * dy * dx];
        let width = dx.min(nx - x0);
        let mut voxels = 0u64;
        for z in z0..(z0 + dz).min(nz) {
            for y in y0..(y0 + dy).min(ny) {
                let from = (z * ny + y) * nx + x0;
                let to = ((z - z0) * dy + (y - y0)) * dx;
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

/// The group's attributes: NGFF 0.5 multiscales (axes in millimetres; each level's scale and
/// the translation that puts its voxel centres where LeapView's halving puts them) and
/// LeapView's own facts.
fn attributes(
    volume: &Volume,
    levels: &[[u32; 3]],
    source: &str,
) -> serde_json::Map<String, Value> {
    let [sx, sy, sz] = volume.spacing_mm();
    let origin = volume.provenance().origin_lps.unwrap_or([0.0; 3]);
    // The index axes taken as RAS, as LeapView reads a store without its own attributes.
    let base = [-origin[0] + 0.0, -origin[1] + 0.0, origin[2]];
    let datasets: Vec<Value> = (0..levels.len())
        .map(|k| {
            let f = f64::from(1u32 << k);
            let shift = (f - 1.0) / 2.0;
            json!({
                "path": k.to_string(),
                "coordinateTransformations": [
                    {"type": "scale", "scale": [sz * f, sy * f, sx * f]},
                    {"type": "translation", "translation": [
                        base[2] + sz * shift, base[1] + sy * shift, base[0] + sx * shift]},
                ],
            })
        })
        .collect();
    let axes: Vec<Value> = ["z", "y", "x"]
        .iter()
        .map(|n| json!({"name": n, "type": "space", "unit": "millimeter"}))
        .collect();
    let mapping = volume.mapping();
    let mut leapview = json!({
        "written_by": format!("LeapView {}", env!("CARGO_PKG_VERSION")),
        "source": source,
        "orientation": volume.orientation().map(|o| o.code()),
        "origin_lps": volume.provenance().origin_lps,
        "modality": volume.modality().map(|m| m.code()),
        "window": volume.provenance().window,
    });
    // The whole volume's statistics: a reader that streams the store sees only a coarse level.
    leapview["statistics"] = json!({
        "range": volume.value_range().map(|r| [r.min, r.max]),
        "non_finite": volume.non_finite_count(),
        "histogram": volume.histogram().counts,
    });
    if mapping != ValueMapping::IDENTITY {
        leapview["value_mapping"] = json!({"slope": mapping.slope, "intercept": mapping.intercept});
    }
    let mut attributes = serde_json::Map::new();
    attributes.insert(
        "ome".into(),
        json!({
            "version": "0.5",
            "multiscales": [{
                "name": volume.name(),
                "axes": axes,
                "datasets": datasets,
                "type": "mean",
                "metadata": {"description": "each level the mean of 2 x 2 x 2 voxels of the one before (an odd axis's last voxel repeated)"},
            }],
        }),
    );
    attributes.insert("leapview".into(), leapview);
    attributes
}

/// Bytes of the files under `dir`.
fn folder_bytes(dir: &Path) -> u64 {
    std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .flatten()
                .map(|e| match e.file_type() {
                    Ok(t) if t.is_dir() => folder_bytes(&e.path()),
                    _ => e.metadata().map_or(0, |m| m.len()),
                })
                .sum()
        })
        .unwrap_or(0)
}
