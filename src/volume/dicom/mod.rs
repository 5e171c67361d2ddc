//! DICOM: series from folders, files and DICOMDIRs, classic and enhanced (multi-frame) images,
//! RT dose grids. dicom-rs reads the files and decodes the codecs; what makes a volume of them is
//! here: [`scan`] finds the frames, [`series`] groups them and picks one, [`geometry`] orders and
//! spaces them by the standard, [`read`] decodes them on all cores.

pub mod codec;
pub mod colour;
pub mod csa;
pub mod geometry;
pub mod guard;
pub mod header;
pub mod mosaic;
pub mod pixels;
pub mod read;
pub mod resample;
pub mod scan;
pub mod series;
pub mod tags;
pub mod write;

use std::path::Path;

pub use crate::volume::error::dicom::DicomError;
pub use header::{FrameHeader, SeriesFacts};
pub use series::{Series, SeriesChoice};

use super::error::VolumeError;
use super::{model::Volume, progress::LoadProgress};

/// The series found under a path, and which one opens by default.
#[derive(Debug)]
pub struct Catalogue {
    /// What the scan found.
    pub scan: scan::Scan,
    /// The series, in listing order.
    pub series: Vec<Series>,
}

impl Catalogue {
    /// Scans `path` (a folder, one file of a series, a DICOMDIR) and groups its frames.
    pub fn open(path: &Path, progress: Option<&LoadProgress>) -> Result<Self, DicomError> {
        let cancelled = || progress.is_some_and(LoadProgress::is_cancelled);
        let mut scan = scan::scan(path, &cancelled)?;
        let frames = std::mem::take(&mut scan.frames);
        Ok(Self {
            series: series::group(frames),
            scan,
        })
    }

    /// The index of the series `choice` names, or the default.
    pub fn choose(&self, choice: Option<&SeriesChoice>) -> Result<usize, DicomError> {
        series::choose(&self.series, choice, self.scan.named_file)
    }

    /// One line per series, numbered from 1 as `--series` takes them.
    pub fn listing(&self) -> Vec<String> {
        self.series
            .iter()
            .enumerate()
            .map(|(i, s)| s.summary(i + 1))
            .collect()
    }
}

/// Loads the series `choice` names (or the default) from `path`, named after the path and the
/// series. The volume's provenance lists every series found and says which one this is.
pub fn load(
    path: &Path,
    choice: Option<&SeriesChoice>,
    progress: Option<&LoadProgress>,
) -> Result<Volume, VolumeError> {
    let started = std::time::Instant::now();
    let catalogue = Catalogue::open(path, progress)?;
    let scanned = started.elapsed();
    let index = catalogue.choose(choice)?;
    let series = &catalogue.series[index];
    let base = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let name = if series.facts.description.is_empty() {
        base
    } else {
        format!("{base} ({})", series.facts.description)
    };
    let read = |series: &Series, name: String| {
        read::read_series(
            &catalogue.scan.files,
            &catalogue.scan.alternatives,
            series,
            name,
            progress,
        )
    };
    let volume = match (read(series, name.clone()), catalogue.scan.named_file) {
        // The file the user named, in a series whose files cannot be placed together (2D
        // images sharing a series, several volumes in one): that file alone, and a note why.
        (Err(VolumeError::Dicom(DicomError::Geometry { reason })), Some(named))
            if series.frames.iter().any(|f| f.file != named)
                && series.frames.iter().any(|f| f.file == named) =>
        {
            let alone = Series {
                frames: series
                    .frames
                    .iter()
                    .filter(|f| f.file == named)
                    .cloned()
                    .collect(),
                ..series.clone()
            };
            let volume = read(&alone, name)?;
            let mut provenance = volume.provenance().clone();
            provenance.notes.insert(
                0,
                format!(
                    "opened alone: the {} other files of its series cannot be placed with it \
                     ({reason})",
                    series
                        .frames
                        .iter()
                        .filter(|f| f.file != named)
                        .map(|f| f.file)
                        .collect::<std::collections::BTreeSet<_>>()
                        .len()
                ),
            );
            volume.with_provenance(provenance)
        }
        (result, _) => result?,
    };
    log::info!(
        "{}: {} files scanned in {:.0} ms; series {} ({} slices) read in {:.0} ms",
        path.display(),
        catalogue.scan.files.len(),
        scanned.as_secs_f64() * 1e3,
        index + 1,
        series.frames.len(),
        (started.elapsed() - scanned).as_secs_f64() * 1e3
    );
    let mut provenance = volume.provenance().clone();
    provenance.listing = catalogue.listing();
    provenance.chosen = Some(index);
    let skipped = catalogue.scan.skipped();
    if !skipped.is_empty() {
        log::info!("{}: skipped {skipped}", path.display());
        provenance.skipped = Some(skipped);
    }
    Ok(volume.with_provenance(provenance))
}
