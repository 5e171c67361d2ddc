//! The 3D ray caster, one kind of drawing: [`VolumeRenderer`] and the owners it orchestrates,
//! one per lifetime — pipelines and layouts (the device's), the volume's resources, the transfer
//! function's tables, the leaping structures, the per-size targets — plus the pure per-frame
//! uniforms, the pass recording, progressive refinement, and the `auto` path and strategy choices
//! (callers; what `auto` strategy stands for is kept by the renderer, `strategy_choice`).

pub mod auto_path;
pub mod auto_strategy;
pub mod error;
pub mod gpu_volume;
pub mod layouts;
pub mod leap;
mod leap_labels;
mod measurements;
pub mod passes;
pub mod pipelines;
pub mod refine;
pub mod refined;
pub mod renderer;
pub mod request;
pub mod strategy_choice;
pub mod targets;
pub mod transfer_tables;
pub mod uniforms;
pub mod variant;
mod waited;

pub use error::RenderError;
pub use refined::RefineRun;
pub use renderer::VolumeRenderer;
pub use request::{Accumulate, FrameRequest, SubmittedFrame, WorkCounts};
pub use variant::PipelineKey;
