//! OME-Zarr stores in a local folder: NGFF 0.4 (Zarr v2) and 0.5 (Zarr v3, sharded or not), and
//! the older 0.1–0.3, with the codecs stores use (blosc, zstd, gzip, none), through `zarrs`.
//!
//! A store's resolution level is read whole into memory: the finest that this machine's memory
//! holds, said in a note where that is not level 0. One time point and one channel; spacing and
//! origin from the level's scale and translation in the units its axes name; no patient
//! orientation (NGFF has none), so the volume opens as RAS, assumed. Chunks absent from the store
//! read as the array's fill value; a chunk that fails to decode is left at it, said once.

mod address;
mod levels;
mod ngff;
mod read;
#[cfg(feature = "remote")]
mod remote;
mod source;
pub mod write;

use std::path::Path;
use std::sync::Arc;

use zarrs::array::Array;
use zarrs::filesystem::FilesystemStore;
use zarrs::group::Group;
use zarrs::storage::ReadableStorageTraits;

use self::address::Scheme;
use self::ngff::{Axis, AxisKind, Image, Level};
use self::read::{Selection, ZarrArray};
use super::error::VolumeError;
use super::error::zarr::ZarrError;
use super::limits;
use super::load::LoadOptions;
use super::model::{Provenance, Volume, VolumeIndex};
use super::samples::{ScalarType, ValueMapping};
use super::streamed::{BrickSource, Streamed};

/// The metadata files a Zarr node may have, v3 first.
const METADATA_FILES: [&str; 4] = ["zarr.json", ".zarray", ".zgroup", ".zattrs"];

/// The largest metadata file read: 16 MiB (zarrs reads one whole; real ones are kilobytes).
const MAX_METADATA_BYTES: u64 = 16 << 20;

/// Whether the folder `path` is a Zarr store (its root holds Zarr metadata).
pub(crate) fn is_store(path: &Path) -> bool {
    METADATA_FILES.iter().any(|f| path.join(f).is_file())
}

/// Whether `path` is the address of a remote store (`http://`, `https://`, `s3://`, `gs://`,
/// `az://`; see [`Scheme`]).
pub(crate) fn is_remote(path: &Path) -> bool {
    Scheme::of(&path.to_string_lossy()).is_some()
}

/// Opens the OME-Zarr image (or plain Zarr array) in the folder `path`, or at the address
/// `path` names (see [`is_remote`]).
pub(crate) fn load(
    path: &Path,
    name: String,
    options: &LoadOptions,
) -> Result<Volume, VolumeError> {
    let scheme = Scheme::of(&path.to_string_lossy());
    load_store(path, name, options).map_err(|e| match (e, scheme) {
        (VolumeError::Zarr(e), Some(scheme)) => refusal(e, scheme).into(),
        (e, _) => e,
    })
}

/// `e`, said as a refusal of the credentials (those `scheme` takes) where the server answered
/// 401 or 403.
fn refusal(e: ZarrError, scheme: Scheme) -> ZarrError {
    let text = e.to_string();
    // object_store's words for 403 and 401, and the statuses themselves.
    let refused = [
        "lacked the necessary privileges",
        "lacked valid authentication credentials",
        "403 Forbidden",
        "401 Unauthorized",
    ];
    match e {
        ZarrError::Open { reason, .. } | ZarrError::Remote { reason, .. }
            if refused.iter().any(|r| text.contains(r)) =>
        {
            ZarrError::Credentials {
                takes: scheme.credentials(),
                reason,
            }
        }
        e => e,
    }
}

fn load_store(path: &Path, name: String, options: &LoadOptions) -> Result<Volume, VolumeError> {
    let store: Store = if is_remote(path) {
        remote_store(path)?
    } else {
        // A folder without Zarr metadata is refused by `image_of`, as an address is.
        Arc::new(FilesystemStore::new(path).map_err(|e| ZarrError::Open {
            what: "group",
            path: "/".into(),
            reason: e.to_string(),
        })?)
    };
    let remote = is_remote(path);
    let (root, image, facts) = image_of(&store)?;
    let arrays = image
        .levels
        .iter()
        .map(|level| open_array(&store, &join(&root, &level.path)))
        .collect::<Result<Vec<_>, _>>()?;
    let ndim = arrays[0].dimensionality();
    let axes = match &image.axes {
        Some(axes) => axes.clone(),
        None => default_axes(ndim)?,
    };
    if let Some((i, a)) = arrays
        .iter()
        .enumerate()
        .find(|(_, a)| a.dimensionality() != axes.len())
    {
        return Err(ZarrError::Metadata(format!(
            "the array '{}' has {} dimensions for {} axes",
            image.levels[i].path,
            a.dimensionality(),
            axes.len()
        ))
        .into());
    }
    let shape0 = arrays[0].shape().to_vec();
    let selection = select(&axes, &shape0, options)?;
    let scalar = read::scalar_type(&arrays[0])?;
    let progress = options.progress.as_deref();
    let full = dims_of(&shape0, &selection);
    let (dims, bytes) = limits::check_dims_within(full, scalar, u64::MAX)?;
    let budget = options
        .ram_budget
        .unwrap_or_else(limits::default_ram_budget);
    let available = limits::available_memory_bytes().unwrap_or(u64::MAX);
    let mut notes = Vec::new();
    let (voxels, faults) = if bytes <= budget && bytes <= available {
        read::check_chunks(&arrays[0], scalar)?;
        limits::admit(progress, dims, scalar, false)?;
        let (samples, faults) = read::read(&arrays[0], &selection, dims, scalar, progress)?;
        (Voxels::Whole(samples), faults)
    } else {
        for array in &arrays {
            read::check_chunks(array, scalar)?;
        }
        limits::admit(progress, dims, scalar, false)?;
        // The budget holds the preview and the cache of decoded chunks.
        let level = super::streamed::preview_level(dims, budget, scalar);
        let held = super::streamed::voxels(super::downsample::level_dims(dims, level))
            * scalar.size_bytes() as u64;
        let cache = budget.saturating_sub(held);
        let source =
            source::ZarrSource::new(arrays, selection.clone(), scalar, cache)?.remote(remote);
        let (streamed, faults) = preview(source, level, scalar, progress)?;
        let [px, py, pz] = streamed.preview().dims;
        notes.push(format!(
            "read from the store brick by brick as the view needs them ({} of samples, more \
             than the {} memory budget; --ram-budget sets it); statistics and info from level \
             {} ({px} x {py} x {pz} voxels)",
            crate::text::bytes(bytes),
            crate::text::bytes(budget),
            streamed.preview_level()
        ));
        (Voxels::Streamed(streamed), faults)
    };
    let (spacing, origin) = geometry(&axes, &selection, &image.levels[0])?;
    if faults.failed > 0 {
        notes.push(format!(
            "{} of {} chunks could not be read and show the fill value ({})",
            faults.failed,
            faults.total,
            faults.first.unwrap_or_default()
        ));
    }
    if axes
        .iter()
        .filter(|a| a.kind == AxisKind::Space)
        .any(|a| a.unit.is_none())
    {
        notes.push("the store names no unit for its space axes: taken as millimetres".into());
    }
    let channel = selection_index(&axes, &selection, AxisKind::Channel);
    let window = (image.windows.get(channel.unwrap_or(0) as usize).copied()).flatten();
    let volumes = chosen_of(&axes, &shape0, &selection, AxisKind::Time);
    let channels = chosen_of(&axes, &shape0, &selection, AxisKind::Channel);
    let name = match &image.name {
        Some(n) if !n.is_empty() && n != &name => format!("{name} ({n})"),
        _ => name,
    };
    let voxel_count = dims.iter().map(|&d| u64::from(d)).product();
    let facts = facts
        .as_ref()
        .map(|f| ngff::LeapViewFacts::of(f, voxel_count))
        .unwrap_or_default();
    let mapping = facts.mapping.unwrap_or(ValueMapping::IDENTITY);
    let volume = match voxels {
        Voxels::Whole(samples) => Volume::new(name, dims, spacing, samples, mapping)?,
        Voxels::Streamed(streamed) => {
            let volume = Volume::streamed(name, dims, spacing, streamed, mapping)?;
            match facts.statistics {
                // The store's own statistics of every voxel, where LeapView wrote them.
                Some(s) => {
                    if let Some(note) = notes.last_mut() {
                        note.push_str("; range and histogram of every voxel, from the store");
                    }
                    volume.with_statistics(s.range, s.histogram, s.non_finite)
                }
                None => volume,
            }
        }
    }
    .with_orientation(facts.orientation)
    .with_modality(facts.modality)
    .with_provenance(Provenance {
        notes,
        window: window.or(facts.window),
        // LeapView's own origin is in its orientation's frame; the NGFF translation is in
        // the axes' (RAS, assumed) and only stands where LeapView stated no orientation.
        origin_lps: match (facts.origin_lps, facts.orientation) {
            (Some(o), _) => Some(o),
            (None, Some(_)) => None,
            (None, None) => Some(origin),
        },
        volumes,
        channels,
        ..Provenance::default()
    });
    Ok(volume)
}

/// The node path of `child` inside the group at `root` (`/` or `/0`).
fn join(root: &str, child: &str) -> String {
    match (root.trim_end_matches('/'), child) {
        ("", "") => "/".into(),
        (r, "") => r.into(),
        (r, c) => format!("{r}/{c}"),
    }
}

/// A store as this reader takes it: a folder, or a remote store read synchronously.
type Store = Arc<dyn ReadableStorageTraits>;

/// The remote store at `path` (an address [`is_remote`] takes).
#[cfg(feature = "remote")]
fn remote_store(path: &Path) -> Result<Store, ZarrError> {
    remote::open(&path.to_string_lossy())
}

/// Without the `remote` feature: refused, saying so.
#[cfg(not(feature = "remote"))]
fn remote_store(_: &Path) -> Result<Store, ZarrError> {
    Err(ZarrError::Metadata(
        "this LeapView was built without remote stores (cargo feature 'remote')".into(),
    ))
}

/// The key of `file` in the node at `node` (`/` or `/0`).
fn key(node: &str, file: &str) -> Result<zarrs::storage::StoreKey, ZarrError> {
    let node = node.trim_matches('/');
    let text = if node.is_empty() {
        file.to_string()
    } else {
        format!("{node}/{file}")
    };
    zarrs::storage::StoreKey::new(text).map_err(|e| ZarrError::Metadata(e.to_string()))
}

/// The size of `file` in the node `node`, where it exists (`None` also where the store cannot
/// say: zarrs' own error then names the failure).
fn size_of(store: &Store, node: &str, file: &str) -> Result<Option<u64>, ZarrError> {
    store
        .size_key(&key(node, file)?)
        .map_err(|e| ZarrError::Open {
            what: "group",
            path: node.into(),
            reason: e.to_string(),
        })
}

/// Refuses a node whose metadata files are larger than [`MAX_METADATA_BYTES`], before zarrs
/// reads one whole.
fn check_metadata(store: &Store, node: &str) -> Result<(), ZarrError> {
    for file in METADATA_FILES {
        let len = size_of(store, node, file)?.unwrap_or(0);
        if len > MAX_METADATA_BYTES {
            return Err(ZarrError::Metadata(format!(
                "{node}/{file} takes {}, more than the {} a metadata file may",
                crate::text::bytes(len),
                crate::text::bytes(MAX_METADATA_BYTES)
            )));
        }
    }
    Ok(())
}

/// The group path and image of the store, and its `leapview` attribute: its root's multiscales, those of `0/` under a
/// bioformats2raw root, or the root array itself as a one-level image without metadata.
fn image_of(store: &Store) -> Result<(String, Image, Option<serde_json::Value>), ZarrError> {
    check_metadata(store, "/")?;
    let mut any = false;
    for file in METADATA_FILES {
        any |= size_of(store, "/", file)?.is_some();
    }
    if !any {
        return Err(ZarrError::NotAStore);
    }
    if is_array(store)? {
        return Ok(("/".into(), bare_image(), None));
    }
    let attributes = |node: &str| -> Result<serde_json::Map<String, serde_json::Value>, ZarrError> {
        check_metadata(store, node)?;
        Group::open(Arc::clone(store), node)
            .map(|g| g.attributes().clone())
            .map_err(|e| ZarrError::Open {
                what: "group",
                path: node.into(),
                reason: e.to_string(),
            })
    };
    let root = attributes("/")?;
    if let Some(image) = ngff::image(&root)? {
        return Ok(("/".into(), image, root.get("leapview").cloned()));
    }
    let nested = root.contains_key("bioformats2raw.layout")
        || root
            .get("ome")
            .is_some_and(|o| o.get("bioformats2raw.layout").is_some());
    if nested && let Some(image) = ngff::image(&attributes("/0")?)? {
        return Ok(("/0".into(), image, None));
    }
    Err(ZarrError::NoMultiscales)
}

/// Whether the store's root node is an array (v2 `.zarray`, or v3 `node_type: array`).
fn is_array(store: &Store) -> Result<bool, ZarrError> {
    if size_of(store, "/", ".zarray")?.is_some() {
        return Ok(true);
    }
    let bytes = store
        .get(&key("/", "zarr.json")?)
        .map_err(|e| ZarrError::Open {
            what: "group",
            path: "/".into(),
            reason: e.to_string(),
        })?;
    Ok(bytes
        .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
        .is_some_and(|v| v.get("node_type").and_then(|t| t.as_str()) == Some("array")))
}

/// A plain array read as an image: one level, no axes or transformations.
fn bare_image() -> Image {
    Image {
        version: None,
        name: None,
        axes: None,
        levels: vec![Level {
            path: String::new(),
            scale: None,
            translation: Vec::new(),
        }],
        windows: Vec::new(),
    }
}

fn open_array(store: &Store, node: &str) -> Result<ZarrArray, ZarrError> {
    check_metadata(store, node)?;
    Array::open(Arc::clone(store), node).map_err(|e| ZarrError::Open {
        what: "array",
        path: node.into(),
        reason: e.to_string(),
    })
}

/// The axes of an image whose metadata names none (NGFF before 0.3, or a plain array): t, c, z,
/// y, x for five dimensions, the last three as z, y, x for three.
fn default_axes(ndim: usize) -> Result<Vec<Axis>, ZarrError> {
    let names: &[&str] = match ndim {
        5 => &["t", "c", "z", "y", "x"],
        4 => &["c", "z", "y", "x"],
        3 => &["z", "y", "x"],
        n => {
            return Err(ZarrError::Metadata(format!(
                "the array has {n} dimensions and no axes; LeapView reads 3 to 5"
            )));
        }
    };
    Ok(names
        .iter()
        .map(|n| Axis {
            name: (*n).into(),
            kind: match *n {
                "t" => AxisKind::Time,
                "c" => AxisKind::Channel,
                _ => AxisKind::Space,
            },
            unit: None,
        })
        .collect())
}

/// The volume's part of arrays of `shape`: three space axes, and the time point and channel the
/// options ask for (the first by default).
fn select(axes: &[Axis], shape: &[u64], options: &LoadOptions) -> Result<Selection, VolumeError> {
    let space: Vec<usize> = (0..axes.len())
        .filter(|&a| axes[a].kind == AxisKind::Space)
        .collect();
    let Ok(space) = <[usize; 3]>::try_from(space.as_slice()) else {
        return Err(VolumeError::UnsupportedDimension {
            dimension: space.len().to_string(),
            hint: " (an OME-Zarr image of 3 space axes)",
        });
    };
    let mut fixed = Vec::new();
    for (a, axis) in axes.iter().enumerate() {
        let size = shape[a];
        let asked = match axis.kind {
            AxisKind::Space => continue,
            AxisKind::Time => options.volume.map(u64::from),
            AxisKind::Channel => options.channel.map(u64::from),
            AxisKind::Other if size > 1 => {
                return Err(ZarrError::ExtraAxis {
                    name: axis.name.clone(),
                    size,
                }
                .into());
            }
            AxisKind::Other => None,
        };
        let index = asked.unwrap_or(0);
        if index >= size {
            let (what, flag) = match axis.kind {
                AxisKind::Time => ("time point", "--volume"),
                _ => ("channel", "--channel"),
            };
            return Err(ZarrError::NoSuchIndex {
                axis: what,
                flag,
                asked: index + 1,
                count: size,
            }
            .into());
        }
        fixed.push((a, index));
    }
    Ok(Selection { space, fixed })
}

/// The index the selection takes along the (first) axis of `kind`.
fn selection_index(axes: &[Axis], selection: &Selection, kind: AxisKind) -> Option<u64> {
    let axis = axes.iter().position(|a| a.kind == kind)?;
    selection
        .fixed
        .iter()
        .find(|(a, _)| *a == axis)
        .map(|&(_, i)| i)
}

/// Which time point (or channel: `kind`) was read, of how many, where there is more than one.
fn chosen_of(
    axes: &[Axis],
    shape: &[u64],
    selection: &Selection,
    kind: AxisKind,
) -> Option<VolumeIndex> {
    let axis = axes.iter().position(|a| a.kind == kind)?;
    let count = u32::try_from(shape[axis]).ok().filter(|&n| n > 1)?;
    let chosen = selection_index(axes, selection, kind)? as u32;
    Some(VolumeIndex { chosen, count })
}

/// Voxels along x, y, z of an array of `shape`.
fn dims_of(shape: &[u64], selection: &Selection) -> [u64; 3] {
    let [k, j, i] = selection.space;
    [shape[i], shape[j], shape[k]]
}

/// Where a store's samples are read to.
enum Voxels {
    Whole(super::samples::Samples),
    Streamed(Streamed),
}

/// The streamed volume of `source`, with its preview, `level`, read whole a slab at a time
/// (progress, cancel).
fn preview(
    source: source::ZarrSource,
    level: u32,
    scalar: ScalarType,
    progress: Option<&super::progress::LoadProgress>,
) -> Result<(Streamed, read::Faults), VolumeError> {
    use super::downsample::{Level, level_dims};
    let dims = source.dims();
    let d = level_dims(dims, level);
    if let Some(p) = progress {
        p.start(super::streamed::voxels(d) * scalar.size_bytes() as u64);
    }
    let slab = 16;
    let mut parts = Vec::new();
    for z0 in (0..d[2]).step_by(slab as usize) {
        if progress.is_some_and(super::progress::LoadProgress::is_cancelled) {
            return Err(VolumeError::Cancelled);
        }
        let z1 = (z0 + slab).min(d[2]);
        parts.push(source.read_box(level, [0, 0, z0], [d[0], d[1], z1])?);
        if let Some(p) = progress {
            p.advance(
                u64::from(d[0]) * u64::from(d[1]) * u64::from(z1 - z0) * scalar.size_bytes() as u64,
            );
        }
    }
    let samples = super::samples::Samples::concat(parts);
    let faults = source.faults();
    let preview = Level {
        dims: d,
        samples,
        colour: None,
    };
    let streamed = Streamed::new(std::sync::Arc::new(source), dims, preview, level)?;
    Ok((streamed, faults))
}

/// Spacing (mm, x y z) of level 0 and the position of its first voxel's centre (LPS, mm, the
/// axes taken as RAS): from its scale and translation (1 per voxel where it gives no scale).
fn geometry(
    axes: &[Axis],
    selection: &Selection,
    level: &Level,
) -> Result<([f64; 3], [f64; 3]), ZarrError> {
    let [k, j, i] = selection.space;
    let mut spacing = [0.0; 3];
    let mut origin = [0.0; 3];
    for (out, axis) in [i, j, k].into_iter().enumerate() {
        let unit = match &axes[axis].unit {
            Some(u) => crate::volume::units::millimetres_per(u).ok_or_else(|| {
                ZarrError::Metadata(format!(
                    "the space axis '{}' has the unit '{u}', which is not a length",
                    axes[axis].name
                ))
            })?,
            None => 1.0,
        };
        let scale = level.scale.as_ref().map_or(1.0, |s| s[axis]);
        spacing[out] = scale * unit;
        origin[out] = level.translation.get(axis).copied().unwrap_or(0.0) * unit;
    }
    // RAS (assumed) to LPS; + 0.0 keeps a zero from printing as -0.
    Ok((spacing, [-origin[0] + 0.0, -origin[1] + 0.0, origin[2]]))
}
