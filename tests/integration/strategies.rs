//! RC against RC-t, and the fragment path against the compute path, on a dense synthetic volume.

use crate::common;

use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::counters::FrameCounters;
use leapview::imaging::ImageF32;
use leapview::render::raycast::strategy_choice::{ChoiceBasis, StrategyChoice};
use leapview::render::raycast::variant::SPLIT_MAX_PIXELS;
use leapview::render::raycast::{auto_path, auto_strategy};
use leapview::render::{FrameRequest, VolumeRenderer};
use leapview::settings::{ConcretePath, IsoSettings, Mode, RenderPath, RenderSettings, Strategy};
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

/// A renderer holding the dense volume and its transfer function, and the oblique perspective
/// camera framing it.
fn dense_oblique() -> (VolumeRenderer, Camera) {
    let volume = dense();
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    r.set_transfer_function(&tf());
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    (
        r,
        Camera::framing(&bounds, dir, up, ProjectionKind::Perspective),
    )
}

#[test]
fn early_termination_changes_the_image_by_at_most_one_level_and_saves_samples() {
    let (mut r, camera) = dense_oblique();
    // RC-t's samples with one invocation per ray (the fragment path, measured first).
    let mut whole_ray_samples = None;
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
        // One invocation per ray (fragment) stops at the opaque sample: RC-t takes under half
        // of RC's samples here. A split ray (the compute path at this size, PipelineKey::split)
        // also takes what its parts behind the stop took before they learnt of it: never
        // fewer samples than one invocation per ray, and at most half as many again here (1.42×
        // on lavapipe).
        match whole_ray_samples {
            None => assert!(
                rct_counts.samples * 2 < rc_counts.samples,
                "{path:?}: RC-t {rct_counts:?} vs RC {rc_counts:?}"
            ),
            Some(whole) => {
                assert!(rct_counts.samples >= whole, "{rct_counts:?} vs {whole}");
                assert!(
                    rct_counts.samples * 2 <= whole * 3,
                    "{rct_counts:?} vs {whole}"
                );
            }
        }
        whole_ray_samples = Some(rct_counts.samples);
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

/// The same ray loop on both paths: the fragment path casts each ray in one invocation, the
/// compute path at this size splits it into parts (PipelineKey::split) joined in order.
#[test]
fn fragment_and_compute_paths_give_the_same_image() {
    let volume = dense();
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    r.set_transfer_function(&tf());
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let iso = IsoSettings {
        value: Some(128.0),
        ..IsoSettings::default()
    };
    // (mode, strategy, whether the counters must agree, tolerance, share of channels allowed
    // past 1/255). Same WGSL ray loop; the entry point is interpolated in registers (fragment)
    // or stored as f32 (compute): both exact to f32, so within one f16 output step, and the
    // parts of a split ray take the same samples. DVR with early termination may differ by
    // the light a stop leaves (1/255): a part behind the stopping one adds what it took before
    // it learnt of the stop. An isosurface's crossing can move at a pixel whose sample lies
    // on the iso value to the last bits of the entry point (one channel of one pixel here, with
    // or without split rays).
    let f16_step = 1.0 / 2048.0;
    let cases = [
        (Mode::Dvr, Strategy::Rc, true, f16_step, 0.0),
        (
            Mode::Dvr,
            Strategy::RcSDistance,
            false,
            1.0 / 255.0 + f16_step,
            0.0,
        ),
        (Mode::Mip, Strategy::RcS, false, f16_step, 0.0),
        (Mode::Iso, Strategy::RcS, false, 0.02, 0.001),
        (Mode::Xray, Strategy::RcSDistance, true, f16_step, 0.0),
    ];
    for view in [ViewPreset::Oblique, ViewPreset::MinusX, ViewPreset::PlusZ] {
        for kind in [ProjectionKind::Perspective, ProjectionKind::Orthographic] {
            let (dir, up) = view.direction_and_up();
            let camera = Camera::framing(&bounds, dir, up, kind);
            for (mode, strategy, same_counts, tolerance, share) in cases {
                let settings = |path| RenderSettings {
                    path,
                    mode,
                    strategy,
                    iso,
                    ..RenderSettings::default()
                };
                let (frag, fc) = render(&mut r, &camera, settings(RenderPath::Fragment));
                let (comp, cc) = render(&mut r, &camera, settings(RenderPath::Compute));
                let label = format!("paths-{view:?}-{kind:?}-{mode:?}-{strategy:?}");
                common::assert_close(&label, &comp, &frag, tolerance, share);
                assert_eq!(fc.rays, cc.rays, "{label}");
                if same_counts {
                    // Lookups excepted: each part of a split ray asks the field on its own.
                    let no_lookups = |c: FrameCounters| FrameCounters { lookups: 0, ..c };
                    assert_eq!(no_lookups(fc), no_lookups(cc), "{label}");
                }
            }
        }
    }
}

/// Above `SPLIT_MAX_PIXELS` the compute path casts each ray in one invocation, as the fragment
/// path does: the same image and the same counts (to a few grazing rays).
#[test]
fn large_images_cast_whole_rays_on_both_paths() {
    let (mut r, camera) = dense_oblique();
    let size = [800, 700];
    assert!(u64::from(size[0] * size[1]) > SPLIT_MAX_PIXELS);
    for mode in [Mode::Dvr, Mode::Mip] {
        let settings = |path| RenderSettings {
            path,
            mode,
            ..RenderSettings::default()
        };
        let (frag, fc) =
            common::render_counted(&mut r, &camera, settings(RenderPath::Fragment), size);
        let (comp, cc) =
            common::render_counted(&mut r, &camera, settings(RenderPath::Compute), size);
        // The same image but for the odd ray that grazes the box's edge, which the two paths'
        // entry points (interpolated, computed) can see hit or missed (2 of 228 k rays here).
        common::assert_close(&format!("large-{mode:?}"), &comp, &frag, 1.0, 1e-4);
        let close = |a: u64, b: u64| a.abs_diff(b) * 10_000 <= a.max(b);
        assert!(close(fc.rays, cc.rays), "{mode:?}: {fc:?} vs {cc:?}");
        assert!(close(fc.samples, cc.samples), "{mode:?}: {fc:?} vs {cc:?}");
    }
}

/// `auto` picks one of the two paths and keeps it; a CPU driver (lavapipe, as in CI) always gets
/// the compute path, so that two processes render one scene alike whatever their load.
#[test]
fn auto_path_picks_one_of_the_two() {
    let mut r = common::renderer();
    r.set_volume(&dense()).expect("upload");
    let p = auto_path::choose(&mut r, RenderPath::Auto).expect("calibrates");
    if r.context().adapter_info.device_type == wgpu::DeviceType::Cpu {
        assert_eq!(p, ConcretePath::Compute);
    }
    assert_eq!(
        auto_path::choose(&mut r, RenderPath::Auto).expect("cached"),
        p
    );
    assert_eq!(r.resolve_path(RenderPath::Auto).expect("chosen"), p);
}

/// `auto` (the default strategy) times RC-t against the mode's leaping strategy and renders
/// with the faster, on exactly the inputs it timed: a new transfer function, size or volume
/// renders with the leaping strategy until timed again. The images are RC-t's either way.
#[test]
fn auto_strategy_renders_with_what_it_timed_for_these_inputs_only() {
    let (mut r, camera) = dense_oblique();
    common::choose_auto_path(&mut r);
    let size = [64, 64];
    let settings = RenderSettings::default();
    assert_eq!(settings.strategy, Strategy::Auto);
    let strategy_of = |r: &mut VolumeRenderer, settings: &RenderSettings, size| {
        let request = FrameRequest {
            camera: &camera,
            size,
            settings,
            stats: false,
        };
        r.render_and_wait(&request).expect("render").0.key.strategy
    };
    // Nothing chosen yet: the leaping strategy.
    assert_eq!(strategy_of(&mut r, &settings, size), Strategy::RcSDistance);

    // Timing (which lavapipe skips in `choose`, its clock following the machine's load) gives
    // two finite times, and leaping only where it was clearly faster.
    let timed = auto_strategy::measure(&mut r, &settings, size, &camera).expect("timed");
    let ChoiceBasis::Timed { rct_ms, leaping_ms } = timed.basis else {
        panic!("not timed: {timed:?}");
    };
    assert!(rct_ms > 0.0 && leaping_ms > 0.0, "{timed:?}");
    let chosen = if leaping_ms < rct_ms * (1.0 - StrategyChoice::LEAPING_MARGIN) {
        Strategy::RcSDistance
    } else {
        Strategy::RcT
    };
    assert_eq!(timed.strategy, chosen);
    assert!(r.strategy_choice().is_none(), "measure keeps nothing");

    // A choice of RC-t holds for its inputs (refinement's shifted sample offset included) ...
    let key = r.choice_key(&settings, size);
    r.set_strategy_choice(StrategyChoice::timed(key, 1.0, 2.0));
    assert_eq!(strategy_of(&mut r, &settings, size), Strategy::RcT);
    let shifted = RenderSettings {
        sample_offset: 0.25,
        ..settings
    };
    assert_eq!(strategy_of(&mut r, &shifted, size), Strategy::RcT);
    let auto_image = r.render_image(&camera, size, &settings).expect("render");
    let rct = RenderSettings {
        strategy: Strategy::RcT,
        ..settings
    };
    let rct_image = r.render_image(&camera, size, &rct).expect("render");
    assert_eq!(auto_image, rct_image);
    // ... and a choice made while the user drags carries it over, without rendering.
    let frames = r.work_counts();
    let carried = RenderSettings {
        step_vox: 0.75,
        ..settings
    };
    assert_eq!(
        auto_strategy::choose(&mut r, &carried, size, &camera, false).expect("carried"),
        Strategy::RcT
    );
    assert_eq!(r.work_counts(), frames, "carrying over rendered something");
    assert!(!r.strategy_choice().expect("kept").basis.is_settled());
    // ... but not for another size, another transfer function or another volume.
    r.set_strategy_choice(StrategyChoice::timed(key, 1.0, 2.0));
    assert_eq!(
        strategy_of(&mut r, &settings, [48, 64]),
        Strategy::RcSDistance
    );
    let mut other = tf();
    other.opacity[1][1] = 0.4;
    r.set_transfer_function(&other);
    assert_eq!(strategy_of(&mut r, &settings, size), Strategy::RcSDistance);
    r.set_transfer_function(&tf());
    let key = r.choice_key(&settings, size);
    r.set_strategy_choice(StrategyChoice::timed(key, 1.0, 2.0));
    r.set_volume(&dense()).expect("upload");
    assert!(r.strategy_choice().is_none());

    // On a CPU driver `choose` takes the leaping strategy untimed and settles on it; MIP leaps
    // by the octree.
    if r.context().adapter_info.device_type == wgpu::DeviceType::Cpu {
        let mip = RenderSettings {
            mode: Mode::Mip,
            ..settings
        };
        assert!(!auto_strategy::wants_timing(&r, &mip, size, true));
        let chosen = auto_strategy::choose(&mut r, &mip, size, &camera, true).expect("chosen");
        assert_eq!(chosen, Strategy::RcS);
        assert_eq!(
            r.strategy_choice().expect("kept").basis,
            ChoiceBasis::CpuDriver
        );
        assert_eq!(strategy_of(&mut r, &mip, size), Strategy::RcS);
    }
}
