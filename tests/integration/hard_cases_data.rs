//! Hard data (issue 7, item 5): 16-bit data with outliers at 65535, float data with NaN and
//! ±Inf (and nothing else), and X-ray paths of zero length. The f64 reference or analytic
//! answers, every strategy and both paths; no pixel may be NaN or infinite.

use crate::common;

use common::{check_reference, colour_ramp, framing, renderer_for, settings, variants};
use glam::DVec3;
use leapview::camera::{Aabb, Camera, Projection, ProjectionKind, ViewPreset};
use leapview::render::VolumeRenderer;
use leapview::settings::effects::{IsoSettings, MipColor, Shading};
use leapview::settings::{Mode, RenderPath, RenderSettings, Strategy};
use leapview::volume::{Samples, ValueMapping, Volume, synthetic};

#[test]
fn sixteen_bit_data_with_outliers_at_65535() {
    // 12-bit data (0..4095) with a few voxels at 65535: the value range is 16 times the data's,
    // so the lookup table spends 16 data units per entry and the window's top is an outlier.
    let dims = [16u32, 12, 10];
    let mut v = Vec::new();
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let p = DVec3::new(f64::from(x), f64::from(y), f64::from(z));
                let r = (p - DVec3::new(8.0, 6.0, 5.0)).length();
                v.push((4095.0 * (1.0 - r / 7.0).clamp(0.0, 1.0)) as u16);
            }
        }
    }
    for i in [17, 500, 1001, 1500] {
        v[i] = 65535;
    }
    let volume = Volume::new(
        "outliers",
        dims,
        [1.0; 3],
        Samples::U16(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid");
    assert_eq!(volume.value_range().map(|r| r.max), Some(65535.0));
    let tf = colour_ramp(1000.0, 3000.0, 0.4);
    let mut r = renderer_for(&volume, &tf);
    let camera = framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let cases = [
        (Mode::Dvr, None),
        (Mode::Iso, None),
        (Mode::Mip, None),
        (Mode::Mip, Some([0.0, 4095.0])),
        (Mode::MinIp, Some([0.0, 4095.0])),
        (Mode::Xray, Some([0.0, 4095.0])),
        (Mode::XrayAttenuation, Some([0.0, 4095.0])),
    ];
    for (mode, window) in cases {
        let base = RenderSettings {
            window,
            iso: IsoSettings {
                value: Some(2000.0),
                refine_iterations: 4,
            },
            xray_density_per_mm: 0.05,
            ..settings(mode, Strategy::RcT, RenderPath::Compute)
        };
        let name = format!("outliers-{}-{window:?}", mode.label());
        check_reference(&mut r, &name, &volume, &tf, &camera, base);
    }
    // MIP through the default window (the whole range): the data reach 4095/65535 = 0.06 grey,
    // samples near an outlier up to white.
    let mip = settings(Mode::Mip, Strategy::RcS, RenderPath::Compute);
    let image = r.render_image(&camera, [40, 40], &mip).expect("render");
    let brightest = image.pixels.iter().map(|p| p[0]).fold(0.0f32, f32::max);
    assert!(brightest > 0.5, "the outliers show: brightest {brightest}");
}

/// The structured field of the NaN test: a ball over a floor, with a slab of NaN across it, a
/// few +Inf and −Inf voxels, and all of the last x column NaN.
fn with_non_finite() -> Volume {
    let dims = [12u32, 10, 8];
    let mut v = Vec::new();
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let p = DVec3::new(f64::from(x), f64::from(y) * 1.2, f64::from(z) * 1.5);
                let r = (p - DVec3::new(6.0, 6.0, 6.0)).length();
                v.push(if y == 4 || x == 11 {
                    f32::NAN
                } else {
                    (100.0 + 800.0 * (1.0 - r / 6.0).clamp(0.0, 1.0)) as f32
                });
            }
        }
    }
    for (i, bad) in [
        (100, f32::INFINITY),
        (333, f32::NEG_INFINITY),
        (700, f32::INFINITY),
    ] {
        v[i] = bad;
    }
    Volume::new(
        "nan",
        dims,
        [1.0, 1.2, 1.5],
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("NaN and ±Inf are accepted")
}

#[test]
fn nan_and_infinite_samples_are_missing_in_every_mode() {
    // The documented mapping (src/volume/mod.rs): non-finite samples stay out of the range and
    // the histogram and render transparent; a sample interpolated from one is missing.
    let volume = with_non_finite();
    assert_eq!(volume.non_finite_count(), 12 * 8 + 10 * 8 - 8 + 3);
    let range = volume.value_range().expect("finite samples");
    assert!(range.min >= 100.0 && range.max <= 900.0, "{range:?}");
    assert_eq!(
        volume.histogram().total(),
        volume.sample_count() - volume.non_finite_count()
    );
    // A loader keeps them the same way: the NRRD of the same samples is the same volume.
    let dir = common::TempDir::new("nan");
    let lines = common::nrrd_lines(volume.scalar_type(), volume.dims(), "raw", false);
    let lines: Vec<&str> = lines.iter().map(String::as_str).collect();
    let bytes = common::nrrd_file(
        &lines,
        &common::to_bytes(volume.samples().expect("in memory"), false),
    );
    let loaded = common::load_ok(&dir.write("nan.nrrd", &bytes));
    assert_eq!(loaded.non_finite_count(), volume.non_finite_count());
    assert_eq!(loaded.value_range(), volume.value_range());

    let tf = colour_ramp(100.0, 900.0, 0.3);
    let mut r = renderer_for(&volume, &tf);
    for view in [ViewPreset::Oblique, ViewPreset::MinusY] {
        let camera = framing(&volume, view, ProjectionKind::Perspective);
        for mode in Mode::ALL {
            for shading in [Shading::Off, Shading::Phong] {
                let base = RenderSettings {
                    shading,
                    mip_color: MipColor::Window,
                    iso: IsoSettings {
                        value: Some(500.0),
                        refine_iterations: 4,
                    },
                    xray_density_per_mm: 0.05,
                    ..settings(mode, Strategy::RcT, RenderPath::Compute)
                };
                let name = format!("nan-{view:?}-{}-{shading:?}", mode.label());
                check_reference(&mut r, &name, &volume, &tf, &camera, base);
            }
        }
    }
    // Nothing but NaN: no value range; every mode shows the background or, for X-ray, no
    // attenuation at all.
    let empty = synthetic::constant([4, 3, 2], [1.0; 3], f32::NAN).expect("valid");
    assert_eq!(empty.value_range(), None);
    r.set_volume(&empty).expect("upload");
    let camera = framing(&empty, ViewPreset::Oblique, ProjectionKind::Perspective);
    for mode in Mode::ALL {
        let base = settings(mode, Strategy::RcT, RenderPath::Compute);
        check_reference(
            &mut r,
            &format!("all-nan-{}", mode.label()),
            &empty,
            &tf,
            &camera,
            base,
        );
    }
}

/// Renders `camera` in `modes` with every strategy on both paths and checks the analytic answer
/// of the uniform volume at a sixteenth of a pixel around each centre (as in
/// hard_cases_camera.rs): a ray of zero length may round to a miss (the background) or to
/// a short hit (the constant's grey), nothing else.
fn check_touching(
    r: &mut VolumeRenderer,
    name: &str,
    volume: &Volume,
    camera: &Camera,
    size: [u32; 2],
    modes: &[Mode],
) {
    let uniform = common::Uniform {
        alpha: 0.1,
        rgb: [1.0; 3],
        d0_mm: 1.0,
        windowed: 0.5,
    };
    r.set_volume(volume).expect("upload");
    r.set_transfer_function(&common::uniform_tf(uniform.alpha, uniform.rgb));
    let b = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let lengths = common::footprint_lengths(camera, &b, size, 1.0 / 16.0);
    for &mode in modes {
        for (strategy, path) in variants() {
            let s = common::uniform_settings(mode, strategy, path);
            let image = r.render_image(camera, size, &s).expect("render");
            common::assert_within_footprint(
                &format!("{name}-{}-{}-{path:?}", mode.label(), strategy.label()),
                &image,
                common::ANALYTIC_TOLERANCE,
                |px, py| lengths[(py * size[0] + px) as usize].map(|l| uniform.pixel(&s, l)),
            );
        }
    }
}

#[test]
fn xray_paths_of_zero_length() {
    // An orthographic view along (−1, 1, 0) centred on the edge x = max, y = max: rays through
    // the middle column (odd width) touch the box only on that edge, a path of length zero; the
    // columns to its left cross ever longer chords, those to its right miss.
    let volume = synthetic::constant([8, 8, 6], [1.0; 3], common::UNIFORM_VALUE).expect("valid");
    let b = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let on_edge = |shift: f64, dir: DVec3| {
        let target = DVec3::new(b.max.x + shift, b.max.y - 0.37 * shift, b.center().z);
        Camera {
            eye: target - dir.normalize() * 30.0,
            target,
            up: DVec3::Z,
            projection: Projection::Orthographic { height_mm: 4.0 },
        }
    };
    let edge = on_edge(0.0, DVec3::new(-1.0, 1.0, 0.0));
    let mut r = common::renderer();
    check_touching(
        &mut r,
        "zero-length-edge",
        &volume,
        &edge,
        [33, 33],
        &Mode::ALL,
    );
    // A single pixel whose ray touches only the corner at the maximum.
    let corner_dir = DVec3::new(-1.0, 1.0, 1.0).normalize();
    let corner = Camera {
        eye: b.max - corner_dir * 30.0,
        target: b.max,
        ..edge
    };
    check_touching(
        &mut r,
        "zero-length-corner",
        &volume,
        &corner,
        [1, 1],
        &Mode::ALL,
    );
    // The edge again, moved by 10⁻⁷ mm steps and tilted: on the compute path some middle-column
    // rays then meet the box with t₁ > t₀ while their f32 entry and exit points coincide. The
    // mean of such a path was 0/0 (NaN, clamped to black by lavapipe); it is the background.
    for k in 0..40 {
        let shift = (f64::from(k) - 20.0) * 1e-7;
        let dir = DVec3::new(
            -1.0,
            1.0 + 0.018 + f64::from(k) * 1e-4,
            0.1 * f64::from(k % 7),
        );
        let modes = [Mode::Xray, Mode::XrayAttenuation];
        let name = format!("zero-length-edge-{k}");
        check_touching(
            &mut r,
            &name,
            &volume,
            &on_edge(shift, dir),
            [33, 33],
            &modes,
        );
    }
}
