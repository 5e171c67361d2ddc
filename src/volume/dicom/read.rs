//! A chosen series into a [`Volume`]: geometry by the standard, the frames decoded on all cores
//! straight into their slices (or into a stack that is then resampled), values mapped to data
//! units.

use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU16, Ordering};

use super::codec::Codec;
use super::colour::{Layout, frame_rgb};
use super::geometry::{AxesFrom, Geometry, SlicePlan, assemble};
use super::header::{FrameHeader, Photometric, Rescale};
use super::pixels::{Decoded, Stored, convert_frame, decode_file, scalar_type};
use super::resample::resample_slice;
use super::series::{Alternatives, Series};
use crate::parallel::parallel;
use crate::volume::error::VolumeError;
use crate::volume::error::dicom::DicomError;
use crate::volume::{
    colour::Colour, limits, modality::Modality, model::Volume, orientation::Orientation,
    orientation::OrientationSource, progress::LoadProgress, samples::Samples, samples::ScalarType,
    samples::ValueMapping,
};

/// The series' files, and the copies of each that can stand in for it.
struct Files<'a> {
    paths: &'a [PathBuf],
    alternatives: &'a Alternatives,
}

impl std::ops::Index<usize> for Files<'_> {
    type Output = PathBuf;
    fn index(&self, i: usize) -> &PathBuf {
        &self.paths[i]
    }
}

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
fn check_files_can_hold(files: &Files<'_>, series: &Series, bytes: u64) -> Result<(), VolumeError> {
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

/// Turns one decoded frame into a slot's samples: (frame's bytes, its header, the file's
/// decoding, the frame's index in the series, the slot).
type Convert<'a, T> =
    dyn Fn(&[u8], &FrameHeader, &Decoded, usize, &mut [T]) -> Result<(), String> + Sync + 'a;

/// Decodes the series' frames into slots of `slot_len` samples: frame i goes to slot
/// `slot_of[i]` (none: not read), through `convert`.
#[allow(clippy::too_many_arguments)]
fn decode_into<T: Stored>(
    files: &Files<'_>,
    series: &Series,
    slot_of: &[Option<usize>],
    slots: usize,
    slot_len: usize,
    progress: Option<&LoadProgress>,
    stream_notes: &Mutex<Vec<String>>,
    convert: &Convert<'_, T>,
) -> Result<Vec<T>, VolumeError> {
    let mut out = allocate::<T>(slot_len * slots)?;
    let chunks: Vec<Mutex<&mut [T]>> = out.chunks_mut(slot_len).map(Mutex::new).collect();
    // Files none of whose frames have a slot are not opened.
    let by_file: Vec<(usize, Vec<(u32, usize)>)> = frames_by_file(&series.frames)
        .into_iter()
        .map(|(file, list)| {
            let kept: Vec<(u32, usize)> = list
                .into_iter()
                .filter(|&(_, i)| slot_of[i].is_some())
                .collect();
            (file, kept)
        })
        .filter(|(_, list)| !list.is_empty())
        .collect();
    let cancelled = || progress.is_some_and(LoadProgress::is_cancelled);
    let slot_bytes = (slot_len * std::mem::size_of::<T>()) as u64;
    let results = parallel(by_file.len(), &cancelled, &|k| -> Result<(), DicomError> {
        let (file, list) = &by_file[k];
        let header = &series.frames[list[0].1];
        let name = header.file_label().to_string();
        let decoded = decode_or_copy(
            files.paths,
            *file,
            &name,
            header,
            files.alternatives,
            stream_notes,
        )?;
        if let Some(note) = decoded.note.as_ref()
            && let Ok(mut notes) = stream_notes.lock()
            && notes.is_empty()
        {
            notes.push(format!("'{}': {note}", header.label));
        }
        for &(frame, index) in list {
            let bytes = decoded.frame(frame);
            let Some(slot) = slot_of[index] else {
                continue;
            };
            if let Ok(mut chunk) = chunks[slot].lock() {
                convert(bytes, header, &decoded, index, &mut chunk).map_err(|reason| {
                    DicomError::Decode {
                        file: series.frames[index].label.clone(),
                        reason,
                    }
                })?;
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

/// Decodes file `file` (named `name`, of whose frames `header` is one) or, where that fails, the
/// first copy of it that decodes, saying so in a note.
fn decode_or_copy(
    files: &[PathBuf],
    file: usize,
    name: &str,
    header: &FrameHeader,
    alternatives: &Alternatives,
    notes: &Mutex<Vec<String>>,
) -> Result<Decoded, DicomError> {
    let error = match decode_file(&files[file], name, header) {
        Ok(decoded) => return Ok(decoded),
        Err(e) => e,
    };
    for &(copy, implicit_vr) in alternatives.get(&file).into_iter().flatten() {
        let copy_name = files[copy].display().to_string();
        let copy_header = FrameHeader {
            implicit_vr,
            ..header.clone()
        };
        if let Ok(decoded) = decode_file(&files[copy], &copy_name, &copy_header) {
            if let Ok(mut n) = notes.lock() {
                n.push(format!(
                    "{error}; its copy '{copy_name}' (the same SOPInstanceUID) was read instead"
                ));
            }
            return Ok(decoded);
        }
    }
    Err(error)
}

/// Decodes every frame (`channels` samples a pixel, interleaved) and places the slices as
/// `geometry` says: one plane per channel, each `dims` in size.
fn samples_of<T: Stored>(
    files: &Files<'_>,
    series: &Series,
    geometry: &Geometry,
    channels: usize,
    progress: Option<&LoadProgress>,
    notes: &Mutex<Vec<String>>,
    convert: &Convert<'_, T>,
) -> Result<Vec<Vec<T>>, VolumeError> {
    let n = series.frames.len();
    let [x, y, _] = geometry.dims;
    let plane = x as usize * y as usize;
    let (slot_of, slots): (Vec<Option<usize>>, usize) = match &geometry.plan {
        SlicePlan::Stack(order) => {
            let mut slot_of = vec![None; n];
            for (k, &frame) in order.iter().enumerate() {
                slot_of[frame] = Some(k);
            }
            (slot_of, order.len())
        }
        SlicePlan::Resample(_) => ((0..n).map(Some).collect(), n),
    };
    let interleaved = decode_into(
        files,
        series,
        &slot_of,
        slots,
        plane * channels,
        progress,
        notes,
        convert,
    )?;
    let stacks: Vec<Vec<T>> = if channels == 1 {
        vec![interleaved]
    } else {
        let mut planes = Vec::with_capacity(channels);
        for c in 0..channels {
            let mut p = allocate::<T>(plane * slots)?;
            for (o, v) in p
                .iter_mut()
                .zip(interleaved.iter().skip(c).step_by(channels))
            {
                *o = *v;
            }
            planes.push(p);
        }
        planes
    };
    let SlicePlan::Resample(plan) = &geometry.plan else {
        return Ok(stacks);
    };
    stacks
        .into_iter()
        .map(|stack| {
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
        })
        .collect()
}

/// Decodes and places a grey series as `geometry` says, in type `T`.
fn grey_samples_of<T: Stored>(
    files: &Files<'_>,
    series: &Series,
    geometry: &Geometry,
    per_frame: Option<&[Rescale]>,
    progress: Option<&LoadProgress>,
    notes: &Mutex<Vec<String>>,
) -> Result<Vec<T>, VolumeError> {
    let convert = |bytes: &[u8],
                   header: &FrameHeader,
                   decoded: &Decoded,
                   index: usize,
                   slot: &mut [T]|
     -> Result<(), String> {
        convert_frame(bytes, &header.pixel, decoded.encapsulated, slot);
        if let Some(rescale) = per_frame {
            let r = rescale[index];
            slot.iter_mut()
                .for_each(|v| *v = T::from_f64_rounded(v.to_f64() * r.slope + r.intercept));
        }
        Ok(())
    };
    let mut planes = samples_of(files, series, geometry, 1, progress, notes, &convert)?;
    Ok(planes.pop().unwrap_or_default())
}

/// Decodes and places a colour series as `geometry` says: its channels, in type `T`.
fn colour_channels_of<T: Stored>(
    files: &Files<'_>,
    series: &Series,
    geometry: &Geometry,
    progress: Option<&LoadProgress>,
    notes: &Mutex<Vec<String>>,
    palette_bits: &AtomicU16,
) -> Result<Vec<Vec<T>>, VolumeError> {
    let convert = |bytes: &[u8],
                   header: &FrameHeader,
                   decoded: &Decoded,
                   _index: usize,
                   slot: &mut [T]|
     -> Result<(), String> {
        let layout = match decoded.codec {
            None => Layout::Native,
            Some(codec) => Layout::Decoded {
                rgb: codec == Codec::Jpeg,
            },
        };
        if let Some(p) = &decoded.palette {
            palette_bits.fetch_max(p.bits, Ordering::Relaxed);
        }
        let pixels = header.rows as usize * header.columns as usize;
        let rgb = frame_rgb(
            bytes,
            &header.pixel,
            layout,
            decoded.palette.as_ref(),
            pixels,
        )?;
        for (o, v) in slot.iter_mut().zip(rgb) {
            *o = T::from_i64(i64::from(v));
        }
        Ok(())
    };
    samples_of(files, series, geometry, 3, progress, notes, &convert)
}

/// A colour series' channels, in the narrowest unsigned type of their bits.
fn colour_of(
    files: &Files<'_>,
    series: &Series,
    geometry: &Geometry,
    progress: Option<&LoadProgress>,
    notes: &Mutex<Vec<String>>,
) -> Result<Colour, VolumeError> {
    let pixel = &series.frames[0].pixel;
    let palette = pixel.photometric == Photometric::Palette;
    let bits = pixel.bits_stored;
    let palette_bits = AtomicU16::new(0);
    let args = (files, series, geometry, progress, notes, &palette_bits);
    let channels: [Samples; 3] = if !palette && bits <= 8 {
        let [r, g, b] = three(colour_channels_of::<u8>(
            args.0, args.1, args.2, args.3, args.4, args.5,
        )?);
        [Samples::U8(r), Samples::U8(g), Samples::U8(b)]
    } else if palette || bits <= 16 {
        let [r, g, b] = three(colour_channels_of::<u16>(
            args.0, args.1, args.2, args.3, args.4, args.5,
        )?);
        [Samples::U16(r), Samples::U16(g), Samples::U16(b)]
    } else {
        let [r, g, b] = three(colour_channels_of::<u32>(
            args.0, args.1, args.2, args.3, args.4, args.5,
        )?);
        [Samples::U32(r), Samples::U32(g), Samples::U32(b)]
    };
    let bits = if palette {
        palette_bits.load(Ordering::Relaxed).max(8)
    } else {
        bits
    };
    Colour::new(channels, bits).ok_or_else(|| {
        DicomError::Decode {
            file: series.frames[0].label.clone(),
            reason: "the colour channels differ in size".into(),
        }
        .into()
    })
}

/// The three planes `samples_of` returns for three channels.
fn three<T>(planes: Vec<Vec<T>>) -> [Vec<T>; 3] {
    let mut it = planes.into_iter();
    std::array::from_fn(|_| it.next().unwrap_or_default())
}

fn assemble_samples(
    files: &Files<'_>,
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
    limits::admit(progress, geometry.dims, stored, false)?;
    if let Some(p) = progress {
        let plane = first.rows as u64 * first.columns as u64;
        p.start(plane * series.frames.len() as u64 * stored.size_bytes() as u64);
    }
    let per_frame = (!uniform).then_some(rescales.as_slice());
    let stream_notes = Mutex::new(Vec::new());
    let (f, s, g, n) = (files, series, geometry, &stream_notes);
    let samples = match stored {
        ScalarType::U8 => Samples::U8(grey_samples_of(f, s, g, per_frame, progress, n)?),
        ScalarType::I8 => Samples::I8(grey_samples_of(f, s, g, per_frame, progress, n)?),
        ScalarType::U16 => Samples::U16(grey_samples_of(f, s, g, per_frame, progress, n)?),
        ScalarType::I16 => Samples::I16(grey_samples_of(f, s, g, per_frame, progress, n)?),
        ScalarType::U32 => Samples::U32(grey_samples_of(f, s, g, per_frame, progress, n)?),
        ScalarType::I32 => Samples::I32(grey_samples_of(f, s, g, per_frame, progress, n)?),
        ScalarType::F32 | ScalarType::F64 => {
            Samples::F32(grey_samples_of(f, s, g, per_frame, progress, n)?)
        }
    };
    notes.extend(stream_notes.into_inner().unwrap_or_default());
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

/// The name of a colour photometric interpretation, for notes.
fn colour_name(photometric: Photometric) -> &'static str {
    match photometric {
        Photometric::Rgb => "RGB",
        Photometric::YbrFull | Photometric::YbrFull422 => "YCbCr, converted to RGB",
        Photometric::YbrDecodedToRgb => "YCbCr, converted to RGB by its codec",
        Photometric::Palette => "palette colour",
        _ => "colour",
    }
}

/// Reads `series` (its frames from `paths`; `alternatives` names copies of a file to read where
/// it cannot be decoded) into a volume named `name`.
pub(crate) fn read_series(
    paths: &[PathBuf],
    alternatives: &Alternatives,
    series: &Series,
    name: String,
    progress: Option<&LoadProgress>,
) -> Result<Volume, VolumeError> {
    let files = &Files {
        paths,
        alternatives,
    };
    let first = series.frames.first().ok_or_else(|| DicomError::Geometry {
        reason: "the series has no frame".into(),
    })?;
    if let Some(why) = first.pixel.unsupported() {
        return Err(DicomError::Unsupported {
            file: first.label.clone(),
            why,
        }
        .into());
    }
    let geometry =
        assemble(&series.frames)?.strided(progress.map_or(1, LoadProgress::slice_stride));
    let colour = first.pixel.photometric.is_colour();
    let (volume, mut notes) = if colour {
        let stored = if first.pixel.bits_stored <= 8 {
            ScalarType::U8
        } else {
            ScalarType::U16
        };
        let (_, bytes) = limits::check_dims(geometry.dims.map(u64::from), stored)?;
        check_files_can_hold(files, series, bytes.saturating_mul(4))?;
        limits::admit(progress, geometry.dims, ScalarType::U8, true)?;
        if let Some(p) = progress {
            p.start(bytes.saturating_mul(3));
        }
        let stream_notes = Mutex::new(Vec::new());
        let channels = colour_of(files, series, &geometry, progress, &stream_notes)?;
        let mut notes = stream_notes.into_inner().unwrap_or_default();
        notes.push(format!(
            "a colour image ({}): shown in its own colours; the transfer function's opacity \
             and the statistics follow its luminance (0-255)",
            colour_name(first.pixel.photometric)
        ));
        let volume = Volume::new_colour(name, geometry.dims, geometry.spacing_mm, channels)?;
        (volume, notes)
    } else {
        let Assembled {
            samples,
            mapping,
            notes,
        } = assemble_samples(files, series, &geometry, progress)?;
        let volume = Volume::new(name, geometry.dims, geometry.spacing_mm, samples, mapping)?;
        (volume, notes)
    };
    notes.splice(0..0, geometry.notes.iter().cloned());
    let orientation =
        Orientation::from_lps_columns(geometry.axes_lps).map(|o| match geometry.axes_from {
            AxesFrom::Stored => o.said_by(OrientationSource::AsStored),
            _ => o,
        });
    // The window is in data units: it applies after the rescale (PS3.3 C.11.2.1.2); colour
    // images have none.
    let window = (!colour).then(|| first.window_range()).flatten();
    let volume = volume
        .with_orientation(orientation)
        .with_modality(Modality::parse(&series.facts.modality));
    Ok(volume.with_provenance(crate::volume::model::Provenance {
        notes,
        window,
        series: Some(series.facts.clone()),
        origin_lps: (geometry.axes_from == AxesFrom::Plane).then_some(geometry.origin_lps),
        invert_grey: first.pixel.photometric == Photometric::Monochrome1,
        ..Default::default()
    }))
}
