//! What the `bench` and `accuracy` commands share when they measure: the record of where they
//! ran, the orbit of cameras around a volume, and one timed frame.

use std::time::Instant;

use glam::DVec3;
use leapview::bench::record::Environment;
use leapview::camera::{Aabb, Camera, ProjectionKind, orbit_direction};
use leapview::render::{
    FrameRequest, FrameResults, GpuContext, RenderError, SubmittedFrame, VolumeRenderer,
};

/// Where a run happens: the adapter, driver, command line and version.
pub fn environment(ctx: &GpuContext, quick: bool) -> Environment {
    let i = &ctx.adapter_info;
    Environment {
        adapter: i.name.clone(),
        device_type: format!("{:?}", i.device_type),
        backend: format!("{:?}", i.backend),
        driver: i.driver.clone(),
        driver_info: i.driver_info.clone(),
        gpu_timestamps: ctx.has_timestamps(),
        command_line: std::env::args().collect::<Vec<_>>().join(" "),
        quick,
        version: env!("CARGO_PKG_VERSION").to_string(),
        started_unix_s: std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs()),
    }
}

/// The orbit: `views` cameras around the volume at `elevation_deg`, each framing it, and their
/// azimuths in degrees.
pub fn orbit(bounds: &Aabb, views: u32, elevation_deg: f64) -> Vec<(Camera, f64)> {
    (0..views)
        .map(|v| {
            let azimuth = 360.0 * v as f64 / views as f64;
            let dir = orbit_direction(azimuth, elevation_deg);
            let camera = Camera::framing(bounds, dir, DVec3::Z, ProjectionKind::Perspective);
            (camera, azimuth)
        })
        .collect()
}

/// Renders one frame and waits; the time is the GPU's where the adapter has timestamp queries,
/// else the CPU's wall clock around submission and wait. Also returns the path that ran.
pub fn timed_frame(
    renderer: &mut VolumeRenderer,
    request: &FrameRequest,
) -> Result<(f64, FrameResults, String), RenderError> {
    let start = Instant::now();
    let (submitted, results) = renderer.render_and_wait(request)?;
    let ms = results
        .gpu_ms
        .unwrap_or_else(|| start.elapsed().as_secs_f64() * 1e3);
    Ok((ms, results, path_name(&submitted)))
}

/// The path a frame ran on, as the reports write it.
fn path_name(submitted: &SubmittedFrame) -> String {
    format!("{:?}", submitted.key.path).to_lowercase()
}

/// Renders one frame and reads its image back to the CPU as 8-bit RGBA (quantised on the GPU, as
/// a screenshot holds it), the way tools that time `render + read-back` do (VTK, vispy and
/// pygfx read 8-bit pixels): one submission of the frame, one of the read-back, one wait for
/// both. Returns the frame's GPU time (as [`timed_frame`]), the wall time from submission to the
/// image in memory, and the path that ran.
pub fn timed_frame_read_back(
    renderer: &mut VolumeRenderer,
    request: &FrameRequest,
) -> Result<(f64, f64, String), RenderError> {
    let start = Instant::now();
    let submitted = renderer.render(request)?;
    renderer.read_image_rgba8()?;
    let wall_ms = start.elapsed().as_secs_f64() * 1e3;
    let results = renderer.wait_for_results(&submitted);
    Ok((
        results.gpu_ms.unwrap_or(wall_ms),
        wall_ms,
        path_name(&submitted),
    ))
}
