//! Reading a label file for an image: its voxels as labels, its segments' descriptions, and the
//! labels put on the image's grid.

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::dicom_seg::{self, Seg};
use super::error::LabelError;
use super::layered;
use super::names::{self, Described};
use super::resample::{self, GridMap, Placement};
use super::{LabelMap, Segment, palette};
use crate::mpr::frame::PatientFrame;
use crate::volume::dicom::scan::looks_like_dicom;
use crate::volume::error::{LoadError, fmt_dims};
use crate::volume::load::load_layers;
use crate::volume::model::Volume;
use crate::volume::samples::Samples;

/// What the user said about a label file.
#[derive(Clone, Debug, Default)]
pub struct LabelOptions {
    /// A file naming and colouring the labels (ITK-SNAP label description or Slicer colour
    /// table); by default one beside the labels with their name and `.txt` or `.ctbl`.
    pub names: Option<PathBuf>,
}

/// The labels of the file at `path`, on `image`'s voxel grid.
pub fn load_labels(
    path: &Path,
    image: &Volume,
    options: &LabelOptions,
) -> Result<LabelMap, LabelError> {
    if image.streaming().is_some() {
        return Err(LabelError::ImageStreamed {
            path: path.to_path_buf(),
        });
    }
    let mut notes = Vec::new();
    let seg = if looks_like_dicom(path) {
        dicom_seg::read(path, image.sample_count()).map_err(|reason| LabelError::Seg {
            path: path.to_path_buf(),
            reason,
        })?
    } else {
        None
    };
    let (mut layers, inside, mut described, strict) = match seg {
        Some(seg) => {
            check_references(&seg, image, path, &mut notes)?;
            notes.extend(seg.notes.iter().cloned());
            let from = Placement {
                axes: seg.axes,
                origin: seg.origin,
                dims: seg.dims,
            };
            let (layers, inside) = resampled(seg.layers, &from, image, path, &mut notes)?;
            (layers, inside, seg.described, true)
        }
        None => {
            let volumes = load_layers(path)?;
            let file_labels = volumes
                .iter()
                .map(|volume| {
                    let samples = volume.samples().ok_or_else(|| LabelError::Streamed {
                        path: path.to_path_buf(),
                    })?;
                    labels_of(samples, volume, path)
                })
                .collect::<Result<Vec<_>, _>>()?;
            let volume = &volumes[0];
            let (layers, inside) = on_grid(file_labels, volume, image, path, &mut notes)?;
            let (described, from_seg_nrrd) = descriptions(path, options)?;
            (layers, inside, described, from_seg_nrrd)
        }
    };
    let total = image.sample_count();
    // A SEG (or a .seg.nrrd, which Slicer crops to its segments) covers only where its segments
    // are: the rest of the image has none by design.
    if inside < total && !strict {
        notes.push(format!(
            "the labels cover {:.1} % of the image; the rest has none",
            inside as f64 * 100.0 / total as f64
        ));
    }
    layered::unique_across_layers(&mut layers, &mut described, &mut notes).map_err(|reason| {
        LabelError::Disagrees {
            path: path.to_path_buf(),
            reason,
        }
    })?;
    let segments = segments(&layers, &described, strict, path, &mut notes)?;
    Ok(LabelMap {
        dims: image.dims(),
        layers,
        segments,
        notes,
        name: path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into(),
        ),
    })
}

/// Refuses a segmentation of another series or frame of reference than the image's (a DICOM
/// series); notes that nothing could be checked where the image is no DICOM series.
fn check_references(
    seg: &Seg,
    image: &Volume,
    path: &Path,
    notes: &mut Vec<String>,
) -> Result<(), LabelError> {
    let other = |referenced: String, image: String| LabelError::OtherScan {
        path: path.to_path_buf(),
        referenced,
        image,
    };
    let Some(series) = &image.provenance().series else {
        notes.push(
            "the image is no DICOM series, so the segmentation's references were not checked: \
             placed by patient position"
                .into(),
        );
        return Ok(());
    };
    if !seg.frame_of_reference.is_empty()
        && !series.frame_of_reference.is_empty()
        && seg.frame_of_reference != series.frame_of_reference
    {
        return Err(other(
            format!("frame of reference {}", seg.frame_of_reference),
            format!("in frame of reference {}", series.frame_of_reference),
        ));
    }
    if !seg.referenced_series.is_empty() && !seg.referenced_series.contains(&series.uid) {
        return Err(other(
            format!("series {}", seg.referenced_series.join(", ")),
            format!("series {}", series.uid),
        ));
    }
    Ok(())
}

/// The file's samples as labels: whole numbers 0 … 65535 (after the file's scaling), else the
/// first voxel that is not one.
fn labels_of(samples: &Samples, volume: &Volume, path: &Path) -> Result<Vec<u16>, LabelError> {
    let mapping = volume.mapping();
    let label = |i: usize| -> Option<u16> {
        let v = mapping.apply(samples.get_f64(i));
        (v.fract() == 0.0 && (0.0..=65535.0).contains(&v)).then_some(v as u16)
    };
    let n = samples.len();
    // One pass where every voxel is a label; the bad ones are counted only to say so.
    if let Some(labels) = (0..n)
        .into_par_iter()
        .map(label)
        .collect::<Option<Vec<u16>>>()
    {
        return Ok(labels);
    }
    let bad = (0..n)
        .into_par_iter()
        .filter(|&i| label(i).is_none())
        .count() as u64;
    let first = (0..n).find(|&i| label(i).is_none()).unwrap_or(0);
    let [nx, ny, _] = volume.dims().map(|d| d as usize);
    let voxel = [first % nx, first / nx % ny, first / (nx * ny)].map(|c| c as u32);
    Err(LabelError::NotLabels {
        path: path.to_path_buf(),
        value: mapping.apply(samples.get_f64(first)),
        voxel,
        count: bad,
    })
}

/// The segments the file or a names file describes, and whether a `.seg.nrrd` did (then every
/// label in it must be one of them).
fn descriptions(path: &Path, options: &LabelOptions) -> Result<(Vec<Described>, bool), LabelError> {
    let lower = path.to_string_lossy().to_ascii_lowercase();
    let mut described = Vec::new();
    if lower.ends_with(".nrrd") || lower.ends_with(".nhdr") {
        let fields = crate::volume::nrrd::key_values(path).map_err(|problem| LoadError {
            path: path.to_path_buf(),
            problem,
        })?;
        described = names::of_seg_nrrd(&fields).map_err(|reason| LabelError::Disagrees {
            path: path.to_path_buf(),
            reason,
        })?;
    }
    let from_seg_nrrd = !described.is_empty();
    let table = options.names.clone().or_else(|| beside(path));
    if let Some(table) = table {
        let text = std::fs::read_to_string(&table).map_err(|e| LabelError::Names {
            path: table.clone(),
            reason: e.to_string(),
        })?;
        let listed = names::of_table(&text).map_err(|reason| LabelError::Names {
            path: table.clone(),
            reason,
        })?;
        // A table given beside a described file renames and recolours its segments.
        for entry in listed {
            match described
                .iter_mut()
                .find(|d| d.layer == entry.layer && d.value == entry.value)
            {
                Some(d) => *d = entry,
                None => described.push(entry),
            }
        }
    }
    Ok((described, from_seg_nrrd))
}

/// A names file beside the labels: their name without its extension, with `.txt` or `.ctbl`.
pub(super) fn beside(path: &Path) -> Option<PathBuf> {
    let name = path.file_name()?.to_string_lossy().into_owned();
    let lower = name.to_ascii_lowercase();
    let stem_len = [
        ".seg.nrrd",
        ".nii.gz",
        ".nii",
        ".nrrd",
        ".nhdr",
        ".mha",
        ".mhd",
    ]
    .iter()
    .find(|e| lower.ends_with(*e))
    .map_or(name.len(), |e| name.len() - e.len());
    let stem = &name[..stem_len];
    ["txt", "ctbl"]
        .iter()
        .map(|ext| path.with_file_name(format!("{stem}.{ext}")))
        .find(|p| p.is_file())
}

/// `layers` (on the grid of `labels`) on the grid of `image`, and how many image voxels the
/// labels cover.
fn on_grid(
    layers: Vec<Vec<u16>>,
    labels: &Volume,
    image: &Volume,
    path: &Path,
    notes: &mut Vec<String>,
) -> Result<(Vec<Vec<u16>>, u64), LabelError> {
    let same_dims = labels.dims() == image.dims();
    let unplaced = match (labels.orientation(), image.orientation()) {
        (None, _) => Some("the labels have"),
        (_, None) => Some("the image has"),
        _ => None,
    };
    if let Some(which) = unplaced {
        if !same_dims {
            return Err(LabelError::NoGeometry {
                path: path.to_path_buf(),
                labels: fmt_dims(&labels.dims()),
                image: fmt_dims(&image.dims()),
                which,
            });
        }
        notes.push(format!(
            "{which} no orientation: the labels are taken voxel for voxel (the grids' sizes agree)"
        ));
        return Ok((layers, image.sample_count()));
    }
    resampled(
        layers,
        &Placement::of(&PatientFrame::of(labels)),
        image,
        path,
        notes,
    )
}

/// `layers` (on the grid placed at `from`) on the grid of `image`, nearest label, and how many
/// image voxels the labels cover; refused where none is.
fn resampled(
    layers: Vec<Vec<u16>>,
    from: &Placement,
    image: &Volume,
    path: &Path,
    notes: &mut Vec<String>,
) -> Result<(Vec<Vec<u16>>, u64), LabelError> {
    let to = Placement::of(&PatientFrame::of(image));
    let map = GridMap::between(from, &to);
    if from.dims == to.dims && map.is_identity(to.dims) {
        return Ok((layers, image.sample_count()));
    }
    let (out, inside) = resample::onto(&layers, from.dims, to.dims, &map);
    if inside == 0 {
        return Err(LabelError::NoOverlap {
            path: path.to_path_buf(),
            labels: from.span(),
            image: to.span(),
        });
    }
    if map.is_shift(to.dims) {
        // The image's own grid, cut to the labels' extent: nothing to say.
        return Ok((out, inside));
    }
    let steps = [from.axes.x_axis, from.axes.y_axis, from.axes.z_axis].map(|a| a.length());
    notes.push(format!(
        "the labels' grid ({}, {}) differs from the image's: each voxel takes the nearest label",
        fmt_dims(&from.dims),
        spacing_text(steps)
    ));
    Ok((out, inside))
}

/// `1 × 1 × 2 mm`.
fn spacing_text(s: [f64; 3]) -> String {
    format!("{} × {} × {} mm", s[0], s[1], s[2])
}

/// The segments: every described one (its voxels counted on the image's grid) and every label
/// present that none describes ("label N", the palette's colour). A `.seg.nrrd` must describe
/// every label its voxels hold, as a DICOM SEG does (`strict`).
fn segments(
    layers: &[Vec<u16>],
    described: &[Described],
    strict: bool,
    path: &Path,
    notes: &mut Vec<String>,
) -> Result<Vec<Segment>, LabelError> {
    let disagrees = |reason: String| LabelError::Disagrees {
        path: path.to_path_buf(),
        reason,
    };
    if let Some(d) = described
        .iter()
        .find(|d| usize::from(d.layer) >= layers.len())
    {
        return Err(disagrees(format!(
            "segment '{}' is in layer {}, but the file holds {} layer(s)",
            d.name,
            d.layer,
            layers.len()
        )));
    }
    let mut segments = Vec::new();
    for (layer, labels) in layers.iter().enumerate() {
        let counts = labels
            .par_chunks(1 << 16)
            .fold(
                || vec![0u64; 65_536],
                |mut c, chunk| {
                    for &l in chunk {
                        c[usize::from(l)] += 1;
                    }
                    c
                },
            )
            .reduce(
                || vec![0u64; 65_536],
                |mut a, b| {
                    a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
                    a
                },
            );
        let mut unnamed = 0;
        for (value, &voxels) in counts.iter().enumerate().skip(1) {
            // Every index of a 65 536-entry table is a u16.
            let value = value as u16;
            let layer = layer as u16;
            let file = described
                .iter()
                .find(|d| d.layer == layer && d.value == value);
            if voxels == 0 && file.is_none() {
                continue;
            }
            if file.is_none() {
                if strict {
                    return Err(disagrees(format!(
                        "{voxels} voxels hold label {value} (layer {layer}), which none of the \
                         file's {} segments has: its fields disagree with its voxels",
                        described.len()
                    )));
                }
                unnamed += 1;
            }
            segments.push(Segment {
                value,
                layer,
                name: file.map_or_else(|| format!("label {value}"), |d| d.name.clone()),
                colour: file
                    .and_then(|d| d.colour)
                    .unwrap_or_else(|| palette::colour(value)),
                voxels,
            });
        }
        if unnamed > 0 && !described.is_empty() {
            notes.push(format!(
                "{unnamed} labels present are not in the names given: named \"label N\""
            ));
        }
    }
    Ok(segments)
}
