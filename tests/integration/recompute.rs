//! Nothing is recomputed that did not change: a camera move only re-renders, a transfer-function
//! edit re-bakes the lookup table and rebuilds the emptiness flags only, the min/max pyramid is
//! built once per volume, modes that leap by the pyramid alone rebuild nothing, the isosurface
//! field follows the iso value only.

use crate::common;

use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::render::{FrameRequest, VolumeRenderer, WorkCounts};
use leapview::settings::{IsoSettings, Mode, RenderPath, RenderSettings, Strategy};
use leapview::transfer::presets::preset;
use leapview::volume::synthetic;

fn frame(r: &mut VolumeRenderer, camera: &Camera, settings: &RenderSettings) -> WorkCounts {
    r.render_and_wait(&FrameRequest {
        camera,
        size: [32, 32],
        settings,
        stats: false,
    })
    .expect("render");
    r.work_counts()
}

/// `after` minus `before`, field by field.
fn delta(before: WorkCounts, after: WorkCounts) -> WorkCounts {
    WorkCounts {
        frames: after.frames - before.frames,
        lut_bakes: after.lut_bakes - before.lut_bakes,
        minmax_builds: after.minmax_builds - before.minmax_builds,
        minmax_brick_builds: after.minmax_brick_builds - before.minmax_brick_builds,
        flag_builds: after.flag_builds - before.flag_builds,
        distance_builds: after.distance_builds - before.distance_builds,
        label_flag_builds: after.label_flag_builds - before.label_flag_builds,
        label_surface_builds: after.label_surface_builds - before.label_surface_builds,
        integral_builds: after.integral_builds - before.integral_builds,
    }
}

/// Only a frame.
const FRAME: WorkCounts = WorkCounts {
    frames: 1,
    lut_bakes: 0,
    minmax_builds: 0,
    minmax_brick_builds: 0,
    flag_builds: 0,
    distance_builds: 0,
    label_flag_builds: 0,
    label_surface_builds: 0,
    integral_builds: 0,
};

#[test]
fn each_change_recomputes_only_what_depends_on_it() {
    let volume = synthetic::vessel_tree(48, 7).expect("volume");
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    r.set_transfer_function(&preset("ct-angio").expect("preset"));
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let view = |p: ViewPreset| {
        let (dir, up) = p.direction_and_up();
        Camera::framing(&bounds, dir, up, ProjectionKind::Perspective)
    };
    let (oblique, side) = (view(ViewPreset::Oblique), view(ViewPreset::PlusX));
    // A fixed path: `auto` times both paths with extra frames once.
    let mut settings = RenderSettings {
        strategy: Strategy::RcS,
        path: RenderPath::Compute,
        ..RenderSettings::default()
    };

    let first = frame(&mut r, &oblique, &settings);
    let everything = WorkCounts {
        lut_bakes: 1,
        minmax_builds: 1,
        flag_builds: 1,
        ..FRAME
    };
    assert_eq!(first, everything, "the first frame builds what it needs");

    let mut last = first;
    let mut step = |r: &mut VolumeRenderer, camera: &Camera, settings: &RenderSettings| {
        let now = frame(r, camera, settings);
        let d = delta(last, now);
        last = now;
        d
    };
    assert_eq!(
        step(&mut r, &side, &settings),
        FRAME,
        "a camera move only renders"
    );
    assert_eq!(
        step(&mut r, &side, &settings),
        FRAME,
        "an unchanged frame too"
    );

    // Setting an equal transfer function is no change.
    r.set_transfer_function(&preset("ct-angio").expect("preset"));
    assert_eq!(step(&mut r, &side, &settings), FRAME);
    r.set_transfer_function(&preset("ct-bone").expect("preset"));
    let tf_edit = WorkCounts {
        lut_bakes: 1,
        flag_builds: 1,
        ..FRAME
    };
    assert_eq!(
        step(&mut r, &side, &settings),
        tf_edit,
        "a TF edit: LUT + flags only"
    );

    // A new step re-bakes the opacity correction; zero opacity stays zero, so no flags.
    settings.step_vox = 0.25;
    let rebake = WorkCounts {
        lut_bakes: 1,
        ..FRAME
    };
    assert_eq!(step(&mut r, &side, &settings), rebake);

    // MIP, MinIP and isosurfaces leap by the pyramid alone.
    for mode in [Mode::Mip, Mode::MinIp, Mode::Iso] {
        settings.mode = mode;
        assert_eq!(step(&mut r, &oblique, &settings), FRAME, "{mode:?}");
    }

    // The distance field: built once, again for a new block size, not for a camera move.
    settings.mode = Mode::Dvr;
    settings.strategy = Strategy::RcSDistance;
    let distance = WorkCounts {
        distance_builds: 1,
        ..FRAME
    };
    assert_eq!(step(&mut r, &oblique, &settings), distance);
    assert_eq!(step(&mut r, &side, &settings), FRAME);
    settings.block_vox = Some(16);
    assert_eq!(step(&mut r, &side, &settings), distance, "a new block size");
    r.set_transfer_function(&preset("ct-angio").expect("preset"));
    let tf_edit_df = WorkCounts {
        distance_builds: 1,
        ..tf_edit
    };
    assert_eq!(step(&mut r, &side, &settings), tf_edit_df);

    // Isosurfaces with the distance field: a field per side of the iso value, built when first
    // needed and when the iso value changes; a camera move or a TF edit (the TF only colours the
    // surface) rebuilds nothing of it.
    settings.mode = Mode::Iso;
    let iso_field = WorkCounts {
        flag_builds: 1,
        distance_builds: 1,
        ..FRAME
    };
    assert_eq!(step(&mut r, &side, &settings), iso_field, "iso: its field");
    assert_eq!(
        step(&mut r, &oblique, &settings),
        FRAME,
        "iso: a camera move"
    );
    r.set_transfer_function(&preset("ct-bone").expect("preset"));
    let lut_only = WorkCounts {
        lut_bakes: 1,
        ..FRAME
    };
    assert_eq!(
        step(&mut r, &oblique, &settings),
        lut_only,
        "iso: a TF edit"
    );
    settings.iso = IsoSettings {
        value: Some(volume.normalization_range().denormalize(0.3)),
        ..settings.iso
    };
    assert_eq!(
        step(&mut r, &oblique, &settings),
        iso_field,
        "iso: a new iso value"
    );
    settings.mode = Mode::Dvr;
    r.set_transfer_function(&preset("ct-angio").expect("preset"));
    assert_eq!(step(&mut r, &side, &settings), tf_edit_df, "back to DVR");

    // Strategies without leaping touch no leaping structure.
    settings.strategy = Strategy::RcT;
    r.set_transfer_function(&preset("ct-bone").expect("preset"));
    assert_eq!(step(&mut r, &side, &settings), lut_only);

    // Pre-integration: its table is built when first needed and after a TF edit, not for a new
    // step (the step enters the shader, not the table) nor a camera move.
    settings.preintegrated = true;
    let integrals = WorkCounts {
        integral_builds: 1,
        ..FRAME
    };
    assert_eq!(step(&mut r, &side, &settings), integrals);
    assert_eq!(step(&mut r, &oblique, &settings), FRAME);
    settings.step_vox = 2.0;
    assert_eq!(step(&mut r, &oblique, &settings), lut_only);
    r.set_transfer_function(&preset("ct-angio").expect("preset"));
    assert_eq!(
        step(&mut r, &oblique, &settings),
        WorkCounts {
            integral_builds: 1,
            ..lut_only
        }
    );
}
