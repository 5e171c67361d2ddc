//! Reads a [`FrameHeader`] for every frame of a DICOM object (dicom-rs), from the classic image
//! modules, the enhanced objects' functional groups (PS3.3 C.7.6.16: plane position, orientation,
//! pixel measures, value transformation, VOI LUT per frame or shared) or an RT dose grid's
//! `GridFrameOffsetVector` (PS3.3 C.8.8.3.2).

use dicom_core::VR;
use dicom_dictionary_std::{tags, uids};
use dicom_object::InMemDicomObject;
use dicom_object::mem::InMemElement;

use super::header::{FrameHeader, Photometric, PixelFormat, Rescale, SeriesFacts};
use crate::volume::error::dicom::DicomError;

/// A DICOM object as dicom-rs reads a file.
pub type Object = dicom_object::DefaultDicomObject;

/// What a DICOM file holds, as far as volumes go.
#[derive(Debug)]
pub enum Contents {
    /// Image frames.
    Image(Vec<FrameHeader>),
    /// Something that is not an image: what it is, for messages and counts.
    NotImage(&'static str),
}

/// The names people know non-image objects by, from their SOP class.
fn not_an_image(sop_class: &str) -> Option<&'static str> {
    Some(match sop_class {
        uids::MEDIA_STORAGE_DIRECTORY_STORAGE => "a DICOMDIR (an index of files)",
        uids::SEGMENTATION_STORAGE => "a DICOM segmentation (SEG)",
        uids::RT_STRUCTURE_SET_STORAGE => "an RT structure set",
        uids::RT_PLAN_STORAGE | uids::RT_ION_PLAN_STORAGE => "an RT plan",
        uids::GRAYSCALE_SOFTCOPY_PRESENTATION_STATE_STORAGE => "a presentation state",
        uids::KEY_OBJECT_SELECTION_DOCUMENT_STORAGE => "a key object selection",
        s if s.starts_with("1.2.840.10008.5.1.4.1.1.88.") => "a structured report (SR)",
        _ => return None,
    })
}

/// Whether `uid` is one of the uncompressed transfer syntaxes.
fn is_uncompressed(uid: &str) -> bool {
    matches!(
        uid,
        uids::IMPLICIT_VR_LITTLE_ENDIAN
            | uids::EXPLICIT_VR_LITTLE_ENDIAN
            | super::header::EXPLICIT_VR_BIG_ENDIAN
    )
}

/// A DICOM text value without its padding (spaces, NULs).
pub(crate) fn trimmed(s: &str) -> String {
    s.trim_matches(|c: char| c.is_whitespace() || c == '\0')
        .to_string()
}

/// An element whose VR the file gave as UN (unknown): its bytes, which dicom-rs keeps as such.
/// Writers use UN for attributes they do not know; the standard VR of everything read here is
/// text but for the US attributes, which [`us`] reads.
fn unknown_bytes(el: &InMemElement) -> Option<Vec<u8>> {
    (el.vr() == VR::UN).then(|| el.to_bytes().map(|b| b.into_owned()).unwrap_or_default())
}

/// A text attribute, trimmed (empty where absent).
pub(crate) fn text(el: Option<&InMemElement>) -> String {
    let Some(el) = el else {
        return String::new();
    };
    match unknown_bytes(el) {
        Some(bytes) => trimmed(&String::from_utf8_lossy(&bytes)),
        None => el.to_str().map(|s| trimmed(&s)).unwrap_or_default(),
    }
}

/// A multi-valued decimal attribute.
pub(crate) fn floats(el: Option<&InMemElement>) -> Option<Vec<f64>> {
    let el = el?;
    match unknown_bytes(el) {
        Some(_) => text(Some(el))
            .split('\\')
            .map(|v| v.trim().parse::<f64>().ok())
            .collect(),
        None => el.to_multi_float64().ok(),
    }
}

fn float(el: Option<&InMemElement>) -> Option<f64> {
    floats(el).and_then(|v| v.first().copied())
}

/// An integer string (IS) attribute.
pub(crate) fn int(el: Option<&InMemElement>) -> Option<i64> {
    let el = el?;
    match unknown_bytes(el) {
        Some(_) => text(Some(el)).split('\\').next()?.trim().parse().ok(),
        None => el.to_int::<i64>().ok(),
    }
}

/// An unsigned short (US) attribute.
pub(crate) fn us(el: Option<&InMemElement>) -> Option<i64> {
    let el = el?;
    match unknown_bytes(el) {
        Some(b) if b.len() >= 2 => Some(i64::from(u16::from_le_bytes([b[0], b[1]]))),
        Some(_) => None,
        None => el.to_int::<i64>().ok(),
    }
}

fn array<const N: usize>(el: Option<&InMemElement>) -> Option<[f64; N]> {
    let v = floats(el)?;
    (v.len() >= N).then(|| std::array::from_fn(|i| v[i]))
}

/// The first item of sequence `seq` in `item`.
pub(crate) fn first_item(
    item: &InMemDicomObject,
    seq: dicom_core::Tag,
) -> Option<&InMemDicomObject> {
    item.get(seq)?.items()?.first()
}

/// An attribute of a functional group macro, from the frame's item, else the shared one.
pub(crate) fn group_attr<'a>(
    frame: Option<&'a InMemDicomObject>,
    shared: Option<&'a InMemDicomObject>,
    macro_seq: dicom_core::Tag,
    attr: dicom_core::Tag,
) -> Option<&'a InMemElement> {
    [frame, shared]
        .into_iter()
        .flatten()
        .find_map(|g| first_item(g, macro_seq)?.get(attr))
}

fn field_error(
    label: &str,
    field: &'static str,
    value: String,
    expected: &'static str,
) -> DicomError {
    DicomError::BadField {
        file: label.to_string(),
        field,
        value,
        expected,
    }
}

fn pixel_format(obj: &Object, label: &str) -> Result<PixelFormat, DicomError> {
    let get = |t| us(obj.get(t));
    let allocated = get(tags::BITS_ALLOCATED).ok_or_else(|| {
        field_error(
            label,
            "BitsAllocated",
            "missing".into(),
            "an image needs it",
        )
    })?;
    if !matches!(allocated, 1 | 8 | 16 | 32) {
        return Err(field_error(
            label,
            "BitsAllocated",
            allocated.to_string(),
            "LeapView reads 8, 16 and 32 bits",
        ));
    }
    let stored = get(tags::BITS_STORED).unwrap_or(allocated);
    if stored < 1 || stored > allocated {
        return Err(field_error(
            label,
            "BitsStored",
            stored.to_string(),
            "it must be between 1 and BitsAllocated",
        ));
    }
    let high = get(tags::HIGH_BIT).unwrap_or(stored - 1);
    let high = if high < stored - 1 || high >= allocated {
        stored - 1
    } else {
        high
    };
    let samples = get(tags::SAMPLES_PER_PIXEL).unwrap_or(1);
    if !(1..=4).contains(&samples) {
        return Err(field_error(
            label,
            "SamplesPerPixel",
            samples.to_string(),
            "it must be 1 (grey) or 3 (colour)",
        ));
    }
    Ok(PixelFormat {
        bits_allocated: allocated as u16,
        bits_stored: stored as u16,
        high_bit: high as u16,
        signed: get(tags::PIXEL_REPRESENTATION) == Some(1),
        samples_per_pixel: samples as u16,
        photometric: Photometric::parse(&text(obj.get(tags::PHOTOMETRIC_INTERPRETATION))),
        planar: get(tags::PLANAR_CONFIGURATION) == Some(1),
    })
}

/// The frames of `obj` (read up to its pixel data), file number `file` of the scan, `file_bytes`
/// long, named `name` in messages.
///
/// `NumberOfFrames` is checked against the file's size before a header is made per frame, so a
/// lying header cannot make this allocate more than the file could hold.
pub fn contents(
    obj: &Object,
    file: usize,
    name: &str,
    file_bytes: u64,
) -> Result<Contents, DicomError> {
    let sop_class = {
        let c = trimmed(obj.meta().media_storage_sop_class_uid());
        if c.is_empty() {
            text(obj.get(tags::SOP_CLASS_UID))
        } else {
            c
        }
    };
    if let Some(what) = not_an_image(&sop_class) {
        return Ok(Contents::NotImage(what));
    }
    let (Some(rows), Some(columns)) = (us(obj.get(tags::ROWS)), us(obj.get(tags::COLUMNS))) else {
        return Ok(Contents::NotImage("a DICOM object without an image"));
    };
    if rows <= 0 || columns <= 0 || rows > 65535 || columns > 65535 {
        return Err(field_error(
            name,
            "Rows x Columns",
            format!("{rows} x {columns}"),
            "each must be between 1 and 65535",
        ));
    }
    let pixel = pixel_format(obj, name)?;
    let ts = trimmed(obj.meta().transfer_syntax());
    let frames = int(obj.get(tags::NUMBER_OF_FRAMES)).unwrap_or(1);
    let frame_bytes = (rows * columns) as u64
        * u64::from(pixel.samples_per_pixel)
        * u64::from(pixel.bits_allocated.div_ceil(8));
    // An encapsulated frame takes at least an 8-byte item header; a native one its bytes.
    let most = if is_uncompressed(&ts) {
        file_bytes / frame_bytes.max(1)
    } else {
        file_bytes / 8
    };
    if frames < 1 || frames as u64 > most.max(1) {
        return Err(field_error(
            name,
            "NumberOfFrames",
            frames.to_string(),
            "it must be at least 1 and no more than the file's size can hold",
        ));
    }
    let frames = frames as u32;
    let instance_uid = text(obj.get(tags::SOP_INSTANCE_UID));
    let date = match text(obj.get(tags::SERIES_DATE)) {
        d if d.is_empty() => text(obj.get(tags::STUDY_DATE)),
        d => d,
    };
    let series = SeriesFacts {
        uid: text(obj.get(tags::SERIES_INSTANCE_UID)),
        number: int(obj.get(tags::SERIES_NUMBER)),
        modality: text(obj.get(tags::MODALITY)),
        description: text(obj.get(tags::SERIES_DESCRIPTION)),
        date,
        frame_of_reference: text(obj.get(tags::FRAME_OF_REFERENCE_UID)),
        sop_class,
    };
    let shared = obj
        .get(tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE)
        .and_then(|e| e.items())
        .and_then(|i| i.first());
    let per_frame = obj
        .get(tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE)
        .and_then(|e| e.items());
    let top_rescale = {
        let slope =
            float(obj.get(tags::RESCALE_SLOPE)).or_else(|| float(obj.get(tags::DOSE_GRID_SCALING)));
        let intercept = float(obj.get(tags::RESCALE_INTERCEPT));
        (slope.is_some() || intercept.is_some()).then(|| Rescale {
            slope: slope.unwrap_or(1.0),
            intercept: intercept.unwrap_or(0.0),
        })
    };
    let top_window = {
        let c = float(obj.get(tags::WINDOW_CENTER));
        let w = float(obj.get(tags::WINDOW_WIDTH));
        c.zip(w).map(|(c, w)| [c, w])
    };
    let orientation = array::<6>(obj.get(tags::IMAGE_ORIENTATION_PATIENT));
    let position = array::<3>(obj.get(tags::IMAGE_POSITION_PATIENT));
    let offsets = floats(obj.get(tags::GRID_FRAME_OFFSET_VECTOR));
    let mut out = Vec::with_capacity(frames as usize);
    for f in 0..frames {
        let item = per_frame.and_then(|items| items.get(f as usize));
        let g = |seq, attr| group_attr(item, shared, seq, attr);
        let orientation = array::<6>(g(
            tags::PLANE_ORIENTATION_SEQUENCE,
            tags::IMAGE_ORIENTATION_PATIENT,
        ))
        .or(orientation);
        let position = match (
            array::<3>(g(
                tags::PLANE_POSITION_SEQUENCE,
                tags::IMAGE_POSITION_PATIENT,
            )),
            &offsets,
        ) {
            (Some(p), _) => Some(p),
            (None, Some(offsets)) if frames > 1 => grid_position(
                position,
                orientation,
                offsets.get(f as usize).copied(),
                offsets,
            ),
            (None, _) if frames > 1 && per_frame.is_none() => None,
            (None, _) => position,
        };
        let rescale = top_rescale
            .or_else(|| {
                let slope = float(g(
                    tags::PIXEL_VALUE_TRANSFORMATION_SEQUENCE,
                    tags::RESCALE_SLOPE,
                ));
                let intercept = float(g(
                    tags::PIXEL_VALUE_TRANSFORMATION_SEQUENCE,
                    tags::RESCALE_INTERCEPT,
                ));
                (slope.is_some() || intercept.is_some()).then(|| Rescale {
                    slope: slope.unwrap_or(1.0),
                    intercept: intercept.unwrap_or(0.0),
                })
            })
            .unwrap_or(Rescale::IDENTITY);
        let window = top_window.or_else(|| {
            let c = float(g(tags::FRAME_VOILUT_SEQUENCE, tags::WINDOW_CENTER));
            let w = float(g(tags::FRAME_VOILUT_SEQUENCE, tags::WINDOW_WIDTH));
            c.zip(w).map(|(c, w)| [c, w])
        });
        let measures = |attr| g(tags::PIXEL_MEASURES_SEQUENCE, attr);
        out.push(FrameHeader {
            file,
            frame: f,
            label: if frames > 1 {
                format!("{name} frame {}", f + 1)
            } else {
                name.to_string()
            },
            frames_in_file: frames,
            series: series.clone(),
            rows: rows as u32,
            columns: columns as u32,
            orientation,
            patient_orientation: Some(text(obj.get(tags::PATIENT_ORIENTATION)))
                .filter(|t| !t.is_empty()),
            position,
            pixel_spacing: array::<2>(obj.get(tags::PIXEL_SPACING))
                .or_else(|| array::<2>(measures(tags::PIXEL_SPACING))),
            slice_thickness: float(obj.get(tags::SLICE_THICKNESS))
                .or_else(|| float(measures(tags::SLICE_THICKNESS))),
            spacing_between_slices: float(obj.get(tags::SPACING_BETWEEN_SLICES))
                .or_else(|| float(measures(tags::SPACING_BETWEEN_SLICES))),
            pixel,
            rescale,
            window,
            instance_number: int(obj.get(tags::INSTANCE_NUMBER)),
            instance_uid: instance_uid.clone(),
            transfer_syntax: ts.clone(),
            implicit_vr: false,
            mosaic: None,
        });
    }
    if frames == 1
        && let Some(facts) = mosaic_facts(obj)
        && let Some(first) = out.first()
    {
        let tiles = super::mosaic::tiles(first, facts).map_err(|reason| DicomError::Decode {
            file: name.to_string(),
            reason: format!("a Siemens mosaic: {reason}"),
        })?;
        return Ok(Contents::Image(tiles));
    }
    Ok(Contents::Image(out))
}

/// The element `element` of the private block whose creator (group, 00xx) contains `creator`.
fn private<'a>(
    obj: &'a Object,
    group: u16,
    creator: &str,
    element: u16,
) -> Option<&'a InMemElement> {
    (0x10u16..=0xFF)
        .find(|&block| text(obj.get(dicom_core::Tag(group, block))).contains(creator))
        .and_then(|block| obj.get(dicom_core::Tag(group, (block << 8) | element)))
}

/// A Siemens mosaic's count of images and slice normal, where `obj` is one (ImageType MOSAIC and
/// a count, from (0019,xx0A) or the CSA image header).
fn mosaic_facts(obj: &Object) -> Option<super::mosaic::MosaicFacts> {
    let image_type = text(obj.get(tags::IMAGE_TYPE)).to_ascii_uppercase();
    if !image_type.split('\\').any(|t| t.trim() == "MOSAIC") {
        return None;
    }
    let csa = private(obj, 0x0029, "SIEMENS CSA HEADER", 0x10)
        .and_then(|e| e.to_bytes().ok())
        .map(|b| b.into_owned());
    let from_csa = |name: &str| csa.as_deref().and_then(|b| super::csa::values(b, name));
    let images = us(private(obj, 0x0019, "SIEMENS MR HEADER", 0x0A))
        .or_else(|| from_csa("NumberOfImagesInMosaic")?.first()?.parse().ok())?;
    let normal = from_csa("SliceNormalVector").and_then(|v| {
        let n: Vec<f64> = v.iter().filter_map(|x| x.parse().ok()).collect();
        (n.len() == 3).then(|| [n[0], n[1], n[2]])
    });
    Some(super::mosaic::MosaicFacts {
        images: u32::try_from(images).ok()?,
        normal,
    })
}

/// An RT dose frame's position: `ImagePositionPatient` moved along the normal by its grid
/// offset. Offsets are relative to the position when the first is 0, else absolute coordinates
/// along the normal (PS3.3 C.8.8.3.2).
fn grid_position(
    position: Option<[f64; 3]>,
    orientation: Option<[f64; 6]>,
    offset: Option<f64>,
    offsets: &[f64],
) -> Option<[f64; 3]> {
    let (p, o, offset) = (position?, orientation?, offset?);
    let n = [
        o[1] * o[5] - o[2] * o[4],
        o[2] * o[3] - o[0] * o[5],
        o[0] * o[4] - o[1] * o[3],
    ];
    let along = if offsets.first() == Some(&0.0) {
        offset
    } else {
        offset - (p[0] * n[0] + p[1] * n[1] + p[2] * n[2])
    };
    Some([
        p[0] + along * n[0],
        p[1] + along * n[1],
        p[2] + along * n[2],
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dose_grid_offsets_are_relative_when_the_first_is_zero() {
        let axial = Some([1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
        let p = Some([1.0, 2.0, 10.0]);
        assert_eq!(
            grid_position(p, axial, Some(5.0), &[0.0, 5.0]),
            Some([1.0, 2.0, 15.0])
        );
        // Absolute: the offsets are z coordinates.
        assert_eq!(
            grid_position(p, axial, Some(15.0), &[10.0, 15.0]),
            Some([1.0, 2.0, 15.0])
        );
    }
}
