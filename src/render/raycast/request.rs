//! What a frame asks of the renderer and what comes back: the request, the submitted frame, the
//! work done so far, and how a frame joins the refinement mean.

use crate::camera::Camera;
use crate::settings::RenderSettings;

use super::variant::PipelineKey;

/// One frame to render.
#[derive(Clone, Copy, Debug)]
pub struct FrameRequest<'a> {
    /// Camera in world millimetres.
    pub camera: &'a Camera,
    /// Image size in pixels.
    pub size: [u32; 2],
    /// Mode, strategy, path and quality knobs.
    pub settings: &'a RenderSettings,
    /// Use the statistics variant (counts samples; slower).
    pub stats: bool,
}

/// What was submitted for a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubmittedFrame {
    /// Sequence number (matches [`crate::render::probe::FrameResults::frame`]).
    pub frame: u64,
    /// The pipeline variant used.
    pub key: PipelineKey,
}

/// How often the renderer did each piece of work since it was made: what tests read to prove
/// that nothing is recomputed that did not change.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WorkCounts {
    /// Frames submitted.
    pub frames: u64,
    /// Lookup tables baked and uploaded (transfer function, value range or step changed).
    pub lut_bakes: u64,
    /// Min/max pyramids built (once per volume, on the first leaping frame).
    pub minmax_builds: u64,
    /// Partial pyramid builds: the nodes that read bricks whose pages changed.
    pub minmax_brick_builds: u64,
    /// Emptiness tables and node flags built (transfer function, or the X-ray window for the
    /// distance field, changed).
    pub flag_builds: u64,
    /// Distance fields built (flags or block size changed).
    pub distance_builds: u64,
    /// Flags of the nodes holding a shown label built (a cut view's shown labels changed).
    pub label_flag_builds: u64,
    /// Label-surface masks built (the shown labels or the smoothing changed in a view drawing
    /// their surfaces).
    pub label_surface_builds: u64,
    /// Pre-integration tables built (transfer function or value range changed while
    /// pre-integration is on).
    pub integral_builds: u64,
}

/// How a frame joins the refinement mean.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Accumulate {
    /// As the first frame of a new mean.
    Restart,
    /// Added to the mean on screen.
    Add,
}
