//! Pre-integrated classification: the GPU matches the f64 reference's pre-integration on both
//! paths, leaping stays exact with it, and a thin transfer-function feature that large steps
//! miss with post-classification survives with it.

use crate::common;

use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::imaging::ImageF32;
use leapview::reference;
use leapview::settings::effects::Shading;
use leapview::settings::{RenderPath, RenderSettings, Strategy};
use leapview::transfer::{TransferFunction, ValueSpace};
use leapview::volume::{Samples, ValueMapping, Volume};

use common::scene::{scene, tf};

fn oblique(volume: &Volume) -> Camera {
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    Camera::framing(&bounds, dir, up, ProjectionKind::Perspective)
}

#[test]
fn preintegrated_dvr_matches_the_reference_on_both_paths() {
    let volume = scene();
    let tf = tf();
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    r.set_transfer_function(&tf);
    let camera = oblique(&volume);
    let size = [64, 64];
    for step_vox in [0.5, 2.0, 4.0] {
        for shading in [Shading::Off, Shading::Phong] {
            let settings = RenderSettings {
                step_vox,
                shading,
                preintegrated: true,
                strategy: Strategy::RcT,
                ..RenderSettings::default()
            };
            let expected = reference::render(&volume, &tf, &camera, size, &settings).image;
            for path in [RenderPath::Fragment, RenderPath::Compute] {
                let actual = r
                    .render_image(&camera, size, &RenderSettings { path, ..settings })
                    .expect("render");
                // The GPU integrates the TF sampled at 4096 entries with the trapezoid rule and
                // subtracts f32 running integrals; the reference integrates the TF's pieces in
                // f64 (Gauss–Legendre). Same 1/255-scale bound as the post-classified modes
                // (modes.rs), with room for the table's resolution at ramp ends.
                common::assert_close(
                    &format!("preint-step{step_vox}-{shading:?}-{path:?}"),
                    &actual,
                    &expected,
                    4.0 / 255.0,
                    0.0,
                );
            }
        }
    }
}

#[test]
fn leaping_is_exact_with_preintegration() {
    let volume = scene();
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    r.set_transfer_function(&tf());
    let camera = oblique(&volume);
    for step_vox in [0.5, 1.5, 4.0] {
        for path in [RenderPath::Fragment, RenderPath::Compute] {
            let settings = |strategy| RenderSettings {
                step_vox,
                strategy,
                path,
                preintegrated: true,
                block_vox: Some(4),
                ..RenderSettings::default()
            };
            let plain = r
                .render_image(&camera, [64, 64], &settings(Strategy::RcT))
                .expect("render");
            for strategy in [Strategy::RcS, Strategy::RcSDistance] {
                let (leapt, counts) =
                    common::render_counted(&mut r, &camera, settings(strategy), [64, 64]);
                assert!(
                    counts.leaps > 0,
                    "{strategy:?} step {step_vox}: nothing leapt"
                );
                // Every segment leaping skips lies inside one empty region, where the running
                // integrals are equal texel for texel: the images are identical.
                common::assert_close(
                    &format!("preint-leap-{strategy:?}-{step_vox}-{path:?}"),
                    &leapt,
                    &plain,
                    0.0,
                    0.0,
                );
            }
        }
    }
}

/// 64×16×16 voxels whose value rises linearly along x from 0 to 1000.
fn ramp() -> Volume {
    let dims = [64u32, 16, 16];
    let v = (0..16 * 16)
        .flat_map(|_| (0..64).map(|x| x as f32 * 1000.0 / 63.0))
        .collect();
    Volume::new(
        "ramp",
        dims,
        [1.0; 3],
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

/// A thin shell: opacity 0.9 only within ±3 of 500 (0.2 voxel of the ramp), white.
fn shell() -> TransferFunction {
    TransferFunction {
        opacity: vec![[0.0, 0.0], [497.0, 0.0], [500.0, 0.9], [503.0, 0.0]],
        color: vec![[0.0, 1.0, 1.0, 1.0]],
        space: ValueSpace::Data,
    }
}

fn rmse(a: &ImageF32, b: &ImageF32) -> f64 {
    a.diff(b).expect("same size").rmse
}

#[test]
fn a_thin_shell_survives_large_steps_only_with_preintegration() {
    let volume = ramp();
    let tf = shell();
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    r.set_transfer_function(&tf);
    let camera = oblique(&volume);
    let size = [64, 64];
    let base = RenderSettings {
        shading: Shading::Off,
        strategy: Strategy::RcT,
        path: RenderPath::Compute,
        ..RenderSettings::default()
    };
    // The truth: post-classification at 1/16 voxel, in f64.
    let truth = reference::render(
        &volume,
        &tf,
        &camera,
        size,
        &RenderSettings {
            step_vox: 1.0 / 16.0,
            ..base
        },
    )
    .image;
    for step_vox in [1.0, 2.0, 4.0] {
        let post = r
            .render_image(&camera, size, &RenderSettings { step_vox, ..base })
            .expect("render");
        let pre = r
            .render_image(
                &camera,
                size,
                &RenderSettings {
                    step_vox,
                    preintegrated: true,
                    ..base
                },
            )
            .expect("render");
        let (e_post, e_pre) = (rmse(&post, &truth), rmse(&pre, &truth));
        eprintln!("step {step_vox}: RMSE post {e_post:.4}, pre-integrated {e_pre:.4}");
        // A shell 0.2 voxel thick: at a step of 1+ voxel most rays sample it nowhere near its
        // peak, so post-classification loses most of it (RMSE of several tenths of its
        // brightness), while pre-integration integrates it whole: at least ten times closer.
        assert!(
            e_pre * 10.0 < e_post,
            "step {step_vox}: pre-integrated {e_pre} vs post {e_post}"
        );
        common::assert_close(
            &format!("preint-shell-step{step_vox}"),
            &pre,
            &truth,
            8.0 / 255.0,
            0.05,
        );
    }
}
