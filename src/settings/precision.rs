//! The texel precision of the volume texture: a knob of the accuracy benchmark and the command
//! line. Which GPU format each one means is the renderer's business
//! (`render::volume_texture::forced_format`).

use serde::{Deserialize, Serialize};

/// The texel precision asked for: the best the adapter filters (the default), or one format
/// forced, to measure what precision costs and buys (the accuracy benchmark).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum TexturePrecision {
    /// Exact integers in unorm texels, floats in 32-bit float texels (where the GPU filters them).
    ///
    /// Where the adapter cannot filter the exact format, it falls back to one that it can.
    #[default]
    Auto,
    /// 8-bit unorm: 256 levels over the value range (exact for 8-bit data).
    Unorm8,
    /// 16-bit unorm: 65536 levels over the value range (exact for 16-bit data).
    Unorm16,
    /// 32-bit float holding the normalised value.
    Float32,
}

impl TexturePrecision {
    /// All precisions.
    pub const ALL: [Self; 4] = [Self::Auto, Self::Unorm8, Self::Unorm16, Self::Float32];

    /// The name used on the command line and in tables.
    pub fn label(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Unorm8 => "8-bit",
            Self::Unorm16 => "16-bit",
            Self::Float32 => "f32",
        }
    }
}
