//! The cropping box: every strategy on both paths against the f64 reference (which clips rays
//! with its own slab test), and a proof that nothing outside the box is ever sampled — a bright
//! object outside it leaves the image bit for bit unchanged.

use crate::common;

use glam::DVec3;
use leapview::camera::{Camera, ProjectionKind, ViewPreset};
use leapview::settings::effects::MipColor;
use leapview::settings::{CropBox, Mode, RenderPath, RenderSettings, Strategy};
use leapview::volume::{Samples, ValueMapping, Volume};

/// A crop of the test scene that cuts through the ball and the dense cube on every axis.
fn cut() -> CropBox {
    CropBox::from_voxels([28, 24, 20], [5.0, 2.0, 4.0], [21.0, 17.0, 15.0])
}

#[test]
fn cropped_dvr_and_mip_match_the_reference_everywhere() {
    let volume = common::scene::scene();
    let tf = common::scene::tf();
    let mut r = common::renderer_for(&volume, &tf);
    for (view, kind) in [
        (ViewPreset::Oblique, ProjectionKind::Perspective),
        (ViewPreset::MinusY, ProjectionKind::Orthographic),
    ] {
        let camera = common::framing(&volume, view, kind);
        for mode in [Mode::Dvr, Mode::Mip, Mode::Xray] {
            let base = RenderSettings {
                crop: cut(),
                mip_color: MipColor::Window,
                ..common::settings(mode, Strategy::Rc, RenderPath::Auto)
            };
            let name = format!("crop-{mode:?}-{view:?}");
            common::check_reference(&mut r, &name, &volume, &tf, &camera, base);
        }
        // Pre-integrated segments end on the box too (the tail segment to the exit included).
        let base = RenderSettings {
            crop: cut(),
            preintegrated: true,
            step_vox: 2.0,
            ..common::settings(Mode::Dvr, Strategy::Rc, RenderPath::Auto)
        };
        let size = [40, 40];
        let expected = leapview::reference::render(&volume, &tf, &camera, size, &base).image;
        for (strategy, path) in common::variants() {
            let s = RenderSettings {
                strategy,
                path,
                ..base
            };
            let image = r.render_image(&camera, size, &s).expect("render");
            // preintegration.rs's bound (4/255); up to 1 % of the pixels may pass 1/255
            // (measured along −y, RC-t on the fragment path: 3 of 1600 pixels, at most 0.0043,
            // at the dense cube the box cuts).
            let name = format!("crop-preintegrated-{view:?}-{}-{path:?}", strategy.label());
            common::assert_close(&name, &image, &expected, 4.0 / 255.0, 0.01);
        }
    }
}

#[test]
fn cropping_with_the_eye_inside_the_box_matches_the_reference() {
    // The near plane cuts the cropping box: rays start on the near-plane cap, clipped to it.
    let volume = common::scene::scene();
    let tf = common::scene::tf();
    let mut r = common::renderer_for(&volume, &tf);
    let crop = cut();
    let bounds = leapview::camera::Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let inside = crop.world(&bounds);
    let mut camera = common::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    camera.eye = inside.min + (inside.max - inside.min) * DVec3::new(0.2, 0.3, 0.25);
    camera.target = inside.center();
    let base = RenderSettings {
        crop,
        ..common::settings(Mode::Dvr, Strategy::Rc, RenderPath::Auto)
    };
    common::check_reference(&mut r, "crop-eye-inside", &volume, &tf, &camera, base);
}

/// The test scene with a block in its far corner (voxels 24..28 × 20..24 × 16..20): of the
/// scene's largest value when `dense`, else of the background value 100.
fn with_corner_block(dense: bool) -> Volume {
    let scene = common::scene::scene();
    let value = if dense {
        scene.value_range().expect("finite values").max as f32
    } else {
        100.0
    };
    let dims = scene.dims();
    let Samples::F32(mut v) = scene.samples().expect("in memory").clone() else {
        panic!("the scene is f32");
    };
    for z in 16..20 {
        for y in 20..24 {
            for x in 24..28 {
                v[(z * dims[1] as usize + y) * dims[0] as usize + x] = value;
            }
        }
    }
    Volume::new(
        "scene-block",
        dims,
        scene.spacing_mm(),
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

#[test]
fn nothing_outside_the_box_reaches_the_image() {
    // Cropped at voxel edge 20 on x, four voxels clear of the block at 24..28, so neither the
    // trilinear filter at the cut face nor the widest gradient stencil (±2 voxels) reads it, the
    // block must change nothing at all; uncropped it must show (or the test proves nothing).
    // The block holds the scene's largest value, so both volumes have the same value range and
    // lookup table.
    let plain = with_corner_block(false);
    let block = with_corner_block(true);
    let tf = common::scene::tf();
    let crop = CropBox::from_voxels(plain.dims(), [0.0; 3], [20.0, 24.0, 20.0]);
    let camera: Camera = common::framing(&plain, ViewPreset::Oblique, ProjectionKind::Perspective);
    let size = [48, 48];
    for mode in [Mode::Dvr, Mode::Mip] {
        for (strategy, path) in common::variants() {
            let settings = RenderSettings {
                crop,
                // A fixed window, so the block's value does not change the normalisation of MIP.
                window: Some([0.0, 1200.0]),
                ..common::settings(mode, strategy, path)
            };
            let mut images = Vec::new();
            for volume in [&plain, &block] {
                let mut r = common::renderer_for(volume, &tf);
                images.push(r.render_image(&camera, size, &settings).expect("render"));
            }
            let uncropped = RenderSettings {
                crop: CropBox::FULL,
                ..settings
            };
            let mut shown = Vec::new();
            for volume in [&plain, &block] {
                let mut r = common::renderer_for(volume, &tf);
                shown.push(r.render_image(&camera, size, &uncropped).expect("render"));
            }
            let name = format!("{mode:?}-{}-{path:?}", strategy.label());
            let d = images[0].diff(&images[1]).expect("same size");
            assert_eq!(
                d.max_abs, 0.0,
                "{name}: the block outside the crop changed the image"
            );
            let seen = shown[0].diff(&shown[1]).expect("same size");
            assert!(
                seen.max_abs > 0.1,
                "{name}: the block does not show uncropped ({}), so the test proves nothing",
                seen.max_abs
            );
        }
    }
}

#[test]
fn a_bad_crop_is_an_error_not_a_picture() {
    let volume = common::scene::scene();
    let tf = common::scene::tf();
    let mut r = common::renderer_for(&volume, &tf);
    let camera = common::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    for crop in [
        CropBox {
            min: [0.5, 0.0, 0.0],
            max: [0.5, 1.0, 1.0],
        },
        CropBox {
            min: [0.0; 3],
            max: [1.5, 1.0, 1.0],
        },
        CropBox {
            min: [f64::NAN, 0.0, 0.0],
            max: [1.0; 3],
        },
    ] {
        let settings = RenderSettings {
            crop,
            ..RenderSettings::default()
        };
        let err = r
            .render_image(&camera, [16, 16], &settings)
            .expect_err("a bad crop renders nothing");
        assert!(err.to_string().contains("cropping box"), "{err}");
    }
}
