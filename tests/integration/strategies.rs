//! RC against RC-t, and the fragment path against the compute path, on a dense synthetic volume.

use crate::common;

use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::counters::FrameCounters;
use leapview::imaging::ImageF32;
use leapview::render::VolumeRenderer;
use leapview::render::raycast::auto_path;
use leapview::settings::{RenderPath, RenderSettings, Strategy};
use leapview::transfer::{TransferFunction, ValueSpace};
use leapview::volume::{Samples, ValueMapping, Volume};

/// A 32³ volume of smooth noise-like structure filling the box (dense: most rays become opaque).
fn dense() -> Volume {
    let n = 32u32;
    let mut v = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let f = |a: u32, k: f64| (a as f64 * k).sin();
                v.push((128.0 + 60.0 * f(x, 0.37) * f(y, 0.23) + 60.0 * f(z, 0.31)) as u8);
            }
        }
    }
    Volume::new(
        "dense",
        [n; 3],
        [1.0; 3],
        Samples::U8(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

fn tf() -> TransferFunction {
    TransferFunction {
        opacity: vec![[60.0, 0.0], [120.0, 0.5], [255.0, 0.9]],
        color: vec![[0.0, 0.9, 0.5, 0.3], [255.0, 1.0, 1.0, 0.9]],
        space: ValueSpace::Data,
    }
}

fn render(
    r: &mut VolumeRenderer,
    camera: &Camera,
    settings: RenderSettings,
) -> (ImageF32, FrameCounters) {
    common::render_counted(r, camera, settings, [64, 64])
}

#[test]
fn early_termination_changes_the_image_by_at_most_one_level_and_saves_samples() {
    let volume = dense();
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    r.set_transfer_function(&tf());
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
    for path in [RenderPath::Fragment, RenderPath::Compute] {
        let base = RenderSettings {
            path,
            ..RenderSettings::default()
        };
        let (rc, rc_counts) = render(
            &mut r,
            &camera,
            RenderSettings {
                strategy: Strategy::Rc,
                ..base
            },
        );
        let (rct, rct_counts) = render(
            &mut r,
            &camera,
            RenderSettings {
                strategy: Strategy::RcT,
                ..base
            },
        );
        // Stopping at opacity > 1 - 1/255 leaves less than 1/255 of the light unaccounted;
        // the f16 output adds at most 2^-11.
        common::assert_close(
            &format!("rc-vs-rct-{path:?}"),
            &rct,
            &rc,
            1.0 / 255.0 + 1.0 / 2048.0,
            0.0,
        );
        assert_eq!(rc_counts.rays, rct_counts.rays);
        assert!(
            rct_counts.samples * 2 < rc_counts.samples,
            "{path:?}: RC-t {rct_counts:?} vs RC {rc_counts:?}"
        );
        // A lower threshold stops earlier still, and the image then differs visibly.
        let (early, early_counts) = render(
            &mut r,
            &camera,
            RenderSettings {
                termination_alpha: 0.5,
                ..base
            },
        );
        assert!(early_counts.samples < rct_counts.samples);
        assert!(early.diff(&rc).expect("same size").max_abs > 0.05);
    }
}

#[test]
fn fragment_and_compute_paths_give_the_same_image() {
    let volume = dense();
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    r.set_transfer_function(&tf());
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    for view in [ViewPreset::Oblique, ViewPreset::MinusX, ViewPreset::PlusZ] {
        for kind in [ProjectionKind::Perspective, ProjectionKind::Orthographic] {
            let (dir, up) = view.direction_and_up();
            let camera = Camera::framing(&bounds, dir, up, kind);
            let (frag, fc) = render(
                &mut r,
                &camera,
                RenderSettings {
                    path: RenderPath::Fragment,
                    ..RenderSettings::default()
                },
            );
            let (comp, cc) = render(
                &mut r,
                &camera,
                RenderSettings {
                    path: RenderPath::Compute,
                    ..RenderSettings::default()
                },
            );
            // Same WGSL ray loop; the entry point is interpolated in registers (fragment) or
            // stored as f32 (compute): both exact to f32, so within one f16 output step.
            common::assert_close(
                &format!("paths-{view:?}-{kind:?}"),
                &comp,
                &frag,
                1.0 / 2048.0,
                0.0,
            );
            assert_eq!(fc, cc, "{view:?} {kind:?}");
        }
    }
}

#[test]
fn auto_path_picks_one_of_the_two() {
    let mut r = common::renderer();
    r.set_volume(&dense()).expect("upload");
    let p = auto_path::choose(&mut r, RenderPath::Auto).expect("calibrates");
    assert_eq!(
        auto_path::choose(&mut r, RenderPath::Auto).expect("cached"),
        p
    );
    assert_eq!(r.resolve_path(RenderPath::Auto).expect("chosen"), p);
}
