//! The 3D view and what is drawn over it: the view area with its gestures and the renderer's
//! output, the readout, the orientation marker, and the cropping box with its handles.

pub mod crop;
pub mod orientation_marker;
pub mod overlay;
pub mod viewport;
