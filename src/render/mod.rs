//! GPU rendering with wgpu: device, volume and transfer-function textures, pipeline variants,
//! the ray-casting passes, timing and read-back. One [`VolumeRenderer`] serves the window, the
//! command line and the tests.

pub mod auto_path;
pub mod context;
pub mod crop;
pub mod effects;
pub mod leap;
pub mod lut_texture;
pub mod pipelines;
pub mod probe;
pub mod quality;
pub mod readback;
pub mod refine;
pub mod renderer;
pub mod settings;
pub mod shader;
pub mod targets;
pub mod uniforms;
pub mod volume_texture;

pub use context::{GpuContext, GpuError};
pub use crop::CropBox;
pub use pipelines::{ConcretePath, PipelineKey};
pub use probe::{FrameCounters, FrameResults};
pub use quality::QualityPreset;
pub use renderer::{FrameRequest, RenderError, SubmittedFrame, VolumeRenderer, WorkCounts};
pub use settings::{Mode, RenderPath, RenderSettings, Strategy};
pub use volume_texture::TexturePrecision;
