//! LeapView: GPU volume ray casting for CT and MRI with empty-space leaping.
//!
//! Layers, bottom up (docs/ARCHITECTURE.md): the pure core — `volume`, `labels`, `transfer`, `accel`,
//! `camera`, `sampling`, `imaging`, `settings`, `counters`, `text` — and what is built on it without a
//! GPU — the CPU `reference` ray caster, the `bench` and `accuracy` records and tables; `render`,
//! the wgpu renderer that the window, the command line and the tests share; `ui`, the window. A
//! module imports only from its own layer or below.

// Items used only inside the crate are `pub(crate)`, and the docs of public ones may name them:
// the crate's documentation is read with `cargo doc --document-private-items`.
#![allow(rustdoc::private_intra_doc_links)]

pub mod accel;
pub mod accuracy;
pub mod bench;
pub mod camera;
pub mod counters;
pub mod imaging;
pub mod labels;
pub mod mpr;
pub mod parallel;
pub mod reference;
pub mod render;
pub mod sampling;
pub mod settings;
pub mod text;
pub mod transfer;
pub mod ui;
pub mod volume;
