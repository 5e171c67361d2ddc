//! GPU rendering.
pub mod settings;
