//! Volumes as bricks in an atlas (`accel::bricks`): images equal to one texture's in every
//! mode, strategy and path (leaping stays exact: its pyramid is built through the same bricks);
//! volumes with an axis past the adapter's 3D texture limit open and match the f64 reference;
//! slices of a bricked volume equal those of one texture; under a GPU memory budget, the finest
//! level that fits is shown, as one texture of that level would show it.

use crate::common;
use crate::modes::cases;

use std::sync::Arc;

use glam::DVec3;
use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::imaging::ImageF32;
use leapview::mpr::{PatientFrame, Plane, PlaneKind, Slab, SlabMode, SliceView};
use leapview::reference;
use leapview::render::VolumeRenderer;
use leapview::render::slice::{LabelLook, SliceLook, SliceRenderer};
use leapview::render::volume_texture::VolumeTexture;
use leapview::settings::effects::Shading;
use leapview::settings::{Bricking, Mode, RenderPath, RenderSettings, Strategy, Upload};
use leapview::transfer::TransferFunction;
use leapview::volume::downsample::Level;
use leapview::volume::{Samples, ValueMapping, Volume};

use common::scene::tf;

/// A volume of `dims` whose values (0 … 1000) vary smoothly along every axis, with a ball of
/// dense values and a hole, so that any misplaced brick, a wrong apron or a seam shows.
fn structured(dims: [u32; 3], nan_at: Option<[u32; 3]>) -> Volume {
    let mut v = Vec::with_capacity(dims.iter().map(|&d| d as usize).product());
    let c = DVec3::new(
        f64::from(dims[0]) * 0.4,
        f64::from(dims[1]) * 0.55,
        f64::from(dims[2]) * 0.5,
    );
    let r = f64::from(*dims.iter().min().unwrap_or(&1)) * 0.35;
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let p = DVec3::new(f64::from(x), f64::from(y), f64::from(z));
                let wave = 250.0
                    + 200.0 * (p.x * 0.21).sin() * (p.y * 0.17).cos()
                    + 150.0 * (p.z * 0.13).sin();
                let d = (p - c).length() / r;
                let ball = if d < 1.0 { 550.0 * (1.0 - d * d) } else { 0.0 };
                let value = if Some([x, y, z]) == nan_at {
                    f32::NAN
                } else {
                    (wave + ball).clamp(0.0, 1000.0) as f32
                };
                v.push(value);
            }
        }
    }
    Volume::new(
        "structured",
        dims,
        [1.0, 0.9, 1.2],
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

fn renderer(volume: &Volume, tf: &TransferFunction, bricking: Bricking) -> VolumeRenderer {
    let mut r = common::renderer();
    r.set_volume_with(
        &Arc::new(volume.clone()),
        &Upload {
            bricking,
            ..Upload::default()
        },
    )
    .expect("upload");
    assert_eq!(
        r.volume_texture().is_some_and(|t| t.view.bricked),
        bricking == Bricking::On
    );
    r.set_transfer_function(tf);
    r
}

fn render(r: &mut VolumeRenderer, camera: &Camera, settings: &RenderSettings) -> ImageF32 {
    r.render_image(camera, [40, 40], settings)
        .unwrap_or_else(|e| panic!("{settings:?}: {e}"))
}

/// A camera framing `volume` from the front, a little from the right and above.
fn oblique_camera(volume: &Volume) -> Camera {
    Camera::framing(
        &Aabb::of_volume(volume.dims(), volume.spacing_mm()),
        DVec3::new(0.3, -1.0, 0.4).normalize(),
        DVec3::Z,
        ProjectionKind::Perspective,
    )
}

/// A renderer of `volume` under `upload` that streams its bricks as the window does, with no
/// upload time: a batch of bricks a frame.
fn streaming_renderer(
    volume: &Arc<Volume>,
    upload: &Upload,
    tf: &TransferFunction,
) -> VolumeRenderer {
    let mut r = common::renderer();
    r.set_residency_time(Some(std::time::Duration::ZERO));
    r.set_volume_with(volume, upload).expect("upload");
    r.set_transfer_function(tf);
    r
}

/// Renders frames until residency is complete (the first frame whatever it finds); returns
/// how many, fewer than `most`.
fn stream_until_complete(
    r: &mut VolumeRenderer,
    camera: &Camera,
    settings: &RenderSettings,
    most: u64,
) -> u64 {
    let mut frames = 0;
    loop {
        render(r, camera, settings);
        frames += 1;
        if r.residency_complete() {
            return frames;
        }
        assert!(frames < most, "still streaming after {frames} frames");
    }
}

/// A GPU memory budget whose texels' share holds about `slots` slots of 34³ × 2 bytes (a little
/// less: the leaping structures and page tables take theirs): besides, a budget keeps a quarter
/// for a frame's targets, a sixteenth for the upload's staging and one for the allocator's
/// unused blocks (`reserves`, `besides_texels` in src/render/volume_texture/mod.rs).
fn budget_of_slots(slots: u64) -> u64 {
    slots * 34u64.pow(3) * 2 * 16 / 10
}

/// Every mode of the mode tests, with RC-t and each leaping strategy, on both paths: bricked
/// images equal one texture's to the 8-bit step (measured on lavapipe: at most 1/255 apart, the
/// filter's weights at the same fractions in the slot as in the whole volume).
#[test]
fn bricked_images_equal_one_textures_in_every_mode_strategy_and_path() {
    // 70 × 45 × 38: three bricks of 32 along x, the last partial, and seams on every axis.
    for nan_at in [None, Some([33, 20, 17])] {
        let volume = structured([70, 45, 38], nan_at);
        let tf = tf();
        let mut single = renderer(&volume, &tf, Bricking::Off);
        let mut bricked = renderer(&volume, &tf, Bricking::On);
        let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
        let (dir, up) = ViewPreset::Oblique.direction_and_up();
        let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
        for (name, base) in cases() {
            // The NaN volume's variants differ only in sampling: one mode of each family.
            if nan_at.is_some() && !["dvr-phong", "iso-phong", "mip-window"].contains(&name) {
                continue;
            }
            for strategy in [Strategy::RcT, Strategy::RcS, Strategy::RcSDistance] {
                if strategy.for_mode(base.mode) != strategy {
                    continue;
                }
                for path in [RenderPath::Fragment, RenderPath::Compute] {
                    let settings = RenderSettings {
                        strategy,
                        path,
                        ..base
                    };
                    let want = render(&mut single, &camera, &settings);
                    let got = render(&mut bricked, &camera, &settings);
                    common::assert_close(
                        &format!(
                            "bricked-{name}-{strategy:?}-{path:?}-nan{}",
                            nan_at.is_some()
                        ),
                        &got,
                        &want,
                        1.0 / 255.0 + 1e-6,
                        0.0,
                    );
                }
            }
        }
    }
}

/// Volumes with an axis past the 3D texture limit of lavapipe (4096), as the issue names them,
/// open (bricked by default) and match the f64 reference: seen from the side and end on, so that
/// rays cross up to 141 bricks.
#[test]
fn volumes_past_the_3d_texture_limit_open_bricked_and_match_the_reference() {
    let max = common::gpu().limits.max_texture_dimension_3d;
    for dims in [[4200, 16, 16], [64, 48, 4500]] {
        let volume = structured(dims, None);
        let tf = tf();
        let mut r = common::renderer();
        r.set_volume(&volume).expect("opens");
        let bricked = r.volume_texture().is_some_and(|t| t.view.bricked);
        assert_eq!(bricked, dims.iter().any(|&d| d > max), "{dims:?}");
        r.set_transfer_function(&tf);
        let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
        let long_axis = if dims[0] > dims[2] {
            ViewPreset::PlusX
        } else {
            ViewPreset::PlusZ
        };
        for view in [ViewPreset::Oblique, long_axis] {
            let (dir, up) = view.direction_and_up();
            let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
            for (name, base) in cases() {
                if !["dvr-phong", "mip-window", "xray-mean"].contains(&name) {
                    continue;
                }
                let settings = RenderSettings {
                    step_vox: 1.0,
                    ..base
                };
                let size = [48, 48];
                let expected = reference::render(&volume, &tf, &camera, size, &settings).image;
                for (strategy, path) in [
                    (Strategy::RcT, RenderPath::Compute),
                    (Strategy::RcS, RenderPath::Fragment),
                ] {
                    let s = RenderSettings {
                        strategy,
                        path,
                        ..settings
                    };
                    let got = r
                        .render_image(&camera, size, &s)
                        .unwrap_or_else(|e| panic!("{s:?}: {e}"));
                    // As the mode tests: within 4/255 of the reference (the table lookup and
                    // f16 output add below 1e-3 to the 8-bit step).
                    common::assert_close(
                        &format!("long-{dims:?}-{view:?}-{name}-{strategy:?}-{path:?}"),
                        &got,
                        &expected,
                        4.0 / 255.0,
                        0.0,
                    );
                }
            }
        }
    }
}

/// Slices of a bricked volume (exact and display variants, thin and a leaping slab, standard and
/// oblique planes) equal those of one texture: the exact variant to the last bit.
#[test]
fn slices_of_a_bricked_volume_equal_one_textures() {
    let ctx = common::gpu();
    let volume = structured([70, 45, 38], None);
    let frame = PatientFrame::of(&volume);
    let upload = |bricking| {
        let upload = Upload {
            bricking,
            ..Upload::default()
        };
        VolumeTexture::upload_with(&ctx, &Arc::new(volume.clone()), &upload).expect("upload")
    };
    let (single, bricked) = (upload(Bricking::Off), upload(Bricking::On));
    assert!(bricked.view.bricked && !single.view.bricked);
    let renderer = SliceRenderer::new(&ctx.device).expect("pipelines");
    let at = frame.centre() + DVec3::new(0.3, -0.6, 1.1);
    let mut views: Vec<SliceView> = PlaneKind::STANDARD
        .iter()
        .map(|&k| SliceView::fit(Plane::standard(k, at), &frame, None))
        .collect();
    let oblique = Plane::standard(PlaneKind::Axial, at).tilted(DVec3::new(1.0, 1.0, 0.0), 0.6);
    views.push(SliceView::fit(oblique, &frame, Some([90, 70])));
    let slab = Slab {
        thickness_mm: 9.0,
        mode: SlabMode::Mip,
    };
    for view in &views {
        for (nearest, slab) in [(false, None), (true, None), (false, Some(slab))] {
            let look = SliceLook {
                window: [100.3, 900.1],
                nearest,
                slab,
                leap: true,
                colour: false,
                invert: false,
                labels: LabelLook::default(),
            };
            let draw = |texture: &VolumeTexture| {
                let bricks = slab.and_then(|_| renderer.bricks_of(&ctx, &volume, texture));
                let exact = renderer
                    .render(&ctx, &volume, texture, bricks.as_ref(), view, look)
                    .expect("slice");
                let display = renderer
                    .render_display(
                        &ctx,
                        &volume,
                        texture,
                        bricks.as_ref(),
                        None,
                        None,
                        view,
                        look,
                    )
                    .expect("slice");
                (exact, display)
            };
            let (want, want_display) = draw(&single);
            let (got, got_display) = draw(&bricked);
            let same = want
                .values
                .iter()
                .zip(&got.values)
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(
                same,
                "{:?} nearest {nearest} slab {}",
                view.plane,
                slab.is_some()
            );
            let worst = want_display
                .iter()
                .zip(&got_display)
                .flat_map(|(a, b)| (0..3).map(move |c| a[c].abs_diff(b[c])))
                .max()
                .unwrap_or(0);
            assert!(worst <= 1, "display: {worst} levels apart");
        }
    }
}

/// Under a budget that holds only half resolution, the volume is shown from level 1: images
/// equal (to the 8-bit step) one texture of the volume halved by `Level::half_of` (a mean of
/// each 2 × 2 × 2) with twice the spacing, in every unlit mode, with RC-t and leaping, on both
/// paths; and the note the window and the CLI show says so. The samples lie at the same
/// millimetres, each with the opacity the table gives it (no opacity correction: it would scale
/// optical depth by the voxel size, and the coarse level keeps the volume's); lit modes are left
/// out, their gradients stepping by a voxel of each.
#[test]
fn under_a_budget_the_finest_level_that_fits_is_shown_exactly_as_that_level() {
    // Even dimensions: the halved volume's box is the volume's.
    let volume = structured([64, 48, 40], None);
    let half = Level::half_of(volume.samples().expect("in memory"), None, volume.dims());
    let spacing = volume.spacing_mm().map(|s| 2.0 * s);
    let halved = Volume::new(
        "halved",
        half.dims,
        spacing,
        half.samples,
        ValueMapping::IDENTITY,
    )
    .expect("valid");
    let tf = tf();
    let mut coarse = common::renderer();
    // Full resolution is 2 × 2 × 2 bricks of 34³ × 4 bytes (1.26 MB); half is one (157 kB).
    let budget = Upload {
        gpu_budget: Some(400_000),
        ..Upload::default()
    };
    coarse
        .set_volume_with(&Arc::new(volume.clone()), &budget)
        .expect("upload");
    let texture = coarse.volume_texture().expect("volume");
    assert_eq!(texture.residency().map(|s| s.level), Some(1));
    let note = texture.coarser.clone().expect("a note");
    assert!(
        note.contains("1/2 resolution (32 x 24 x 20 voxels, level 1)"),
        "{note}"
    );
    coarse.set_transfer_function(&tf);
    let mut single = renderer(&halved, &tf, Bricking::Off);
    // Each framed by its own box: the halved volume's voxel 0 (the mean of the volume's voxels
    // 0 and 1) lies half a voxel of the volume from the volume's voxel 0, where the renderer
    // puts a volume's first voxel, so its box is the volume's moved by that much.
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    let frame = |v: &Volume| {
        let bounds = Aabb::of_volume(v.dims(), v.spacing_mm());
        Camera::framing(&bounds, dir, up, ProjectionKind::Perspective)
    };
    let (camera, halved_camera) = (frame(&volume), frame(&halved));
    let unlit = cases()
        .into_iter()
        .filter(|(_, s)| s.shading == Shading::Off || !matches!(s.mode, Mode::Dvr | Mode::Iso));
    for (name, base) in unlit {
        for strategy in [Strategy::RcT, Strategy::RcS] {
            for path in [RenderPath::Fragment, RenderPath::Compute] {
                // The same step in millimetres: the halved volume's voxels are twice as large.
                let settings = RenderSettings {
                    strategy,
                    path,
                    opacity_correction: false,
                    ..base
                };
                let halved_settings = RenderSettings {
                    step_vox: settings.step_vox / 2.0,
                    ..settings
                };
                let want = render(&mut single, &halved_camera, &halved_settings);
                let got = render(&mut coarse, &camera, &settings);
                common::assert_close(
                    &format!("level1-{name}-{strategy:?}-{path:?}"),
                    &got,
                    &want,
                    1.0 / 255.0 + 1e-6,
                    0.0,
                );
            }
        }
    }
}

/// A volume of 256 × 96 × 64 whose values stay below the transfer function's first opacity
/// (300) except in a ball with a sharp edge that ends two voxels before a brick border: a lit
/// sample there reads the next brick, which holds only noise.
fn ball_in_noise() -> Volume {
    let dims = [256u32, 96, 64];
    let mut v = Vec::with_capacity(dims.iter().map(|&d| d as usize).product());
    // Voxel 62 inside, 63 outside: a sample beside brick 2 (from x = 64) reads into it.
    let c = DVec3::new(52.5, 44.0, 30.0);
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let p = DVec3::new(f64::from(x), f64::from(y), f64::from(z));
                let noise =
                    120.0 + 100.0 * (p.x * 0.3).sin() * (p.y * 0.23).cos() * (p.z * 0.4).sin();
                let ball = if (p - c).length() < 10.0 { 800.0 } else { 0.0 };
                v.push(((noise + ball).clamp(0.0, 1000.0)) as u16);
            }
        }
    }
    Volume::new(
        "ball in noise",
        dims,
        [1.0, 1.1, 0.9],
        Samples::U16(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

/// Under a budget of 30 bricks, fewer than the volume's 48 and the coarsest, DVR and
/// isosurfaces hold only the bricks their rays can see (those the ball reaches) at full
/// resolution, every other brick a constant: images equal one texture's, lit and unlit, RC-t and
/// leaping, both paths, seen obliquely and facing the edge beside the next brick. MIP, which
/// sees every brick, falls back to a coarser level, and the
/// residency follows the mode back and forth.
#[test]
fn over_budget_the_bricks_the_transfer_function_hides_are_constants_and_images_stay_exact() {
    let volume = ball_in_noise();
    let tf = tf();
    let mut single = renderer(&volume, &tf, Bricking::Off);
    let mut culled = common::renderer();
    let budget = budget_of_slots(30);
    culled
        .set_volume_with(
            &Arc::new(volume.clone()),
            &Upload {
                gpu_budget: Some(budget),
                ..Upload::default()
            },
        )
        .expect("upload");
    culled.set_transfer_function(&tf);
    let status = |r: &VolumeRenderer| r.volume_texture().and_then(|t| t.residency().cloned());
    // Loaded with every brick needing data: 48 + 1 do not fit 30, level 1 (8 + 1) does.
    assert_eq!(status(&culled).map(|s| s.level), Some(1));
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let cameras = [ViewPreset::Oblique, ViewPreset::MinusX].map(|view| {
        let (dir, up) = view.direction_and_up();
        Camera::framing(&bounds, dir, up, ProjectionKind::Perspective)
    });
    let camera = &cameras[0];
    let mut shown: Vec<_> = cases()
        .into_iter()
        .filter(|(_, s)| matches!(s.mode, Mode::Dvr | Mode::Iso))
        .collect();
    // Crossing past voxel 63's centre: the gradient at the hit reads brick 2.
    let (_, iso) = shown[shown.len() - 2];
    shown.push((
        "iso-phong-low",
        RenderSettings {
            iso: leapview::settings::IsoSettings {
                value: Some(350.0),
                ..iso.iso
            },
            ..iso
        },
    ));
    for ((name, base), camera) in shown
        .into_iter()
        .flat_map(|c| cameras.iter().map(move |k| (c, k)))
    {
        for strategy in [Strategy::RcT, Strategy::RcS, Strategy::RcSDistance] {
            if strategy.for_mode(base.mode) != strategy {
                continue;
            }
            for path in [RenderPath::Fragment, RenderPath::Compute] {
                let settings = RenderSettings {
                    strategy,
                    path,
                    ..base
                };
                let size = [64, 64];
                let want = single.render_image(camera, size, &settings).expect("frame");
                let got = culled.render_image(camera, size, &settings).expect("frame");
                let s = status(&culled).expect("bricked");
                // Every brick of level 0 is data or a constant; the rays read level 0 only;
                // level 1's bricks stay resident in the slots left (nothing needs them).
                assert_eq!((s.level, s.levels, s.missing), (0, 1, 0), "{name}: {s:?}");
                assert_eq!(s.wanted_at_level + s.constant, 48, "{name}: {s:?}");
                assert!(s.constant >= 40 && s.resident >= s.wanted, "{name}: {s:?}");
                common::assert_close(
                    &format!("culled-{name}-{strategy:?}-{path:?}"),
                    &got,
                    &want,
                    1.0 / 255.0 + 1e-6,
                    0.0,
                );
            }
        }
    }
    let mip = RenderSettings {
        mode: Mode::Mip,
        path: RenderPath::Compute,
        ..RenderSettings::default()
    };
    render(&mut culled, camera, &mip);
    let s = status(&culled).expect("bricked");
    assert_eq!((s.level, s.constant), (1, 0), "{s:?}");
    let note = culled
        .volume_texture()
        .and_then(|t| t.coarser.clone())
        .expect("a note");
    assert!(note.contains("level 1"), "{note}");
    let dvr = RenderSettings {
        path: RenderPath::Compute,
        ..cases()[1].1
    };
    render(&mut culled, camera, &dvr);
    let s = status(&culled).expect("bricked");
    assert_eq!((s.level, s.levels), (0, 1), "{s:?}");
    assert!(s.constant >= 40, "{s:?}");
    assert!(culled.residency_complete());
}

/// Over the budget, the slices shown keep the bricks they cross: a sagittal slice through bricks
/// the transfer function hides (noise only) reads level 0 there, bit for bit one texture's
/// slice; without the plane given, the same slice reads a coarser level.
#[test]
fn over_budget_the_bricks_a_slice_crosses_stay_at_full_resolution() {
    use leapview::render::volume_texture::SlicePlane;
    let volume = ball_in_noise();
    let frame = PatientFrame::of(&volume);
    let tf = tf();
    let at = frame.to_patient(DVec3::new(200.0, 48.0, 32.0));
    let plane = Plane::standard(PlaneKind::Sagittal, at);
    let view = SliceView::fit(plane, &frame, None);
    let voxel = |p: DVec3| frame.to_voxel(p) + DVec3::splat(0.5);
    let normal = (voxel(at + plane.right) - voxel(at))
        .cross(voxel(at + plane.up) - voxel(at))
        .normalize();
    let planes = [SlicePlane {
        point: voxel(at).to_array(),
        normal: normal.to_array(),
        half_thickness: 0.0,
    }];
    let look = SliceLook {
        window: [0.0, 1000.0],
        nearest: false,
        slab: None,
        leap: true,
        colour: false,
        invert: false,
        labels: LabelLook::default(),
    };
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let (dir, up) = ViewPreset::Oblique.direction_and_up();
    let camera = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
    let dvr = RenderSettings {
        path: RenderPath::Compute,
        ..cases()[1].1
    };
    for with_plane in [true, false] {
        let mut r = common::renderer();
        r.set_volume_with(
            &Arc::new(volume.clone()),
            &Upload {
                gpu_budget: Some(budget_of_slots(30)),
                ..Upload::default()
            },
        )
        .expect("upload");
        r.set_transfer_function(&tf);
        if with_plane {
            assert!(r.set_slice_planes(&planes));
        }
        render(&mut r, &camera, &dvr);
        // One texture's slice on the renderer's own device.
        let ctx = r.context();
        let slices = SliceRenderer::new(&ctx.device).expect("pipelines");
        let single = VolumeTexture::upload(ctx, &volume).expect("upload");
        let want = slices
            .render(ctx, &volume, &single, None, &view, look)
            .expect("slice");
        let texture = r.volume_texture().expect("volume");
        let s = texture.residency().cloned().expect("bricked");
        assert_eq!((s.level, s.missing), (0, 0), "{s:?}");
        let got = slices
            .render(ctx, &volume, texture, None, &view, look)
            .expect("slice");
        let same = want
            .values
            .iter()
            .zip(&got.values)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert_eq!(same, with_plane, "with the plane: {with_plane}; {s:?}");
    }
}

/// The atlas as the driver allocates it stays inside the texels' share of the budget (the
/// budget less a sixteenth for staging and a quarter for a frame): lavapipe pads x to 64 texels
/// and y to 4, so a box of slots 4 across (136 texels) takes 1.4× its texels unless it lies
/// otherwise or holds fewer slots.
#[test]
fn the_atlas_as_allocated_stays_inside_the_texels_share() {
    let (ctx, volume) = (common::gpu(), Arc::new(ball_in_noise()));
    for slots in [9, 24, 40, 60, 100] {
        let budget = budget_of_slots(slots);
        let texture = VolumeTexture::upload_with(
            &ctx,
            &volume,
            &Upload {
                gpu_budget: Some(budget),
                bricking: Bricking::On,
                ..Upload::default()
            },
        )
        .expect("upload");
        let size = texture.texture.size();
        let texels = u64::from(size.width * size.height * size.depth_or_array_layers) * 2;
        let atlas = texture.texture_bytes();
        assert!(
            atlas <= budget * 11 / 16,
            "{slots} slots: the atlas {size:?} takes {atlas} bytes ({texels} of texels) of {budget}"
        );
        // Not much lost to the padding: at least half the slots the texels' share holds.
        assert!(
            texels * 2 >= slots * 34u64.pow(3) * 2,
            "{slots} slots: {size:?}"
        );
    }
}

/// Over the budget, only the bricks in view are wanted: MIP (which sees every brick of the
/// volume, 48 + 1 > 30 slots, level 1 when framed whole) zoomed in on the ball holds the bricks
/// in the view frustum at full resolution, and equals one texture's image.
#[test]
fn over_budget_only_the_bricks_in_view_are_held() {
    let volume = ball_in_noise();
    let tf = tf();
    let spacing = DVec3::from_array(volume.spacing_mm());
    let zoomed = Aabb {
        min: DVec3::new(36.0, 30.0, 18.0) * spacing,
        max: DVec3::new(70.0, 58.0, 42.0) * spacing,
    };
    let (dir, up) = ViewPreset::PlusZ.direction_and_up();
    let camera = Camera::framing(&zoomed, dir, up, ProjectionKind::Perspective);
    let mut single = renderer(&volume, &tf, Bricking::Off);
    let mut culled = common::renderer();
    culled
        .set_volume_with(
            &Arc::new(volume.clone()),
            &Upload {
                gpu_budget: Some(budget_of_slots(30)),
                ..Upload::default()
            },
        )
        .expect("upload");
    culled.set_transfer_function(&tf);
    for path in [RenderPath::Compute, RenderPath::Fragment] {
        let mip = RenderSettings {
            mode: Mode::Mip,
            strategy: Strategy::RcT,
            path,
            ..RenderSettings::default()
        };
        let want = render(&mut single, &camera, &mip);
        let got = render(&mut culled, &camera, &mip);
        let s = culled
            .volume_texture()
            .and_then(|t| t.residency().cloned())
            .expect("bricked");
        assert_eq!((s.level, s.levels, s.missing), (0, 1, 0), "{s:?}");
        assert!(s.wanted <= 30, "{s:?}");
        common::assert_close(
            &format!("in-view-mip-{path:?}"),
            &got,
            &want,
            1.0 / 255.0 + 1e-6,
            0.0,
        );
    }
}

/// While bricks stream in (one batch a frame), the leaping pyramid is built again only where
/// bricks arrived (the nodes that read a voxel of theirs): once complete it equals, bit for
/// bit, the pyramid a renderer that held every brick from the start built whole, and leaping
/// images equal RC-t's.
#[test]
fn streamed_bricks_rebuild_only_their_pyramid_nodes_the_distance_field_waits_and_all_stays_exact() {
    use leapview::render::readback::read_buffer;
    let volume = Arc::new(structured([200, 160, 136], None));
    let tf = tf();
    let camera = oblique_camera(&volume);
    let upload = Upload {
        bricking: Bricking::On,
        ..Upload::default()
    };
    let leaping = RenderSettings {
        mode: Mode::Dvr,
        strategy: Strategy::RcSDistance,
        path: RenderPath::Compute,
        ..RenderSettings::default()
    };
    let mut streamed = streaming_renderer(&volume, &upload, &tf);
    let frames = stream_until_complete(&mut streamed, &camera, &leaping, 50);
    let counts = streamed.work_counts();
    assert!(frames >= 2, "{frames} frame: the bricks came in one batch");
    assert_eq!(counts.minmax_builds, 1, "{counts:?}");
    assert!(counts.minmax_brick_builds >= 1, "{counts:?}");
    // The distance field waits while bricks arrive (the frames leap by the pyramid's flags,
    // rebuilt each frame) and is built once, in the frame that completed residency.
    assert_eq!(counts.distance_builds, 1, "{counts:?}");
    assert!(counts.flag_builds >= frames - 1, "{counts:?}");
    let mut whole = common::renderer();
    whole.set_volume_with(&volume, &upload).expect("upload");
    whole.set_transfer_function(&tf);
    let want = render(&mut whole, &camera, &leaping);
    let got = render(&mut streamed, &camera, &leaping);
    let minmax = |r: &VolumeRenderer| {
        let leap = r.leap_structures().expect("leaping");
        let n = leap.pyramid.node_count() as u64;
        let bytes = read_buffer(r.context(), &leap.minmax, n * 8).expect("read");
        bytemuck::cast_slice::<u8, [f32; 2]>(&bytes).to_vec()
    };
    let (a, b) = (minmax(&streamed), minmax(&whole));
    let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
    assert_eq!(differ, 0, "{differ} of {} nodes differ", a.len());
    // The bricks' builder (a brick's texels each once) equals one texture's (every voxel
    // through volume_load, which tests/integration/leaping.rs checks against the CPU's).
    let mut one = common::renderer();
    let off = Upload {
        bricking: Bricking::Off,
        ..Upload::default()
    };
    one.set_volume_with(&volume, &off).expect("upload");
    one.set_transfer_function(&tf);
    render(&mut one, &camera, &leaping);
    let c = minmax(&one);
    assert_eq!(c.len(), b.len());
    let differ = c.iter().zip(&b).filter(|(x, y)| x != y).count();
    assert_eq!(
        differ,
        0,
        "{differ} of {} nodes differ from one texture's",
        c.len()
    );
    // Equal but for rounding: the two atlases put the bricks in different slots, so a sample's
    // texture coordinate rounds differently (seen: 2.4e-4 at one pixel in a few, on lavapipe).
    common::assert_close("streamed-leaping", &got, &want, 1e-3, 0.0);
    let rc_t = RenderSettings {
        strategy: Strategy::RcT,
        ..leaping
    };
    let plain = render(&mut streamed, &camera, &rc_t);
    common::assert_close("streamed-rc-t", &got, &plain, 1.0 / 255.0 + 1e-6, 0.0);
}

/// Streaming under a time budget while the bricks' value ranges are computed on a thread of
/// their own: whenever they arrive (the frame deciding with them, the next writing the page
/// tables), residency completes, and the tables it leaves give, once every brick is wanted at
/// level 0, the image `render` waits for.
#[test]
fn streaming_while_the_ranges_arrive_completes_to_the_image_render_waits_for() {
    let volume = Arc::new(ball_in_noise());
    let tf = tf();
    let upload = Upload {
        gpu_budget: Some(budget_of_slots(30)),
        ..Upload::default()
    };
    let camera = oblique_camera(&volume);
    let dvr = RenderSettings {
        mode: Mode::Dvr,
        strategy: Strategy::RcSDistance,
        path: RenderPath::Compute,
        ..RenderSettings::default()
    };
    let mut streamed = streaming_renderer(&volume, &upload, &tf);
    stream_until_complete(&mut streamed, &camera, &dvr, 200);
    let status = streamed
        .volume_texture()
        .and_then(|t| t.residency().cloned());
    let s = status.expect("bricked");
    assert!(s.constant > 0 && s.missing == 0, "{s:?}");
    // Streaming held each brick at its footprint's level (40 × 40 pixels: coarse); without a
    // time budget every brick is wanted at level 0, and the tables streaming left are
    // refreshed only where that changes them.
    streamed.set_residency_time(None);
    let got = render(&mut streamed, &camera, &dvr);
    let mut waited = common::renderer();
    waited.set_volume_with(&volume, &upload).expect("upload");
    waited.set_transfer_function(&tf);
    let want = render(&mut waited, &camera, &dvr);
    common::assert_close("streamed-with-ranges", &got, &want, 1e-3, 0.0);
}
