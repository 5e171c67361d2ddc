//! Acceleration structures for empty-space leaping (RC-s), as pure CPU code: the min/max
//! pyramid, the transfer function's emptiness table and the distance field over blocks. The GPU
//! builds the same structures with compute shaders (`src/render/raycast/leap.rs`); these are their
//! references. And how a volume is cut into bricks for the GPU's atlas and page table
//! (`bricks`), and which bricks the atlas holds (`residency`), decided from the leaping structures'
//! emptiness. And which labels each cell of a segmentation holds (`label_cells`), for leaping
//! over hidden labels.

pub mod bricks;
pub mod distance;
pub mod emptiness;
pub mod label_cells;
pub mod pyramid;
pub mod residency;
