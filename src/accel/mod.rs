//! Acceleration structures for empty-space leaping (RC-s), as pure CPU code: the min/max
//! pyramid, the transfer function's emptiness table and the distance field over blocks. The GPU
//! builds the same structures with compute shaders (`src/render/raycast/leap.rs`); these are their
//! references.

pub mod bricks;
pub mod distance;
pub mod emptiness;
pub mod pyramid;
