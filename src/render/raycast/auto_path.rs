//! `--path auto`: time the fragment and compute ray loops on the adapter once and keep the
//! faster. On data-centre GPUs fragment work runs on a small part of the chip (docs/benchmarks/README.md: about 30×
//! slower), while on desktop GPUs the two are close. A CPU driver (lavapipe) gets the compute
//! path without timing: measured faster there (Mesa 22.3, 192², idle: 22 against 38 ms a frame),
//! and its wall-clock timing, the only one it has, follows the load of other processes, so two
//! processes rendering one scene chose differently and their images differed by one 8-bit level
//! in a few pixels (the paths find the box's entry differently).
//!
//! This is a caller of [`VolumeRenderer`], not a part of it: whoever renders with
//! [`RenderPath::Auto`] runs [`choose`] once (after a volume is loaded); the renderer itself
//! never renders on its own behalf.

use std::time::Instant;

use crate::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use crate::settings::{ConcretePath, RenderPath, RenderSettings};

use super::error::RenderError;
use super::renderer::VolumeRenderer;
use super::request::FrameRequest;

/// Calibration image edge: large enough to keep the GPU busy, small enough for a CPU driver.
const SIZE: u32 = 192;
/// Timed frames per path after one warm-up frame (which also builds the pipeline).
const FRAMES: usize = 3;

/// The path `path` stands for on `renderer`: for `auto`, the faster one, measured on the loaded
/// volume the first time and remembered by the renderer from then on.
pub fn choose(
    renderer: &mut VolumeRenderer,
    path: RenderPath,
) -> Result<ConcretePath, RenderError> {
    if path != RenderPath::Auto {
        return renderer.resolve_path(path);
    }
    if let Some(chosen) = renderer.auto_path() {
        return Ok(chosen);
    }
    let chosen = if renderer.context().adapter_info.device_type == wgpu::DeviceType::Cpu {
        ConcretePath::Compute
    } else {
        measure(renderer)?
    };
    renderer.set_auto_path(chosen);
    Ok(chosen)
}

/// Times both paths on the loaded volume and returns the faster.
fn measure(renderer: &mut VolumeRenderer) -> Result<ConcretePath, RenderError> {
    let (dims, spacing) = renderer.volume_geometry().ok_or(RenderError::NoVolume)?;
    let bounds = Aabb::of_volume(dims, spacing);
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
    let mut best = (ConcretePath::Compute, f64::INFINITY);
    for (path, setting) in [
        (ConcretePath::Compute, RenderPath::Compute),
        (ConcretePath::Fragment, RenderPath::Fragment),
    ] {
        let settings = RenderSettings {
            path: setting,
            ..RenderSettings::default()
        };
        let request = FrameRequest {
            camera: &camera,
            size: [SIZE, SIZE],
            settings: &settings,
            stats: false,
        };
        renderer.render_and_wait(&request)?;
        let mut times = Vec::with_capacity(FRAMES);
        for _ in 0..FRAMES {
            let start = Instant::now();
            let (_, results) = renderer.render_and_wait(&request)?;
            let wall_ms = start.elapsed().as_secs_f64() * 1e3;
            // The wall clock where the adapter has no timestamps.
            times.push(results.gpu_ms.unwrap_or(wall_ms));
        }
        times.sort_by(f64::total_cmp);
        let median = times[FRAMES / 2];
        log::info!("auto path: {path:?} takes {median:.3} ms at {SIZE}×{SIZE}");
        if median < best.1 {
            best = (path, median);
        }
    }
    Ok(best.0)
}
