//! Writing a volume as a multiscale OME-Zarr store (NGFF 0.5 on Zarr v3): levels halved as
//! LeapView halves them (`downsample::halve`) down to one chunk, each a sharded array of 32³
//! inner chunks compressed with zstd, spacing and the voxel-centre shift of each level in its
//! `scale` and `translation` (millimetres), and what NGFF has no field for (patient orientation,
//! origin, value mapping, modality, display window, source) under the `leapview` attribute, which
//! LeapView reads back. The store is written under a hidden name beside `out` and renamed to it
//! only once complete, so an interrupted or failed write leaves no store that looks valid.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde_json::{Value, json};
use zarrs::filesystem::FilesystemStore;
use zarrs::group::GroupBuilder;
use zarrs::storage::ReadableWritableListableStorage;

pub use super::levels::Slabs;
use crate::volume::error::VolumeError;
use crate::volume::modality::Modality;
use crate::volume::model::Volume;
use crate::volume::orientation::Orientation;
use crate::volume::samples::{Samples, ScalarType, ValueMapping};
use crate::volume::stats::{Histogram, ValueRange};

/// Edge of an inner chunk (a shard's unit of reading and decoding).
pub const CHUNK_EDGE: u32 = 32;

/// Largest edge of a shard (a file of the store), a multiple of [`CHUNK_EDGE`].
pub const SHARD_EDGE: u32 = 256;

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
    /// The samples could not be read from where they come from.
    #[error("reading the samples: {0}")]
    Read(String),
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

/// What a store says of its volume besides the samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Facts {
    /// The volume's name.
    pub name: String,
    /// Spacing of level 0 (mm, x y z).
    pub spacing_mm: [f64; 3],
    /// Stored values to data units.
    pub mapping: ValueMapping,
    /// The patient orientation of the index axes.
    pub orientation: Option<Orientation>,
    /// The first voxel's centre (LPS, mm).
    pub origin_lps: Option<[f64; 3]>,
    /// The modality.
    pub modality: Option<Modality>,
    /// The display window (data units).
    pub window: Option<[f64; 2]>,
    /// Every voxel's range, histogram and count of non-finite samples, where known (else
    /// counted while writing 8- and 16-bit integers).
    pub statistics: Option<(Option<ValueRange>, Histogram, u64)>,
}

impl Facts {
    /// The facts of `volume` (its statistics where they are of every voxel).
    pub fn of(volume: &Volume) -> Self {
        Self {
            name: volume.name().to_string(),
            spacing_mm: volume.spacing_mm(),
            mapping: volume.mapping(),
            orientation: volume.orientation(),
            origin_lps: volume.provenance().origin_lps,
            modality: volume.modality().cloned(),
            window: volume.provenance().window,
            statistics: volume.exact_statistics().then(|| {
                (
                    volume.value_range(),
                    volume.histogram().clone(),
                    volume.non_finite_count(),
                )
            }),
        }
    }
}

/// A volume's level-0 slabs: from its samples, or read from its store.
struct VolumeSlabs<'a>(&'a Volume);

impl Slabs for VolumeSlabs<'_> {
    fn dims(&self) -> [u32; 3] {
        self.0.dims()
    }

    fn scalar_type(&self) -> ScalarType {
        self.0.scalar_type()
    }

    fn read(&self, z0: u32, z1: u32) -> Result<Samples, VolumeError> {
        let [x, y, _] = self.0.dims();
        if let Some(streamed) = self.0.streaming() {
            return streamed.read_box(0, [0, 0, z0], [x, y, z1]);
        }
        let plane = x as usize * y as usize;
        let samples = self.0.whole_samples("writing")?;
        Ok(samples.slice(z0 as usize * plane..z1 as usize * plane))
    }
}

/// Writes `volume` to a new store at `out`, calling `progress` with the share done (0 to 1)
/// after each shard. `source` is said in the store's attributes (the file it came from). A
/// volume read from its store is read a slab at a time.
pub fn write_ome_zarr(
    volume: &Volume,
    out: &Path,
    source: &str,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<Written, WriteError> {
    write_store(
        &VolumeSlabs(volume),
        &Facts::of(volume),
        out,
        source,
        progress,
    )
}

/// Writes the volume `slabs` gives, with `facts`, to a new store at `out`, a row of shards at
/// a time (memory: about 1.33 rows of 256 slices of level 0), calling `progress` with the
/// share done. The store is written under a hidden name beside `out`, renamed once complete.
pub fn write_store(
    slabs: &dyn Slabs,
    facts: &Facts,
    out: &Path,
    source: &str,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<Written, WriteError> {
    if out.exists() {
        return Err(WriteError::Exists(out.to_path_buf()));
    }
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
    let result = write_all(slabs, facts, &partial, source, progress).and_then(|written| {
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

/// The error of zarrs refusing the array (or group) at `path`, from what it said.
pub(super) fn zarr_error(path: &str) -> impl Fn(String) -> WriteError + '_ {
    move |reason| WriteError::Zarr {
        path: path.to_string(),
        reason,
    }
}

fn write_all(
    slabs: &dyn Slabs,
    facts: &Facts,
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
    let (levels, counted) = super::levels::write_levels(&store, slabs, facts.mapping, progress)?;
    let statistics = facts.statistics.clone().or(counted);
    let attributes = attributes(facts, statistics, &levels, source);
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

/// The group's attributes: NGFF 0.5 multiscales (axes in millimetres; each level's scale and
/// the translation that puts its voxel centres where LeapView's halving puts them) and
/// LeapView's own facts.
fn attributes(
    facts: &Facts,
    statistics: Option<(Option<ValueRange>, Histogram, u64)>,
    levels: &[[u32; 3]],
    source: &str,
) -> serde_json::Map<String, Value> {
    let [sx, sy, sz] = facts.spacing_mm;
    let origin = facts.origin_lps.unwrap_or([0.0; 3]);
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
    let mapping = facts.mapping;
    let mut leapview = json!({
        "written_by": format!("LeapView {}", env!("CARGO_PKG_VERSION")),
        "source": source,
        "orientation": facts.orientation.map(|o| o.code()),
        "origin_lps": facts.origin_lps,
        "modality": facts.modality.as_ref().map(|m| m.code()),
        "window": facts.window,
    });
    // The whole volume's statistics: a reader that streams the store sees only a coarse level.
    if let Some((range, histogram, non_finite)) = statistics {
        leapview["statistics"] = json!({
            "range": range.map(|r| [r.min, r.max]),
            "non_finite": non_finite,
            "histogram": histogram.counts,
        });
    }
    if mapping != ValueMapping::IDENTITY {
        leapview["value_mapping"] = json!({"slope": mapping.slope, "intercept": mapping.intercept});
    }
    let mut attributes = serde_json::Map::new();
    attributes.insert(
        "ome".into(),
        json!({
            "version": "0.5",
            "multiscales": [{
                "name": facts.name,
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
