//! Helpers shared by the hard-case tests (tests/hard_cases_*.rs): the settings they start from,
//! standard cameras, and every strategy on both paths compared with the f64 reference.

use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::reference;
use leapview::render::VolumeRenderer;
use leapview::settings::effects::Shading;
use leapview::settings::{Mode, RenderPath, RenderSettings, Strategy};
use leapview::transfer::{TransferFunction, ValueSpace};
use leapview::volume::Volume;

/// A background no mode produces by itself, so that a pixel showing it is recognisable.
pub const BACKGROUND: [f64; 3] = [0.2, 0.3, 0.4];

/// The defaults with `mode`, `strategy`, `path` and [`BACKGROUND`].
pub fn settings(mode: Mode, strategy: Strategy, path: RenderPath) -> RenderSettings {
    RenderSettings {
        mode,
        strategy,
        path,
        background: BACKGROUND,
        ..RenderSettings::default()
    }
}

/// [`Camera::framing`] of the whole volume along a standard view.
pub fn framing(volume: &Volume, view: ViewPreset, kind: ProjectionKind) -> Camera {
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = view.direction_and_up();
    Camera::framing(&bounds, dir, up, kind)
}

/// A renderer holding `volume` and `tf`.
pub fn renderer_for(volume: &Volume, tf: &TransferFunction) -> VolumeRenderer {
    let mut r = super::renderer();
    r.set_volume(volume).expect("upload");
    r.set_transfer_function(tf);
    r
}

/// Every strategy on both paths.
pub fn variants() -> impl Iterator<Item = (Strategy, RenderPath)> {
    Strategy::ALL
        .into_iter()
        .flat_map(|s| super::PATHS.map(|p| (s, p)))
}

/// Blue to orange over `lo..hi`, opacity rising from 0 to `alpha`.
pub fn colour_ramp(lo: f64, hi: f64, alpha: f64) -> TransferFunction {
    TransferFunction {
        opacity: vec![[lo, 0.0], [hi, alpha]],
        color: vec![[lo, 0.2, 0.4, 1.0], [hi, 1.0, 0.8, 0.3]],
        space: ValueSpace::Data,
    }
}

/// Renders `mode` with `base` on every strategy and path and compares with the reference, the
/// isosurface bounds of modes.rs: up to 0.5 % of the pixels may flip where a ray grazes
/// the surface; elsewhere 4/255 (lookup table, f16 output).
pub fn check_reference(
    r: &mut VolumeRenderer,
    name: &str,
    volume: &Volume,
    tf: &TransferFunction,
    camera: &Camera,
    base: RenderSettings,
) {
    let bounds = if base.mode == Mode::Iso {
        (1.0, 0.005)
    } else {
        (4.0 / 255.0, 0.0)
    };
    check_reference_within(r, name, (volume, tf, camera), base, bounds);
}

/// As [`check_reference`], with the bounds given: at most `share` of the pixels may differ by
/// more than 1/255, none by more than `max_abs`.
pub fn check_reference_within(
    r: &mut VolumeRenderer,
    name: &str,
    (volume, tf, camera): (&Volume, &TransferFunction, &Camera),
    base: RenderSettings,
    (max_abs, share): (f64, f64),
) {
    let size = [40, 40];
    let expected = reference::render(volume, tf, camera, size, &base).image;
    for (strategy, path) in variants() {
        let s = RenderSettings {
            strategy,
            path,
            ..base
        };
        let image = r.render_image(camera, size, &s).expect("render");
        let name = format!("{name}-{}-{path:?}", strategy.label());
        super::assert_close(&name, &image, &expected, max_abs, share);
    }
}

/// The value of the uniform volumes the analytic checks render.
pub const UNIFORM_VALUE: f32 = 100.0;

/// Settings for a uniform volume of [`UNIFORM_VALUE`]: lit (its gradients are zero), the
/// [`BACKGROUND`], a window of [`UNIFORM_VALUE`] ± 1 (the value in its middle: grey 0.5) and an
/// X-ray density of 0.05 per mm.
pub fn uniform_settings(mode: Mode, strategy: Strategy, path: RenderPath) -> RenderSettings {
    RenderSettings {
        shading: Shading::Phong,
        window: Some([
            f64::from(UNIFORM_VALUE) - 1.0,
            f64::from(UNIFORM_VALUE) + 1.0,
        ]),
        xray_density_per_mm: 0.05,
        ..settings(mode, strategy, path)
    }
}

/// Renders a uniform volume of value [`UNIFORM_VALUE`] with `step_vox` in every mode, the given
/// strategies and both paths, and checks each image against the analytic answer.
pub fn check_uniform(
    name: &str,
    volume: &Volume,
    alpha: f64,
    cameras: &[Camera],
    size: [u32; 2],
    step_vox: f64,
    strategies: &[Strategy],
) -> f64 {
    let uniform = super::Uniform {
        alpha,
        rgb: [1.0, 0.6, 0.2],
        d0_mm: volume.min_spacing_mm(),
        windowed: 0.5,
    };
    let mut r = super::renderer();
    r.set_volume(volume).expect("upload");
    r.set_transfer_function(&super::uniform_tf(uniform.alpha, uniform.rgb));
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let mut worst = 0.0f64;
    for (i, camera) in cameras.iter().enumerate() {
        // A sixteenth of a pixel around each centre, as in hard_cases_camera.rs.
        let lengths = super::footprint_lengths(camera, &bounds, size, 1.0 / 16.0);
        for mode in Mode::ALL {
            for &strategy in strategies {
                for path in super::PATHS {
                    let settings = RenderSettings {
                        step_vox,
                        ..uniform_settings(mode, strategy, path)
                    };
                    let image = r.render_image(camera, size, &settings).expect("render");
                    let (_, w) = super::assert_within_footprint(
                        &format!("{name}-{i}-{}-{}-{path:?}", mode.label(), strategy.label()),
                        &image,
                        super::ANALYTIC_TOLERANCE,
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
