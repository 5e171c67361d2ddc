//! RC-s against RC-t on all eight shared scans: three transfer functions, two views, both
//! paths, both leaping schemes. Leaping must not change a pixel by more than 1/255 and must take
//! every sample RC-t takes that has non-zero opacity.

use crate::common;

use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::counters::FrameCounters;
use leapview::render::VolumeRenderer;
use leapview::settings::{IsoSettings, Mode, RenderPath, RenderSettings, Strategy};
use leapview::transfer::TransferFunction;
use leapview::transfer::presets::preset;
use leapview::volume::{Volume, load_volume};

const SCANS: [&str; 8] = [
    "ct_bonsai_256x256x256_uint8.nrrd",
    "ct_engine_256x256x128_uint8.nrrd",
    "ct_head_cthead_256x256x113_uint16.nrrd",
    "cta_avm_337x319x154_uint8.nrrd",
    "cta_stent_128x128x256_int16.nrrd",
    "mr_brain_t1_stripped_124x160x140_uint8.nrrd",
    "mr_head_t1_seg3d_160x232x160_uint8.nrrd",
    "mra_head_200x256x120_uint8.nrrd",
];

/// Transfer functions in fractions of each scan's range, from a low threshold (most blocks
/// visible) to a high one (most blocks empty).
fn transfer_functions() -> Vec<(&'static str, TransferFunction)> {
    let mut high = TransferFunction::grey_ramp();
    high.opacity = vec![[0.0, 0.0], [0.45, 0.0], [0.6, 0.5], [1.0, 0.9]];
    vec![
        ("mr-default", preset("mr-default").expect("preset")),
        ("mr-angio", preset("mr-angio").expect("preset")),
        ("high", high),
    ]
}

type Rendered = (leapview::imaging::ImageF32, FrameCounters);

/// Loads and uploads each shared scan in turn and calls `f` with its name, bounds and volume.
fn each_scan(r: &mut VolumeRenderer, mut f: impl FnMut(&mut VolumeRenderer, &str, &Aabb, &Volume)) {
    let dir = common::data_dir();
    for scan in SCANS {
        let volume =
            load_volume(&dir.join(scan), &Default::default()).unwrap_or_else(|e| panic!("{e}"));
        r.set_volume(&volume).expect("upload");
        let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
        f(r, scan, &bounds, &volume);
    }
}

/// `base` rendered with RC-t, then with RC-s and RC-s-df (each checked against its plain
/// variant by `render_counted`).
fn rct_and_leaping(
    r: &mut VolumeRenderer,
    camera: &Camera,
    base: RenderSettings,
) -> (Rendered, [(Strategy, Rendered); 2]) {
    let mut render =
        |strategy| common::render_counted(r, camera, RenderSettings { strategy, ..base }, [48, 48]);
    let rct = render(Strategy::RcT);
    let leaping = [Strategy::RcS, Strategy::RcSDistance].map(|s| (s, render(s)));
    (rct, leaping)
}

/// A leaping image within 1/255 of RC-t's, from the same visible samples and no more samples.
fn assert_leaping_exact(
    label: &str,
    (leapt, counts): (&leapview::imaging::ImageF32, FrameCounters),
    (rct, rct_counts): (&leapview::imaging::ImageF32, FrameCounters),
) {
    common::assert_close(label, leapt, rct, 1.0 / 255.0, 0.0);
    assert_eq!(
        counts.visible_samples, rct_counts.visible_samples,
        "{label}"
    );
    assert!(counts.samples <= rct_counts.samples, "{label}");
}

#[test]
fn rc_s_equals_rc_t_on_every_shared_scan() {
    let mut r = common::renderer();
    let mut saved = (0u64, 0u64);
    each_scan(&mut r, |r, scan, bounds, _| {
        for (tf_name, tf) in transfer_functions() {
            r.set_transfer_function(&tf);
            for view in [ViewPreset::Oblique, ViewPreset::MinusY] {
                let (dir, up) = view.direction_and_up();
                let camera = Camera::framing(bounds, dir, up, ProjectionKind::Perspective);
                for path in [RenderPath::Fragment, RenderPath::Compute] {
                    let base = RenderSettings {
                        path,
                        ..RenderSettings::default()
                    };
                    let ((rct, rct_counts), leaping) = rct_and_leaping(r, &camera, base);
                    for (strategy, (rcs, counts)) in leaping {
                        let label = format!("{scan}-{tf_name}-{view:?}-{path:?}-{strategy:?}");
                        assert_leaping_exact(&label, (&rcs, counts), (&rct, rct_counts));
                        saved.0 += counts.samples;
                        saved.1 += rct_counts.samples;
                    }
                }
            }
        }
    });
    // Over all cases leaping must save a good share of the samples (not a no-op): at least a
    // quarter. (`saved.1` counts RC-t once per leaping scheme, like `saved.0`.)
    let (rcs, rct) = saved;
    eprintln!(
        "RC-s took {rcs} samples where RC-t took {rct} ({:.1} %)",
        100.0 * rcs as f64 / rct as f64
    );
    assert!(rcs * 4 < rct * 3, "RC-s took {rcs} samples, RC-t {rct}");
}

#[test]
fn preintegrated_leaping_equals_rc_t_on_every_shared_scan() {
    let mut r = common::renderer();
    each_scan(&mut r, |r, scan, bounds, _| {
        let (d, up) = ViewPreset::Oblique.direction_and_up();
        let camera = Camera::framing(bounds, d, up, ProjectionKind::Perspective);
        for (tf_name, tf) in transfer_functions().into_iter().skip(1) {
            r.set_transfer_function(&tf);
            for path in [RenderPath::Fragment, RenderPath::Compute] {
                // A step that is not a whole number of voxels, so samples fall anywhere in a
                // block and segments straddle block faces.
                let base = RenderSettings {
                    path,
                    step_vox: 1.5,
                    preintegrated: true,
                    ..RenderSettings::default()
                };
                let ((rct, rct_counts), leaping) = rct_and_leaping(r, &camera, base);
                for (strategy, (rcs, counts)) in leaping {
                    let label = format!("preint-{scan}-{tf_name}-{path:?}-{strategy:?}");
                    // Every skipped segment lies inside one empty region, where the running
                    // integrals are equal texel for texel (preintegration.rs): identical.
                    common::assert_close(&label, &rcs, &rct, 0.0, 0.0);
                    assert!(counts.samples <= rct_counts.samples, "{label}");
                }
            }
        }
    });
}

/// Isosurfaces leap by the octree (RC-s) and by the per-side distance field (RC-s-df, the field
/// rebuilt for each iso value): on every shared scan, at a low, the middle and a high iso value,
/// both paths, the image must be RC-t's and the crossings found the same (leaping lands on the
/// last sample before each crossing, so the bracket is RC-t's), from fewer samples.
#[test]
fn isosurface_leaping_equals_rc_t_on_every_shared_scan() {
    let mut r = common::renderer();
    let mut saved = [(0u64, 0u64); 2];
    each_scan(&mut r, |r, scan, bounds, volume| {
        let range = volume.normalization_range();
        let (d, up) = ViewPreset::Oblique.direction_and_up();
        let camera = Camera::framing(bounds, d, up, ProjectionKind::Perspective);
        for fraction in [0.15, 0.5, 0.7] {
            for path in [RenderPath::Fragment, RenderPath::Compute] {
                let base = RenderSettings {
                    path,
                    mode: Mode::Iso,
                    iso: IsoSettings {
                        value: Some(range.denormalize(fraction)),
                        ..IsoSettings::default()
                    },
                    ..RenderSettings::default()
                };
                let ((rct, rct_counts), leaping) = rct_and_leaping(r, &camera, base);
                for (i, (strategy, (rcs, counts))) in leaping.into_iter().enumerate() {
                    // (Visible samples of an isosurface: the crossings found.)
                    let label = format!("iso-{scan}-{fraction}-{path:?}-{strategy:?}");
                    assert_leaping_exact(&label, (&rcs, counts), (&rct, rct_counts));
                    saved[i].0 += counts.samples;
                    saved[i].1 += rct_counts.samples;
                }
            }
        }
    });
    for (strategy, (taken, rct)) in [Strategy::RcS, Strategy::RcSDistance].iter().zip(saved) {
        eprintln!("iso {strategy:?}: {taken} samples where RC-t took {rct}");
        assert!(
            taken * 2 < rct,
            "{strategy:?} took {taken} samples, RC-t {rct}"
        );
    }
}
