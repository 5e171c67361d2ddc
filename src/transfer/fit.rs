//! Defaults that fit the data: what kind of values a volume holds (CT in Hounsfield units, CT in
//! uncalibrated scanner units, MR, anything else), judged from the modality its file declares and
//! from its histogram, and the transfer-function preset that suits it, with the CT presets
//! (written in HU) mapped onto uncalibrated CT values.
//!
//! Uncalibrated CT is calibrated the way HU are defined: by two materials of known value. The
//! histogram of a CT of a body has a peak for air (−1000 HU) and one for soft tissue (about
//! +40 HU); the line through them maps stored values to HU. The calibration is kept only when
//! both peaks are clear and the slope is one a scanner could have written.

use super::presets::{self, preset};
use super::{TransferError, TransferFunction, ValueSpace};
use crate::text::number_to;
use crate::volume::{Histogram, Modality, ValueRange, Volume};

/// Below this minimum (data units) values are taken for Hounsfield units: air is −1000 HU, and no
/// MR or unitless volume has values this negative.
pub const HU_MINIMUM_BELOW: f64 = -500.0;
/// Hounsfield units of air, the first landmark.
pub const AIR_HU: f64 = -1000.0;
/// Hounsfield units of the soft-tissue peak (brain, muscle), the second landmark.
pub const SOFT_TISSUE_HU: f64 = 40.0;
/// Share of all voxels the soft-tissue peak (±5 bins) must hold to count as a landmark.
const MIN_TISSUE_SHARE: f64 = 0.01;
/// How much higher than the valley between air and tissue the tissue peak must be.
const MIN_PEAK_OVER_VALLEY: f64 = 2.0;
/// HU per stored unit a calibration may imply (scanners store 1 HU, sometimes ½ or 2, per unit).
const PLAUSIBLE_SLOPE: std::ops::RangeInclusive<f64> = 0.25..=4.0;
/// Narrowest value range that may hold HU clipped at air (soft tissue to dense bone is wider).
const MIN_HU_WIDTH: f64 = 400.0;

/// A line from a volume's data units to Hounsfield units: `hu = scale · value + offset`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HuCalibration {
    /// HU per data unit.
    pub scale: f64,
    /// HU at data value 0.
    pub offset: f64,
    /// The air level found (data units).
    pub air: f64,
    /// The soft-tissue level found (data units).
    pub tissue: f64,
}

impl HuCalibration {
    /// The line through (air, −1000 HU) and (tissue, +40 HU).
    pub fn through(air: f64, tissue: f64) -> Self {
        let scale = (SOFT_TISSUE_HU - AIR_HU) / (tissue - air);
        Self {
            scale,
            offset: AIR_HU - scale * air,
            air,
            tissue,
        }
    }

    /// The data value that corresponds to `hu`.
    pub(crate) fn value_of(&self, hu: f64) -> f64 {
        (hu - self.offset) / self.scale
    }
}

/// What a volume's values are, for choosing defaults.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum DataKind {
    /// CT whose values are Hounsfield units (or clipped HU); `angio` for CT angiography.
    CtHounsfield {
        /// CT angiography.
        angio: bool,
    },
    /// CT in scanner units: HU follow from the air and soft-tissue peaks.
    CtCalibrated {
        /// CT angiography.
        angio: bool,
        /// Data units to HU.
        to_hu: HuCalibration,
    },
    /// MR; `angio` for MR angiography.
    Mr {
        /// MR angiography.
        angio: bool,
    },
    /// Anything else (industrial CT, unknown modality, 8-bit CT without units): presets relative
    /// to the value range.
    Other,
}

impl DataKind {
    /// Judges `volume` by its declared modality and its values.
    pub fn of(volume: &Volume) -> Self {
        classify(
            volume.modality(),
            volume.value_range(),
            volume.histogram(),
            volume.mapping().slope == 1.0 && volume.scalar_type().size_bytes() == 1,
        )
    }

    /// The preset a volume of this kind opens with.
    pub fn default_preset(&self) -> &'static str {
        match self {
            Self::CtHounsfield { angio: true } | Self::CtCalibrated { angio: true, .. } => {
                "ct-angio"
            }
            Self::CtHounsfield { angio: false } | Self::CtCalibrated { angio: false, .. } => {
                presets::DEFAULT_CT_PRESET
            }
            Self::Mr { angio: true } => "mr-angio",
            Self::Mr { angio: false } => presets::DEFAULT_OTHER_PRESET,
            Self::Other => "object",
        }
    }

    /// Whether the HU presets (`ct-*`) suit this kind.
    pub fn is_ct(&self) -> bool {
        matches!(self, Self::CtHounsfield { .. } | Self::CtCalibrated { .. })
    }

    /// A few words for the side panel: `CT (HU)`, `CT (scanner units → HU)`, `MR`, …
    pub(crate) fn short_label(&self) -> &'static str {
        match self {
            Self::CtHounsfield { angio: false } => "CT, Hounsfield units",
            Self::CtHounsfield { angio: true } => "CT angiography, Hounsfield units",
            Self::CtCalibrated { .. } => "CT, scanner units (HU from air and tissue)",
            Self::Mr { angio: false } => "MR",
            Self::Mr { angio: true } => "MR angiography",
            Self::Other => "values without known units",
        }
    }

    /// One line saying what the values were taken for and why, for `info` and the side panel.
    pub fn describe(&self, modality: Option<&Modality>) -> String {
        let declared = modality.map_or_else(
            || "no modality in the file".to_string(),
            |m| format!("{} by the file", m.label()),
        );
        match self {
            Self::CtHounsfield { .. } => format!("CT in Hounsfield units ({declared})"),
            Self::CtCalibrated { to_hu, .. } => format!(
                "CT in scanner units ({declared}): air at {} and soft tissue at {} give \
                 HU = {} × value {} {}",
                number_to(to_hu.air, 3),
                number_to(to_hu.tissue, 3),
                number_to(to_hu.scale, 3),
                if to_hu.offset < 0.0 { "−" } else { "+" },
                number_to(to_hu.offset.abs(), 3),
            ),
            Self::Mr { .. } => format!("MR, values relative to their range ({declared})"),
            Self::Other => {
                format!("values without known units, relative to their range ({declared})")
            }
        }
    }
}

/// The classification behind [`DataKind::of`]; `eight_bit_unscaled` says the values are 8-bit
/// samples taken as they are (which cannot hold HU).
pub(crate) fn classify(
    modality: Option<&Modality>,
    range: Option<ValueRange>,
    histogram: &Histogram,
    eight_bit_unscaled: bool,
) -> DataKind {
    let has_hu_air = range.is_some_and(|r| r.min < HU_MINIMUM_BELOW);
    match modality {
        Some(Modality::Ct { angio }) => {
            let angio = *angio;
            if has_hu_air {
                DataKind::CtHounsfield { angio }
            } else if let Some(to_hu) = calibrate(histogram) {
                DataKind::CtCalibrated { angio, to_hu }
            } else if !eight_bit_unscaled && range.is_some_and(|r| r.width() >= MIN_HU_WIDTH) {
                // Wide enough for soft tissue to bone: HU with air clipped to 0, as in masked CTs.
                DataKind::CtHounsfield { angio }
            } else {
                DataKind::Other
            }
        }
        Some(Modality::Mr { angio }) => DataKind::Mr { angio: *angio },
        Some(Modality::IndustrialCt | Modality::Other(_)) => DataKind::Other,
        // No modality: CT only where the values look like Hounsfield units (air and soft tissue
        // where CT has them), not merely negative (a filtered MR or a statistics map can be).
        None if has_hu_air && hounsfield_landmarks(histogram) => {
            DataKind::CtHounsfield { angio: false }
        }
        None => DataKind::Mr { angio: false },
    }
}

/// Shares of the voxels that HU-valued CT holds around air (−1100 … −900 HU) and around water
/// and soft tissue (−200 … +200 HU) for a histogram taken for Hounsfield units.
const AIR_WINDOW_HU: [f64; 2] = [-1100.0, -900.0];
const TISSUE_WINDOW_HU: [f64; 2] = [-200.0, 200.0];
/// The least share of voxels each window must hold (a head CT holds tens of percent in each).
const MIN_LANDMARK_SHARE: f64 = 0.005;

/// Whether the histogram has voxels where CT in Hounsfield units has air and soft tissue.
fn hounsfield_landmarks(histogram: &Histogram) -> bool {
    let total = histogram.total() as f64;
    let n = histogram.counts.len();
    if total == 0.0 || n == 0 || histogram.range.width() <= 0.0 {
        return false;
    }
    let share = |[lo, hi]: [f64; 2]| -> f64 {
        let width = histogram.range.width() / n as f64;
        histogram
            .counts
            .iter()
            .enumerate()
            .filter(|(i, _)| {
                let centre = histogram.range.min + (*i as f64 + 0.5) * width;
                (lo..=hi).contains(&centre)
            })
            .map(|(_, &c)| c as f64)
            .sum::<f64>()
            / total
    };
    share(AIR_WINDOW_HU) >= MIN_LANDMARK_SHARE && share(TISSUE_WINDOW_HU) >= MIN_LANDMARK_SHARE
}

/// Finds air and soft tissue in a CT histogram; `None` unless both are clear and the line through
/// them is a plausible scanner calibration.
fn calibrate(histogram: &Histogram) -> Option<HuCalibration> {
    let counts = &histogram.counts;
    let n = counts.len();
    let total = histogram.total() as f64;
    if n < 32 || total == 0.0 || histogram.range.width() <= 0.0 {
        return None;
    }
    // Five-bin moving sums, zero beyond the ends: a window cut short at an end must not look
    // taller than a full one (that pulled the air peak onto the first bin).
    let smooth: Vec<f64> = (0..n)
        .map(|i| {
            counts[i.saturating_sub(2)..(i + 3).min(n)]
                .iter()
                .sum::<u64>() as f64
                / 5.0
        })
        .collect();
    let top = percentile_bin(counts, 0.999);
    let air = argmax(&smooth, 0, (top / 10).max(1));
    let from = air + ((top.saturating_sub(air)) / 10).max(2);
    let to = top * 8 / 10;
    if to <= from {
        return None;
    }
    let tissue = argmax(&smooth, from, to);
    let valley = smooth[air + 1..tissue]
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let share = counts[tissue.saturating_sub(5)..(tissue + 6).min(n)]
        .iter()
        .sum::<u64>() as f64
        / total;
    if share < MIN_TISSUE_SHARE || smooth[tissue] < MIN_PEAK_OVER_VALLEY * valley.max(1.0) {
        return None;
    }
    let width = histogram.range.width() / n as f64;
    // Each landmark at the centroid of the counts within three bins of its peak: finer than a
    // bin, where the peak straddles two.
    let centre = |bin: usize| {
        let (lo, hi) = (bin.saturating_sub(3), (bin + 4).min(n));
        let mass: u64 = counts[lo..hi].iter().sum();
        let moment: f64 = (lo..hi).map(|i| counts[i] as f64 * (i as f64 + 0.5)).sum();
        let at = if mass > 0 {
            moment / mass as f64
        } else {
            bin as f64 + 0.5
        };
        histogram.range.min + at * width
    };
    let calibration = HuCalibration::through(centre(air), centre(tissue));
    PLAUSIBLE_SLOPE
        .contains(&calibration.scale)
        .then_some(calibration)
}

/// The first bin by which `q` of the counts are reached.
fn percentile_bin(counts: &[u64], q: f64) -> usize {
    let total: u64 = counts.iter().sum();
    let mut seen = 0u64;
    for (i, &c) in counts.iter().enumerate() {
        seen += c;
        if seen as f64 >= q * total as f64 {
            return i;
        }
    }
    counts.len().saturating_sub(1)
}

/// Index of the largest value in `values[from..=to]` (the first of equals).
fn argmax(values: &[f64], from: usize, to: usize) -> usize {
    (from..=to.min(values.len() - 1)).fold(
        from,
        |best, i| {
            if values[i] > values[best] { i } else { best }
        },
    )
}

/// Share of the voxels a default window leaves below its bottom and above its top: a few bright
/// outliers (metal, a vessel's flow artefact) must not take the whole grey scale.
pub const WINDOW_TAIL: f64 = 0.001;

/// The window MIP, MinIP and X-ray use when none is given: the values between the 0.1 and 99.9
/// percentiles ([`WINDOW_TAIL`]), to a bin of the histogram (bin edges outwards); `None` when the
/// histogram has no width (a constant volume: its value range is all there is).
pub fn default_window(histogram: &Histogram) -> Option<[f64; 2]> {
    let n = histogram.counts.len();
    let total = histogram.total();
    let range = histogram.range;
    if n == 0 || total == 0 || range.width() <= 0.0 {
        return None;
    }
    let width = range.width() / n as f64;
    let lo_bin = percentile_bin(&histogram.counts, WINDOW_TAIL);
    let hi_bin = percentile_bin(&histogram.counts, 1.0 - WINDOW_TAIL);
    let lo = range.min + lo_bin as f64 * width;
    let hi = (range.min + (hi_bin + 1) as f64 * width).min(range.max);
    (hi > lo).then_some([lo, hi])
}

/// The window MIP, MinIP and X-ray use for `volume` when none is given: its header's (DICOM
/// `WindowCenter`/`WindowWidth`), else [`default_window`] of its histogram.
pub fn default_window_of(volume: &crate::volume::Volume) -> Option<[f64; 2]> {
    volume
        .provenance()
        .window
        .or_else(|| default_window(volume.histogram()))
}

/// The preset `name` fitted to data of `kind`: a CT preset (in HU) on calibrated CT is mapped
/// onto the data's values; anything else is the preset as written.
pub(crate) fn fitted_preset(
    name: &str,
    kind: &DataKind,
) -> Result<TransferFunction, TransferError> {
    Ok(fit(preset(name)?, kind).0)
}

/// `tf` fitted to data of `kind` (see [`fitted_preset`]), and whether it was mapped.
fn fit(tf: TransferFunction, kind: &DataKind) -> (TransferFunction, bool) {
    match kind {
        DataKind::CtCalibrated { to_hu, .. } if tf.space == ValueSpace::Data => {
            (mapped(&tf, to_hu), true)
        }
        _ => (tf, false),
    }
}

/// `tf`, written in HU, moved onto data values through `to_hu`.
pub fn mapped(tf: &TransferFunction, to_hu: &HuCalibration) -> TransferFunction {
    TransferFunction {
        opacity: tf
            .opacity
            .iter()
            .map(|p| [to_hu.value_of(p[0]), p[1]])
            .collect(),
        color: tf
            .color
            .iter()
            .map(|p| [to_hu.value_of(p[0]), p[1], p[2], p[3]])
            .collect(),
        space: ValueSpace::Data,
    }
}

/// The preset to use after opening a volume of `kind`: the current one when it suits the kind (a
/// `ct-*` preset for CT, an `mr-*` one for MR, a range-relative one for other data, the grey ramp
/// for any), else the kind's default.
pub(crate) fn preset_for_kind(current: &str, kind: &DataKind) -> &'static str {
    let suits = current == "grey-ramp"
        || match kind {
            DataKind::CtHounsfield { .. } | DataKind::CtCalibrated { .. } => {
                current.starts_with("ct-")
            }
            DataKind::Mr { .. } => current.starts_with("mr-"),
            DataKind::Other => current == "object" || current.starts_with("mr-"),
        };
    match presets::NAMES.iter().find(|&&n| n == current) {
        Some(name) if suits => name,
        _ => kind.default_preset(),
    }
}

/// A transfer function as the user named it (`auto`, a preset, or a JSON file), fitted to the data.
#[derive(Clone, Debug)]
pub struct Resolved {
    /// The function to render with.
    pub tf: TransferFunction,
    /// The preset used (`None` for a file).
    pub preset: Option<&'static str>,
    /// Said to the user when the function is not exactly what they named: the preset `auto`
    /// chose, or a CT preset mapped onto scanner units.
    pub note: Option<String>,
}

/// Name for "choose the transfer function from the data".
pub const AUTO: &str = "auto";

/// Resolves `arg` (`auto`, a preset name or a JSON file) for data of `kind`.
pub fn resolve(arg: &str, kind: &DataKind) -> Result<Resolved, TransferError> {
    let named = if arg == AUTO {
        Some(kind.default_preset())
    } else {
        presets::NAMES.iter().copied().find(|&n| n == arg)
    };
    let Some(name) = named else {
        return Ok(Resolved {
            tf: TransferFunction::from_preset_or_file(arg)?,
            preset: None,
            note: None,
        });
    };
    let (tf, mapped) = fit(preset(name)?, kind);
    let note = match (arg == AUTO, mapped) {
        (true, true) => Some(format!(
            "transfer function {name}, mapped onto scanner units"
        )),
        (false, true) => Some(format!("{name} mapped onto scanner units")),
        // A CT preset's points are Hounsfield units: on other values they land anywhere.
        _ if name.starts_with("ct-") && !kind.is_ct() => Some(format!(
            "{name} is for CT in Hounsfield units, and these values are {} (try {})",
            kind.short_label(),
            kind.default_preset()
        )),
        _ => None,
    };
    Ok(Resolved {
        tf,
        preset: Some(name),
        note,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::stats::HISTOGRAM_BINS;

    #[test]
    fn a_ct_preset_on_other_data_says_so() {
        let mr = DataKind::Mr { angio: false };
        let note = resolve("ct-brain", &mr).expect("preset").note;
        assert_eq!(
            note.as_deref(),
            Some(
                "ct-brain is for CT in Hounsfield units, and these values are MR (try mr-default)"
            )
        );
        let ct = DataKind::CtHounsfield { angio: false };
        assert_eq!(resolve("ct-brain", &ct).expect("preset").note, None);
    }

    /// A histogram over `range` with Gaussian peaks `(centre, width, voxels)`.
    fn peaks(range: ValueRange, peaks: &[(f64, f64, f64)]) -> Histogram {
        let w = range.width() / HISTOGRAM_BINS as f64;
        let counts = (0..HISTOGRAM_BINS)
            .map(|i| {
                let x = range.min + (i as f64 + 0.5) * w;
                peaks
                    .iter()
                    .map(|&(c, s, n)| n * w * (-(x - c).powi(2) / (2.0 * s * s)).exp() / s)
                    .sum::<f64>()
                    .round() as u64
            })
            .collect();
        Histogram { range, counts }
    }

    const RAW_CT: ValueRange = ValueRange {
        min: 0.0,
        max: 3272.0,
    };

    #[test]
    fn a_ct_in_scanner_units_is_calibrated_by_air_and_tissue() {
        // Air at 24, soft tissue at 1064, bone tailing off: HU + 1024.
        let h = peaks(
            RAW_CT,
            &[
                (24.0, 15.0, 5e6),
                (1064.0, 30.0, 1.5e6),
                (1600.0, 400.0, 4e5),
            ],
        );
        let c = calibrate(&h).expect("clear peaks");
        // Within one bin (12.8 units) of the truth at each landmark.
        assert!((c.air - 24.0).abs() < 13.0, "{c:?}");
        assert!((c.tissue - 1064.0).abs() < 13.0, "{c:?}");
        assert!((c.scale - 1.0).abs() < 0.03, "{c:?}");
        // Bone at 1024 + 700 stored is about 700 HU.
        assert!((c.scale * 1724.0 + c.offset - 700.0).abs() < 30.0, "{c:?}");
        let ct = Some(Modality::Ct { angio: false });
        let kind = classify(ct.as_ref(), Some(RAW_CT), &h, false);
        assert!(matches!(kind, DataKind::CtCalibrated { .. }), "{kind:?}");
        // ct-bone's first opaque point (150 HU) lands at about 1174 stored.
        let tf = fitted_preset("ct-bone", &kind).expect("preset");
        let at = tf
            .opacity
            .iter()
            .rfind(|p| p[1] == 0.0)
            .expect("a zero point");
        assert!((at[0] - 1174.0).abs() < 30.0, "{:?}", tf.opacity);
    }

    #[test]
    fn the_default_window_leaves_out_a_thousandth_at_each_end() {
        // 10 000 voxels over 0..256 in 256 bins: 9 000 background at 0, 980 tissue at 100, 20
        // bright voxels at 250: 0.2 % is more than the tail, so they are in the window.
        let range = ValueRange {
            min: 0.0,
            max: 256.0,
        };
        let mut counts = vec![0; 256];
        counts[0] = 9000;
        counts[100] = 980;
        counts[250] = 20;
        let h = Histogram { range, counts };
        assert_eq!(default_window(&h), Some([0.0, 251.0]));
        // Outliers of 0.05 % are left out: the top is the tissue bin's upper edge.
        let mut counts = vec![0; 256];
        counts[0] = 9000;
        counts[100] = 995;
        counts[250] = 5;
        let h = Histogram { range, counts };
        assert_eq!(default_window(&h), Some([0.0, 101.0]));
        let mut counts = vec![0; 256];
        counts[10] = 5000;
        counts[200] = 5000;
        assert_eq!(
            default_window(&Histogram { range, counts }),
            Some([10.0, 201.0])
        );
        let empty = Histogram {
            range,
            counts: vec![0; 256],
        };
        assert_eq!(default_window(&empty), None);
    }

    #[test]
    fn unclear_or_implausible_peaks_are_not_a_calibration() {
        // No tissue peak: air and a flat tail.
        let flat = peaks(RAW_CT, &[(24.0, 15.0, 5e6), (1500.0, 2000.0, 1e6)]);
        assert_eq!(calibrate(&flat), None);
        // A "tissue" peak 100 units above air would mean 10 HU per unit: no scanner writes that.
        let r = ValueRange {
            min: 0.0,
            max: 2000.0,
        };
        let steep = peaks(r, &[(5.0, 5.0, 5e6), (105.0, 10.0, 1e6)]);
        assert_eq!(calibrate(&steep), None);
        // A CT that stays uncalibrated: HU with air clipped when wide enough, else range-relative.
        let ct = Some(Modality::Ct { angio: true });
        assert_eq!(
            classify(ct.as_ref(), Some(r), &steep, false),
            DataKind::CtHounsfield { angio: true }
        );
        let byte = ValueRange {
            min: 0.0,
            max: 255.0,
        };
        let h = peaks(byte, &[(2.0, 2.0, 5e6), (40.0, 2.0, 1e4)]);
        assert_eq!(classify(ct.as_ref(), Some(byte), &h, true), DataKind::Other);
    }

    #[test]
    fn the_declared_modality_decides_before_the_values() {
        let hu = ValueRange {
            min: -1024.0,
            max: 3071.0,
        };
        let h = peaks(hu, &[(-1000.0, 10.0, 1e6), (40.0, 20.0, 1e6)]);
        let kind = |m: Option<Modality>, r| classify(m.as_ref(), Some(r), &h, false);
        assert_eq!(kind(None, hu), DataKind::CtHounsfield { angio: false });
        assert_eq!(
            kind(Some(Modality::Ct { angio: false }), hu),
            DataKind::CtHounsfield { angio: false }
        );
        assert_eq!(kind(Some(Modality::IndustrialCt), RAW_CT), DataKind::Other);
        assert_eq!(
            kind(Some(Modality::Mr { angio: true }), RAW_CT),
            DataKind::Mr { angio: true }
        );
        assert_eq!(kind(None, RAW_CT), DataKind::Mr { angio: false });
        assert_eq!(kind(None, hu).default_preset(), "ct-bone");
        assert_eq!(DataKind::Mr { angio: true }.default_preset(), "mr-angio");
    }

    #[test]
    fn the_current_preset_is_kept_when_it_suits() {
        let ct = DataKind::CtHounsfield { angio: false };
        assert_eq!(preset_for_kind("ct-skin", &ct), "ct-skin");
        assert_eq!(preset_for_kind("mr-angio", &ct), "ct-bone");
        assert_eq!(preset_for_kind("grey-ramp", &DataKind::Other), "grey-ramp");
        assert_eq!(preset_for_kind("ct-bone", &DataKind::Other), "object");
        assert_eq!(
            preset_for_kind("no-such", &DataKind::Mr { angio: false }),
            "mr-default"
        );
        for name in presets::NAMES {
            for kind in [ct.clone(), DataKind::Other, DataKind::Mr { angio: true }] {
                assert!(presets::NAMES.contains(&preset_for_kind(name, &kind)));
            }
        }
    }
}
