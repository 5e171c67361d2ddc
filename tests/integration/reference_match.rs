//! GPU images against the f64 CPU reference on small synthetic volumes.

use crate::common;

use glam::DVec3;
use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::counters::FrameCounters;
use leapview::reference;
use leapview::render::FrameRequest;
use leapview::settings::{RenderPath, RenderSettings, Strategy};
use leapview::transfer::{TransferFunction, ValueSpace};
use leapview::volume::{Samples, ValueMapping, Volume};

/// A 24×20×16 volume with a soft ball and a denser off-centre cube, on anisotropic spacing.
fn blobs() -> Volume {
    let dims = [24u32, 20, 16];
    let spacing = [1.0, 1.2, 1.5];
    let mut v = Vec::new();
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let p = DVec3::new(
                    x as f64 * spacing[0],
                    y as f64 * spacing[1],
                    z as f64 * spacing[2],
                );
                let r = (p - DVec3::new(11.0, 12.0, 11.0)).length();
                let ball = (1.0 - r / 9.0).clamp(0.0, 1.0) * 600.0;
                let cube = if (3..8).contains(&x) && (4..10).contains(&y) && (2..6).contains(&z) {
                    900.0
                } else {
                    0.0
                };
                v.push((ball + cube) as f32);
            }
        }
    }
    Volume::new(
        "blobs",
        dims,
        spacing,
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

fn tf() -> TransferFunction {
    TransferFunction {
        opacity: vec![[0.0, 0.0], [100.0, 0.0], [400.0, 0.15], [900.0, 0.6]],
        color: vec![
            [0.0, 0.2, 0.4, 1.0],
            [500.0, 1.0, 0.6, 0.2],
            [900.0, 1.0, 1.0, 1.0],
        ],
        space: ValueSpace::Data,
    }
}

#[test]
fn dvr_matches_reference_on_both_paths() {
    let volume = blobs();
    let tf = tf();
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    r.set_transfer_function(&tf);
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
    let size = [64, 64];
    for strategy in [Strategy::Rc, Strategy::RcT] {
        let settings = RenderSettings {
            strategy,
            ..RenderSettings::default()
        };
        let expected = reference::render(&volume, &tf, &camera, size, &settings).image;
        for path in [RenderPath::Fragment, RenderPath::Compute] {
            let settings = RenderSettings { path, ..settings };
            r.render(&FrameRequest {
                camera: &camera,
                size,
                settings: &settings,
                stats: false,
            })
            .expect("render");
            let actual = r.read_image().expect("read");
            let name = format!("blobs-{strategy:?}-{path:?}");
            let d = common::assert_close(&name, &actual, &expected, 0.05, 0.2);
            eprintln!("{name}: {d:?}");
        }
    }
}

/// Renders with the GPU on both paths and compares with the reference; returns the GPU counters
/// of the compute path and the reference counts.
fn compare(
    name: &str,
    volume: &Volume,
    tf: &TransferFunction,
    camera: &Camera,
    size: [u32; 2],
    settings: RenderSettings,
) -> (FrameCounters, FrameCounters) {
    let mut r = common::renderer();
    r.set_volume(volume).expect("upload");
    r.set_transfer_function(tf);
    let expected = reference::render(volume, tf, camera, size, &settings);
    let mut counters = Default::default();
    for path in [RenderPath::Fragment, RenderPath::Compute] {
        let settings = RenderSettings { path, ..settings };
        let (_, results) = r
            .render_and_wait(&FrameRequest {
                camera,
                size,
                settings: &settings,
                stats: true,
            })
            .expect("render");
        let actual = r.read_image().expect("read");
        // Output is RGBA16F: 2^-11 relative; texture-unit interpolation weights have 8 fractional
        // bits (1/256 of a voxel) on most GPUs and lavapipe, so values near steep edges differ by a
        // few 1/255 levels. Rays grazing the box edges may round to the other side of a face.
        common::assert_close(
            &format!("{name}-{path:?}"),
            &actual,
            &expected.image,
            8.0 / 255.0,
            0.02,
        );
        counters = results.counters.expect("stats variant counts");
    }
    (counters, expected.counts)
}

#[test]
fn camera_inside_the_volume_starts_rays_on_the_near_plane() {
    let volume = blobs();
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    for kind in [ProjectionKind::Perspective, ProjectionKind::Orthographic] {
        let (dir, up) = ViewPreset::Oblique.direction_and_up();
        let mut camera = Camera::framing(&bounds, dir, up, kind);
        // Inside the box, 4 mm in front of the ball's centre along the view direction.
        camera.eye = DVec3::new(11.0, 12.0, 11.0) - dir * 4.0;
        camera.target = camera.eye + dir;
        if let leapview::camera::Projection::Orthographic { height_mm } = &mut camera.projection {
            *height_mm = 10.0;
        }
        let settings = RenderSettings {
            strategy: Strategy::Rc,
            ..RenderSettings::default()
        };
        let (gpu, cpu) = compare(
            &format!("inside-{kind:?}"),
            &volume,
            &tf(),
            &camera,
            [48, 48],
            settings,
        );
        assert_eq!(gpu.rays, cpu.rays, "every pixel starts inside the volume");
        assert_eq!(cpu.rays, 48 * 48);
    }
}

#[test]
fn axis_aligned_and_orthographic_views_match() {
    let volume = blobs();
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    for (i, view) in [ViewPreset::PlusX, ViewPreset::MinusY, ViewPreset::PlusZ]
        .into_iter()
        .enumerate()
    {
        let (dir, up) = view.direction_and_up();
        let kind = if i % 2 == 0 {
            ProjectionKind::Orthographic
        } else {
            ProjectionKind::Perspective
        };
        let camera = Camera::framing(&bounds, dir, up, kind);
        let (gpu, cpu) = compare(
            &format!("axis-{view:?}"),
            &volume,
            &tf(),
            &camera,
            [40, 32],
            // The reference takes every sample up to termination: compare with RC-t.
            RenderSettings {
                strategy: Strategy::RcT,
                ..RenderSettings::default()
            },
        );
        // Sample counts differ only where a ray's length rounds across a step boundary, or where
        // the rasteriser and the slab test disagree at a silhouette pixel: well under 1 %.
        let rel = (gpu.samples as f64 - cpu.samples as f64).abs() / cpu.samples as f64;
        assert!(rel < 0.01, "{view:?}: gpu {gpu:?} cpu {cpu:?}");
    }
}

#[test]
fn nan_and_infinite_voxels_render_transparent() {
    let mut v = vec![500.0f32; 8 * 8 * 8];
    v[3 + 8 * (4 + 8 * 4)] = f32::NAN;
    v[5 + 8 * (2 + 8 * 3)] = f32::INFINITY;
    let volume = Volume::new(
        "nan",
        [8, 8, 8],
        [1.0; 3],
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid");
    let tf = TransferFunction {
        opacity: vec![[0.0, 0.1]],
        color: vec![[0.0, 1.0, 1.0, 1.0]],
        space: ValueSpace::Data,
    };
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = ViewPreset::PlusZ.direction_and_up();
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Orthographic);
    compare(
        "nan",
        &volume,
        &tf,
        &camera,
        [32, 32],
        RenderSettings::default(),
    );
}

/// Real scans against the reference: the 16-bit CT head (bone, in the scanner's raw units, so
/// the threshold edge is sharp) and the 8-bit MR angiogram (thin vessels).
#[test]
fn real_volumes_match_reference() {
    let dir = common::data_dir();
    let bone = TransferFunction {
        opacity: vec![[0.0, 0.0], [1150.0, 0.0], [1400.0, 0.5], [3272.0, 0.9]],
        color: vec![[1150.0, 0.8, 0.5, 0.35], [1500.0, 1.0, 0.95, 0.85]],
        space: ValueSpace::Data,
    };
    let angio = leapview::transfer::presets::preset("mr-angio").expect("preset");
    let cases = [
        (
            "ct_head_cthead_256x256x113_uint16.nrrd",
            bone,
            ViewPreset::PlusY,
        ),
        ("mra_head_200x256x120_uint8.nrrd", angio, ViewPreset::MinusZ),
    ];
    for (file, tf, view) in cases {
        let volume =
            leapview::volume::load_volume(&dir.join(file), &Default::default()).expect("loads");
        let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
        let (dir, up) = view.direction_and_up();
        let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
        let settings = RenderSettings {
            step_vox: 1.0,
            ..RenderSettings::default()
        };
        let mut r = common::renderer();
        r.set_volume(&volume).expect("upload");
        r.set_transfer_function(&tf);
        let expected = reference::render(&volume, &tf, &camera, [80, 80], &settings);
        for path in [RenderPath::Fragment, RenderPath::Compute] {
            let settings = RenderSettings { path, ..settings };
            r.render(&FrameRequest {
                camera: &camera,
                size: [80, 80],
                settings: &settings,
                stats: false,
            })
            .expect("render");
            let actual = r.read_image().expect("read");
            // Measured on lavapipe: max 0.0006 (CT head, the f16 output step) and 0.0086 in 0.23 %
            // of the pixels (MR angiogram: thin vessels, where a value close to the threshold
            // meets the texture unit's rounding). GPUs with 8-bit interpolation weights round
            // more, hence up to 8/255 in at most 1 % of the pixels.
            let d = common::assert_close(
                &format!("real-{file}-{path:?}"),
                &actual,
                &expected.image,
                8.0 / 255.0,
                0.01,
            );
            eprintln!("{file} {path:?}: {d:?}");
        }
    }
}

#[test]
fn jittered_starts_follow_the_reference_and_leaping_stays_exact() {
    let volume = blobs();
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
    // A coarse step, where the jitter moves samples far enough to change the image.
    let jittered = RenderSettings {
        strategy: Strategy::RcT,
        step_vox: 2.0,
        jitter: true,
        ..RenderSettings::default()
    };
    let (gpu, cpu) = compare("jitter", &volume, &tf(), &camera, [40, 40], jittered);
    let rel = (gpu.samples as f64 - cpu.samples as f64).abs() / cpu.samples as f64;
    assert!(rel < 0.01, "gpu {gpu:?} cpu {cpu:?}");

    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    // Settings left at their default render with the path `auto`.
    common::choose_auto_path(&mut r);
    r.set_transfer_function(&tf());
    let mut image = |settings: RenderSettings| {
        r.render_image(&camera, [40, 40], &settings)
            .expect("render")
    };
    let plain = image(RenderSettings {
        jitter: false,
        ..jittered
    });
    let rc_t = image(jittered);
    assert_ne!(plain, rc_t, "jitter moves the samples");
    for strategy in [Strategy::RcS, Strategy::RcSDistance] {
        for path in [RenderPath::Fragment, RenderPath::Compute] {
            let leapt = image(RenderSettings {
                strategy,
                path,
                ..jittered
            });
            let reference = image(RenderSettings { path, ..jittered });
            assert_eq!(
                leapt, reference,
                "{strategy:?} {path:?}: leaping lands on the jittered grid"
            );
        }
    }
}
