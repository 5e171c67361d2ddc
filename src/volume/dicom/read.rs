//! A chosen series into a [`Volume`]: geometry by the standard, the frames decoded on all cores
//! straight into their slices (or into a stack that is then resampled), values mapped to data
//! units.

use std::path::PathBuf;
use std::sync::Mutex;

use super::error::DicomError;
use super::geometry::{Geometry, SlicePlan, assemble};
use super::header::{FrameHeader, Rescale};
use super::pixels::{Stored, convert_frame, decode_file, scalar_type};
use super::resample::resample_slice;
use super::scan::parallel;
use super::series::Series;
use crate::volume::error::VolumeError;
use crate::volume::{
    LoadProgress, Modality, Orientation, Samples, ScalarType, ValueMapping, Volume, limits,
};

/// The volume's samples before the [`Volume`] is built, and its value mapping.
struct Assembled {
    samples: Samples,
    mapping: ValueMapping,
    notes: Vec<String>,
}

/// The frames of each file, as (frame in the file, index in the series' frames).
fn frames_by_file(frames: &[FrameHeader]) -> Vec<(usize, Vec<(u32, usize)>)> {
    let mut by_file: std::collections::BTreeMap<usize, Vec<(u32, usize)>> = Default::default();
    for (i, f) in frames.iter().enumerate() {
        by_file.entry(f.file).or_default().push((f.frame, i));
    }
    by_file.into_iter().collect()
}

/// Refuses a volume that the series' files cannot hold even at the highest compression a codec
/// reaches ([`limits::MAX_DEFLATE_RATIO`]: deflate's bound, beyond any lossless image codec's) or
/// that this machine has no memory for, before anything is allocated: headers that lie about
/// rows, columns or frames never make a large allocation.
fn check_files_can_hold(files: &[PathBuf], series: &Series, bytes: u64) -> Result<(), VolumeError> {
    let mut ids: Vec<usize> = series.frames.iter().map(|f| f.file).collect();
    ids.sort_unstable();
    ids.dedup();
    let held: u64 = ids
        .iter()
        .filter_map(|&i| std::fs::metadata(&files[i]).ok())
        .map(|m| m.len())
        .sum();
    let most = held.saturating_mul(limits::MAX_DEFLATE_RATIO);
    if bytes > most {
        let first = &series.frames[0];
        return Err(DicomError::BadField {
            file: first.label.clone(),
            field: "Rows x Columns x frames",
            value: format!(
                "{} x {} x {} ({bytes} bytes of samples)",
                first.rows,
                first.columns,
                series.frames.len()
            ),
            expected: "more than the series' files can hold, even compressed",
        }
        .into());
    }
    if let Some(available) = limits::available_memory_bytes()
        && bytes > available
    {
        return Err(VolumeError::NotEnoughMemory { bytes, available });
    }
    Ok(())
}

/// Allocates `len` samples, or says there is not enough memory.
fn allocate<T: Stored>(len: usize) -> Result<Vec<T>, VolumeError> {
    let mut v = Vec::new();
    v.try_reserve_exact(len)
        .map_err(|_| VolumeError::OutOfMemory {
            bytes: (len * std::mem::size_of::<T>()) as u64,
        })?;
    v.resize(len, T::default());
    Ok(v)
}

/// Decodes the series' frames into slots: frame i goes to slot `slot_of[i]` (`plane` samples
/// each). Per-frame rescaling is applied where `per_frame` is given (float output).
fn decode_into<T: Stored>(
    files: &[PathBuf],
    series: &Series,
    slot_of: &[usize],
    slots: usize,
    per_frame: Option<&[Rescale]>,
    progress: Option<&LoadProgress>,
) -> Result<Vec<T>, VolumeError> {
    let first = &series.frames[0];
    let plane = first.rows as usize * first.columns as usize;
    let mut out = allocate::<T>(plane * slots)?;
    let chunks: Vec<Mutex<&mut [T]>> = out.chunks_mut(plane).map(Mutex::new).collect();
    let by_file = frames_by_file(&series.frames);
    let cancelled = || progress.is_some_and(LoadProgress::is_cancelled);
    let slot_bytes = (plane * std::mem::size_of::<T>()) as u64;
    let results = parallel(by_file.len(), &cancelled, &|k| -> Result<(), DicomError> {
        let (file, list) = &by_file[k];
        let header = &series.frames[list[0].1];
        let decoded = decode_file(
            &files[*file],
            &files[*file].file_name().map_or_else(
                || header.label.clone(),
                |n| n.to_string_lossy().into_owned(),
            ),
            header.rows,
            header.columns,
            header.frames_in_file,
            &header.pixel,
        )?;
        for &(frame, index) in list {
            let bytes = decoded.frame(frame);
            if let Ok(mut chunk) = chunks[slot_of[index]].lock() {
                convert_frame(bytes, &header.pixel, decoded.encapsulated, &mut chunk);
                if let Some(rescale) = per_frame {
                    let r = rescale[index];
                    chunk
                        .iter_mut()
                        .for_each(|v| *v = T::from_f64_rounded(v.to_f64() * r.slope + r.intercept));
                }
            }
            if let Some(p) = progress {
                p.advance(slot_bytes);
            }
        }
        Ok(())
    });
    drop(chunks);
    if cancelled() {
        return Err(VolumeError::Cancelled);
    }
    for r in results.into_iter().flatten() {
        r?;
    }
    Ok(out)
}

/// Decodes and places every slice as `geometry` says, in type `T`.
fn samples_of<T: Stored>(
    files: &[PathBuf],
    series: &Series,
    geometry: &Geometry,
    per_frame: Option<&[Rescale]>,
    progress: Option<&LoadProgress>,
) -> Result<Vec<T>, VolumeError> {
    let n = series.frames.len();
    match &geometry.plan {
        SlicePlan::Stack(order) => {
            let mut slot_of = vec![0; n];
            for (k, &frame) in order.iter().enumerate() {
                slot_of[frame] = k;
            }
            decode_into(files, series, &slot_of, order.len(), per_frame, progress)
        }
        SlicePlan::Resample(plan) => {
            let slot_of: Vec<usize> = (0..n).collect();
            let stack: Vec<T> = decode_into(files, series, &slot_of, n, per_frame, progress)?;
            let [x, y, _] = geometry.dims;
            let plane = x as usize * y as usize;
            let fill = stack
                .iter()
                .copied()
                .min_by(|a, b| a.to_f64().total_cmp(&b.to_f64()))
                .unwrap_or_default();
            let mut out = allocate::<T>(plane * plan.len())?;
            for (sources, slice) in plan.iter().zip(out.chunks_mut(plane)) {
                resample_slice(&stack, [x as usize, y as usize], sources, fill, slice);
            }
            Ok(out)
        }
    }
}

fn assemble_samples(
    files: &[PathBuf],
    series: &Series,
    geometry: &Geometry,
    progress: Option<&LoadProgress>,
) -> Result<Assembled, VolumeError> {
    let first = &series.frames[0];
    let rescales: Vec<Rescale> = series.frames.iter().map(|f| f.rescale).collect();
    let uniform = rescales.iter().all(|r| *r == rescales[0]);
    let mut notes = Vec::new();
    let stored = if uniform {
        scalar_type(&first.pixel)
    } else {
        notes.push(
            "the slices have different RescaleSlope/RescaleIntercept: values converted to \
             float in data units"
                .into(),
        );
        ScalarType::F32
    };
    let (_, bytes) = limits::check_dims(geometry.dims.map(u64::from), stored)?;
    check_files_can_hold(files, series, bytes)?;
    if let Some(p) = progress {
        let plane = first.rows as u64 * first.columns as u64;
        p.start(plane * series.frames.len() as u64 * stored.size_bytes() as u64);
    }
    if first.pixel.monochrome1 {
        notes.push(
            "MONOCHROME1 (white is the lowest value): values inverted so that larger is brighter"
                .into(),
        );
    }
    let per_frame = (!uniform).then_some(rescales.as_slice());
    let samples = match stored {
        ScalarType::U8 => Samples::U8(samples_of(files, series, geometry, per_frame, progress)?),
        ScalarType::I8 => Samples::I8(samples_of(files, series, geometry, per_frame, progress)?),
        ScalarType::U16 => Samples::U16(samples_of(files, series, geometry, per_frame, progress)?),
        ScalarType::I16 => Samples::I16(samples_of(files, series, geometry, per_frame, progress)?),
        ScalarType::U32 => Samples::U32(samples_of(files, series, geometry, per_frame, progress)?),
        ScalarType::I32 => Samples::I32(samples_of(files, series, geometry, per_frame, progress)?),
        ScalarType::F32 | ScalarType::F64 => {
            Samples::F32(samples_of(files, series, geometry, per_frame, progress)?)
        }
    };
    let mapping = if uniform {
        ValueMapping {
            slope: rescales[0].slope,
            intercept: rescales[0].intercept,
        }
    } else {
        ValueMapping::IDENTITY
    };
    Ok(Assembled {
        samples,
        mapping,
        notes,
    })
}

/// Reads `series` (its frames from `files`) into a volume named `name`.
pub fn read_series(
    files: &[PathBuf],
    series: &Series,
    name: String,
    progress: Option<&LoadProgress>,
) -> Result<Volume, VolumeError> {
    if !series.is_grey_volume() {
        let first = series.frames.first();
        return Err(DicomError::BadField {
            file: first.map(|f| f.label.clone()).unwrap_or_default(),
            field: "SamplesPerPixel / BitsAllocated",
            value: first
                .map(|f| format!("{} / {}", f.pixel.samples_per_pixel, f.pixel.bits_allocated))
                .unwrap_or_default(),
            expected: "LeapView shows grey images of 8, 16 or 32 bits (1 sample per pixel)",
        }
        .into());
    }
    let geometry = assemble(&series.frames)?;
    let Assembled {
        samples,
        mapping,
        mut notes,
    } = assemble_samples(files, series, &geometry, progress)?;
    notes.splice(0..0, geometry.notes.iter().cloned());
    let orientation = geometry
        .axes_known
        .then(|| Orientation::from_lps_columns(geometry.axes_lps))
        .flatten();
    // The window is in data units: it applies after the rescale (PS3.3 C.11.2.1.2).
    let window = series.frames[0].window_range();
    let volume = Volume::new(name, geometry.dims, geometry.spacing_mm, samples, mapping)?
        .with_orientation(orientation)
        .with_modality(Modality::parse(&series.facts.modality));
    Ok(volume.with_provenance(crate::volume::Provenance {
        notes,
        window,
        series: Some(series.facts.clone()),
        origin_lps: geometry.axes_known.then_some(geometry.origin_lps),
        ..Default::default()
    }))
}
