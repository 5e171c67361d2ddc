//! Labels as surfaces (`LabelView::Surfaces`): the shared CT head with its labels (written by
//! SimpleITK), the soft tissue at half opacity around the brain, against the f64 reference
//! rendering from the CPU twin of the smoothed mask; leaping exact; the mask rebuilt only when
//! the shown labels or the smoothing change; the CLI.

use std::sync::Arc;

use leapview::camera::{Camera, ProjectionKind, ViewPreset};
use leapview::imaging::ImageF32;
use leapview::labels::surface::smoothed_mask;
use leapview::labels::{LabelMap, LabelOptions, Segment, load_labels};
use leapview::reference::{self, Labelled};
use leapview::render::VolumeRenderer;
use leapview::render::labels::GpuLabels;
use leapview::settings::effects::LabelView;
use leapview::settings::{Mode, RenderPath, RenderSettings, Strategy};
use leapview::transfer::TransferFunction;
use leapview::volume::{LoadOptions, Volume, load_volume};

use crate::common;

const SIZE: [u32; 2] = [56, 56];

/// The CT head series, its labels (1 soft tissue, 2 skull, 3 brain) and the bone function (the
/// skull in the image, the labels' surfaces over it).
fn scene() -> (Volume, LabelMap, TransferFunction) {
    let data = common::data_dir();
    let volume = load_volume(&data.join("dicom/ct_head_cthead"), &LoadOptions::default())
        .expect("the CT head series");
    let labels = load_labels(
        &data.join("labels/ct_head_cthead_labels.nii.gz"),
        &volume,
        &LabelOptions::default(),
    )
    .expect("its labels");
    let tf = leapview::transfer::presets::preset("ct-bone").expect("preset");
    (volume, labels, tf)
}

/// Soft tissue at half opacity in green, the skull hidden, the brain opaque in its colour.
fn style(s: &Segment) -> [u8; 4] {
    match s.value {
        1 => [40, 200, 90, 128],
        2 => [0, 0, 0, 0],
        _ => [s.colour[0], s.colour[1], s.colour[2], 255],
    }
}

fn renderer(volume: &Volume, labels: &LabelMap, tf: &TransferFunction) -> VolumeRenderer {
    let mut r = common::renderer_for(volume, tf);
    let ctx = r.context().clone();
    let gpu = GpuLabels::new(&ctx.device, &ctx.queue, labels).expect("labels upload");
    gpu.show_styled(&ctx.queue, labels, style);
    r.set_labels(Some(Arc::new(gpu))).expect("labels");
    r
}

fn render(r: &mut VolumeRenderer, camera: &Camera, settings: RenderSettings) -> ImageF32 {
    r.render_image(camera, SIZE, &settings)
        .unwrap_or_else(|e| panic!("{settings:?}: {e}"))
}

fn surfaces(smoothing: f64) -> RenderSettings {
    RenderSettings {
        step_vox: 0.5,
        strategy: Strategy::RcT,
        path: RenderPath::Compute,
        labels: LabelView::Surfaces,
        label_smoothing: smoothing,
        ..RenderSettings::default()
    }
}

#[test]
fn surfaces_match_the_reference_on_both_paths() {
    let (volume, labels, tf) = scene();
    let table = labels.styled_table(style);
    let mut r = renderer(&volume, &labels, &tf);
    let camera = common::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    for (smoothing, preintegrated) in [(0.7, false), (1.5, false), (0.0, false), (0.7, true)] {
        let settings = RenderSettings {
            preintegrated,
            ..surfaces(smoothing)
        };
        let mask = smoothed_mask(
            volume.dims(),
            &labels.shown_voxels(&table),
            smoothing as f32,
        );
        let labelled = Labelled {
            map: &labels,
            table: &table,
            mask: Some(&mask),
        };
        let expected =
            reference::render_labelled(&volume, &tf, &camera, SIZE, &settings, Some(&labelled))
                .image;
        let plain = reference::render(&volume, &tf, &camera, SIZE, &settings).image;
        let name = format!("surfaces-{smoothing}-pre{preintegrated}");
        assert!(
            expected.diff(&plain).expect("same size").max_abs > 0.2,
            "{name}: the surfaces change nothing in the reference"
        );
        for path in [RenderPath::Fragment, RenderPath::Compute] {
            let actual = render(&mut r, &camera, RenderSettings { path, ..settings });
            // The texture unit filters with 8-bit weights where the reference filters in f64:
            // a crossing may move by a fraction of a voxel, and where two labels meet at the
            // surface, or a ray grazes it, either side may colour a pixel: at most 2 % of the
            // pixels differ by more than 1/255 (any amount), and the whole by an RMSE of 1 %.
            let diff =
                common::assert_close(&format!("{name}-{path:?}"), &actual, &expected, 1.0, 0.02);
            assert!(diff.rmse < 0.01, "{name}-{path:?}: {diff:?}");
        }
    }
}

#[test]
fn leaping_stays_exact_with_surfaces_and_rebuilds_only_on_change() {
    let (volume, labels, tf) = scene();
    let mut r = renderer(&volume, &labels, &tf);
    let camera = common::framing(&volume, ViewPreset::PlusX, ProjectionKind::Perspective);
    for path in [RenderPath::Fragment, RenderPath::Compute] {
        let plain = render(
            &mut r,
            &camera,
            RenderSettings {
                path,
                ..surfaces(0.7)
            },
        );
        for strategy in [Strategy::RcS, Strategy::RcSDistance] {
            let settings = RenderSettings {
                path,
                strategy,
                ..surfaces(0.7)
            };
            let leapt = render(&mut r, &camera, settings);
            common::assert_close(
                &format!("surfaces-leap-{path:?}-{strategy:?}"),
                &leapt,
                &plain,
                1.0 / 255.0,
                0.0,
            );
        }
    }
    // Built once for these labels and this smoothing; again for another smoothing only.
    let built = r.work_counts().label_surface_builds;
    assert_eq!(built, 1);
    render(&mut r, &camera, surfaces(1.0));
    render(&mut r, &camera, surfaces(1.0));
    assert_eq!(r.work_counts().label_surface_builds, 2);
    // Other modes show the image alone under this view.
    let mip = RenderSettings {
        mode: Mode::Mip,
        ..surfaces(0.7)
    };
    let off = RenderSettings {
        labels: LabelView::Off,
        ..mip
    };
    let a = render(&mut r, &camera, mip);
    let b = render(&mut r, &camera, off);
    assert_eq!(a.diff(&b).expect("same size").max_abs, 0.0);
}

#[test]
fn render_draws_surfaces_and_refuses_a_bad_smoothing() {
    use common::{leapview, stderr};
    let data = common::data_dir();
    let out = common::output_dir().join("label-surfaces-cli.png");
    let volume = data.join("ct_head_cthead_256x256x113_uint16.nrrd");
    let labels = data.join("labels/ct_head_cthead.seg.nrrd");
    let (volume, labels) = (volume.to_string_lossy(), labels.to_string_lossy());
    let out_text = out.to_string_lossy().into_owned();
    let run = |extra: &[&str]| {
        let mut args = vec![
            "render",
            &volume,
            "--labels",
            &labels,
            "--label-view",
            "surfaces",
            "--size",
            "48x48",
            "--out",
            &out_text,
        ];
        args.extend(extra);
        leapview(&args)
    };
    let ok = run(&["--label-smoothing", "1.0", "--stats"]);
    assert!(ok.status.success(), "{}", stderr(&ok));
    let stdout = String::from_utf8_lossy(&ok.stdout);
    assert!(stdout.contains("label_surfaces: smoothing 1"), "{stdout}");
    assert!(out.exists());
    let bad = run(&["--label-smoothing", "2"]);
    assert!(!bad.status.success());
    let err = stderr(&bad);
    assert!(err.contains("label smoothing"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}
