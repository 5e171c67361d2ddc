//! Hard transfer functions (issue 7, item 5): a constant volume (min = max) of every stored type,
//! an all-transparent and a fully opaque transfer function, opacities of exactly 1 and of 10⁻⁶.
//! Each case asserts an analytic answer (or the f64 reference where lighting makes one
//! impractical) on every strategy and both paths, and that no pixel is NaN or infinite.

use crate::common;

use common::{BACKGROUND, framing, renderer_for, settings, variants};

use common::Uniform;
use leapview::camera::{Aabb, Camera, Projection, ProjectionKind, ViewPreset};
use leapview::imaging::ImageF32;
use leapview::reference::{self, sample_trilinear};
use leapview::settings::effects::{IsoSettings, MipColor, Shading};
use leapview::settings::{Mode, RenderPath, RenderSettings, Strategy};
use leapview::transfer::{TransferFunction, ValueSpace};
use leapview::volume::{Samples, ValueMapping, Volume, synthetic};

/// A 7×6×5 volume of one stored value `v` in each stored type.
fn constants() -> Vec<Volume> {
    let n = 7 * 6 * 5;
    let samples = [
        Samples::U8(vec![7; n]),
        Samples::I8(vec![-7; n]),
        Samples::U16(vec![4000; n]),
        Samples::I16(vec![-1000; n]),
        Samples::U32(vec![70_000; n]),
        Samples::F32(vec![0.25; n]),
        Samples::F64(vec![-3.5e5; n]),
    ];
    samples
        .into_iter()
        .map(|s| {
            Volume::new(
                "constant",
                [7, 6, 5],
                [1.0, 0.8, 1.2],
                s,
                ValueMapping::IDENTITY,
            )
        })
        .map(|v| v.expect("valid"))
        .collect()
}

#[test]
fn a_constant_volume_of_every_type_in_every_mode() {
    for volume in constants() {
        let range = volume.value_range().expect("finite");
        assert_eq!(range.min, range.max, "{:?}", volume.scalar_type());
        let value = range.min;
        let uniform = Uniform {
            alpha: 0.1,
            rgb: [0.9, 0.5, 0.1],
            d0_mm: 0.8,
            // The default window is the normalisation range [v, v + 1]: v at its bottom.
            windowed: 0.0,
        };
        let mut r = renderer_for(&volume, &common::uniform_tf(uniform.alpha, uniform.rgb));
        let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
        let camera = framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
        // A sixteenth of a pixel, as in hard_cases_camera.rs.
        let lengths = common::footprint_lengths(&camera, &bounds, [32, 32], 1.0 / 16.0);
        let name = volume.scalar_type().name();
        for mode in Mode::ALL {
            // The iso value at the constant itself and the default (the range's middle): the ray
            // starts at or above it and never crosses.
            for iso in [Some(value), None] {
                for (strategy, path) in variants() {
                    let s = RenderSettings {
                        iso: IsoSettings {
                            value: iso,
                            ..IsoSettings::default()
                        },
                        xray_density_per_mm: 0.05,
                        ..settings(mode, strategy, path)
                    };
                    let image = r.render_image(&camera, [32, 32], &s).expect("render");
                    common::assert_within_footprint(
                        &format!(
                            "constant-{name}-{}-{}-{path:?}",
                            mode.label(),
                            strategy.label()
                        ),
                        &image,
                        common::ANALYTIC_TOLERANCE,
                        |px, py| lengths[(py * 32 + px) as usize].map(|l| uniform.pixel(&s, l)),
                    );
                }
            }
        }
    }
}

/// 12×10×8 voxels on anisotropic spacing: a ball and a dense cube over a floor of 100.
fn structured() -> Volume {
    let dims = [12u32, 10, 8];
    let spacing = [1.0, 1.2, 1.5];
    let mut v = Vec::new();
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let p = glam::DVec3::new(x as f64, y as f64 * 1.2, z as f64 * 1.5);
                let r = (p - glam::DVec3::new(6.0, 6.0, 6.0)).length();
                let ball = 700.0 * (1.0 - r / 6.0).clamp(0.0, 1.0);
                let cube = if x < 4 && y < 4 && z < 3 { 900.0 } else { 0.0 };
                v.push((100.0 + ball + cube) as f32);
            }
        }
    }
    Volume::new(
        "structured",
        dims,
        spacing,
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

#[test]
fn an_all_transparent_transfer_function_shows_the_background_exactly() {
    let volume = structured();
    let tf = TransferFunction {
        opacity: vec![[0.0, 0.0]],
        color: vec![[0.0, 1.0, 1.0, 1.0]],
        space: ValueSpace::Data,
    };
    let mut r = renderer_for(&volume, &tf);
    for view in [ViewPreset::Oblique, ViewPreset::PlusZ] {
        let camera = framing(&volume, view, ProjectionKind::Perspective);
        for (mode, mip_color) in [(Mode::Dvr, MipColor::Window), (Mode::Mip, MipColor::Tf)] {
            for (strategy, path) in variants() {
                let s = RenderSettings {
                    mip_color,
                    ..settings(mode, strategy, path)
                };
                let image = r.render_image(&camera, [40, 40], &s).expect("render");
                let name = format!(
                    "transparent-{view:?}-{}-{}-{path:?}",
                    mode.label(),
                    strategy.label()
                );
                // The corner pixel's ray misses the volume: the background as the f16 output
                // stores it (lavapipe rounds towards zero): within one f16 step, 2^-10 of the
                // value's binade, so at most 1/1024 of the value.
                let bg = image.get(0, 0);
                for c in 0..3 {
                    let err = (f64::from(bg[c]) - BACKGROUND[c]).abs();
                    assert!(err <= BACKGROUND[c] / 1024.0, "{name}: background {bg:?}");
                }
                // Every ray through the volume adds exactly nothing to it.
                let expected = ImageF32::filled(40, 40, bg);
                common::assert_close(&name, &image, &expected, 0.0, 0.0);
                assert_eq!(image, expected, "{name}");
            }
        }
    }
}

/// The colour the transfer function gives the value at the first sample of each footprint
/// point's ray (`None`: the ray misses), for a volume whose opacity is 1 everywhere.
fn first_sample_colour(
    volume: &Volume,
    tf: &TransferFunction,
    camera: &Camera,
    s: &RenderSettings,
    size: [u32; 2],
    (x, y): (f64, f64),
) -> [f64; 3] {
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (origin, dir) = camera.pixel_ray(x, y, size, &bounds);
    let Some(l) = common::path_length_mm(camera, &bounds, size, x, y) else {
        return s.background;
    };
    let (t0, _) = bounds.intersect(origin, dir).expect("hit");
    let step_mm = s.step_vox * volume.min_spacing_mm();
    let t = t0.max(0.0) + (s.sample_offset * step_mm).min(l);
    let value = sample_trilinear(volume, origin + dir * t).expect("finite");
    tf.color_at(value, volume.normalization_range())
}

#[test]
fn a_fully_opaque_transfer_function_shows_the_first_sample() {
    // u16 ramp along x: voxel i holds 13107·i, so the value is linear in x.
    let volume = synthetic::ramp([6, 4, 5], [1.0, 1.3, 0.9], synthetic::Axis::X).expect("ramp");
    let tf = TransferFunction {
        opacity: vec![[0.0, 1.0]],
        color: vec![[0.0, 0.0, 0.2, 1.0], [65535.0, 1.0, 0.9, 0.0]],
        space: ValueSpace::Data,
    };
    let mut r = renderer_for(&volume, &tf);
    let size = [32, 32];
    for (view, kind) in [
        (ViewPreset::MinusZ, ProjectionKind::Orthographic),
        (ViewPreset::Oblique, ProjectionKind::Perspective),
    ] {
        let camera = framing(&volume, view, kind);
        for (strategy, path) in variants() {
            let s = RenderSettings {
                shading: Shading::Off,
                ..settings(Mode::Dvr, strategy, path)
            };
            let answers: Vec<[[f64; 3]; 9]> = (0..size[0] * size[1])
                .map(|i| {
                    common::footprint(i % size[0], i / size[0], 1.0 / 16.0)
                        .map(|p| first_sample_colour(&volume, &tf, &camera, &s, size, p))
                })
                .collect();
            let image = r.render_image(&camera, size, &s).expect("render");
            common::assert_within_footprint(
                &format!("opaque-{view:?}-{}-{path:?}", strategy.label()),
                &image,
                // The table's 4096 entries interpolate the colour ramp exactly; f16 output.
                common::ANALYTIC_TOLERANCE,
                |px, py| answers[(py * size[0] + px) as usize],
            );
        }
    }
    // Lit, the first sample's colour is lit by its gradient: the reference's answer.
    let camera = framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let lit = settings(Mode::Dvr, Strategy::Rc, RenderPath::Compute);
    let expected = reference::render(&volume, &tf, &camera, size, &lit).image;
    for (strategy, path) in variants() {
        let s = RenderSettings {
            strategy,
            path,
            ..lit
        };
        let image = r.render_image(&camera, size, &s).expect("render");
        // modes.rs's bound for lit DVR against the reference.
        let name = format!("opaque-lit-{}-{path:?}", strategy.label());
        common::assert_close(&name, &image, &expected, 4.0 / 255.0, 0.0);
    }
}

#[test]
fn opacities_of_exactly_one_and_of_a_millionth() {
    // Opacity 1 on a uniform volume: the TF colour wherever a ray enters, whatever the path.
    let volume = synthetic::constant([24, 6, 6], [1.0; 3], 100.0).expect("valid");
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let camera = framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let opaque = Uniform {
        alpha: 1.0,
        rgb: [0.9, 0.5, 0.1],
        d0_mm: 1.0,
        windowed: 0.0,
    };
    let mut r = renderer_for(&volume, &common::uniform_tf(opaque.alpha, opaque.rgb));
    let lengths = common::footprint_lengths(&camera, &bounds, [32, 32], 1.0 / 16.0);
    for (strategy, path) in variants() {
        let s = settings(Mode::Dvr, strategy, path);
        let image = r.render_image(&camera, [32, 32], &s).expect("render");
        common::assert_within_footprint(
            &format!("alpha-one-{}-{path:?}", strategy.label()),
            &image,
            common::ANALYTIC_TOLERANCE,
            |px, py| lengths[(py * 32 + px) as usize].map(|l| opaque.pixel(&s, l)),
        );
    }
    // Opacity 1 from a value on, 0 below another: the reference, lit.
    let structured = structured();
    let tf = TransferFunction {
        opacity: vec![[0.0, 0.0], [500.0, 0.0], [600.0, 1.0]],
        color: vec![[0.0, 0.2, 0.4, 1.0], [1000.0, 1.0, 0.8, 0.3]],
        space: ValueSpace::Data,
    };
    r.set_volume(&structured).expect("upload");
    r.set_transfer_function(&tf);
    let camera = framing(
        &structured,
        ViewPreset::Oblique,
        ProjectionKind::Perspective,
    );
    let lit = settings(Mode::Dvr, Strategy::RcT, RenderPath::Compute);
    let expected = reference::render(&structured, &tf, &camera, [40, 40], &lit).image;
    for (strategy, path) in variants() {
        let image = r
            .render_image(
                &camera,
                [40, 40],
                &RenderSettings {
                    strategy,
                    path,
                    ..lit
                },
            )
            .expect("render");
        // modes.rs's bound for lit DVR against the reference.
        let name = format!("alpha-one-structured-{}-{path:?}", strategy.label());
        common::assert_close(&name, &image, &expected, 4.0 / 255.0, 0.0);
    }

    // Opacity 10⁻⁶ through 24 voxels: 1 − (1 − 10⁻⁶)^24 = 2.4·10⁻⁵ of white over black, with
    // samples of 5·10⁻⁷ (half a voxel) and 10⁻⁹ (a thousandth of a voxel) each.
    let faint: f64 = 1e-6;
    let expected = 1.0 - (1.0 - faint).powi(24);
    r.set_volume(&volume).expect("upload");
    r.set_transfer_function(&common::uniform_tf(faint, [1.0; 3]));
    // Orthographic along x, 8 mm tall: the 6 × 6 mm face covers the middle 12 × 12 pixels.
    let mut camera = framing(&volume, ViewPreset::PlusX, ProjectionKind::Orthographic);
    camera.projection = Projection::Orthographic { height_mm: 8.0 };
    let mut worst = 0.0f64;
    for step_vox in [0.5, 1e-3] {
        for (strategy, path) in variants() {
            let s = RenderSettings {
                step_vox,
                background: [0.0; 3],
                ..settings(Mode::Dvr, strategy, path)
            };
            let image = r.render_image(&camera, [16, 16], &s).expect("render");
            common::assert_all_finite("faint", &image);
            // The middle 4 × 4 pixels: their rays cross all 24 voxels, 2 pixels from a side.
            for y in 6..10 {
                for x in 6..10 {
                    let rel = (f64::from(image.get(x, y)[0]) - expected).abs() / expected;
                    worst = worst.max(rel);
                    // 1 %: f16 holds 2.4·10⁻⁵ to 0.25 % (subnormal step 6·10⁻⁸), and the f32
                    // sums of 24 000 increments of 10⁻⁹ round each to 10⁻³ of themselves.
                    assert!(
                        rel < 0.01,
                        "step {step_vox} {strategy:?} {path:?} ({x},{y}): {rel}"
                    );
                }
            }
        }
    }
    eprintln!("opacity 1e-6: largest relative deviation {worst:.1e}");
}
