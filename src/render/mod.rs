//! GPU rendering with wgpu. Shared by every kind of drawing: the device ([`context`]), the
//! volume's 3D texture, table textures, timing probes, read-back (f32, or 8-bit packed on the GPU: [`pack`]), WGSL composition and the data
//! shared with the shaders. The 3D ray caster is [`raycast`]; what to render is described by the
//! pure [`crate::settings`]. One [`VolumeRenderer`] serves the window, the command line and the
//! tests.

pub mod context;
pub mod gpu_data;
pub mod label_surface;
pub mod labels;
pub mod memory;
pub mod pack;
pub mod pipeline_stats;
pub mod probe;
pub mod raycast;
pub mod readback;
pub mod shader;
pub mod slice;
pub mod table_texture;
pub mod texture;
pub mod volume_texture;

pub use context::{GpuContext, GpuError};
pub use probe::FrameResults;
pub use raycast::{
    Accumulate, FrameRequest, PipelineKey, RefineRun, RenderError, SubmittedFrame, VolumeRenderer,
    WorkCounts,
};
