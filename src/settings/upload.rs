//! How a volume goes to the GPU: its texel precision, one 3D texture or bricks in an atlas
//! (`accel::bricks`), and the GPU memory it may take (a coarser level where full resolution does
//! not fit). Knobs of the command line and the benchmarks.

use serde::{Deserialize, Serialize};

use super::TexturePrecision;

/// What an upload is asked for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Upload {
    /// Texel precision.
    pub precision: TexturePrecision,
    /// One texture or bricks.
    pub bricking: Bricking,
    /// The most GPU memory the volume's texels may take, in bytes (`None`: bounded only by the
    /// adapter's texture limits). Where full resolution does not fit, the volume is bricked at
    /// the finest level that does.
    pub gpu_budget: Option<u64>,
}

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

/// The sizes `--gpu-budget` accepts, for its error message.
pub const SIZE_FORMS: &str = "a number with a unit: 512MB, 1.5GB, 2GiB, 800M (K, M, G, T: binary, \
                              as KiB, MiB, GiB, TiB; KB, MB, GB, TB: decimal)";

/// A memory size as a person writes it: `512MB`, `1.5 GB`, `2GiB`, `800M`, `4096B`.
pub fn parse_size(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let unit = unit.trim();
    let bad = || format!("`{text}` is not a size: give {SIZE_FORMS}");
    let value: f64 = number.parse().map_err(|_| bad())?;
    let scale: f64 = match unit.to_ascii_lowercase().as_str() {
        "b" => 1.0,
        "k" | "kib" => 1024.0,
        "m" | "mib" => 1024f64.powi(2),
        "g" | "gib" => 1024f64.powi(3),
        "t" | "tib" => 1024f64.powi(4),
        "kb" => 1e3,
        "mb" => 1e6,
        "gb" => 1e9,
        "tb" => 1e12,
        _ => return Err(bad()),
    };
    let bytes = value * scale;
    if !bytes.is_finite() || bytes < 1.0 || bytes > u64::MAX as f64 / 2.0 {
        return Err(bad());
    }
    Ok(bytes as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_in_every_accepted_form_and_nothing_else() {
        for (text, bytes) in [
            ("512MB", 512_000_000),
            ("1.5 GB", 1_500_000_000),
            ("2GiB", 2 << 30),
            ("800M", 800 << 20),
            ("4096b", 4096),
            ("1t", 1 << 40),
        ] {
            assert_eq!(parse_size(text), Ok(bytes), "{text}");
        }
        for text in [
            "",
            "12",
            "1.2.3GB",
            "GB",
            "-1GB",
            "0MB",
            "12 parsecs",
            "1e9B",
            "nanGB",
        ] {
            let e = parse_size(text).expect_err(text);
            assert!(e.contains("512MB"), "{e}");
        }
    }
}
