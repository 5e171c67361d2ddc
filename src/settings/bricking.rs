//! Whether the volume goes to the GPU as one 3D texture or as bricks in an atlas
//! (`accel::bricks`): a knob of the command line and the benchmark, to compare the two where a
//! volume fits one texture.

use serde::{Deserialize, Serialize};

/// How the volume is laid out on the GPU.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum Bricking {
    /// One 3D texture where every axis fits the GPU's 3D texture limit, else bricks.
    #[default]
    Auto,
    /// Always one 3D texture (a volume past the GPU's limit is refused).
    Off,
    /// Always bricks in an atlas, found through a page table.
    On,
}

impl Bricking {
    /// The name used on the command line and in tables.
    pub fn label(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Off => "off",
            Self::On => "on",
        }
    }
}
