//! LeapView: GPU volume ray casting for CT and MRI with empty-space leaping.
//!
//! Pure parts (volume loading, transfer functions, camera maths, the sample grid and the CPU
//! reference ray caster) are independent of the GPU; `render` holds the wgpu renderer that the
//! window, the command line and the tests share.

pub mod accel;
pub mod accuracy;
pub mod app;
pub mod bench;
pub mod camera;
pub mod counters;
pub mod imaging;
pub mod reference;
pub mod render;
pub mod sampling;
pub mod settings;
pub mod transfer;
pub mod ui;
pub mod volume;
