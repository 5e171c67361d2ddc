//! Writes a volume as a DICOM series: one uncompressed file (explicit VR little endian) per
//! slice, CT image storage, slices along +z of LPS with the volume's spacing, its value mapping as
//! the rescale. For trying the DICOM path without a scanner's data, and for measuring how fast a
//! large series loads; the tests check the reader against series other software wrote.

use std::path::{Path, PathBuf};

use dicom_core::{DataElement, PrimitiveValue, VR};
use dicom_dictionary_std::{tags, uids};
use dicom_object::{FileMetaTableBuilder, InMemDicomObject};

use crate::parallel::parallel;
use crate::volume::{model::Volume, samples::Samples};

/// A failure to write the series.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// Only 8- and 16-bit integer volumes are written.
    #[error("only 8- and 16-bit integer volumes are written as DICOM, not {0}")]
    UnsupportedType(crate::volume::samples::ScalarType),
    /// A file could not be written.
    #[error("cannot write {path}: {reason}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
}

fn ds(values: &[f64]) -> PrimitiveValue {
    PrimitiveValue::Strs(values.iter().map(|v| format!("{v}")).collect())
}

/// A UID under the UUID-derived root (2.25), unique per run, series and slice.
fn uid(seed: u128, part: u64) -> String {
    format!("2.25.{}", seed.wrapping_add(u128::from(part)))
}

/// Writes `volume` into `folder` (which must exist) as `IM00001.dcm`…, slice k of the volume at
/// `z = k · spacing` mm; `slices` resamples the volume's z axis to that many slices (nearest
/// slice), keeping its extent. Returns the files written.
pub fn write_series(
    volume: &Volume,
    folder: &Path,
    description: &str,
    slices: Option<u32>,
) -> Result<Vec<PathBuf>, WriteError> {
    let [nx, ny, nz] = volume.dims();
    let out_z = slices.unwrap_or(nz).max(1);
    let [sx, sy, sz] = volume.spacing_mm();
    let dz = sz * f64::from(nz) / f64::from(out_z);
    let samples = volume
        .whole_samples("writing DICOM")
        .map_err(|e| WriteError::Io {
            path: folder.to_path_buf(),
            reason: e.to_string(),
        })?;
    let (bits, signed) = match samples {
        Samples::U8(_) => (8u16, false),
        Samples::I8(_) => (8, true),
        Samples::U16(_) => (16, false),
        Samples::I16(_) => (16, true),
        other => return Err(WriteError::UnsupportedType(other.scalar_type())),
    };
    let seed = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(1, |d| d.as_nanos())
        .wrapping_mul(1_000_003);
    let (series, study, frame) = (uid(seed, 1), uid(seed, 2), uid(seed, 3));
    let plane = nx as usize * ny as usize;
    let mapping = volume.mapping();
    let modality = volume.modality().map_or("OT".into(), |m| {
        if m.code().starts_with("CT") {
            "CT".to_string()
        } else if m.code().starts_with("MR") {
            "MR".into()
        } else {
            "OT".into()
        }
    });
    let write = |k: usize| -> Result<PathBuf, WriteError> {
        let source = ((k as f64 + 0.5) * f64::from(nz) / f64::from(out_z)) as usize;
        let source = source.min(nz as usize - 1);
        let range = source * plane..(source + 1) * plane;
        let pixels = match samples {
            Samples::U8(v) => PrimitiveValue::U8(v[range].to_vec().into()),
            Samples::I8(v) => PrimitiveValue::U8(v[range].iter().map(|x| *x as u8).collect()),
            Samples::U16(v) => PrimitiveValue::U16(v[range].to_vec().into()),
            // OW holds words: signed samples go as their bit patterns.
            Samples::I16(v) => PrimitiveValue::U16(v[range].iter().map(|x| *x as u16).collect()),
            _ => return Err(WriteError::UnsupportedType(volume.scalar_type())),
        };
        let instance = uid(seed, 1000 + k as u64);
        let mut obj = InMemDicomObject::new_empty();
        let mut put = |tag, vr, value: PrimitiveValue| {
            obj.put(DataElement::new(tag, vr, value));
        };
        // UTF-8: the description may hold any character.
        put(tags::SPECIFIC_CHARACTER_SET, VR::CS, "ISO_IR 192".into());
        put(tags::SOP_CLASS_UID, VR::UI, uids::CT_IMAGE_STORAGE.into());
        put(tags::SOP_INSTANCE_UID, VR::UI, instance.as_str().into());
        put(tags::MODALITY, VR::CS, modality.as_str().into());
        put(tags::STUDY_INSTANCE_UID, VR::UI, study.as_str().into());
        put(tags::SERIES_INSTANCE_UID, VR::UI, series.as_str().into());
        put(tags::SERIES_NUMBER, VR::IS, "1".into());
        put(tags::SERIES_DESCRIPTION, VR::LO, description.into());
        put(tags::FRAME_OF_REFERENCE_UID, VR::UI, frame.as_str().into());
        put(tags::INSTANCE_NUMBER, VR::IS, (k + 1).to_string().into());
        put(
            tags::IMAGE_POSITION_PATIENT,
            VR::DS,
            ds(&[0.0, 0.0, k as f64 * dz]),
        );
        put(
            tags::IMAGE_ORIENTATION_PATIENT,
            VR::DS,
            ds(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0]),
        );
        put(tags::PIXEL_SPACING, VR::DS, ds(&[sy, sx]));
        put(tags::SLICE_THICKNESS, VR::DS, ds(&[dz]));
        put(tags::ROWS, VR::US, PrimitiveValue::from(ny as u16));
        put(tags::COLUMNS, VR::US, PrimitiveValue::from(nx as u16));
        put(tags::SAMPLES_PER_PIXEL, VR::US, PrimitiveValue::from(1u16));
        put(
            tags::PHOTOMETRIC_INTERPRETATION,
            VR::CS,
            "MONOCHROME2".into(),
        );
        put(tags::BITS_ALLOCATED, VR::US, PrimitiveValue::from(bits));
        put(tags::BITS_STORED, VR::US, PrimitiveValue::from(bits));
        put(tags::HIGH_BIT, VR::US, PrimitiveValue::from(bits - 1));
        put(
            tags::PIXEL_REPRESENTATION,
            VR::US,
            PrimitiveValue::from(u16::from(signed)),
        );
        put(tags::RESCALE_INTERCEPT, VR::DS, ds(&[mapping.intercept]));
        put(tags::RESCALE_SLOPE, VR::DS, ds(&[mapping.slope]));
        if let Some([lo, hi]) = volume.provenance().window {
            put(tags::WINDOW_CENTER, VR::DS, ds(&[(lo + hi) / 2.0]));
            put(tags::WINDOW_WIDTH, VR::DS, ds(&[hi - lo]));
        }
        put(
            tags::PIXEL_DATA,
            if bits == 8 { VR::OB } else { VR::OW },
            pixels,
        );
        let path = folder.join(format!("IM{:05}.dcm", k + 1));
        let io = |reason: String| WriteError::Io {
            path: path.clone(),
            reason,
        };
        let file = obj
            .with_meta(
                FileMetaTableBuilder::new()
                    .transfer_syntax(uids::EXPLICIT_VR_LITTLE_ENDIAN)
                    .media_storage_sop_class_uid(uids::CT_IMAGE_STORAGE)
                    .media_storage_sop_instance_uid(instance.as_str()),
            )
            .map_err(|e| io(super::pixels::error_chain(&e)))?;
        file.write_to_file(&path)
            .map_err(|e| io(super::pixels::error_chain(&e)))?;
        Ok(path)
    };
    parallel(out_z as usize, &|| false, &write)
        .into_iter()
        .flatten()
        .collect()
}
