//! Shadows in lit DVR (issue 42, item 1): a slab of known opacity shadowing an opaque floor (the
//! transmittance it must have), every strategy on both paths against the f64 reference (the
//! reference marches the same shadow rays), leaping shadow rays exactly as the plain ones, and
//! the hard cases: a light grazing the box, the eye inside it, shadow steps of ⅛ and 4 voxels.

use glam::DVec3;
use leapview::camera::{Aabb, Camera, Projection, ProjectionKind, ViewPreset};
use leapview::reference;
use leapview::settings::effects::{Light, Phong, Shading};
use leapview::settings::{Mode, RenderPath, RenderSettings, Shadows, Strategy};
use leapview::transfer::{TransferFunction, ValueSpace};
use leapview::volume::{Samples, ValueMapping, Volume};

use crate::common::{self as hard, PATHS, check_reference_within, renderer_for, scene};

/// The slab scene's grid: x, y, z voxels of 1 mm.
const DIMS: [u32; 3] = [64, 16, 64];
/// The slab's voxels along z (inclusive) and its extent along x (exclusive).
const SLAB_Z: [u32; 2] = [20, 27];
const SLAB_X: u32 = 32;
/// The floor: every voxel from this z on.
const FLOOR_Z: u32 = 48;
/// The slab's opacity per voxel.
const SLAB_ALPHA: f64 = 0.1;

/// Empty space, a translucent slab (value 100) over the left half, and an opaque floor (value
/// 200) below it; `slab` false leaves the slab out.
fn slab_scene(slab: bool) -> Volume {
    slab_scene_of(slab.then_some(100.0))
}

/// [`slab_scene`] with the slab's value, or none.
fn slab_scene_of(slab: Option<f32>) -> Volume {
    let mut v = Vec::new();
    for z in 0..DIMS[2] {
        for _y in 0..DIMS[1] {
            for x in 0..DIMS[0] {
                let in_slab = (SLAB_Z[0]..=SLAB_Z[1]).contains(&z) && x < SLAB_X;
                v.push(match (z >= FLOOR_Z, in_slab, slab) {
                    (true, _, _) => 200.0f32,
                    (false, true, Some(value)) => value,
                    _ => 0.0,
                });
            }
        }
    }
    Volume::new(
        "slab",
        DIMS,
        [1.0; 3],
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

/// The slab's opacity at every value from 6 to 150 (so the slab reaches to 0.945 voxel past its
/// outer voxels' centres), opaque from 160: the floor. Empty space (0) lies in the lookup
/// tables' first bins with none of the slab's opacity: nodes there are empty.
fn slab_tf() -> TransferFunction {
    TransferFunction {
        opacity: vec![
            [0.0, 0.0],
            [5.0, 0.0],
            [6.0, SLAB_ALPHA],
            [150.0, SLAB_ALPHA],
            [160.0, 1.0],
            [200.0, 1.0],
        ],
        color: vec![[0.0, 1.0, 1.0, 1.0]],
        space: ValueSpace::Data,
    }
}

/// Diffuse light only (so a pixel is proportional to the light reaching it), shadows on, the
/// light travelling along +x and +z at 45°: from a floor point right of the slab, through it.
fn slab_settings(strategy: Strategy, path: RenderPath, step_vox: f64) -> RenderSettings {
    RenderSettings {
        mode: Mode::Dvr,
        strategy,
        path,
        shading: Shading::Phong,
        phong: Phong {
            ambient: 0.0,
            diffuse: 1.0,
            specular: 0.0,
            shininess: 1.0,
        },
        light: Light::Direction([1.0, 0.0, 1.0]),
        shadows: Shadows {
            on: true,
            step_vox,
            ..Shadows::default()
        },
        step_vox: 0.25,
        background: [0.0; 3],
        ..RenderSettings::default()
    }
}

/// Looking along +z at the floor through the empty right half.
fn slab_camera(volume: &Volume) -> Camera {
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    Camera::framing(
        &bounds,
        DVec3::Z,
        DVec3::NEG_Y,
        ProjectionKind::Orthographic,
    )
}

/// The pixels whose rays meet the floor at x in 36..44 and y in 3..12 (mm), away from the
/// slab's edge and the box's sides: each one's shadow ray crosses the whole slab.
fn floor_pixels(camera: &Camera, volume: &Volume, size: [u32; 2]) -> Vec<(u32, u32)> {
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let mut pixels = Vec::new();
    for py in 0..size[1] {
        for px in 0..size[0] {
            let (o, _) = camera.pixel_ray(f64::from(px), f64::from(py), size, &bounds);
            if (36.0..44.0).contains(&o.x) && (3.0..12.0).contains(&o.y) {
                pixels.push((px, py));
            }
        }
    }
    pixels
}

/// [`slab_settings`] as an isosurface at 150: the floor (and a slab of 200) its surface.
fn slab_iso(strategy: Strategy, path: RenderPath) -> RenderSettings {
    RenderSettings {
        mode: Mode::Iso,
        iso: leapview::settings::IsoSettings {
            value: Some(150.0),
            ..Default::default()
        },
        ..slab_settings(strategy, path, 1.0)
    }
}

/// The red channel of pixel `(px, py)`.
fn red_at(image: &leapview::imaging::ImageF32, (px, py): (u32, u32)) -> f64 {
    f64::from(image.pixels[(py * image.width + px) as usize][0])
}

/// How far the reference's 40 × 40 picture with `a` lies from the one with `b`: an effect the
/// GPU is checked against must change it, or the check would pass without the effect.
fn reference_change(
    (volume, tf, camera): (&Volume, &TransferFunction, &Camera),
    a: &RenderSettings,
    b: &RenderSettings,
) -> leapview::imaging::ImageDiff {
    let a = reference::render(volume, tf, camera, [40, 40], a).image;
    let b = reference::render(volume, tf, camera, [40, 40], b).image;
    a.diff(&b).expect("sizes")
}

#[test]
fn a_slab_shadows_the_floor_by_its_transmittance() {
    let size = [128, 128];
    let (with, without) = (slab_scene(true), slab_scene(false));
    let tf = slab_tf();
    let camera = slab_camera(&with);
    let pixels = floor_pixels(&camera, &with, size);
    assert!(pixels.len() > 40, "{} floor pixels", pixels.len());
    // The slab reaches 0.945 voxel past its outer voxels' centres (values above 5.5 of 100):
    // 8.89 voxels thick, crossed at 45°.
    let thickness = f64::from(SLAB_Z[1] - SLAB_Z[0]) + 1.89;
    let expected = (1.0 - SLAB_ALPHA).powf(thickness * 2f64.sqrt());
    for (strategy, path) in [
        (Strategy::RcT, RenderPath::Compute),
        (Strategy::RcS, RenderPath::Fragment),
        (Strategy::RcSDistance, RenderPath::Compute),
    ] {
        let s = slab_settings(strategy, path, 0.125);
        let lit = renderer_for(&without, &tf)
            .render_image(&camera, size, &s)
            .expect("render");
        let shadowed = renderer_for(&with, &tf)
            .render_image(&camera, size, &s)
            .expect("render");
        let mut worst = 0.0f64;
        for &(px, py) in &pixels {
            let l = red_at(&lit, (px, py));
            // The floor faces the light at 45°: at most cos = 0.71 of the white floor's colour,
            // less the floor's own first voxel shadowing the samples behind it (the same with
            // the slab: the ratio holds the slab's alone).
            assert!(
                l > 0.3 && l < 0.72,
                "{strategy:?} {path:?} ({px}, {py}): lit {l}"
            );
            let ratio = red_at(&shadowed, (px, py)) / l;
            worst = worst.max((ratio - expected).abs());
        }
        // One shadow step's depth (⅛ voxel at 45°) either way and the f16 output: 1.5 %.
        assert!(
            worst < 0.015 * expected + 2e-3,
            "{strategy:?} {path:?}: transmittance off by {worst} from {expected}"
        );
    }
}

#[test]
fn shadow_rays_match_the_reference_on_every_strategy_and_path() {
    let volume = scene::scene();
    let tf = scene::tf();
    let camera = hard::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let mut r = renderer_for(&volume, &tf);
    for light in [Light::Direction([0.6, -0.3, 0.75]), Light::Headlight] {
        let base = RenderSettings {
            light,
            shadows: Shadows {
                on: true,
                step_vox: 0.5,
                ..Shadows::default()
            },
            ..hard::settings(Mode::Dvr, Strategy::Rc, RenderPath::Compute)
        };
        let name = format!("shadows-{light:?}");
        check_reference_within(
            &mut r,
            &name,
            (&volume, &tf, &camera),
            base,
            (4.0 / 255.0, 0.0),
        );
        // Shadows change the picture: the test above would pass unshadowed images otherwise.
        let plain = RenderSettings {
            shadows: Shadows::default(),
            ..base
        };
        let d = reference_change((&volume, &tf, &camera), &base, &plain);
        assert!(d.max_abs > 0.05, "{name}: shadows change little: {d:?}");
    }
}

#[test]
fn an_isosurface_shadows_the_floor_wholly_and_matches_the_reference() {
    // The slab as part of the isosurface (value 200 as the floor's), the surface at 150.
    let volume = slab_scene_of(Some(200.0));
    let tf = slab_tf();
    let camera = slab_camera(&volume);
    let size = [128, 128];
    let pixels = floor_pixels(&camera, &volume, size);
    let mut r = renderer_for(&volume, &tf);
    let iso = slab_iso(Strategy::Rc, RenderPath::Compute);
    for (strategy, path) in hard::variants() {
        let s = |on| RenderSettings {
            strategy,
            path,
            shadows: Shadows { on, ..iso.shadows },
            ..iso
        };
        let shadowed = r.render_image(&camera, size, &s(true)).expect("render");
        let lit = r.render_image(&camera, size, &s(false)).expect("render");
        for &(px, py) in &pixels {
            // Diffuse only: cos 45° of the white floor lit, nothing in the slab's shadow.
            let (l, s) = (red_at(&lit, (px, py)), red_at(&shadowed, (px, py)));
            assert!(
                (l - 0.5f64.sqrt()).abs() < 0.02,
                "{strategy:?} {path:?}: lit {l}"
            );
            assert!(s < 1e-3, "{strategy:?} {path:?} ({px}, {py}): shadowed {s}");
        }
    }
    let camera = hard::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    hard::check_reference(&mut r, "shadows-iso", &volume, &tf, &camera, iso);
}

#[test]
fn leaping_shadow_rays_add_the_same_depth_as_plain_ones() {
    // The slab's sharp faces: the first sample past an empty node already has its opacity.
    let volume = slab_scene(true);
    let tf = slab_tf();
    let camera = hard::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let mut r = renderer_for(&volume, &tf);
    for path in PATHS {
        for step_vox in [0.125, 1.0, 4.0] {
            let s = |strategy| RenderSettings {
                strategy,
                ..slab_settings(strategy, path, step_vox)
            };
            let plain = r
                .render_image(&camera, [48, 48], &s(Strategy::RcT))
                .expect("render");
            for strategy in [Strategy::RcS, Strategy::RcSDistance] {
                let leaping = r
                    .render_image(&camera, [48, 48], &s(strategy))
                    .expect("render");
                let d = leaping.diff(&plain).expect("sizes");
                assert!(
                    d.max_abs <= 1e-6,
                    "{strategy:?} {path:?} step {step_vox}: {d:?}"
                );
            }
        }
    }
}

#[test]
fn grazing_lights_an_eye_inside_and_extreme_steps_stay_with_the_reference() {
    let volume = scene::scene();
    let tf = scene::tf();
    let outside = hard::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let centre = Aabb::of_volume(volume.dims(), volume.spacing_mm()).center();
    let inside = Camera {
        eye: centre + DVec3::new(-3.0, -2.0, 1.0),
        target: centre,
        up: DVec3::Z,
        projection: Projection::Perspective { fov_y_deg: 70.0 },
    };
    let mut r = renderer_for(&volume, &tf);
    let cases = [
        // Along an axis: parallel to four faces.
        ("axis", Light::Direction([1.0, 0.0, 0.0]), 1.0, &outside),
        // Within 1e-6 of a face.
        (
            "grazing",
            Light::Direction([1.0, 1e-7, -1e-7]),
            1.0,
            &outside,
        ),
        (
            "step-eighth",
            Light::Direction([0.3, 0.4, 0.8]),
            0.125,
            &outside,
        ),
        (
            "step-four",
            Light::Direction([0.3, 0.4, 0.8]),
            4.0,
            &outside,
        ),
        ("inside-headlight", Light::Headlight, 1.0, &inside),
        (
            "inside-direction",
            Light::Direction([0.3, 0.4, 0.8]),
            1.0,
            &inside,
        ),
    ];
    for (name, light, step_vox, camera) in cases {
        let base = RenderSettings {
            light,
            shadows: Shadows {
                on: true,
                step_vox,
                ..Shadows::default()
            },
            ..hard::settings(Mode::Dvr, Strategy::Rc, RenderPath::Compute)
        };
        check_reference_within(
            &mut r,
            &format!("shadows-{name}"),
            (&volume, &tf, camera),
            base,
            (4.0 / 255.0, 0.0),
        );
    }
}

#[test]
fn soft_shadows_follow_the_reference_frame_by_frame_and_refined() {
    let volume = scene::scene();
    let tf = scene::tf();
    let camera = hard::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let mut r = renderer_for(&volume, &tf);
    let base = RenderSettings {
        light: Light::Direction([0.6, -0.3, 0.75]),
        shadows: Shadows {
            on: true,
            softness_deg: 8.0,
            ..Shadows::default()
        },
        ..hard::settings(Mode::Dvr, Strategy::Rc, RenderPath::Compute)
    };
    // One frame: each pixel's shadow rays aim at their own point of the light.
    check_reference_within(
        &mut r,
        "shadows-soft",
        (&volume, &tf, &camera),
        base,
        (4.0 / 255.0, 0.0),
    );
    // Refined: the mean of frames at the refinement's offsets and light samples.
    let frames = 8;
    let size = [40, 40];
    for strategy in [Strategy::RcT, Strategy::RcSDistance] {
        let s = RenderSettings { strategy, ..base };
        let refined = r
            .render_refined(
                &camera,
                size,
                &s,
                leapview::render::RefineRun::frames(frames),
            )
            .expect("render");
        let mut mean = vec![[0.0f64; 4]; (size[0] * size[1]) as usize];
        for k in 0..frames {
            let frame = RenderSettings {
                sample_offset: leapview::render::raycast::refine::offset(k),
                shadows: Shadows {
                    sample: leapview::sampling::light_sample(k),
                    ..s.shadows
                },
                ..s
            };
            let image = reference::render(&volume, &tf, &camera, size, &frame).image;
            for (m, p) in mean.iter_mut().zip(&image.pixels) {
                for c in 0..4 {
                    m[c] += f64::from(p[c]) / f64::from(frames);
                }
            }
        }
        let expected = leapview::imaging::ImageF32 {
            width: size[0],
            height: size[1],
            pixels: mean.iter().map(|p| p.map(|c| c as f32)).collect(),
        };
        crate::common::assert_close(
            "shadows-soft-refined",
            &refined,
            &expected,
            4.0 / 255.0,
            0.0,
        );
        // Soft: the mean differs from the hard shadow's picture.
        let hard = RenderSettings {
            shadows: Shadows {
                softness_deg: 0.0,
                ..s.shadows
            },
            ..s
        };
        let hard = r.render_image(&camera, size, &hard).expect("render");
        assert!(refined.diff(&hard).expect("sizes").max_abs > 0.01);
    }
}

#[test]
fn shadow_knobs_out_of_range_are_refused() {
    for (step_vox, reach, softness_deg) in [
        (0.1, 1.0, 0.0),
        (4.5, 1.0, 0.0),
        (f64::NAN, 1.0, 0.0),
        (1.0, 0.0, 0.0),
        (1.0, 1.5, 0.0),
        (1.0, 1.0, -1.0),
        (1.0, 1.0, 25.0),
        (1.0, 1.0, f64::NAN),
    ] {
        let s = RenderSettings {
            shadows: Shadows {
                on: true,
                step_vox,
                reach,
                softness_deg,
                ..Shadows::default()
            },
            ..RenderSettings::default()
        };
        assert!(
            s.validate().is_err(),
            "step {step_vox}, reach {reach}, softness {softness_deg}"
        );
    }
    let data = crate::common::data_dir().join("ct_engine_256x256x128_uint8.nrrd");
    let out = crate::common::leapview(&[
        "render",
        data.to_str().expect("utf-8"),
        "--shadows",
        "on",
        "--shadow-step",
        "9",
        "-o",
        "/tmp/leapview-shadow-refused.png",
    ]);
    let err = crate::common::stderr(&out);
    assert!(
        !out.status.success() && err.contains("shadow step"),
        "{err}"
    );
}

#[test]
fn ambient_occlusion_matches_the_reference_in_dvr_and_isosurfaces() {
    let volume = scene::scene();
    let tf = scene::tf();
    let camera = hard::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let mut r = renderer_for(&volume, &tf);
    let occluded = leapview::settings::Occlusion {
        on: true,
        radius_vox: 5.0,
    };
    // Jittered starts turn each pixel's rays differently.
    for (mode, jitter) in [(Mode::Dvr, false), (Mode::Dvr, true), (Mode::Iso, true)] {
        let base = RenderSettings {
            occlusion: occluded,
            jitter,
            iso: leapview::settings::IsoSettings {
                value: Some(450.0),
                ..Default::default()
            },
            ..hard::settings(mode, Strategy::Rc, RenderPath::Compute)
        };
        let name = format!("occlusion-{mode:?}-{jitter}");
        if mode == Mode::Iso {
            hard::check_reference(&mut r, &name, &volume, &tf, &camera, base);
        } else {
            check_reference_within(
                &mut r,
                &name,
                (&volume, &tf, &camera),
                base,
                (4.0 / 255.0, 0.0),
            );
        }
        let open = RenderSettings {
            occlusion: leapview::settings::Occlusion::default(),
            ..base
        };
        let d = reference_change((&volume, &tf, &camera), &base, &open);
        assert!(d.max_abs > 0.02, "{name}: occlusion changes little: {d:?}");
    }
}

#[test]
fn an_open_floor_is_unoccluded() {
    // The isosurface's floor lit by the ambient term alone: 1 where nothing lies within the
    // rays' reach (the slab hangs 20 voxels above).
    let volume = slab_scene_of(Some(200.0));
    let tf = slab_tf();
    let camera = slab_camera(&volume);
    let size = [128, 128];
    let pixels = floor_pixels(&camera, &volume, size);
    let mut r = renderer_for(&volume, &tf);
    let s = RenderSettings {
        phong: Phong {
            ambient: 1.0,
            diffuse: 0.0,
            specular: 0.0,
            shininess: 1.0,
        },
        occlusion: leapview::settings::Occlusion {
            on: true,
            radius_vox: 4.0,
        },
        ..slab_iso(Strategy::RcSDistance, RenderPath::Compute)
    };
    let image = r.render_image(&camera, size, &s).expect("render");
    for &(px, py) in &pixels {
        let v = red_at(&image, (px, py));
        assert!((v - 1.0).abs() < 2e-3, "({px}, {py}): {v}");
    }
}
