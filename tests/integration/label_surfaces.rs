//! Labels as surfaces (`LabelView::Surfaces`): the shared CT head with its labels (written by
//! SimpleITK), the soft tissue at half opacity around the brain, in DVR and over every other
//! mode's picture, against the f64 reference (which renders from the CPU twin of the smoothed
//! mask); leaping exact; the mask rebuilt only when the shown labels or the smoothing change; the CLI.

use std::sync::Arc;

use leapview::camera::{Camera, ProjectionKind, ViewPreset};
use leapview::imaging::ImageF32;
use leapview::labels::{LabelMap, LabelOptions, Segment, load_labels};
use leapview::reference::{self, Labelled};
use leapview::render::VolumeRenderer;
use leapview::render::labels::GpuLabels;
use leapview::settings::effects::{IsoSettings, LabelView};
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
    let gpu = GpuLabels::new(&ctx.device, &ctx.queue, labels.clone()).expect("labels upload");
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
        let labelled = Labelled {
            map: &labels,
            table: &table,
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

/// The modes that show the surfaces over their picture: the isosurface (the skull at 300 HU,
/// the surfaces in front of it), MIP, MinIP and both X-rays (the projection of the whole ray).
fn over_cases() -> Vec<(&'static str, RenderSettings)> {
    let base = surfaces(0.7);
    let iso = IsoSettings {
        value: Some(300.0),
        refine_iterations: 4,
    };
    let window = Some([-200.0, 1500.0]);
    vec![
        (
            "iso",
            RenderSettings {
                mode: Mode::Iso,
                iso,
                ..base
            },
        ),
        (
            "mip",
            RenderSettings {
                mode: Mode::Mip,
                window,
                ..base
            },
        ),
        (
            "minip",
            RenderSettings {
                mode: Mode::MinIp,
                window: Some([-1000.0, 200.0]),
                ..base
            },
        ),
        (
            "xray",
            RenderSettings {
                mode: Mode::Xray,
                window,
                ..base
            },
        ),
        (
            "xray-attenuation",
            RenderSettings {
                mode: Mode::XrayAttenuation,
                window,
                ..base
            },
        ),
    ]
}

#[test]
fn surfaces_over_every_other_mode_match_the_reference() {
    let (volume, labels, tf) = scene();
    let table = labels.styled_table(style);
    let mut r = renderer(&volume, &labels, &tf);
    let camera = common::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let labelled = Labelled {
        map: &labels,
        table: &table,
    };
    for (name, settings) in over_cases() {
        let expected =
            reference::render_labelled(&volume, &tf, &camera, SIZE, &settings, Some(&labelled))
                .image;
        let plain = reference::render(&volume, &tf, &camera, SIZE, &settings).image;
        assert!(
            expected.diff(&plain).expect("same size").max_abs > 0.2,
            "{name}: the surfaces change nothing in the reference"
        );
        for path in [RenderPath::Fragment, RenderPath::Compute] {
            let actual = render(&mut r, &camera, RenderSettings { path, ..settings });
            // As in DVR (surfaces_match_the_reference_on_both_paths).
            let diff = common::assert_close(
                &format!("surfaces-{name}-{path:?}"),
                &actual,
                &expected,
                1.0,
                0.02,
            );
            assert!(diff.rmse < 0.01, "{name}-{path:?}: {diff:?}");
            // Leaping over what neither the projection nor a surface needs changes nothing.
            for strategy in [Strategy::RcS, Strategy::RcSDistance] {
                if strategy.for_mode(settings.mode) != strategy {
                    continue;
                }
                let leapt = render(
                    &mut r,
                    &camera,
                    RenderSettings {
                        path,
                        strategy,
                        ..settings
                    },
                );
                common::assert_close(
                    &format!("surfaces-leap-{name}-{path:?}-{strategy:?}"),
                    &leapt,
                    &actual,
                    1.0 / 255.0,
                    0.0,
                );
            }
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

/// The shading of a grey surface (0.502) under the default Phong headlight whose normal makes
/// an angle with cosine `c` with the view: ambient + diffuse · c + specular · cos(2θ)^24.
fn shade(c: f64) -> f64 {
    128.0 / 255.0 * (0.3 + 0.7 * c) + 0.25 * (2.0 * c * c - 1.0).max(0.0).powi(24)
}

/// The normal's angle (degrees) from the view that gives `intensity` (shade is monotonic).
fn angle_of(intensity: f64) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if shade(mid) < intensity {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (0.5 * (lo + hi)).clamp(0.0, 1.0).acos().to_degrees()
}

/// A ball of label 1 written by nibabel (scripts/python/sphere_labels.py), seen head-on by an
/// orthographic camera: each pixel's normal, read back from its shading, against the analytic
/// sphere's at that pixel (the ball's silhouette gives its centre and radius), between a fifth
/// and four fifths of the radius out. Unsmoothed, the voxels' staircase tilts them by up to
/// 20°; the default smoothing halves that; the widest follows the sphere to a few degrees.
#[test]
fn a_sphere_label_has_the_sphere_s_normals_without_a_staircase() {
    let dir = common::TempDir::new("label-sphere");
    common::run_python("sphere_labels.py", &[dir.path()]);
    let volume = load_volume(
        &dir.path().join("sphere_image.nii.gz"),
        &LoadOptions::default(),
    )
    .expect("the image");
    let labels = load_labels(
        &dir.path().join("sphere_labels.nii.gz"),
        &volume,
        &LabelOptions::default(),
    )
    .expect("the ball");
    // The image itself shows nothing.
    let tf = TransferFunction {
        opacity: vec![[0.0, 0.0], [1.0, 0.0]],
        color: vec![[0.0, 0.0, 0.0, 0.0], [1.0, 1.0, 1.0, 1.0]],
        space: leapview::transfer::ValueSpace::Normalized,
    };
    let mut r = common::renderer_for(&volume, &tf);
    let ctx = r.context().clone();
    let gpu = GpuLabels::new(&ctx.device, &ctx.queue, labels.clone()).expect("labels upload");
    gpu.show_styled(&ctx.queue, &labels, |_| [128, 128, 128, 255]);
    r.set_labels(Some(Arc::new(gpu))).expect("labels");
    let camera = common::framing(&volume, ViewPreset::PlusZ, ProjectionKind::Orthographic);
    let size = [192u32, 192];
    let mut errors = |smoothing: f64| {
        let image = r
            .render_image(&camera, size, &surfaces(smoothing))
            .expect("render");
        if std::env::var_os("LEAPVIEW_SAVE_IMAGES").is_some() {
            let out = common::output_dir().join(format!("label-sphere-{smoothing}.png"));
            image.save(&out).expect("save");
        }
        let lit: Vec<(f64, f64, f64)> = (0..size[1])
            .flat_map(|y| (0..size[0]).map(move |x| (x, y)))
            .filter_map(|(x, y)| {
                let p = image.get(x, y);
                (p[1] > 0.0).then_some((f64::from(x) + 0.5, f64::from(y) + 0.5, f64::from(p[1])))
            })
            .collect();
        let n = lit.len() as f64;
        let (cx, cy) = lit
            .iter()
            .fold((0.0, 0.0), |(a, b), l| (a + l.0 / n, b + l.1 / n));
        let radius = (n / std::f64::consts::PI).sqrt();
        let mut errors: Vec<f64> = lit
            .iter()
            .filter_map(|&(x, y, intensity)| {
                let rho = ((x - cx).powi(2) + (y - cy).powi(2)).sqrt() / radius;
                (0.2..0.8)
                    .contains(&rho)
                    .then(|| (angle_of(intensity) - rho.asin().to_degrees()).abs())
            })
            .collect();
        errors.sort_by(f64::total_cmp);
        let mean = errors.iter().sum::<f64>() / errors.len() as f64;
        (mean, errors[errors.len() * 95 / 100], radius)
    };
    let (smooth_mean, smooth_p95, radius) = errors(0.7);
    let (stairs_mean, stairs_p95, _) = errors(0.0);
    let (wide_mean, wide_p95, _) = errors(1.5);
    eprintln!(
        "sphere of {radius:.1} px, normals' error (mean, 95th percentile): smoothing 0 \
         {stairs_mean:.2}° {stairs_p95:.2}°, 0.7 {smooth_mean:.2}° {smooth_p95:.2}°, 1.5 \
         {wide_mean:.2}° {wide_p95:.2}°"
    );
    assert!(radius > 30.0, "the ball is {radius} px across");
    // Measured on lavapipe: 6.96° / 20.1°, 3.43° / 8.8° and 1.15° / 3.0°.
    assert!(
        stairs_p95 > 15.0,
        "the voxels' staircase shows: {stairs_p95}°"
    );
    assert!(
        smooth_mean < 4.5 && smooth_p95 < 11.0,
        "0.7: {smooth_mean}°, {smooth_p95}°"
    );
    assert!(
        wide_mean < 2.0 && wide_p95 < 5.0,
        "1.5: {wide_mean}°, {wide_p95}°"
    );
}

/// Walls between touching labels on real data: the MR head's 120 watershed parcels (nibabel;
/// every parcel touches others), all shown at half opacity. The shown labels are coloured into
/// classes (a channel of the mask each), so a ray that enters a parcel through its neighbour
/// draws the wall between them; the GPU matches the f64 reference (which colours the same
/// neighbour graph and smooths each class on the CPU) on both paths, and RC-s matches RC-t.
#[test]
fn walls_between_the_mr_parcels_match_the_reference() {
    let data = common::data_dir();
    let volume = load_volume(
        &data.join("originals/VolumeRenderingData_seg3D_MR.nii.gz"),
        &LoadOptions::default(),
    )
    .expect("the MR head");
    let labels = load_labels(
        &data.join("labels/mr_head_t1_seg3d_parcels.nii.gz"),
        &volume,
        &LabelOptions::default(),
    )
    .expect("its parcels");
    let half = |s: &Segment| [s.colour[0], s.colour[1], s.colour[2], 128];
    let table = labels.styled_table(half);
    let tf = leapview::transfer::presets::preset("ct-bone").expect("preset");
    let mut r = common::renderer_for(&volume, &tf);
    let ctx = r.context().clone();
    let gpu = GpuLabels::new(&ctx.device, &ctx.queue, labels.clone()).expect("labels upload");
    gpu.show_styled(&ctx.queue, &labels, half);
    let classes = gpu.classes();
    assert!(classes.used >= 3, "{} classes", classes.used);
    // Every parcel touches another: with one class no wall would be drawn.
    let touching = classes.class.iter().flatten().count();
    assert_eq!(touching, 120);
    let gpu = Arc::new(gpu);
    r.set_labels(Some(Arc::clone(&gpu))).expect("labels");
    let camera = common::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let settings = surfaces(0.7);
    let labelled = Labelled {
        map: &labels,
        table: &table,
    };
    let expected =
        reference::render_labelled(&volume, &tf, &camera, SIZE, &settings, Some(&labelled)).image;
    for (strategy, path) in [
        (Strategy::RcT, RenderPath::Compute),
        (Strategy::RcT, RenderPath::Fragment),
        (Strategy::RcS, RenderPath::Compute),
    ] {
        let actual = render(
            &mut r,
            &camera,
            RenderSettings {
                strategy,
                path,
                ..settings
            },
        );
        // As surfaces_match_the_reference_on_both_paths: a crossing may move by a fraction of
        // a voxel where the texture unit's 8-bit weights filter; many more surfaces here.
        let name = format!("walls-mr-parcels-{strategy:?}-{path:?}");
        let diff = common::assert_close(&name, &actual, &expected, 1.0, 0.05);
        assert!(diff.rmse < 0.015, "{name}: {diff:?}");
    }
    // A toggle of a parcel (the median by voxels) remakes the mask over the box of the labels
    // whose class or visibility changed: the frame equals one whose mask was made whole (a
    // change of smoothing and back remakes it whole), hiding the parcel and showing it again.
    // (Not always the first frame again: a neighbour may have taken the parcel's class
    // meanwhile to leave fewer touching pairs in one class.)
    let compute = RenderSettings {
        strategy: Strategy::RcT,
        path: RenderPath::Compute,
        ..settings
    };
    let first = render(&mut r, &camera, compute);
    let mut parcels: Vec<&Segment> = labels.segments().iter().collect();
    parcels.sort_by_key(|s| s.voxels);
    let toggled = parcels[parcels.len() / 2].value;
    let without = |s: &Segment| if s.value == toggled { [0; 4] } else { half(s) };
    let smoother = RenderSettings {
        label_smoothing: 0.75,
        ..compute
    };
    for (step, shown) in [("hidden", false), ("shown again", true)] {
        if shown {
            gpu.show_styled(&ctx.queue, &labels, half);
        } else {
            gpu.show_styled(&ctx.queue, &labels, without);
        }
        let toggle = render(&mut r, &camera, compute);
        let share = r.label_surface_facts().expect("a mask").last_build_share;
        assert!(
            share < 0.05,
            "parcel {toggled} {step}: remade over {share} of the grid"
        );
        if !shown {
            assert!(toggle.diff(&first).expect("same size").max_abs > 0.02);
        }
        render(&mut r, &camera, smoother);
        let remade = render(&mut r, &camera, compute);
        assert_eq!(
            r.label_surface_facts().expect("a mask").last_build_share,
            1.0
        );
        assert!(
            remade == toggle,
            "parcel {toggled} {step}: against a whole mask"
        );
    }
}
