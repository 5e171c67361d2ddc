//! Segmentations in the ray loop: the shared CT head (its DICOM series) with its labels (written
//! by SimpleITK; the palette's colours, far from any transfer function's), every mode with the labels colouring the image and
//! cutting it to the shown labels, on both paths, against the f64 reference; leaping exact with
//! labels; labels over a bricked volume as over one texture; a label toggle against a render
//! without it.

use std::sync::Arc;

use leapview::camera::{Camera, ProjectionKind, ViewPreset};
use leapview::imaging::ImageF32;
use leapview::labels::{LabelMap, LabelOptions, Segment, load_labels};
use leapview::reference::{self, Labelled};
use leapview::render::VolumeRenderer;
use leapview::render::labels::GpuLabels;
use leapview::settings::effects::{IsoSettings, LabelView, MipColor, Shading};
use leapview::settings::{Bricking, Mode, RenderPath, RenderSettings, Strategy, Upload};
use leapview::transfer::TransferFunction;
use leapview::volume::{LoadOptions, Volume, load_volume};

use crate::common;

/// The CT head series, its labels (1 soft tissue, 2 skull, 3 brain) and a soft-tissue function.
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
    let tf = leapview::transfer::presets::preset("ct-soft-tissue").expect("preset");
    (volume, labels, tf)
}

/// A renderer holding the scene, the labels shown where `visible` says.
fn renderer(
    volume: &Volume,
    labels: &LabelMap,
    tf: &TransferFunction,
    visible: impl Fn(&Segment) -> bool,
) -> VolumeRenderer {
    let mut r = common::renderer_for(volume, tf);
    let ctx = r.context();
    let gpu = GpuLabels::new(&ctx.device, &ctx.queue, labels.clone()).expect("labels upload");
    gpu.show(&ctx.queue, labels, visible);
    r.set_labels(Some(Arc::new(gpu)))
        .expect("labels over the volume");
    r
}

/// The largest RGB difference between two images.
fn max_diff(a: &ImageF32, b: &ImageF32) -> f64 {
    a.diff(b).expect("same size").max_abs
}

fn render(r: &mut VolumeRenderer, camera: &Camera, settings: RenderSettings) -> ImageF32 {
    render_at(r, camera, settings, [56, 56])
}

fn render_at(
    r: &mut VolumeRenderer,
    camera: &Camera,
    settings: RenderSettings,
    size: [u32; 2],
) -> ImageF32 {
    r.render_image(camera, size, &settings)
        .unwrap_or_else(|e| panic!("{settings:?}: {e}"))
}

/// Each mode under each way of showing labels.
fn cases() -> Vec<(&'static str, RenderSettings)> {
    let base = RenderSettings {
        step_vox: 0.5,
        strategy: Strategy::RcT,
        ..RenderSettings::default()
    };
    let iso = IsoSettings {
        value: Some(300.0),
        refine_iterations: 4,
    };
    vec![
        ("dvr-colour", base),
        (
            "dvr-unlit-inside",
            RenderSettings {
                shading: Shading::Off,
                labels: LabelView::Inside,
                ..base
            },
        ),
        (
            "dvr-colour-inside",
            RenderSettings {
                labels: LabelView::ColourInside,
                ..base
            },
        ),
        (
            "dvr-preintegrated-colour-inside",
            RenderSettings {
                labels: LabelView::ColourInside,
                preintegrated: true,
                ..base
            },
        ),
        (
            "iso-colour",
            RenderSettings {
                mode: Mode::Iso,
                iso,
                ..base
            },
        ),
        (
            "iso-inside",
            RenderSettings {
                mode: Mode::Iso,
                iso,
                labels: LabelView::Inside,
                ..base
            },
        ),
        (
            "mip-colour-inside",
            RenderSettings {
                mode: Mode::Mip,
                window: Some([0.0, 1500.0]),
                labels: LabelView::ColourInside,
                ..base
            },
        ),
        (
            "mip-tf-colour",
            RenderSettings {
                mode: Mode::Mip,
                mip_color: MipColor::Tf,
                ..base
            },
        ),
        (
            "minip-inside",
            RenderSettings {
                mode: Mode::MinIp,
                window: Some([-200.0, 200.0]),
                labels: LabelView::Inside,
                ..base
            },
        ),
        (
            "xray-inside",
            RenderSettings {
                mode: Mode::Xray,
                window: Some([-200.0, 1500.0]),
                labels: LabelView::ColourInside,
                ..base
            },
        ),
    ]
}

/// Skull and brain shown, soft tissue (label 1) hidden: colouring leaves soft tissue the
/// function's colour, cutting takes it away.
fn skull_and_brain(s: &Segment) -> bool {
    s.value != 1
}

#[test]
fn labels_colour_and_cut_every_mode_as_the_reference_does() {
    let (volume, labels, tf) = scene();
    // The skull at half opacity in another colour: colouring mixes towards it by half.
    let style = |s: &Segment| match s.value {
        1 => [0, 0, 0, 0],
        2 => [40, 200, 90, 128],
        _ => [s.colour[0], s.colour[1], s.colour[2], 255],
    };
    let table = labels.styled_table(style);
    let labelled = Labelled {
        map: &labels,
        table: &table,
    };
    let mut r = renderer(&volume, &labels, &tf, skull_and_brain);
    let ctx = r.context().clone();
    let gpu = Arc::new(GpuLabels::new(&ctx.device, &ctx.queue, labels.clone()).expect("upload"));
    gpu.show_styled(&ctx.queue, &labels, style);
    r.set_labels(Some(gpu)).expect("labels");
    let camera = common::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    for (name, settings) in cases() {
        let expected =
            reference::render_labelled(&volume, &tf, &camera, [56, 56], &settings, Some(&labelled))
                .image;
        let unlabelled = reference::render(&volume, &tf, &camera, [56, 56], &settings).image;
        // (X-ray's mean loses only the soft tissue's faint share of each path.)
        assert!(
            max_diff(&expected, &unlabelled) > 0.03,
            "{name}: the labels change nothing in the reference"
        );
        for path in [RenderPath::Fragment, RenderPath::Compute] {
            let actual = render(&mut r, &camera, RenderSettings { path, ..settings });
            // The nearest label is taken at f32 positions on the GPU, f64 in the reference: a
            // sample on a label's border may fall on either side, so a few pixels may differ
            // by a label's colour (at most 2 %); the rest within 4/255 as every mode is.
            common::assert_close(
                &format!("labels-{name}-{path:?}"),
                &actual,
                &expected,
                4.0 / 255.0,
                0.02,
            );
        }
    }
}

#[test]
fn leaping_stays_exact_with_labels() {
    let (volume, labels, tf) = scene();
    let mut r = renderer(&volume, &labels, &tf, skull_and_brain);
    let camera = common::framing(&volume, ViewPreset::PlusX, ProjectionKind::Perspective);
    for (name, settings) in cases() {
        for path in [RenderPath::Fragment, RenderPath::Compute] {
            let plain = render(&mut r, &camera, RenderSettings { path, ..settings });
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
                    &format!("labels-leap-{name}-{path:?}-{strategy:?}"),
                    &leapt,
                    &plain,
                    1.0 / 255.0,
                    0.0,
                );
            }
        }
    }
}

/// A bricked volume (an atlas of bricks, fully resident) shows its labels as one texture does,
/// in every view including surfaces, with and without leaping, on both paths.
#[test]
fn labels_over_a_bricked_volume_draw_as_over_one_texture() {
    let (volume, labels, tf) = scene();
    let mut single = renderer(&volume, &labels, &tf, skull_and_brain);
    let mut bricked = common::renderer();
    bricked
        .set_volume_with(
            &Arc::new(volume.clone()),
            &Upload {
                bricking: Bricking::On,
                ..Upload::default()
            },
        )
        .expect("upload");
    assert!(bricked.volume_texture().is_some_and(|t| t.view.bricked));
    bricked.set_transfer_function(&tf);
    let ctx = bricked.context();
    let gpu = GpuLabels::new(&ctx.device, &ctx.queue, labels.clone()).expect("labels upload");
    gpu.show(&ctx.queue, &labels, skull_and_brain);
    bricked
        .set_labels(Some(Arc::new(gpu)))
        .expect("labels over a bricked volume");
    let camera = common::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let surfaces = RenderSettings {
        step_vox: 0.5,
        strategy: Strategy::RcT,
        labels: LabelView::Surfaces,
        ..RenderSettings::default()
    };
    let mip_surfaces = RenderSettings {
        mode: Mode::Mip,
        window: Some([0.0, 1500.0]),
        ..surfaces
    };
    let all = cases()
        .into_iter()
        .chain([("dvr-surfaces", surfaces), ("mip-surfaces", mip_surfaces)]);
    for (name, settings) in all {
        for path in [RenderPath::Fragment, RenderPath::Compute] {
            for strategy in [Strategy::RcT, Strategy::RcS, Strategy::RcSDistance] {
                if strategy.for_mode(settings.mode) != strategy {
                    continue;
                }
                let settings = RenderSettings {
                    path,
                    strategy,
                    ..settings
                };
                let want = render(&mut single, &camera, settings);
                let got = render(&mut bricked, &camera, settings);
                common::assert_close(
                    &format!("labels-bricked-{name}-{path:?}-{strategy:?}"),
                    &got,
                    &want,
                    1.0 / 255.0 + 1e-6,
                    0.0,
                );
            }
        }
    }
}

#[test]
fn a_label_toggle_shows_as_a_render_without_it() {
    let (volume, labels, tf) = scene();
    let camera = common::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let colour = RenderSettings {
        step_vox: 0.5,
        path: RenderPath::Compute,
        strategy: Strategy::RcS,
        ..RenderSettings::default()
    };
    let mut plain = common::renderer_for(&volume, &tf);
    let without = render(&mut plain, &camera, colour);
    // Every label hidden: the image as if none were loaded, to the bit.
    let mut r = common::renderer_for(&volume, &tf);
    let ctx = r.context().clone();
    let gpu = Arc::new(GpuLabels::new(&ctx.device, &ctx.queue, labels.clone()).expect("upload"));
    gpu.show(&ctx.queue, &labels, |_| false);
    r.set_labels(Some(Arc::clone(&gpu))).expect("labels");
    assert_eq!(render(&mut r, &camera, colour), without);
    // Shown (the table rewritten, nothing else), they colour the next frame; hidden again, the
    // image is back.
    gpu.show(&ctx.queue, &labels, |_| true);
    let shown = render(&mut r, &camera, colour);
    assert!(max_diff(&shown, &without) > 0.2);
    gpu.show(&ctx.queue, &labels, |_| false);
    assert_eq!(render(&mut r, &camera, colour), without);
    gpu.show(&ctx.queue, &labels, |_| true);
    // The view `Off` shows no labels however many are shown.
    let off = RenderSettings {
        labels: LabelView::Off,
        ..colour
    };
    assert_eq!(render(&mut r, &camera, off), without);
    // Cut to hidden labels only: nothing is left but the background.
    let cut = RenderSettings {
        labels: LabelView::Inside,
        ..colour
    };
    let mut none = renderer(&volume, &labels, &tf, |_| false);
    let empty = render(&mut none, &camera, cut);
    assert!(empty.pixels.iter().all(|p| p[..3] == [0.0, 0.0, 0.0]));
}

/// Only the brain (label 3) shown.
fn brain(s: &Segment) -> bool {
    s.value == 3
}

#[test]
fn cut_views_leap_over_hidden_labels_and_a_toggle_rebuilds_only_their_flags() {
    let (volume, labels, tf) = scene();
    let camera = common::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let mut r = common::renderer_for(&volume, &tf);
    let ctx = r.context().clone();
    let gpu = Arc::new(GpuLabels::new(&ctx.device, &ctx.queue, labels.clone()).expect("upload"));
    gpu.show(&ctx.queue, &labels, brain);
    r.set_labels(Some(Arc::clone(&gpu))).expect("labels");
    let size = [48, 48];
    for (mode, window) in [
        (Mode::Dvr, None),
        (Mode::Mip, Some([0.0, 1500.0])),
        (Mode::Xray, Some([-200.0, 1500.0])),
    ] {
        for strategy in [Strategy::RcS, Strategy::RcSDistance] {
            if strategy.for_mode(mode) != strategy {
                continue;
            }
            let base = RenderSettings {
                mode,
                window,
                strategy,
                path: RenderPath::Compute,
                ..RenderSettings::default()
            };
            let inside = RenderSettings {
                labels: LabelView::Inside,
                ..base
            };
            let (cut, cut_counts) = common::render_counted(&mut r, &camera, inside, size);
            // Leaping by the values alone: the labels' flags built for every label shown.
            gpu.show(&ctx.queue, &labels, |_| true);
            let (_, all_counts) = common::render_counted(&mut r, &camera, inside, size);
            gpu.show(&ctx.queue, &labels, brain);
            let plain = render_at(
                &mut r,
                &camera,
                RenderSettings {
                    strategy: Strategy::RcT,
                    ..inside
                },
                size,
            );
            common::assert_close(
                &format!("labels-cut-leap-{mode:?}-{strategy:?}"),
                &cut,
                &plain,
                1.0 / 255.0,
                0.0,
            );
            // The brain is a small part of the head: fewer samples than where every label is
            // shown (measured on lavapipe at 48 × 48: DVR 20 336 against 33 122, MIP 39 268
            // against 100 025, X-ray 34 967 against 134 011, with the field 20 336 against
            // 86 190).
            assert!(
                cut_counts.samples * 5 < all_counts.samples * 4,
                "{mode:?} {strategy:?}: {} samples cut to the brain, {} cut to every label",
                cut_counts.samples,
                all_counts.samples
            );
        }
    }
    // A toggle in a cut view rebuilds the label flags and what reads them, nothing else; in a
    // view that only colours, nothing at all. The next frame shows it, exactly.
    let inside = RenderSettings {
        labels: LabelView::Inside,
        strategy: Strategy::RcSDistance,
        path: RenderPath::Compute,
        ..RenderSettings::default()
    };
    render_at(&mut r, &camera, inside, size);
    let before = r.work_counts();
    gpu.show(&ctx.queue, &labels, skull_and_brain);
    let toggled = render_at(&mut r, &camera, inside, size);
    let after = r.work_counts();
    assert_eq!(
        (
            after.label_flag_builds - before.label_flag_builds,
            after.flag_builds - before.flag_builds,
            after.distance_builds - before.distance_builds,
            after.minmax_builds - before.minmax_builds,
            after.lut_bakes - before.lut_bakes,
        ),
        (1, 1, 1, 0, 0)
    );
    let plain = render_at(
        &mut r,
        &camera,
        RenderSettings {
            strategy: Strategy::RcT,
            ..inside
        },
        size,
    );
    common::assert_close("labels-toggle-leap", &toggled, &plain, 1.0 / 255.0, 0.0);
    let colour = RenderSettings {
        labels: LabelView::Colour,
        ..inside
    };
    render_at(&mut r, &camera, colour, size);
    let before = r.work_counts();
    gpu.show(&ctx.queue, &labels, brain);
    render_at(&mut r, &camera, colour, size);
    let after = r.work_counts();
    assert_eq!(
        (
            after.label_flag_builds - before.label_flag_builds,
            after.flag_builds - before.flag_builds,
        ),
        (0, 0)
    );
    // A new colour or opacity for a shown label, in a cut view: the same labels are shown, so
    // nothing is rebuilt, but the picture changes.
    let shown = render_at(&mut r, &camera, inside, size);
    let before = r.work_counts();
    gpu.show_styled(&ctx.queue, &labels, |s| {
        [250, 20, 20, if brain(s) { 200 } else { 0 }]
    });
    let recoloured = render_at(
        &mut r,
        &camera,
        RenderSettings {
            labels: LabelView::ColourInside,
            ..inside
        },
        size,
    );
    let after = r.work_counts();
    assert_eq!(after.label_flag_builds - before.label_flag_builds, 0);
    assert!(max_diff(&shown, &recoloured) > 0.1);
}

#[test]
fn render_shows_labels_and_refuses_what_it_cannot_show() {
    use common::{leapview, stderr};
    let data = common::data_dir();
    let series = data.join("dicom/ct_head_cthead");
    let labels = data.join("labels/ct_head_cthead.seg.nrrd");
    let dir = common::output_dir();
    let out = |name: &str| dir.join(format!("labels-cli-{name}.png"));
    let (series, labels) = (series.to_string_lossy(), labels.to_string_lossy());
    let render = |name: &str, extra: &[&str]| {
        let path = out(name);
        let mut args = vec![
            "render",
            &series,
            "--size",
            "64x64",
            "--tf",
            "ct-soft-tissue",
        ];
        let path_text = path.to_string_lossy().into_owned();
        args.extend(["--out", &path_text]);
        args.extend(extra);
        let run = leapview(&args);
        (run, path)
    };
    let (plain, plain_png) = render("plain", &[]);
    assert!(plain.status.success(), "{}", stderr(&plain));
    // Only the brain, by name, the rest cut away: a different picture.
    let (cut, cut_png) = render(
        "brain",
        &[
            "--labels",
            &labels,
            "--label-view",
            "inside",
            "--show-labels",
            "Brain",
        ],
    );
    assert!(cut.status.success(), "{}", stderr(&cut));
    let a = image::open(&plain_png).expect("png").to_rgb8();
    let b = image::open(&cut_png).expect("png").to_rgb8();
    assert!(a != b, "the labels changed nothing");
    // A label the file does not hold: refused, naming what it holds.
    let (bad, _) = render("bad", &["--labels", &labels, "--show-labels", "liver"]);
    assert_eq!(bad.status.code(), Some(2), "{}", stderr(&bad));
    let text = stderr(&bad);
    assert!(
        text.contains("\"liver\" is no label") && text.contains("3 brain"),
        "{text}"
    );
    // --label-view without --labels is a usage error.
    let (usage, _) = render("usage", &["--label-view", "inside"]);
    assert_eq!(usage.status.code(), Some(2), "{}", stderr(&usage));
}

/// Labels on a grid past this GPU's 3D textures (a bar one voxel longer than its side, written
/// by nibabel) travel in the volume's bricks: `render` colours each half of the bar by its
/// label in 3D, `slice` fills each half, and each half shows as its label's surface (found on
/// the labels' grid halved to fit one texture).
#[test]
fn labels_past_one_texture_travel_in_the_volumes_bricks() {
    use common::{leapview, stderr};
    let max = common::renderer().context().limits.max_texture_dimension_3d;
    let dir = common::TempDir::new("labels-past-one-texture");
    let n = (max + 8).to_string();
    let (flag, n) = (std::path::Path::new("--long"), std::path::Path::new(&n));
    common::run_python("label_files.py", &[flag, n, dir.path()]);
    let image = dir.path().join("long_image.nii.gz");
    let labels = dir.path().join("long_labels.nii.gz");
    let (image, labels) = (image.to_string_lossy(), labels.to_string_lossy());
    let png = |name: &str| common::output_dir().join(format!("labels-bricks-{name}.png"));
    let pixels = |path: &std::path::Path, at: [[u32; 2]; 2]| {
        let picture = image::open(path).expect("png").to_rgb8();
        at.map(|[x, y]| picture.get_pixel(x, y).0.map(i32::from))
    };
    // Seen from the front, orthographic: the bar across the middle row, a quarter and three
    // quarters along it.
    let across = [[128, 256], [384, 256]];
    let chroma = |p: [i32; 3]| p.iter().max().unwrap_or(&0) - p.iter().min().unwrap_or(&0);
    let render = |name: &str, extra: &[&str]| {
        let path = png(name);
        let path_text = path.to_string_lossy().into_owned();
        let mut args = vec![
            "render",
            &image,
            "--size",
            "512x512",
            "--view",
            "A",
            "--projection",
            "orthographic",
            "--out",
            &path_text,
        ];
        args.extend(extra);
        let run = leapview(&args);
        assert!(run.status.success(), "{name}: {}", stderr(&run));
        pixels(&path, across)
    };
    let plain = render("plain", &[]);
    assert!(
        plain.iter().all(|&p| chroma(p) < 16 && p[0] > 100),
        "{plain:?}"
    );
    let coloured = render("colour", &["--labels", &labels, "--label-view", "colour"]);
    assert!(coloured.iter().all(|&p| chroma(p) > 40), "{coloured:?}");
    assert!(
        coloured[0] != coloured[1],
        "both halves show one label: {coloured:?}"
    );
    // The slice through the bar's axis: each half filled with its label's colour.
    let path = png("slice");
    let run = leapview(&[
        "slice",
        &image,
        "--labels",
        &labels,
        "--plane",
        "coronal",
        "--size",
        "512x16",
        "--out",
        &path.to_string_lossy(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let filled = pixels(&path, [[128, 8], [384, 8]]);
    assert!(filled.iter().all(|&p| chroma(p) > 40), "{filled:?}");
    assert!(filled[0] != filled[1], "{filled:?}");
    let surfaces = render(
        "surfaces",
        &["--labels", &labels, "--label-view", "surfaces"],
    );
    assert!(surfaces.iter().all(|&p| chroma(p) > 40), "{surfaces:?}");
    assert!(surfaces[0] != surfaces[1], "{surfaces:?}");
    // Each half in its label's colour, as the colour view shows it: the surface's hue.
    for (s, c) in surfaces.iter().zip(&coloured) {
        let hue = |p: &[i32; 3]| (0..3).max_by_key(|&i| p[i]);
        assert_eq!(hue(s), hue(c), "{surfaces:?} against {coloured:?}");
    }
    // Leaping over the space far from the shown labels (the halved mask's wider apron) stays
    // exact: the same picture as RC-t's.
    let leapt = |strategy: &str| {
        render(
            &format!("surfaces-{strategy}"),
            &[
                "--labels",
                &labels,
                "--label-view",
                "surfaces",
                "--strategy",
                strategy,
            ],
        );
        image::open(png(&format!("surfaces-{strategy}")))
            .expect("png")
            .to_rgb8()
    };
    let (plain, leaping) = (leapt("rc-t"), leapt("rc-s"));
    let worst = (plain.pixels().zip(leaping.pixels()))
        .flat_map(|(a, b)| (0..3).map(move |i| a[i].abs_diff(b[i])))
        .max();
    assert!(worst <= Some(1), "RC-s against RC-t: {worst:?}");
}
