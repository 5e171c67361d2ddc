//! Hard volume geometry (issue 7, item 5): volumes of 1×1×1, 1×N×1 and 2×2×2 voxels, spacing
//! 0.01 mm against 10 mm, steps of 10⁻³ and 100 voxels. Uniform volumes are checked against
//! their analytic answers, structured ones against the f64 reference; every mode and both paths,
//! and no pixel may be NaN or infinite.

use crate::common;

use glam::DVec3;
use leapview::camera::{Camera, ProjectionKind, ViewPreset};
use leapview::reference;
use leapview::render::VolumeRenderer;
use leapview::settings::effects::IsoSettings;
use leapview::settings::{Mode, RenderPath, RenderSettings, Strategy};
use leapview::transfer::{TransferFunction, ValueSpace};
use leapview::volume::{Samples, ValueMapping, Volume, synthetic};

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
            ..common::uniform_settings(mode, Strategy::RcT, RenderPath::Compute)
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
                // modes.rs's bounds: 4/255 (lookup table, f16 output, RC against the
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
    let one =
        synthetic::constant([1, 1, 1], [1.5, 1.0, 2.0], common::UNIFORM_VALUE).expect("valid");
    let cameras = [
        common::framing(&one, ViewPreset::Oblique, ProjectionKind::Perspective),
        common::framing(&one, ViewPreset::PlusX, ProjectionKind::Orthographic),
        common::framing(&one, ViewPreset::MinusZ, ProjectionKind::Perspective),
    ];
    common::check_uniform(
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
                let camera = common::framing(volume, view, kind);
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
    let plate = synthetic::constant([6, 4, 5], spacing, common::UNIFORM_VALUE).expect("valid");
    let cameras = [
        common::framing(&plate, ViewPreset::PlusX, ProjectionKind::Orthographic),
        common::framing(&plate, ViewPreset::MinusY, ProjectionKind::Orthographic),
        common::framing(&plate, ViewPreset::PlusZ, ProjectionKind::Orthographic),
        common::framing(&plate, ViewPreset::Oblique, ProjectionKind::Perspective),
    ];
    // α = 10⁻³ per 0.01 mm: 1 − 0.999^4000 = 0.98 along y, 0.006 across x.
    let strategies = [Strategy::Rc, Strategy::RcSDistance];
    common::check_uniform("plate", &plate, 1e-3, &cameras, [24, 24], 0.5, &strategies);
    let structured = field([6, 4, 5], spacing, |p| {
        1000.0 * (p.x / 0.05) * (1.0 - p.y / 30.0) * (0.5 + p.z / 8.0)
    });
    let mut r = common::renderer();
    for view in [ViewPreset::Oblique, ViewPreset::PlusX, ViewPreset::MinusY] {
        let camera = common::framing(&structured, view, ProjectionKind::Perspective);
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
    let volume =
        synthetic::constant([6, 5, 4], [1.0, 1.25, 1.5], common::UNIFORM_VALUE).expect("valid");
    let cameras = [
        common::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective),
        common::framing(&volume, ViewPreset::PlusY, ProjectionKind::Orthographic),
    ];
    let strategies = [Strategy::Rc, Strategy::RcSDistance];
    // α = 0.05: at 100 voxels a full step transmits 0.95^100 = 0.006, well within f32 (see
    // `a_hundred_voxel_step_keeps_the_opacity_of_short_paths` for a step that transmits less).
    for step_vox in [1e-3, 100.0] {
        let name = format!("step-{step_vox}");
        common::check_uniform(
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
    let camera = common::framing(
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
/// 1: a lookup table of step-corrected opacity rounded it to exactly 1, the last, partial segment
/// of every ray (here the only one: every path is shorter than a step) could no longer be scaled
/// back (`1 − (1 − 1)^w = 1`), and every pixel the volume covered turned fully opaque. The table
/// now holds the step's optical depth (src/transfer/lut.rs).
#[test]
fn a_hundred_voxel_step_keeps_the_opacity_of_short_paths() {
    let volume =
        synthetic::constant([6, 5, 4], [1.0, 1.25, 1.5], common::UNIFORM_VALUE).expect("valid");
    let camera = common::framing(&volume, ViewPreset::PlusY, ProjectionKind::Orthographic);
    common::check_uniform(
        "step-100-saturated",
        &volume,
        0.2,
        &[camera],
        [20, 20],
        100.0,
        &[Strategy::Rc],
    );
}
