//! The integration tests, as one test binary: each module below was once a binary of its own, but
//! every binary links the whole crate with wgpu, naga and egui (about half a gigabyte each with
//! debug info), so two dozen of them filled CI's disk and spent most of its time linking.
//! One binary links once. Run one group with `cargo test --test integration <module>::`, e.g.
//! `cargo test --test integration golden::`.
//!
//! Data the tests compare with stays beside this folder: `tests/golden/` (golden images) and
//! `tests/snapshots/` (UI snapshots).

mod common;

mod accuracy;
mod bands;
mod bench;
mod bricks;
mod cli;
mod cropping;
mod golden;
mod gpu_limits;
mod hard_cases_camera;
mod hard_cases_data;
mod hard_cases_image;
mod hard_cases_iso;
mod hard_cases_values;
mod hard_cases_volume;
mod label_surfaces;
mod labels;
mod labels_3d;
mod leaping;
mod leaping_real;
mod loaders;
mod modes;
mod newcomer_faults;
mod opacity;
mod pictures;
mod preintegration;
mod readback;
mod readme;
mod recompute;
mod reference_match;
mod refine;
mod remote;
mod shaders;
mod shadows;
mod slice;
mod slice_real;
mod strategies;
mod streamed;
mod ui_snapshots;
mod window;
