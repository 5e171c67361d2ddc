//! Opacity correction holds: a uniform slab `L` voxels thick whose transfer function gives
//! opacity α per voxel length composites to `1 − (1 − α)^L` for every step from 1/8 to 4 voxels,
//! on both paths, with and without early termination, with post-classification and with
//! pre-integration.

use crate::common;

use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::settings::effects::Shading;
use leapview::settings::{RenderPath, RenderSettings, Strategy};
use leapview::transfer::{TransferFunction, ValueSpace};
use leapview::volume::{Samples, ValueMapping, Volume};

/// `L × 24 × 24` voxels of 50, except one corner voxel of 0 so the value range is not empty.
fn slab(thickness: u32) -> Volume {
    let dims = [thickness, 24, 24];
    let mut v = vec![50.0f32; (thickness * 24 * 24) as usize];
    v[0] = 0.0;
    Volume::new(
        "slab",
        dims,
        [0.7, 0.7, 0.7],
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

/// Opacity `alpha` and white at 50 (and everywhere above 25).
fn tf(alpha: f64) -> TransferFunction {
    TransferFunction {
        opacity: vec![[0.0, 0.0], [25.0, alpha], [50.0, alpha]],
        color: vec![[0.0, 1.0, 1.0, 1.0]],
        space: ValueSpace::Data,
    }
}

#[test]
fn a_uniform_slab_composites_to_the_analytic_opacity_at_every_step() {
    let mut r = common::renderer();
    let mut worst = 0.0f64;
    for (thickness, alpha) in [(1u32, 0.5), (8, 0.1), (13, 0.2)] {
        let volume = slab(thickness);
        r.set_volume(&volume).expect("upload");
        r.set_transfer_function(&tf(alpha));
        let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
        // Orthographic along x: every ray crosses exactly `thickness` voxels.
        let (dir, up) = ViewPreset::PlusX.direction_and_up();
        let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Orthographic);
        let expected = 1.0 - (1.0 - alpha).powi(thickness as i32);
        for step_vox in [0.125, 0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0] {
            for (strategy, preintegrated) in [
                (Strategy::Rc, false),
                (Strategy::RcT, false),
                (Strategy::RcT, true),
            ] {
                for path in [RenderPath::Fragment, RenderPath::Compute] {
                    let settings = RenderSettings {
                        step_vox,
                        strategy,
                        path,
                        preintegrated,
                        shading: Shading::Off,
                        ..RenderSettings::default()
                    };
                    let image = r
                        .render_image(&camera, [48, 48], &settings)
                        .expect("render");
                    // The middle 16×16 pixels: their rays stay 4+ voxels from the slab's sides
                    // (the volume fills about 90 % of the view) and from the zero corner voxel.
                    for y in 16..32 {
                        for x in 16..32 {
                            let g = f64::from(image.pixels[y * 48 + x][0]);
                            let err = (g - expected).abs();
                            worst = worst.max(err);
                            // 1/255: the bound; the output is f16 (2^-11 relative).
                            assert!(
                                err <= 1.0 / 255.0,
                                "L {thickness} α {alpha} step {step_vox} {strategy:?} {path:?} \
                                 pre-integrated {preintegrated} \
                                 pixel ({x},{y}): {g} vs {expected}"
                            );
                        }
                    }
                }
            }
        }
    }
    eprintln!("largest deviation from 1 − (1 − α)^L: {worst:.2e}");
}
