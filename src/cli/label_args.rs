//! The segmentation flags of `render`: a label file, its names, which labels show and how; and
//! the one way every command reads a label file (its notes on standard error).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use clap::Args;
use leapview::labels::{LabelMap, LabelOptions, Segment, load_labels};
use leapview::settings::LabelView;
use leapview::volume::Volume;

use super::{Failure, OrFail};

/// A segmentation shown in 3D.
#[derive(Args, Debug, Clone)]
pub struct LabelArgs {
    /// A segmentation of the volume, shown as --label-view says.
    ///
    /// NIfTI, NRRD or Slicer .seg.nrrd, MetaImage or DICOM SEG; put on the volume's grid by
    /// patient position. Names and colours as info --labels lists them.
    #[arg(long, value_name = "FILE", help_heading = "Segmentation")]
    pub labels: Option<PathBuf>,
    /// An ITK-SNAP label description file or a Slicer colour table naming the labels.
    #[arg(
        long,
        value_name = "FILE",
        requires = "labels",
        help_heading = "Segmentation",
        hide_short_help = true
    )]
    pub label_names: Option<PathBuf>,
    /// How the labels show: colour (each sample in its label's colour), inside (the image only
    /// inside the shown labels, the rest cut away), colour-inside (both), surfaces (each shown
    /// label's boundary as a smooth lit surface) or off.
    #[arg(
        long,
        value_enum,
        default_value = "colour",
        requires = "labels",
        help_heading = "Segmentation"
    )]
    pub label_view: LabelView,
    /// How much --label-view surfaces smooths the labels' boundaries: a Gaussian's standard
    /// deviation in voxels, 0 (none: the voxels' trilinear outline) to 1.5.
    #[arg(
        long,
        value_name = "VOXELS",
        default_value_t = leapview::labels::surface::DEFAULT_SMOOTHING,
        requires = "labels",
        help_heading = "Segmentation",
        hide_short_help = true
    )]
    pub label_smoothing: f64,
    /// The shown labels' opacity in 3D, 0 to 1: their surfaces' and their colour's weight.
    #[arg(
        long,
        value_name = "OPACITY",
        default_value_t = 1.0,
        value_parser = unit_interval,
        requires = "labels",
        help_heading = "Segmentation",
        hide_short_help = true
    )]
    pub label_opacity: f64,
    /// Show only these labels, by value or name (comma-separated); the rest are hidden.
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "LABELS",
        requires = "labels",
        help_heading = "Segmentation"
    )]
    pub show_labels: Option<Vec<String>>,
}

/// A number 0 … 1.
pub(crate) fn unit_interval(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if (0.0..=1.0).contains(&v) => Ok(v),
        _ => Err(format!("'{text}' is no opacity: a number 0 … 1")),
    }
}

impl LabelArgs {
    /// A segment's colour and opacity in 3D: its colour at --label-opacity where `shown` holds
    /// it, hidden (alpha 0) elsewhere.
    pub fn style(&self, shown: &BTreeSet<(u16, u16)>, s: &Segment) -> [u8; 4] {
        let [r, g, b] = s.colour;
        let alpha = if shown.contains(&(s.layer, s.value)) {
            (self.label_opacity * 255.0).round() as u8
        } else {
            0
        };
        [r, g, b, alpha]
    }
}

/// Reads the label file at `path` onto `volume`'s grid, named by `names` where given; prints
/// what was done to it (resampled, partly outside) on standard error.
pub fn read_labels(
    path: &Path,
    names: Option<&PathBuf>,
    volume: &Volume,
) -> Result<LabelMap, Failure> {
    let options = LabelOptions {
        names: names.cloned(),
    };
    let map = load_labels(path, volume, &options).bad_input()?;
    for note in map.notes() {
        eprintln!("leapview: note: {}: {note}", map.name());
    }
    Ok(map)
}

impl LabelArgs {
    /// The labels on `volume`'s grid, if a file was given.
    pub fn load(&self, volume: &Volume) -> Result<Option<LabelMap>, Failure> {
        self.labels
            .as_ref()
            .map(|path| read_labels(path, self.label_names.as_ref(), volume))
            .transpose()
    }

    /// The segments of `map` shown, by (layer, value): every one, or those --show-labels names
    /// by value or name (any case). An entry that names none is refused, listing what there is.
    pub fn shown(&self, map: &LabelMap) -> Result<BTreeSet<(u16, u16)>, Failure> {
        let key = |s: &Segment| (s.layer, s.value);
        let Some(wanted) = &self.show_labels else {
            return Ok(map.segments().iter().map(key).collect());
        };
        let names = |s: &Segment, w: &str| {
            w.trim().parse::<u16>().is_ok_and(|v| v == s.value)
                || s.name.eq_ignore_ascii_case(w.trim())
        };
        if let Some(unknown) = wanted
            .iter()
            .find(|w| !map.segments().iter().any(|s| names(s, w)))
        {
            let known: Vec<String> = map
                .segments()
                .iter()
                .take(20)
                .map(|s| format!("{} {}", s.value, s.name))
                .collect();
            let more = map.segments().len().saturating_sub(known.len());
            return Err(Failure::BadInput(anyhow::anyhow!(
                "--show-labels: {:?} is no label of {} (it has: {}{})",
                unknown,
                map.name(),
                known.join(", "),
                if more > 0 {
                    format!(" and {more} more")
                } else {
                    String::new()
                }
            )));
        }
        Ok(map
            .segments()
            .iter()
            .filter(|s| wanted.iter().any(|w| names(s, w)))
            .map(key)
            .collect())
    }
}
