//! OME-Zarr stores in a local folder: NGFF 0.4 (Zarr v2) and 0.5 (Zarr v3, sharded or not), and
//! the older 0.1–0.3, with the codecs stores use (blosc, zstd, gzip, none), through `zarrs`.
//!
//! A store's resolution level is read whole into memory: the finest that this machine's memory
//! holds, said in a note where that is not level 0. One time point and one channel; spacing and
//! origin from the level's scale and translation in the units its axes name; no patient
//! orientation (NGFF has none), so the volume opens as RAS, assumed. Chunks absent from the store
//! read as the array's fill value; a chunk that fails to decode is left at it, said once.

mod ngff;
mod read;
pub mod write;

use std::path::Path;
use std::sync::Arc;

use zarrs::array::Array;
use zarrs::filesystem::FilesystemStore;
use zarrs::group::Group;
use zarrs::storage::ReadableStorageTraits;

use self::ngff::{Axis, AxisKind, Image, Level};
use self::read::{Selection, ZarrArray};
use super::error::VolumeError;
use super::error::zarr::ZarrError;
use super::limits;
use super::load::LoadOptions;
use super::model::{Provenance, Volume, VolumeIndex};
use super::samples::{ScalarType, ValueMapping};

/// The metadata files a Zarr node may have, v3 first.
const METADATA_FILES: [&str; 4] = ["zarr.json", ".zarray", ".zgroup", ".zattrs"];

/// The largest metadata file read: 16 MiB (zarrs reads one whole; real ones are kilobytes).
const MAX_METADATA_BYTES: u64 = 16 << 20;

/// Whether the folder `path` is a Zarr store (its root holds Zarr metadata).
pub(crate) fn is_store(path: &Path) -> bool {
    METADATA_FILES.iter().any(|f| path.join(f).is_file())
}

/// Opens the OME-Zarr image (or plain Zarr array) in the folder `path`.
pub(crate) fn load(
    path: &Path,
    name: String,
    options: &LoadOptions,
) -> Result<Volume, VolumeError> {
    if !is_store(path) {
        return Err(ZarrError::NotAStore.into());
    }
    let store: Arc<dyn ReadableStorageTraits> =
        Arc::new(FilesystemStore::new(path).map_err(|e| ZarrError::Open {
            what: "group",
            path: "/".into(),
            reason: e.to_string(),
        })?);
    let (root, image, facts) = image_of(path, &store)?;
    let arrays = image
        .levels
        .iter()
        .map(|level| open_array(path, &store, &join(&root, &level.path)))
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
    let selection = select(&axes, arrays[0].shape(), options)?;
    let (index, scalar, dims) = finest_that_fits(&arrays, &selection)?;
    let array = &arrays[index];
    read::check_chunks(array, scalar)?;
    let progress = options.progress.as_deref();
    limits::admit(progress, dims, scalar, false)?;
    let (samples, faults) = read::read(array, &selection, dims, scalar, progress)?;
    let (spacing, origin) = geometry(&axes, &selection, &image.levels, &arrays, index)?;
    let mut notes = Vec::new();
    if index > 0 {
        let full = dims_of(arrays[0].shape(), &selection);
        notes.push(format!(
            "shown at level {index} of the store ({}, {} x {} x {} voxels): level 0 ({} x {} x \
             {}) needs more memory than this machine has",
            image.levels[index].path, dims[0], dims[1], dims[2], full[0], full[1], full[2]
        ));
    }
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
    let volumes = chosen_of(&axes, arrays[0].shape(), &selection, AxisKind::Time);
    let channels = chosen_of(&axes, arrays[0].shape(), &selection, AxisKind::Channel);
    let name = match &image.name {
        Some(n) if !n.is_empty() && n != &name => format!("{name} ({n})"),
        _ => name,
    };
    let facts = facts
        .as_ref()
        .map(ngff::LeapViewFacts::of)
        .unwrap_or_default();
    let volume = Volume::new(
        name,
        dims,
        spacing,
        samples,
        facts.mapping.unwrap_or(ValueMapping::IDENTITY),
    )?
    .with_orientation(facts.orientation)
    .with_modality(facts.modality)
    .with_provenance(Provenance {
        notes,
        window: window.or(facts.window),
        // LeapView's own origin is level 0's, in its orientation: a coarser level read
        // instead has none that can be stated without the shift in that frame.
        origin_lps: match (facts.origin_lps, facts.orientation) {
            (Some(o), _) if index == 0 => Some(o),
            (_, Some(_)) => None,
            _ => Some(origin),
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

/// Refuses a node whose metadata files are larger than [`MAX_METADATA_BYTES`], before zarrs
/// reads one whole.
fn check_metadata(dir: &Path, node: &str) -> Result<(), ZarrError> {
    let folder = dir.join(node.trim_start_matches('/'));
    for file in METADATA_FILES {
        let len = std::fs::metadata(folder.join(file)).map_or(0, |m| m.len());
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
fn image_of(
    dir: &Path,
    store: &Arc<dyn ReadableStorageTraits>,
) -> Result<(String, Image, Option<serde_json::Value>), ZarrError> {
    check_metadata(dir, "/")?;
    if is_array(dir) {
        return Ok(("/".into(), bare_image(), None));
    }
    let attributes = |node: &str| -> Result<serde_json::Map<String, serde_json::Value>, ZarrError> {
        check_metadata(dir, node)?;
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

/// Whether the folder's root node is an array (v2 `.zarray`, or v3 `node_type: array`).
fn is_array(dir: &Path) -> bool {
    if dir.join(".zarray").is_file() {
        return true;
    }
    std::fs::read(dir.join("zarr.json"))
        .ok()
        .and_then(|bytes| serde_json::from_slice::<serde_json::Value>(&bytes).ok())
        .is_some_and(|v| v.get("node_type").and_then(|t| t.as_str()) == Some("array"))
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

fn open_array(
    dir: &Path,
    store: &Arc<dyn ReadableStorageTraits>,
    node: &str,
) -> Result<ZarrArray, ZarrError> {
    check_metadata(dir, node)?;
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

/// The finest level whose samples this machine's memory holds: its index, type and dimensions.
fn finest_that_fits(
    arrays: &[ZarrArray],
    selection: &Selection,
) -> Result<(usize, ScalarType, [u32; 3]), VolumeError> {
    let available = limits::available_memory_bytes();
    let mut first_error = None;
    for (index, array) in arrays.iter().enumerate() {
        let scalar = read::scalar_type(array)?;
        let fits = limits::check_dims(dims_of(array.shape(), selection), scalar).and_then(
            |(dims, bytes)| match available {
                Some(available) if bytes > available => {
                    Err(VolumeError::NotEnoughMemory { bytes, available })
                }
                _ => Ok(dims),
            },
        );
        match fits {
            Ok(dims) => return Ok((index, scalar, dims)),
            Err(e @ (VolumeError::TooLarge { .. } | VolumeError::NotEnoughMemory { .. })) => {
                first_error.get_or_insert(e);
            }
            Err(e) => return Err(e),
        }
    }
    Err(first_error.unwrap_or(VolumeError::Zarr(ZarrError::NoMultiscales)))
}

/// Spacing (mm, x y z) of level `index` and the position of its first voxel's centre (LPS, mm,
/// the axes taken as RAS): from its scale and translation, or, where the metadata gives no scale,
/// 1 per voxel of level 0 and the shape ratio for coarser levels.
fn geometry(
    axes: &[Axis],
    selection: &Selection,
    levels: &[Level],
    arrays: &[ZarrArray],
    index: usize,
) -> Result<([f64; 3], [f64; 3]), ZarrError> {
    let level = &levels[index];
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
        let scale = match &level.scale {
            Some(s) => s[axis],
            None => arrays[0].shape()[axis] as f64 / arrays[index].shape()[axis].max(1) as f64,
        };
        spacing[out] = scale * unit;
        origin[out] = level.translation.get(axis).copied().unwrap_or(0.0) * unit;
    }
    // RAS (assumed) to LPS; + 0.0 keeps a zero from printing as -0.
    Ok((spacing, [-origin[0] + 0.0, -origin[1] + 0.0, origin[2]]))
}
