//! Hard volume and frame geometry (issue 7, item 5): volumes of 1×1×1, 1×N×1 and 2×2×2 voxels,
//! spacing 0.01 mm against 10 mm, steps of 10⁻³ and 100 voxels, images of 1×1 and 8192×8192
//! pixels. Uniform volumes are checked against their analytic answers, structured ones against
//! the f64 reference; every mode and both paths, and no pixel may be NaN or infinite.

mod common;

use common::Uniform;
use glam::DVec3;
use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::imaging::ImageF32;
use leapview::reference;
use leapview::render::context::device_descriptor;
use leapview::render::effects::{IsoSettings, Shading};
use leapview::render::renderer::RenderError;
use leapview::render::{GpuContext, Mode, RenderPath, RenderSettings, Strategy, VolumeRenderer};
use leapview::transfer::{TransferFunction, ValueSpace};
use leapview::volume::{Samples, ValueMapping, Volume, synthetic};

const VALUE: f32 = 100.0;
const BACKGROUND: [f64; 3] = [0.2, 0.3, 0.4];

/// The settings every case starts from: lit, a visible background, the uniform value in the
/// middle of the window.
fn base(mode: Mode, strategy: Strategy, path: RenderPath) -> RenderSettings {
    RenderSettings {
        mode,
        strategy,
        path,
        shading: Shading::Phong,
        background: BACKGROUND,
        window: Some([f64::from(VALUE) - 1.0, f64::from(VALUE) + 1.0]),
        xray_density_per_mm: 0.05,
        ..RenderSettings::default()
    }
}

fn framing(volume: &Volume, view: ViewPreset, kind: ProjectionKind) -> Camera {
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = view.direction_and_up();
    Camera::framing(&bounds, dir, up, kind)
}

/// Renders a uniform volume of value [`VALUE`] with `step_vox` in every mode, the given
/// strategies and both paths, and checks each image against the analytic answer.
fn check_uniform(
    name: &str,
    volume: &Volume,
    alpha: f64,
    cameras: &[Camera],
    size: [u32; 2],
    step_vox: f64,
    strategies: &[Strategy],
) -> f64 {
    let uniform = Uniform {
        alpha,
        rgb: [1.0, 0.6, 0.2],
        d0_mm: volume.min_spacing_mm(),
        windowed: 0.5,
    };
    let mut r = common::renderer();
    r.set_volume(volume).expect("upload");
    r.set_transfer_function(&common::uniform_tf(uniform.alpha, uniform.rgb));
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let mut worst = 0.0f64;
    for (i, camera) in cameras.iter().enumerate() {
        // A sixteenth of a pixel around each centre, as in tests/hard_cases_camera.rs.
        let lengths = common::footprint_lengths(camera, &bounds, size, 1.0 / 16.0);
        for mode in Mode::ALL {
            for &strategy in strategies {
                for path in common::PATHS {
                    let settings = RenderSettings {
                        step_vox,
                        ..base(mode, strategy, path)
                    };
                    let image = r.render_image(camera, size, &settings).expect("render");
                    let (_, w) = common::assert_within_footprint(
                        &format!("{name}-{i}-{}-{}-{path:?}", mode.label(), strategy.label()),
                        &image,
                        common::ANALYTIC_TOLERANCE,
                        |px, py| {
                            lengths[(py * size[0] + px) as usize]
                                .map(|l| uniform.pixel(&settings, l))
                        },
                    );
                    worst = worst.max(w);
                }
            }
        }
    }
    eprintln!("{name}: largest deviation from the analytic answer {worst:.1e}");
    worst
}

/// A colour ramp over 0..1000 with opacity rising from 0 to `max_alpha`.
fn ramp_tf(max_alpha: f64) -> TransferFunction {
    TransferFunction {
        opacity: vec![[0.0, 0.0], [1000.0, max_alpha]],
        color: vec![[0.0, 0.2, 0.4, 1.0], [1000.0, 1.0, 0.8, 0.3]],
        space: ValueSpace::Data,
    }
}

/// Renders `volume` in every mode, strategy and path and compares with the f64 reference, under
/// [`ramp_tf`] up to `max_alpha`.
fn check_reference(
    r: &mut VolumeRenderer,
    name: &str,
    volume: &Volume,
    camera: &Camera,
    size: [u32; 2],
    step_vox: f64,
    max_alpha: f64,
) -> f64 {
    let tf = ramp_tf(max_alpha);
    r.set_volume(volume).expect("upload");
    r.set_transfer_function(&tf);
    let mut worst = 0.0f64;
    for mode in Mode::ALL {
        let settings = RenderSettings {
            step_vox,
            strategy: Strategy::RcT,
            iso: IsoSettings {
                value: Some(400.0),
                ..IsoSettings::default()
            },
            window: Some([0.0, 1000.0]),
            ..base(mode, Strategy::RcT, RenderPath::Compute)
        };
        let expected = reference::render(volume, &tf, camera, size, &settings).image;
        for strategy in Strategy::ALL {
            for path in common::PATHS {
                let settings = RenderSettings {
                    strategy,
                    path,
                    ..settings
                };
                let image = r.render_image(camera, size, &settings).expect("render");
                // tests/modes.rs's bounds: 4/255 (lookup table, f16 output, RC against the
                // reference's RC-t); isosurfaces may flip up to 0.5 % of the pixels.
                let (max_abs, share) = if mode == Mode::Iso {
                    (1.0, 0.005)
                } else {
                    (4.0 / 255.0, 0.0)
                };
                let d = common::assert_close(
                    &format!("{name}-{}-{}-{path:?}", mode.label(), strategy.label()),
                    &image,
                    &expected,
                    max_abs,
                    share,
                );
                worst = worst.max(d.max_abs);
            }
        }
    }
    eprintln!("{name}: largest difference from the reference {worst:.1e}");
    worst
}

/// `dims` voxels on `spacing`, valued by `f` of the voxel's world position.
fn field(dims: [u32; 3], spacing: [f64; 3], f: impl Fn(DVec3) -> f64) -> Volume {
    let mut v = Vec::new();
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let p = DVec3::new(x as f64, y as f64, z as f64) * DVec3::from_array(spacing);
                v.push(f(p) as f32);
            }
        }
    }
    Volume::new(
        "field",
        dims,
        spacing,
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

#[test]
fn volumes_of_one_a_line_and_eight_voxels() {
    let one = synthetic::constant([1, 1, 1], [1.5, 1.0, 2.0], VALUE).expect("valid");
    let cameras = [
        framing(&one, ViewPreset::Oblique, ProjectionKind::Perspective),
        framing(&one, ViewPreset::PlusX, ProjectionKind::Orthographic),
        framing(&one, ViewPreset::MinusZ, ProjectionKind::Perspective),
    ];
    check_uniform(
        "one-voxel",
        &one,
        0.3,
        &cameras,
        [24, 24],
        0.5,
        &Strategy::ALL,
    );
    let line = field([1, 9, 1], [1.0, 2.0, 1.0], |p| 1000.0 * (p.y / 16.0));
    let cube = field([2, 2, 2], [1.0, 1.0, 1.0], |p| {
        100.0 + 800.0 * p.x + 300.0 * p.y - 200.0 * p.z
    });
    let mut r = common::renderer();
    for (name, volume) in [("line", &line), ("eight", &cube)] {
        for view in [ViewPreset::Oblique, ViewPreset::PlusX, ViewPreset::PlusY] {
            for kind in [ProjectionKind::Perspective, ProjectionKind::Orthographic] {
                let camera = framing(volume, view, kind);
                let name = format!("{name}-{view:?}-{kind:?}");
                check_reference(&mut r, &name, volume, &camera, [24, 24], 0.5, 0.3);
            }
        }
    }
}

#[test]
fn spacing_of_a_hundredth_against_ten_millimetres() {
    let spacing = [0.01, 10.0, 1.0];
    // 0.06 × 40 × 5 mm: a ray along y crosses 4000 d0 (8000 samples of half a d0).
    let plate = synthetic::constant([6, 4, 5], spacing, VALUE).expect("valid");
    let cameras = [
        framing(&plate, ViewPreset::PlusX, ProjectionKind::Orthographic),
        framing(&plate, ViewPreset::MinusY, ProjectionKind::Orthographic),
        framing(&plate, ViewPreset::PlusZ, ProjectionKind::Orthographic),
        framing(&plate, ViewPreset::Oblique, ProjectionKind::Perspective),
    ];
    // α = 10⁻³ per 0.01 mm: 1 − 0.999^4000 = 0.98 along y, 0.006 across x.
    let strategies = [Strategy::Rc, Strategy::RcSDistance];
    check_uniform("plate", &plate, 1e-3, &cameras, [24, 24], 0.5, &strategies);
    let structured = field([6, 4, 5], spacing, |p| {
        1000.0 * (p.x / 0.05) * (1.0 - p.y / 30.0) * (0.5 + p.z / 8.0)
    });
    let mut r = common::renderer();
    for view in [ViewPreset::Oblique, ViewPreset::PlusX, ViewPreset::MinusY] {
        let camera = framing(&structured, view, ProjectionKind::Perspective);
        check_reference(
            &mut r,
            &format!("plate-{view:?}"),
            &structured,
            &camera,
            [24, 24],
            0.5,
            // Per 0.01 mm: a ray along y still sees about 2 mm deep.
            0.01,
        );
    }
}

#[test]
fn steps_of_a_thousandth_and_a_hundred_voxels() {
    let volume = synthetic::constant([6, 5, 4], [1.0, 1.25, 1.5], VALUE).expect("valid");
    let cameras = [
        framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective),
        framing(&volume, ViewPreset::PlusY, ProjectionKind::Orthographic),
    ];
    let strategies = [Strategy::Rc, Strategy::RcSDistance];
    // α = 0.05: at 100 voxels a full step transmits 0.95^100 = 0.006, well within f32 (see
    // `a_hundred_voxel_step_keeps_the_opacity_of_short_paths` for a step that transmits less).
    for step_vox in [1e-3, 100.0] {
        let name = format!("step-{step_vox}");
        check_uniform(
            &name,
            &volume,
            0.05,
            &cameras,
            [20, 20],
            step_vox,
            &strategies,
        );
    }
    let structured = field([6, 5, 4], [1.0, 1.25, 1.5], |p| {
        100.0 * p.x + 80.0 * p.y * (1.0 + 0.2 * p.z)
    });
    let mut r = common::renderer();
    let camera = framing(
        &structured,
        ViewPreset::Oblique,
        ProjectionKind::Perspective,
    );
    // Opacities up to 0.05 again, for the same reason.
    for step_vox in [1e-3, 100.0] {
        let name = format!("step-{step_vox}-structured");
        check_reference(
            &mut r,
            &name,
            &structured,
            &camera,
            [20, 20],
            step_vox,
            0.05,
        );
    }
}

/// At 100 voxels a step of α = 0.2 transmits 0.8^100 = 2·10⁻¹⁰, below f32's resolution next to
/// 1: the lookup table's step-corrected opacity rounds to exactly 1, and the last, partial
/// segment of every ray (here the only one: every path is shorter than a step) can no longer be
/// scaled back (`1 − (1 − 1)^w = 1`), so every pixel the volume covers turns fully opaque.
#[test]
#[ignore = "known bug, reported: the f32 lookup table saturates the step-corrected opacity at \
            large steps; partial segments need the optical depth, not 1 − (1 − α)^step"]
fn a_hundred_voxel_step_keeps_the_opacity_of_short_paths() {
    let volume = synthetic::constant([6, 5, 4], [1.0, 1.25, 1.5], VALUE).expect("valid");
    let camera = framing(&volume, ViewPreset::PlusY, ProjectionKind::Orthographic);
    check_uniform(
        "step-100-saturated",
        &volume,
        0.2,
        &[camera],
        [20, 20],
        100.0,
        &[Strategy::Rc],
    );
}

#[test]
fn images_of_one_pixel_and_of_the_largest_size() {
    let volume = synthetic::constant([5, 4, 3], [1.0; 3], VALUE).expect("valid");
    let cameras = [
        framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective),
        framing(&volume, ViewPreset::PlusZ, ProjectionKind::Orthographic),
    ];
    check_uniform(
        "one-pixel",
        &volume,
        0.2,
        &cameras,
        [1, 1],
        0.5,
        &Strategy::ALL,
    );

    let one = synthetic::constant([1, 1, 1], [1.0; 3], VALUE).expect("valid");
    let mut r = common::renderer();
    r.set_volume(&one).expect("upload");
    r.set_transfer_function(&common::uniform_tf(0.5, [1.0, 0.6, 0.2]));
    let max = r.context().limits.max_texture_dimension_2d;
    let side = max.min(8192);
    eprintln!("largest image side on this adapter: {max}; rendering {side}²");
    let camera = framing(&one, ViewPreset::Oblique, ProjectionKind::Perspective);
    let settings = base(Mode::Dvr, Strategy::Rc, RenderPath::Compute);
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
            covered += usize::from(answers[0] != BACKGROUND);
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
    let volume = synthetic::constant([3, 2, 2], [1.0; 3], VALUE).expect("valid");
    r.set_volume(&volume).expect("upload");
    r.set_transfer_function(&common::uniform_tf(0.5, [1.0, 0.6, 0.2]));
    let camera = framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let settings = base(Mode::Dvr, Strategy::Rc, RenderPath::Compute);
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
