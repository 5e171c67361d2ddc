//! DICOM Segmentation objects (PS3.3 A.51, C.8.20), read with dicom-rs: the segments (number,
//! label, recommended display CIELab colour), the frames (each one plane of one segment, placed
//! by its functional groups' position and the shared orientation and pixel spacing), binary
//! (1 bit a pixel, packed across frames) or fractional (8 bits, shown where at least half the
//! maximum), native or compressed (RLE, JPEG-LS, JPEG 2000, JPEG: each frame decoded by the
//! volume reader's codecs). The frames are put on the SEG's own grid, one layer per set of segments that do not
//! overlap.

use std::path::Path;

use dicom_dictionary_std::{tags, uids};
use dicom_object::{InMemDicomObject, OpenFileOptions};
use glam::{DMat3, DVec3};

use super::names::Described;
use crate::volume::dicom::codec::{Codec, FrameSpec, fragments};
use crate::volume::dicom::guard::{self, Encoding, ImplicitForExplicit};
use crate::volume::dicom::tags::{Object, first_item, floats, group_attr, text, us};

/// Most layers of overlapping segments taken.
const MOST_LAYERS: usize = 16;

/// Most voxels of the SEG's own grid: 2³¹, and no more than [`GRID_PER_IMAGE`] times the
/// image's (a few frames far apart would otherwise ask for a grid of gigabytes).
const MOST_VOXELS: u64 = 1 << 31;

/// How many times the image's voxels a SEG's grid may hold (finer in-plane, say), plus 2²⁰.
const GRID_PER_IMAGE: u64 = 8;

/// A DICOM SEG on its own grid.
pub(super) struct Seg {
    /// Its segments, each with its layer.
    pub described: Vec<Described>,
    /// The layers' segment numbers per voxel of the grid, x fastest.
    pub layers: Vec<Vec<u16>>,
    /// The grid's dimensions: columns, rows, planes.
    pub dims: [u32; 3],
    /// One step along each grid axis in patient millimetres (LPS): the matrix's columns.
    pub axes: DMat3,
    /// The patient position of voxel (0, 0, 0).
    pub origin: DVec3,
    /// The series it references (`ReferencedSeriesSequence`).
    pub referenced_series: Vec<String>,
    /// Its `FrameOfReferenceUID`.
    pub frame_of_reference: String,
    /// What a user should know (fractional segments thresholded).
    pub notes: Vec<String>,
}

/// The DICOM file at `path` as dicom-rs reads it (up to its pixel data where `headers_only`),
/// once its lengths are checked; `None` where they lie or dicom-rs cannot read it (the volume
/// reader then says why).
fn open(path: &Path, headers_only: bool) -> Option<Object> {
    let options = OpenFileOptions::new();
    let options = if headers_only {
        options.read_until(tags::PIXEL_DATA)
    } else {
        options
    };
    // dicom-rs allocates what a length says before reading: lying lengths are refused first.
    match guard::check_lengths(path).ok()? {
        Encoding::AsDeclared => options.open_file(path),
        Encoding::ImplicitForExplicit => options
            .transfer_syntax_index(ImplicitForExplicit)
            .open_file(path),
    }
    .ok()
}

/// Whether `obj` is a segmentation.
fn is_seg_object(obj: &InMemDicomObject) -> bool {
    text(obj.get(tags::SOP_CLASS_UID)) == uids::SEGMENTATION_STORAGE
        || text(obj.get(tags::MODALITY)) == "SEG"
}

/// Whether the DICOM file at `path` is a segmentation (one whose lengths lie is not: it is
/// refused as a volume then, with the reason).
pub(super) fn is_seg(path: &Path) -> bool {
    open(path, true).is_some_and(|obj| is_seg_object(&obj))
}

/// One frame: its segment and where it lies.
struct Frame {
    segment: u16,
    position: DVec3,
}

/// Reads the SEG at `path` for an image of `image_voxels`: `None` where the DICOM file is no
/// segmentation (or cannot be read as one: the volume reader says why), the reason where it is one
/// that cannot be shown.
pub(super) fn read(path: &Path, image_voxels: u64) -> Result<Option<Seg>, String> {
    let Some(obj) = open(path, false).filter(|obj| is_seg_object(obj)) else {
        return Ok(None);
    };
    let syntax = obj
        .meta()
        .transfer_syntax()
        .trim_end_matches('\0')
        .to_string();
    let number = |tag, what: &str| -> Result<u32, String> {
        us(obj.get(tag))
            .or_else(|| crate::volume::dicom::tags::int(obj.get(tag)))
            .and_then(|v| u32::try_from(v).ok())
            .filter(|&v| v > 0)
            .ok_or_else(|| format!("no usable {what}"))
    };
    let rows = number(tags::ROWS, "Rows")?;
    let cols = number(tags::COLUMNS, "Columns")?;
    let frames_count = number(tags::NUMBER_OF_FRAMES, "NumberOfFrames")?;
    let bits = number(tags::BITS_ALLOCATED, "BitsAllocated")?;
    let kind = text(obj.get(tags::SEGMENTATION_TYPE));
    let fractional = match (kind.as_str(), bits) {
        ("BINARY", 1) => None,
        ("FRACTIONAL", 8) => Some(
            us(obj.get(tags::MAXIMUM_FRACTIONAL_VALUE))
                .filter(|&m| m > 0)
                .ok_or("a FRACTIONAL segmentation without MaximumFractionalValue")?,
        ),
        (kind, bits) => {
            return Err(format!(
                "SegmentationType {kind} with BitsAllocated {bits} is not a segmentation \
                 LeapView reads (BINARY with 1 bit, FRACTIONAL with 8)"
            ));
        }
    };
    let described = segments(&obj)?;
    let shared = first_item(&obj, tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE);
    let per_frame = obj
        .get(tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE)
        .and_then(|e| e.items())
        .ok_or("no PerFrameFunctionalGroupsSequence: the frames cannot be placed")?;
    if per_frame.len() != frames_count as usize {
        return Err(format!(
            "{} per-frame functional groups for {frames_count} frames",
            per_frame.len()
        ));
    }
    let frames = per_frame
        .iter()
        .enumerate()
        .map(|(i, item)| frame(i, item, shared, &described))
        .collect::<Result<Vec<_>, _>>()?;
    let orientation = floats(group_attr(
        per_frame.first(),
        shared,
        tags::PLANE_ORIENTATION_SEQUENCE,
        tags::IMAGE_ORIENTATION_PATIENT,
    ))
    .filter(|v| v.len() == 6)
    .ok_or("no ImageOrientationPatient in the functional groups")?;
    let spacing = floats(group_attr(
        per_frame.first(),
        shared,
        tags::PIXEL_MEASURES_SEQUENCE,
        tags::PIXEL_SPACING,
    ))
    .filter(|v| v.len() == 2 && v.iter().all(|s| s.is_finite() && *s > 0.0))
    .ok_or("no usable PixelSpacing in the functional groups")?;
    let between = floats(group_attr(
        per_frame.first(),
        shared,
        tags::PIXEL_MEASURES_SEQUENCE,
        tags::SPACING_BETWEEN_SLICES,
    ))
    .and_then(|v| v.first().copied())
    .filter(|s| s.is_finite() && *s > 0.0);
    let row_dir = DVec3::new(orientation[0], orientation[1], orientation[2]).normalize_or_zero();
    let col_dir = DVec3::new(orientation[3], orientation[4], orientation[5]).normalize_or_zero();
    let normal = row_dir.cross(col_dir);
    if normal.length() < 0.99 {
        return Err("ImageOrientationPatient is not two perpendicular directions".into());
    }
    let grid = Grid::of(&frames, normal, between)?;
    let dims = [cols, rows, grid.planes];
    let voxels = dims.iter().map(|&d| u64::from(d)).product::<u64>();
    let most = MOST_VOXELS.min(image_voxels.saturating_mul(GRID_PER_IMAGE) + (1 << 20));
    if voxels > most {
        return Err(format!(
            "its frames span a grid of {cols}×{rows}×{} voxels, far more than the image's \
             {image_voxels}: is it of another scan?",
            grid.planes
        ));
    }
    let pixel_data = obj
        .get(tags::PIXEL_DATA)
        .ok_or("the file holds no PixelData element")?;
    let plane = rows as usize * cols as usize;
    let samples = match pixel_data.value() {
        dicom_core::DicomValue::PixelSequence(sequence) => {
            let spec = FrameSpec {
                rows,
                columns: cols,
                samples_per_pixel: 1,
                bits_allocated: bits as u16,
                bits_stored: bits as u16,
                signed: false,
                rgb: false,
            };
            decoded(&syntax, sequence, frames.len(), &spec)?
        }
        _ => {
            let bytes = pixel_data.to_bytes().map_err(|e| e.to_string())?;
            let needed = (plane * frames.len() * bits as usize).div_ceil(8);
            if bytes.len() < needed {
                return Err(format!(
                    "its pixel data holds {} bytes, {needed} are needed for {} frames of \
                     {cols}×{rows}",
                    bytes.len(),
                    frames.len()
                ));
            }
            match fractional {
                // Binary frames are packed across frames, a bit a pixel.
                None => (0..plane * frames.len())
                    .map(|i| bytes[i / 8] >> (i % 8) & 1)
                    .collect(),
                Some(_) => bytes[..plane * frames.len()].to_vec(),
            }
        }
    };
    let inside = |f: usize, p: usize| -> bool {
        let v = samples[f * plane + p];
        match fractional {
            None => v != 0,
            Some(max) => i64::from(v) * 2 >= max,
        }
    };
    let mut layers: Vec<Vec<u16>> = Vec::new();
    let mut placed = Vec::with_capacity(described.len());
    for segment in &described {
        // The segment's voxels on the grid.
        let mine: Vec<usize> = frames
            .iter()
            .enumerate()
            .filter(|(_, f)| f.segment == segment.value)
            .flat_map(|(f, frame)| {
                let k = grid.plane_of(frame.position, normal);
                (0..plane)
                    .filter(move |&p| inside(f, p))
                    .map(move |p| k * plane + p)
            })
            .collect();
        let free = layers
            .iter()
            .position(|layer| mine.iter().all(|&v| layer[v] == 0));
        let layer = match free {
            Some(l) => l,
            None if layers.len() < MOST_LAYERS => {
                layers.push(vec![0; voxels as usize]);
                layers.len() - 1
            }
            None => {
                return Err(format!(
                    "its segments overlap more than {MOST_LAYERS} deep, which LeapView does not show"
                ));
            }
        };
        for &v in &mine {
            layers[layer][v] = segment.value;
        }
        placed.push(Described {
            layer: layer as u16,
            ..segment.clone()
        });
    }
    if layers.is_empty() {
        layers.push(vec![0; voxels as usize]);
    }
    let origin = grid.origin;
    let axes = DMat3::from_cols(
        row_dir * spacing[1],
        col_dir * spacing[0],
        normal * grid.step,
    );
    let referenced_series = obj
        .get(tags::REFERENCED_SERIES_SEQUENCE)
        .and_then(|e| e.items())
        .map(|items| {
            items
                .iter()
                .map(|i| text(i.get(tags::SERIES_INSTANCE_UID)))
                .filter(|u| !u.is_empty())
                .collect()
        })
        .unwrap_or_default();
    let mut notes = Vec::new();
    if let Some(max) = fractional {
        notes.push(format!(
            "fractional segments shown where at least half their maximum ({max}) holds"
        ));
    }
    Ok(Some(Seg {
        described: placed,
        layers,
        dims,
        axes,
        origin,
        referenced_series,
        frame_of_reference: text(obj.get(tags::FRAME_OF_REFERENCE_UID)),
        notes,
    }))
}

/// The frames of encapsulated pixel data (`frames` of `spec`) decoded, a byte a pixel (0 or 1
/// for binary frames, the fraction for fractional ones), each codestream checked against the
/// header by the volume reader's codecs.
fn decoded(
    syntax: &str,
    sequence: &dicom_core::value::PixelFragmentSequence<Vec<u8>>,
    frames: usize,
    spec: &FrameSpec,
) -> Result<Vec<u8>, String> {
    let codec = Codec::of(syntax).ok_or_else(|| {
        format!("its pixel data is compressed with transfer syntax {syntax}, which LeapView does not decode")
    })?;
    let streams =
        fragments::frame_streams(sequence.fragments(), sequence.offset_table(), frames as u32)?;
    let plane = spec.pixels();
    let mut samples = Vec::new();
    samples
        .try_reserve_exact(plane * frames)
        .map_err(|_| "not enough memory for its decoded frames".to_string())?;
    for (f, stream) in streams.iter().enumerate() {
        let frame = codec
            .decode(stream, spec)
            .map_err(|e| format!("{} frame {}: {e}", codec.name(), f + 1))?;
        if frame.bytes.len() != plane {
            return Err(format!(
                "{} frame {} decodes to {} bytes where {plane} pixels of one byte were expected",
                codec.name(),
                f + 1,
                frame.bytes.len()
            ));
        }
        samples.extend_from_slice(&frame.bytes);
    }
    Ok(samples)
}

/// The segments of `SegmentSequence`: number, label, colour.
fn segments(obj: &InMemDicomObject) -> Result<Vec<Described>, String> {
    let items = obj
        .get(tags::SEGMENT_SEQUENCE)
        .and_then(|e| e.items())
        .filter(|items| !items.is_empty())
        .ok_or("no SegmentSequence: the file describes no segment")?;
    items
        .iter()
        .map(|item| {
            let value = us(item.get(tags::SEGMENT_NUMBER))
                .and_then(|n| u16::try_from(n).ok())
                .filter(|&n| n > 0)
                .ok_or("a segment without a usable SegmentNumber")?;
            let colour = item
                .get(tags::RECOMMENDED_DISPLAY_CIE_LAB_VALUE)
                .and_then(|e| e.to_multi_int::<u16>().ok())
                .filter(|v| v.len() == 3)
                .map(|v| dicom_lab_to_srgb([v[0], v[1], v[2]]));
            let name = text(item.get(tags::SEGMENT_LABEL));
            Ok(Described {
                value,
                layer: 0,
                name: if name.is_empty() {
                    format!("segment {value}")
                } else {
                    name
                },
                colour,
            })
        })
        .collect()
}

/// Frame `i`'s segment and position, from its functional groups (`item`), else the shared ones
/// (a SEG of one segment names it there).
fn frame(
    i: usize,
    item: &InMemDicomObject,
    shared: Option<&InMemDicomObject>,
    described: &[Described],
) -> Result<Frame, String> {
    let segment = us(group_attr(
        Some(item),
        shared,
        tags::SEGMENT_IDENTIFICATION_SEQUENCE,
        tags::REFERENCED_SEGMENT_NUMBER,
    ))
    .and_then(|n| u16::try_from(n).ok())
    .ok_or_else(|| format!("frame {} names no segment", i + 1))?;
    if !described.iter().any(|d| d.value == segment) {
        return Err(format!(
            "frame {} is of segment {segment}, which SegmentSequence does not describe",
            i + 1
        ));
    }
    let position = floats(group_attr(
        Some(item),
        shared,
        tags::PLANE_POSITION_SEQUENCE,
        tags::IMAGE_POSITION_PATIENT,
    ))
    .filter(|v| v.len() == 3 && v.iter().all(|c| c.is_finite()))
    .ok_or_else(|| format!("frame {} has no ImagePositionPatient", i + 1))?;
    Ok(Frame {
        segment,
        position: DVec3::new(position[0], position[1], position[2]),
    })
}

/// Where the frames' planes lie along the normal: the first plane's position, the step between
/// planes and their number.
struct Grid {
    origin: DVec3,
    first: f64,
    step: f64,
    planes: u32,
}

impl Grid {
    /// The planes of `frames` along `normal`, `between` apart where the file says, else the
    /// smallest distance between two of them. Every frame must lie on the grid.
    fn of(frames: &[Frame], normal: DVec3, between: Option<f64>) -> Result<Self, String> {
        let lowest = frames
            .iter()
            .min_by(|a, b| normal.dot(a.position).total_cmp(&normal.dot(b.position)))
            .ok_or("the segmentation has no frame")?;
        let first = normal.dot(lowest.position);
        let mut depths: Vec<f64> = frames
            .iter()
            .map(|f| normal.dot(f.position) - first)
            .collect();
        depths.sort_by(f64::total_cmp);
        depths.dedup_by(|a, b| (*a - *b).abs() < 1e-3);
        let step = between
            .or_else(|| {
                depths
                    .windows(2)
                    .map(|w| w[1] - w[0])
                    .min_by(f64::total_cmp)
            })
            .unwrap_or(1.0);
        let grid = Self {
            origin: lowest.position,
            first,
            step,
            planes: 0,
        };
        let mut planes = 0u32;
        for f in frames {
            let along = (normal.dot(f.position) - first) / step;
            let off_plane = (along - along.round()).abs() * step;
            let sideways = (f.position - lowest.position) - normal * (along * step);
            if off_plane > 0.01 * step.max(0.1) || sideways.length() > 0.01 {
                return Err(
                    "its frames do not lie on one grid of evenly spaced planes, which LeapView \
                     does not read yet"
                        .into(),
                );
            }
            let k = along.round();
            if k >= f64::from(u16::MAX) {
                return Err("its frames span more than 65535 planes".into());
            }
            planes = planes.max(k as u32 + 1);
        }
        Ok(Self { planes, ..grid })
    }

    /// The plane holding a frame at `position` (on the grid: checked by [`Grid::of`]).
    fn plane_of(&self, position: DVec3, normal: DVec3) -> usize {
        ((normal.dot(position) - self.first) / self.step).round() as usize
    }
}

/// sRGB of a DICOM CIELab value (PS3.3 C.10.7.1.1: L* 0…100 and a*, b* −128…127 scaled to
/// 0…65535), through CIE XYZ with the D65 white point, as dcmtk and highdicom convert it.
pub(super) fn dicom_lab_to_srgb(lab: [u16; 3]) -> [u8; 3] {
    let l = f64::from(lab[0]) * 100.0 / 65535.0;
    let a = f64::from(lab[1]) * 255.0 / 65535.0 - 128.0;
    let b = f64::from(lab[2]) * 255.0 / 65535.0 - 128.0;
    let inverse = |t: f64| {
        if t > 6.0 / 29.0 {
            t.powi(3)
        } else {
            3.0 * (6.0f64 / 29.0).powi(2) * (t - 4.0 / 29.0)
        }
    };
    let fy = (l + 16.0) / 116.0;
    let [x, y, z] = [
        0.950_456 * inverse(fy + a / 500.0),
        inverse(fy),
        1.088_754 * inverse(fy - b / 200.0),
    ];
    let linear = [
        3.240_479 * x - 1.537_150 * y - 0.498_535 * z,
        -0.969_256 * x + 1.875_992 * y + 0.041_556 * z,
        0.055_648 * x - 0.204_043 * y + 1.057_311 * z,
    ];
    linear.map(|c| {
        let c = c.clamp(0.0, 1.0);
        let s = if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        };
        (s * 255.0).round() as u8
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cielab_white_black_and_a_red_come_out_as_srgb() {
        // L* 100, a* = b* = 0 (0.5 of the scale is 127.5 − 128 ≈ −0.5: nearly neutral).
        let white = dicom_lab_to_srgb([65535, 32896, 32896]);
        assert!(white.iter().all(|&c| c >= 253), "{white:?}");
        assert_eq!(dicom_lab_to_srgb([0, 32896, 32896]), [0, 0, 0]);
        // sRGB red is L* 53.24, a* 80.09, b* 67.20 (D65).
        let scale = |v: f64, lo: f64, span: f64| ((v - lo) / span * 65535.0).round() as u16;
        let red = dicom_lab_to_srgb([
            scale(53.24, 0.0, 100.0),
            scale(80.09, -128.0, 255.0),
            scale(67.20, -128.0, 255.0),
        ]);
        assert!(red[0] >= 250 && red[1] <= 5 && red[2] <= 5, "{red:?}");
    }
}
