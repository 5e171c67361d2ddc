//! The transfer-function presets shipped in `assets/tf/`, compiled into the binary so that no
//! file is needed at run time.

use super::{TransferError, TransferFunction};
use crate::volume::ValueRange;

/// Preset names and their JSON text, in the order menus show them.
const PRESETS: &[(&str, &str)] = &[
    ("ct-bone", include_str!("../../assets/tf/ct-bone.json")),
    ("ct-skin", include_str!("../../assets/tf/ct-skin.json")),
    (
        "ct-soft-tissue",
        include_str!("../../assets/tf/ct-soft-tissue.json"),
    ),
    ("ct-angio", include_str!("../../assets/tf/ct-angio.json")),
    (
        "mr-default",
        include_str!("../../assets/tf/mr-default.json"),
    ),
    ("mr-angio", include_str!("../../assets/tf/mr-angio.json")),
    ("grey-ramp", include_str!("../../assets/tf/grey-ramp.json")),
];

/// Names of all presets.
pub const NAMES: [&str; 7] = [
    "ct-bone",
    "ct-skin",
    "ct-soft-tissue",
    "ct-angio",
    "mr-default",
    "mr-angio",
    "grey-ramp",
];

/// The preset called `name`.
pub fn preset(name: &str) -> Result<TransferFunction, TransferError> {
    let text = PRESETS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, text)| *text)
        .ok_or_else(|| TransferError::UnknownPreset {
            name: name.to_string(),
            known: NAMES.join(", "),
        })?;
    TransferFunction::from_json_str(text)
}

/// Preset chosen for volumes that look like CT (values in Hounsfield units).
pub const DEFAULT_CT_PRESET: &str = "ct-bone";
/// Preset chosen for every other volume (MRI and unitless data).
pub const DEFAULT_OTHER_PRESET: &str = "mr-default";

/// Below this minimum (data units) a volume is taken for CT: air is −1000 HU, and no MRI or
/// unitless volume has values this negative.
pub const CT_MINIMUM_BELOW: f64 = -500.0;

/// Whether a volume with this value range looks like CT (see [`CT_MINIMUM_BELOW`]).
pub fn is_ct_like(range: Option<ValueRange>) -> bool {
    range.is_some_and(|r| r.min < CT_MINIMUM_BELOW)
}

/// The preset to use after opening a volume: the current one when it suits the volume's kind
/// (a `ct-*` preset for CT, an `mr-*` preset otherwise, the grey ramp for either), else the
/// default for that kind.
pub fn preset_for_volume(current: &str, ct_like: bool) -> String {
    let fits = current == "grey-ramp"
        || (ct_like && current.starts_with("ct-"))
        || (!ct_like && current.starts_with("mr-"));
    if fits {
        current.to_string()
    } else if ct_like {
        DEFAULT_CT_PRESET.to_string()
    } else {
        DEFAULT_OTHER_PRESET.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::ValueSpace;

    #[test]
    fn ct_is_recognised_by_air() {
        let ct = ValueRange {
            min: -1024.0,
            max: 3071.0,
        };
        let mr = ValueRange {
            min: 0.0,
            max: 4095.0,
        };
        assert!(is_ct_like(Some(ct)));
        assert!(!is_ct_like(Some(mr)));
        assert!(!is_ct_like(None));
    }

    #[test]
    fn preset_follows_the_kind_of_volume() {
        assert_eq!(preset_for_volume("ct-skin", true), "ct-skin");
        assert_eq!(preset_for_volume("ct-skin", false), DEFAULT_OTHER_PRESET);
        assert_eq!(preset_for_volume("mr-angio", true), DEFAULT_CT_PRESET);
        assert_eq!(preset_for_volume("grey-ramp", false), "grey-ramp");
        // Whatever is chosen is a preset that exists.
        for name in NAMES {
            for ct in [false, true] {
                assert!(NAMES.contains(&preset_for_volume(name, ct).as_str()));
            }
        }
    }

    #[test]
    fn every_preset_parses_and_names_match() {
        assert_eq!(PRESETS.len(), NAMES.len());
        for (name, (listed, _)) in NAMES.iter().zip(PRESETS) {
            assert_eq!(name, listed);
            preset(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        assert!(preset("nope").is_err());
    }

    /// A typical CT value range (12-bit scanners store −1024…3071 HU).
    const CT_RANGE: ValueRange = ValueRange {
        min: -1024.0,
        max: 3071.0,
    };

    #[test]
    fn ct_presets_suit_hounsfield_units() {
        let at = |name: &str, hu: f64| {
            let tf = preset(name).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(tf.space, ValueSpace::Data, "{name} must be in HU");
            tf.opacity_at(hu, CT_RANGE)
        };
        for name in ["ct-bone", "ct-skin", "ct-soft-tissue", "ct-angio"] {
            // Air must be fully transparent, or the whole box renders as fog (and no block
            // outside the patient could be leapt).
            assert_eq!(at(name, -1000.0), 0.0, "{name} in air");
            // Cortical bone (+1000 HU) becomes an opaque surface within a few voxels.
            let bone = at(name, 1000.0);
            assert!((0.3..=0.9).contains(&bone), "{name}: bone {bone} per voxel");
        }
        for name in ["ct-bone", "ct-angio"] {
            // Fat (−100 HU) and soft tissue or brain (40 HU) vanish.
            assert_eq!(
                at(name, -100.0) + at(name, 40.0),
                0.0,
                "{name} shows soft tissue"
            );
        }
        // Contrast-filled lumen (300 HU) is a surface in the angiography preset.
        assert!(at("ct-angio", 300.0) >= 0.3);
        // Soft tissue is translucent: a few per cent per voxel, less than bone.
        let soft = at("ct-soft-tissue", 40.0);
        assert!(soft > 0.0 && soft < 0.1, "soft tissue {soft} per voxel");
        // The skin–air boundary (about −500…0 HU) turns opaque within two voxels.
        assert!(at("ct-skin", -200.0) >= 0.3);
    }

    #[test]
    fn normalised_presets_are_transparent_at_the_background() {
        let range = ValueRange {
            min: 0.0,
            max: 255.0,
        };
        for name in ["mr-default", "mr-angio", "grey-ramp"] {
            let tf = preset(name).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(tf.space, ValueSpace::Normalized, "{name}");
            assert_eq!(
                tf.opacity_at(range.min, range),
                0.0,
                "{name} at the minimum"
            );
            assert!(
                tf.opacity_at(range.max, range) > 0.5,
                "{name} at the maximum"
            );
        }
        // MR air is noise up to about 10 % of the range (the Seg3D T1 head's air threshold is
        // 25.5 of 255): the MR presets must not show it.
        for name in ["mr-default", "mr-angio"] {
            let tf = preset(name).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(
                tf.opacity_at(0.1 * range.max, range),
                0.0,
                "{name} shows noise"
            );
        }
    }
}
