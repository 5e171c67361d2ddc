//! The transfer-function presets shipped in `assets/tf/`, compiled into the binary so that no
//! file is needed at run time.

use super::{TransferError, TransferFunction};

/// Preset names and their JSON text, in the order menus show them.
const PRESETS: &[(&str, &str)] = &[
    ("ct-bone", include_str!("../../assets/tf/ct-bone.json")),
    ("ct-skin", include_str!("../../assets/tf/ct-skin.json")),
    (
        "ct-soft-tissue",
        include_str!("../../assets/tf/ct-soft-tissue.json"),
    ),
    ("ct-angio", include_str!("../../assets/tf/ct-angio.json")),
    ("ct-brain", include_str!("../../assets/tf/ct-brain.json")),
    (
        "mr-default",
        include_str!("../../assets/tf/mr-default.json"),
    ),
    ("mr-angio", include_str!("../../assets/tf/mr-angio.json")),
    ("object", include_str!("../../assets/tf/object.json")),
    ("grey-ramp", include_str!("../../assets/tf/grey-ramp.json")),
];

/// Names of all presets.
pub const NAMES: [&str; 9] = [
    "ct-bone",
    "ct-skin",
    "ct-soft-tissue",
    "ct-angio",
    "ct-brain",
    "mr-default",
    "mr-angio",
    "object",
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
/// Preset chosen for MR volumes.
pub const DEFAULT_OTHER_PRESET: &str = "mr-default";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::ValueSpace;
    use crate::volume::ValueRange;

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
