//! What the driver says of a compiled compute shader: registers, instructions, spills, shared
//! memory, whatever statistics it reports through `VK_KHR_pipeline_executable_properties`.
//!
//! wgpu exposes no pipeline statistics, so this opens a Vulkan device of its own (ash), turns the
//! composed WGSL into SPIR-V with naga as wgpu's Vulkan backend does (the same bounds-check
//! policies for the robustness features it enables, loop bounding, integer-division checks) and
//! builds the compute pipeline with `CAPTURE_STATISTICS`. It renders nothing: it is how to see
//! why one ray-casting variant runs slower per sample than another (how many registers each
//! invocation holds decides how many rays an SM keeps in flight).
//!
//! `device.rs` holds the device and asks the driver; `spirv.rs` turns WGSL into SPIR-V and the
//! descriptor set layouts its resources need (pure: tested without a device).

use ash::vk;

mod device;
mod spirv;

pub use device::StatsDevice;
pub use spirv::Stages;

/// Why the statistics could not be read.
#[derive(Debug, thiserror::Error)]
pub enum PipelineStatsError {
    /// No Vulkan loader on this machine.
    #[error("no Vulkan loader: {0}")]
    Loader(String),
    /// A Vulkan call failed.
    #[error("Vulkan: {what} failed: {result}")]
    Vulkan {
        /// The call.
        what: &'static str,
        /// What it returned.
        result: vk::Result,
    },
    /// No device reports pipeline statistics (the extension is missing).
    #[error(
        "no Vulkan device here reports pipeline statistics (VK_KHR_pipeline_executable_properties); devices: {0}"
    )]
    Unsupported(String),
    /// No device's name contains the one asked for.
    #[error("no Vulkan device named like {asked:?} reports pipeline statistics; devices: {found}")]
    NoSuchDevice {
        /// The name asked for.
        asked: String,
        /// The devices there are.
        found: String,
    },
    /// The WGSL did not parse, validate or translate.
    #[error("shader: {0}")]
    Shader(String),
}

/// One statistic's value, in the format the driver gives it.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(untagged)]
pub enum StatValue {
    /// A yes/no.
    Bool(bool),
    /// A signed count.
    Int(i64),
    /// An unsigned count.
    Uint(u64),
    /// A measure.
    Float(f64),
}

impl std::fmt::Display for StatValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Bool(b) => write!(f, "{b}"),
            Self::Int(v) => write!(f, "{v}"),
            Self::Uint(v) => write!(f, "{v}"),
            Self::Float(v) => write!(f, "{v:.3}"),
        }
    }
}

/// One statistic of one executable.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Statistic {
    /// The driver's name for it ("Register Count", …).
    pub name: String,
    /// The driver's description.
    pub description: String,
    /// Its value.
    pub value: StatValue,
}

/// One executable of a pipeline (a compute pipeline has one; some drivers report more) and its
/// statistics.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Executable {
    /// The driver's name for it.
    pub name: String,
    /// The driver's description.
    pub description: String,
    /// The subgroup size it was compiled for.
    pub subgroup_size: u32,
    /// Its statistics, in the driver's order.
    pub statistics: Vec<Statistic>,
}
