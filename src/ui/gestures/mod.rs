//! Gestures as pure maths, tested without a window: mouse motion to camera motion, and
//! right-drag window/level.

pub mod interaction;
pub mod window_level;
