//! Frames rendered in bands of rows (what the window does when a frame would keep the GPU busy
//! for long) equal frames rendered whole, bit for bit, on both paths and with every leaping
//! strategy; statistics add up over the bands; the refinement mean takes the banded frame.

use crate::common;

use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::render::{Accumulate, FrameRequest, RefineRun, VolumeRenderer};
use leapview::settings::{Mode, RenderPath, RenderSettings, Strategy};
use leapview::transfer::presets::preset;
use leapview::volume::synthetic;

/// Renders `request` in bands of `band` rows and returns the last band's results, waiting for
/// each band.
fn banded(
    r: &mut VolumeRenderer,
    request: &FrameRequest,
    band: u32,
    accumulate: Option<Accumulate>,
) -> (Option<u32>, leapview::render::FrameResults) {
    let height = request.size[1];
    let mut first = 0;
    let mut last = (None, Default::default());
    while first < height {
        let end = (first + band).min(height);
        let (submitted, mean) = r
            .render_band(request, [first, end], accumulate)
            .expect("band");
        let results = r.collect_results(true);
        let mine = results
            .into_iter()
            .find(|x| x.frame == submitted.frame)
            .unwrap_or_default();
        last = (mean, mine);
        first = end;
    }
    last
}

/// A renderer holding `volume` with transfer function `tf`, and an oblique camera framing it.
fn scene(volume: &leapview::volume::Volume, tf: &str) -> (VolumeRenderer, Camera) {
    let mut r = common::renderer();
    r.set_volume(volume).expect("upload");
    r.set_transfer_function(&preset(tf).expect("preset"));
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    (
        r,
        Camera::framing(&bounds, dir, up, ProjectionKind::Perspective),
    )
}

#[test]
fn a_frame_in_bands_equals_the_whole_frame_on_both_paths() {
    let (mut r, camera) = scene(&synthetic::vessel_tree(48, 3).expect("volume"), "mr-angio");
    // 61 rows: neither a multiple of the compute path's 8-row workgroups nor of the bands.
    let size = [53, 61];
    for path in [RenderPath::Compute, RenderPath::Fragment] {
        for (mode, strategy) in [
            (Mode::Dvr, Strategy::RcT),
            (Mode::Dvr, Strategy::RcSDistance),
            (Mode::Mip, Strategy::RcS),
        ] {
            let settings = RenderSettings {
                path,
                mode,
                strategy,
                ..RenderSettings::default()
            };
            let request = FrameRequest {
                camera: &camera,
                size,
                settings: &settings,
                stats: true,
            };
            let (_, whole) = r.render_and_wait(&request).expect("render");
            let whole_image = r.read_image().expect("read");
            for band in [1, 13, 16, 61] {
                let (_, last) = banded(&mut r, &request, band, None);
                let image = r.read_image().expect("read");
                let case = format!("{path:?} {mode:?} {strategy:?}, bands of {band} rows");
                assert_eq!(image, whole_image, "{case}");
                assert_eq!(last.counters, whole.counters, "{case}: counters add up");
                assert!(whole.counters.is_some_and(|c| c.samples > 0), "{case}");
            }
        }
    }
}

#[test]
fn a_banded_frame_starts_and_joins_the_refinement_mean() {
    let (mut r, camera) = scene(&synthetic::shepp_logan(32).expect("volume"), "ct-bone");
    let size = [40, 37];
    let mut settings = RenderSettings {
        path: RenderPath::Compute,
        ..RenderSettings::default()
    };
    let whole = r
        .render_refined(&camera, size, &settings, RefineRun::frames(2))
        .expect("whole");
    fn request<'a>(camera: &'a Camera, size: [u32; 2], s: &'a RenderSettings) -> FrameRequest<'a> {
        FrameRequest {
            camera,
            size,
            settings: s,
            stats: false,
        }
    }
    // The last band of the first frame restarts the mean, that of the second adds to it.
    for (k, accumulate) in [Accumulate::Restart, Accumulate::Add]
        .into_iter()
        .enumerate()
    {
        settings.sample_offset = leapview::render::raycast::refine::offset(k as u32);
        let (mean, _) = banded(
            &mut r,
            &request(&camera, size, &settings),
            10,
            Some(accumulate),
        );
        assert_eq!(mean, Some(k as u32 + 1), "{accumulate:?}");
    }
    assert_eq!(r.read_refined().expect("mean"), whole);
}

/// The window's pump submits bands without waiting for their measurements, so more bands are in
/// flight than there are probes: a statistics frame's last band, which alone carries the
/// frame's counters, must still get one (it waits), and the results of the bands before it that
/// were collected meanwhile are not lost.
#[test]
fn a_statistics_frame_keeps_its_counters_when_its_bands_outrun_the_probes() {
    let (mut r, camera) = scene(&synthetic::vessel_tree(48, 3).expect("volume"), "mr-angio");
    let settings = RenderSettings {
        path: RenderPath::Compute,
        strategy: Strategy::RcSDistance,
        ..RenderSettings::default()
    };
    let request = FrameRequest {
        camera: &camera,
        size: [40, 48],
        settings: &settings,
        stats: true,
    };
    let (_, whole) = r.render_and_wait(&request).expect("render");
    // Twelve bands of four rows, none waited for.
    let mut submitted = Vec::new();
    for first in (0..48).step_by(4) {
        let (frame, _) = r
            .render_band(&request, [first, first + 4], None)
            .expect("band");
        submitted.push(frame.frame);
    }
    let results = r.collect_results(true);
    let last = results
        .iter()
        .find(|x| Some(&x.frame) == submitted.last())
        .expect("the last band's measurements");
    assert!(whole.counters.is_some_and(|c| c.samples > 0));
    assert_eq!(last.counters, whole.counters, "the frame's counters");
    // What was collected while the last band waited comes back too: more bands than probes.
    let measured = results
        .iter()
        .filter(|x| submitted.contains(&x.frame))
        .count();
    assert!(measured > 4, "{measured} of 12 bands measured");
}
