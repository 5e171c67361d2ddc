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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_parses_and_names_match() {
        assert_eq!(PRESETS.len(), NAMES.len());
        for (name, (listed, _)) in NAMES.iter().zip(PRESETS) {
            assert_eq!(name, listed);
            preset(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        assert!(preset("nope").is_err());
    }
}
