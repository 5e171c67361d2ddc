//! Progressive refinement: the GPU's mean of frames at shifted sample grids equals the mean of
//! the f64 reference's renders at the same offsets (so the accumulation adds exactly what it
//! should), with and without jitter, on both paths; and the mean is closer to a fine-step
//! rendering than any one frame at the coarse step (what refinement is for).

use crate::common;

use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::imaging::ImageF32;
use leapview::reference;
use leapview::render::RefineRun;
use leapview::render::raycast::refine::offset;
use leapview::settings::{RenderPath, RenderSettings, Strategy};
use leapview::transfer::{TransferFunction, ValueSpace};
use leapview::volume::{Volume, synthetic};

/// A 20³ volume holding a ball of radius 7 (1000 inside, 0 outside, a one-voxel edge): under a
/// sharp transfer function its surface aliases at coarse steps.
fn hard_ball() -> Volume {
    synthetic::sphere(20, 7.0, 1000.0, 0.0).expect("valid")
}

/// Opaque from 450 to 550: a thin shell of the interpolated edge.
fn sharp_tf() -> TransferFunction {
    TransferFunction {
        opacity: vec![
            [0.0, 0.0],
            [450.0, 0.0],
            [500.0, 0.9],
            [550.0, 0.0],
            [1000.0, 0.0],
        ],
        color: vec![[0.0, 1.0, 0.8, 0.5], [1000.0, 0.6, 0.8, 1.0]],
        space: ValueSpace::Data,
    }
}

fn mean(images: &[ImageF32]) -> ImageF32 {
    let n = images.len() as f32;
    let mut out = images[0].clone();
    for (i, p) in out.pixels.iter_mut().enumerate() {
        for (c, v) in p.iter_mut().enumerate() {
            *v = images.iter().map(|im| im.pixels[i][c]).sum::<f32>() / n;
        }
    }
    out
}

fn camera(volume: &Volume) -> Camera {
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    Camera::framing(&bounds, dir, up, ProjectionKind::Perspective)
}

#[test]
fn the_gpu_mean_is_the_mean_of_the_reference_at_the_same_offsets() {
    const FRAMES: u32 = 4;
    let volume = hard_ball();
    let tf = sharp_tf();
    let camera = camera(&volume);
    let size = [48, 48];
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    r.set_transfer_function(&tf);
    for jitter in [false, true] {
        let base = RenderSettings {
            strategy: Strategy::RcSDistance,
            step_vox: 1.0,
            jitter,
            ..RenderSettings::default()
        };
        let frames: Vec<ImageF32> = (0..FRAMES)
            .map(|k| {
                let s = RenderSettings {
                    sample_offset: offset(k),
                    ..base
                };
                reference::render(&volume, &tf, &camera, size, &s).image
            })
            .collect();
        let expected = mean(&frames);
        for path in [RenderPath::Fragment, RenderPath::Compute] {
            let settings = RenderSettings { path, ..base };
            let actual = r
                .render_refined(&camera, size, &settings, RefineRun::frames(FRAMES))
                .expect("refined render");
            let name = format!("refine-mean-jitter-{jitter}-{path:?}");
            // Measured on lavapipe: at most 3.4e-4 (f16 output, f32 against f64); a level of
            // 8-bit output, and none over 1/255, leaves room for other drivers' filtering.
            let d = common::assert_close(&name, &actual, &expected, 2.0 / 255.0, 0.0);
            eprintln!("{name}: {d:?}");
            // Not the single frame: the mean moved away from it where the grid aliases.
            let single = r.render_image(&camera, size, &settings).expect("render");
            let moved = single.diff(&actual).expect("same size");
            assert!(
                moved.max_abs > 0.05,
                "{name}: the mean equals one frame: {moved:?}"
            );
        }
    }
}

#[test]
fn the_mean_of_coarse_frames_is_closer_to_a_fine_step_than_one_frame() {
    let volume = hard_ball();
    let tf = sharp_tf();
    let camera = camera(&volume);
    let size = [64, 64];
    let fine = RenderSettings {
        step_vox: 1.0 / 16.0,
        ..RenderSettings::default()
    };
    let truth = reference::render(&volume, &tf, &camera, size, &fine).image;
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    // Settings left at their default render with the path `auto`.
    common::choose_auto_path(&mut r);
    r.set_transfer_function(&tf);
    let coarse = RenderSettings {
        step_vox: 1.0,
        strategy: Strategy::RcSDistance,
        ..RenderSettings::default()
    };
    let one = r.render_image(&camera, size, &coarse).expect("render");
    let one_error = one.diff(&truth).expect("same size").rmse;
    let mut last = one_error;
    for frames in [4, 16] {
        let refined = r
            .render_refined(&camera, size, &coarse, RefineRun::frames(frames))
            .expect("refined");
        let error = refined.diff(&truth).expect("same size").rmse;
        eprintln!(
            "RMSE against 1/16-voxel steps: one frame {one_error:.5}, mean of {frames} {error:.5}"
        );
        assert!(error < last, "{frames} frames: {error} not below {last}");
        last = error;
    }
    assert!(
        last < 0.5 * one_error,
        "16 frames: {last} against {one_error}"
    );
}
