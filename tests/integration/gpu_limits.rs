//! Volumes and images past the adapter's limits get clear errors, not panics or wrong pictures.

use crate::common;

use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::render::FrameRequest;
use leapview::render::RenderError;
use leapview::render::volume_texture::VolumeTextureError;
use leapview::settings::{Bricking, RenderSettings, Upload};
use leapview::volume::{Samples, ValueMapping, Volume};

fn line(n: u32) -> Volume {
    Volume::new(
        "line",
        [n, 1, 1],
        [1.0; 3],
        Samples::U8(vec![7; n as usize]),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

#[test]
fn volume_past_the_3d_texture_limit_is_bricked_and_refused_only_in_one_texture() {
    let mut r = common::renderer();
    let max = r.context().limits.max_texture_dimension_3d;
    r.set_volume(&line(4)).expect("small volume fits");
    // Settings left at their default render with the path `auto`.
    common::choose_auto_path(&mut r);
    // Asked for one texture, it is refused and the previous volume kept.
    let err = r
        .set_volume_with(
            &std::sync::Arc::new(line(max + 1)),
            &Upload {
                bricking: Bricking::Off,
                ..Upload::default()
            },
        )
        .expect_err("too large");
    assert!(
        matches!(
            err,
            RenderError::Volume(VolumeTextureError::TooLarge { .. })
        ),
        "{err:?}"
    );
    let msg = err.to_string();
    assert!(msg.contains(&format!("at most {max}")), "{msg}");
    assert_eq!(r.volume_geometry().map(|g| g.0), Some([4, 1, 1]));
    let bounds = Aabb::of_volume([4, 1, 1], [1.0; 3]);
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
    let frame = |r: &mut leapview::render::VolumeRenderer, camera: &Camera| {
        r.render(&FrameRequest {
            camera,
            size: [8, 8],
            settings: &RenderSettings::default(),
            stats: false,
        })
        .map(|_| ())
    };
    frame(&mut r, &camera).expect("renders");
    // By default it is bricked, and renders.
    r.set_volume(&line(max + 1)).expect("bricked");
    assert!(r.volume_texture().is_some_and(|t| t.view.bricked));
    let bounds = Aabb::of_volume([max + 1, 1, 1], [1.0; 3]);
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
    frame(&mut r, &camera).expect("renders");
}

#[test]
fn image_sizes_outside_the_2d_limit_are_refused() {
    let mut r = common::renderer();
    r.set_volume(&line(4)).expect("fits");
    // Settings left at their default render with the path `auto`.
    common::choose_auto_path(&mut r);
    let max = r.context().limits.max_texture_dimension_2d;
    let bounds = Aabb::of_volume([4, 1, 1], [1.0; 3]);
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
    for size in [[max + 1, 1], [1, 0]] {
        let err = r
            .render(&FrameRequest {
                camera: &camera,
                size,
                settings: &RenderSettings::default(),
                stats: false,
            })
            .expect_err("refused");
        assert!(matches!(err, RenderError::ImageSize { .. }), "{err:?}");
    }
}

#[test]
fn rendering_without_a_volume_is_an_error() {
    let mut r = common::renderer();
    let bounds = Aabb::of_volume([4, 4, 4], [1.0; 3]);
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
    let err = r
        .render(&FrameRequest {
            camera: &camera,
            size: [8, 8],
            settings: &RenderSettings {
                path: leapview::settings::RenderPath::Compute,
                ..RenderSettings::default()
            },
            stats: false,
        })
        .expect_err("no volume");
    assert!(matches!(err, RenderError::NoVolume), "{err:?}");
}

/// A volume that cannot go to the GPU (here: a GPU memory budget smaller than its coarsest
/// level, one brick) is refused from its header, before its samples are read (an 8 GiB volume
/// used to read for 82 s first): a gzip NRRD whose stream is cut short after a few bytes, so
/// that reading at all would fail on the stream instead. The message names both sizes and the
/// whole path given.
#[test]
fn a_volume_past_the_gpus_limits_is_refused_before_its_samples_are_read() {
    let ctx = common::gpu();
    let dir = common::TempDir::new("gpu-admission");
    let sizes = "sizes: 4097 2 2".to_string();
    let lines = [
        "type: uint8",
        "dimension: 3",
        sizes.as_str(),
        "encoding: gzip",
    ];
    let mut stream = common::gzip(&vec![1u8; 4096]);
    stream.truncate(20);
    let path = dir.write("wide.nrrd", &common::nrrd_file(&lines, &stream));
    let options = leapview::volume::LoadOptions {
        progress: Some(std::sync::Arc::new(
            leapview::volume::LoadProgress::with_admission(
                leapview::render::volume_texture::admission(&ctx, Some(10_000)),
            ),
        )),
        ..Default::default()
    };
    let e = leapview::volume::load_volume(&path, &options).expect_err("too wide");
    let text = e.to_string();
    assert!(text.contains("before reading"), "{text}");
    let both = "a GPU memory budget of 10.0 kB is smaller than the volume's coarsest level \
                (39.3 kB)";
    assert!(text.contains(both), "{text}");
    assert!(text.ends_with(&*path.to_string_lossy()), "{text}");
    // Without the check, the cut stream is what fails.
    let e = leapview::volume::load_volume(&path, &Default::default()).expect_err("cut short");
    assert!(!e.to_string().contains("budget"), "{e}");
    // The command line checks first too.
    let render = |budget: &str| {
        common::leapview(&[
            "render",
            path.to_str().expect("utf-8"),
            "--out",
            dir.path().join("x.png").to_str().expect("utf-8"),
            "--gpu-budget",
            budget,
        ])
    };
    let out = render("10kB");
    assert_eq!(out.status.code(), Some(2));
    let stderr = common::stderr(&out);
    assert!(
        stderr.contains("before reading") && stderr.contains(both),
        "{stderr}"
    );
    // A budget in a unit it does not know: exit 2 with the forms it takes.
    let out = render("2 parsecs");
    assert_eq!(out.status.code(), Some(2));
    let stderr = common::stderr(&out);
    assert!(
        stderr.contains("is not a size") && stderr.contains("512MB, 1.5GB, 2GiB"),
        "{stderr}"
    );
}
