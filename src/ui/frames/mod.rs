//! The frame pump and its scheduling: the scene (the one renderer, the camera, the frame on
//! screen), the band pump thread that feeds a frame to the GPU band by band, the frame job, the
//! level of detail while dragging and the rule that redraws only on change.

pub mod band_pump;
pub mod frame_job;
pub mod frame_stats;
pub mod framing;
pub mod lod;
pub mod redraw;
pub mod scene;
pub mod shown;
