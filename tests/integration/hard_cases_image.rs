//! Hard image sizes (issue 7, item 5): 1×1 pixel, 8192×8192 (the adapter's limit when smaller)
//! with a clear error one pixel beyond the limit, and an image whose read-back needs more than
//! the device's largest buffer. Analytic answers of uniform volumes; no pixel NaN or infinite.

use crate::common;

use common::Uniform;
use leapview::camera::{Aabb, ProjectionKind, ViewPreset};
use leapview::imaging::ImageF32;
use leapview::render::RenderError;
use leapview::render::context::device_descriptor;
use leapview::render::{GpuContext, VolumeRenderer};
use leapview::settings::{Mode, RenderPath, Strategy};
use leapview::volume::synthetic;

#[test]
fn images_of_one_pixel_and_of_the_largest_size() {
    let volume = synthetic::constant([5, 4, 3], [1.0; 3], common::UNIFORM_VALUE).expect("valid");
    let cameras = [
        common::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective),
        common::framing(&volume, ViewPreset::PlusZ, ProjectionKind::Orthographic),
    ];
    common::check_uniform(
        "one-pixel",
        &volume,
        0.2,
        &cameras,
        [1, 1],
        0.5,
        &Strategy::ALL,
    );

    let one = synthetic::constant([1, 1, 1], [1.0; 3], common::UNIFORM_VALUE).expect("valid");
    let mut r = common::renderer();
    r.set_volume(&one).expect("upload");
    r.set_transfer_function(&common::uniform_tf(0.5, [1.0, 0.6, 0.2]));
    let max = r.context().limits.max_texture_dimension_2d;
    let side = max.min(8192);
    eprintln!("largest image side on this adapter: {max}; rendering {side}²");
    let camera = common::framing(&one, ViewPreset::Oblique, ProjectionKind::Perspective);
    let settings = common::uniform_settings(Mode::Dvr, Strategy::Rc, RenderPath::Compute);
    let started = std::time::Instant::now();
    let image = r
        .render_image(&camera, [side, side], &settings)
        .expect("render");
    eprintln!(
        "{side}² rendered and read in {:.1} s",
        started.elapsed().as_secs_f64()
    );
    common::assert_all_finite("largest", &image);
    // Every 97th pixel of every 97th row (a prime: the grid is not aligned with anything).
    let uniform = Uniform {
        alpha: 0.5,
        rgb: [1.0, 0.6, 0.2],
        d0_mm: 1.0,
        windowed: 0.5,
    };
    let bounds = Aabb::of_volume([1, 1, 1], [1.0; 3]);
    let mut covered = 0;
    for py in (0..side).step_by(97) {
        for px in (0..side).step_by(97) {
            let answers = common::footprint(px, py, 1.0 / 16.0).map(|(x, y)| {
                let l = common::path_length_mm(&camera, &bounds, [side, side], x, y);
                uniform.pixel(&settings, l)
            });
            covered += usize::from(answers[0] != common::BACKGROUND);
            let sub = ImageF32 {
                width: 1,
                height: 1,
                pixels: vec![image.get(px, py)],
            };
            common::assert_within_footprint(
                &format!("largest-{px}-{py}"),
                &sub,
                common::ANALYTIC_TOLERANCE,
                |_, _| answers,
            );
        }
    }
    assert!(
        covered > 100,
        "the voxel covers {covered} of the checked pixels"
    );
    drop(image);
    // One pixel more is a clear error, not a panic.
    for size in [[max + 1, 1], [1, max + 1]] {
        let err = r
            .render_image(&camera, size, &settings)
            .expect_err("too large");
        assert!(matches!(err, RenderError::ImageSize { .. }), "{err:?}");
        assert!(err.to_string().contains(&max.to_string()), "{err}");
    }
}

/// A device like the headless one but whose buffers may hold at most `max_buffer_bytes`.
fn context_with_buffer_limit(max_buffer_bytes: u64) -> GpuContext {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle());
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))
        .expect("an adapter (see common::gpu)");
    let mut descriptor = device_descriptor(&adapter);
    let limits = &mut descriptor.required_limits;
    limits.max_buffer_size = max_buffer_bytes;
    limits.max_storage_buffer_binding_size =
        limits.max_storage_buffer_binding_size.min(max_buffer_bytes);
    limits.max_uniform_buffer_binding_size =
        limits.max_uniform_buffer_binding_size.min(max_buffer_bytes);
    let (device, queue) = pollster::block_on(adapter.request_device(&descriptor)).expect("device");
    GpuContext::new(&adapter, device, queue)
}

#[test]
fn an_image_larger_than_the_largest_buffer_reads_back() {
    // lavapipe takes 16384² images but buffers of at most 2³¹ − 1 bytes: the RGBA16F read-back
    // of a 16384² image needs 2³¹. The same situation, scaled down: 16 MiB buffers, a 2048²
    // image of 32 MiB.
    let ctx = context_with_buffer_limit(16 << 20);
    let mut r = VolumeRenderer::new(ctx).expect("renderer");
    let volume = synthetic::constant([3, 2, 2], [1.0; 3], common::UNIFORM_VALUE).expect("valid");
    r.set_volume(&volume).expect("upload");
    r.set_transfer_function(&common::uniform_tf(0.5, [1.0, 0.6, 0.2]));
    let camera = common::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let settings = common::uniform_settings(Mode::Dvr, Strategy::Rc, RenderPath::Compute);
    let size = [2048, 2048];
    let image = r
        .render_image(&camera, size, &settings)
        .unwrap_or_else(|e| panic!("{e}"));
    common::assert_all_finite("banded", &image);
    let uniform = Uniform {
        alpha: 0.5,
        rgb: [1.0, 0.6, 0.2],
        d0_mm: 1.0,
        windowed: 0.5,
    };
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    // Every 31st pixel of every 31st row, the last row and column included.
    let picks = (0..size[0]).step_by(31).chain([size[0] - 1]);
    for py in picks.clone() {
        for px in picks.clone() {
            let answers = common::footprint(px, py, 1.0 / 16.0).map(|(x, y)| {
                uniform.pixel(
                    &settings,
                    common::path_length_mm(&camera, &bounds, size, x, y),
                )
            });
            let sub = ImageF32 {
                width: 1,
                height: 1,
                pixels: vec![image.get(px, py)],
            };
            common::assert_within_footprint(
                &format!("banded-{px}-{py}"),
                &sub,
                common::ANALYTIC_TOLERANCE,
                |_, _| answers,
            );
        }
    }
}
