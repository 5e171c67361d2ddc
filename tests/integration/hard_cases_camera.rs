//! Hard cameras (issue 7, item 5): the eye inside the volume, exactly on a face, an edge or a
//! corner, rays parallel to each axis, rays grazing a face, the eye 10⁶ mm away and 10⁻⁶ mm away.
//! The volume holds one value, so every mode has an analytic answer that depends only on each
//! ray's path length through the box (`common::Uniform`); every case runs every mode, strategy and
//! path, and no pixel may be NaN or infinite.

use crate::common;

use common::Uniform;
use glam::DVec3;
use leapview::camera::{Aabb, Camera, Projection, ProjectionKind, ViewPreset};
use leapview::reference;
use leapview::render::VolumeRenderer;
use leapview::settings::effects::IsoSettings;
use leapview::settings::{Mode, RenderSettings, Strategy};
use leapview::transfer::{TransferFunction, ValueSpace};
use leapview::volume::{Samples, ValueMapping, Volume, synthetic};

const DIMS: [u32; 3] = [12, 10, 8];
/// Anisotropic, so a swapped axis changes path lengths; d0 = 0.75 mm.
const SPACING: [f64; 3] = [1.0, 1.5, 0.75];
const UNIFORM: Uniform = Uniform {
    alpha: 0.05,
    rgb: [1.0, 0.6, 0.2],
    d0_mm: 0.75,
    // The window of `common::uniform_settings` puts the value in its middle.
    windowed: 0.5,
};

fn volume() -> Volume {
    synthetic::constant(DIMS, SPACING, common::UNIFORM_VALUE).expect("valid")
}

fn bounds() -> Aabb {
    Aabb::of_volume(DIMS, SPACING)
}

fn renderer() -> VolumeRenderer {
    let mut r = common::renderer();
    r.set_volume(&volume()).expect("upload");
    r.set_transfer_function(&common::uniform_tf(UNIFORM.alpha, UNIFORM.rgb));
    r
}

/// A look-at camera with +z up (the view matrix picks another up when looking along z).
fn look(eye: DVec3, target: DVec3, projection: Projection) -> Camera {
    Camera {
        eye,
        target,
        up: DVec3::Z,
        projection,
    }
}

/// How far (pixels) around each pixel centre the analytic answer is also accepted: a sixteenth of
/// a pixel, far more than the f32 ray set-up moves a ray (a few 10⁻⁶ of the view at most, except
/// from 10⁶ mm), far less than the distance over which a silhouette crosses a pixel. Where the
/// answer changes within this reach (a silhouette, a face the ray grazes), any value between
/// the answers passes.
const REACH: f64 = 1.0 / 16.0;

const WIDE: Projection = Projection::Perspective { fov_y_deg: 60.0 };

/// Renders `camera` in every mode, strategy and path and checks each image against the
/// analytic answer at every pixel's footprint of ±`reach` pixels.
fn check(r: &mut VolumeRenderer, name: &str, camera: &Camera, size: [u32; 2], reach: f64) {
    let lengths = common::footprint_lengths(camera, &bounds(), size, reach);
    let (mut straddling, mut worst) = (0, 0.0f64);
    for mode in Mode::ALL {
        for strategy in Strategy::ALL {
            for path in common::PATHS {
                let settings = common::uniform_settings(mode, strategy, path);
                let image = r
                    .render_image(camera, size, &settings)
                    .unwrap_or_else(|e| panic!("{name} {settings:?}: {e}"));
                let (s, w) = common::assert_within_footprint(
                    &format!(
                        "camera-{name}-{}-{}-{path:?}",
                        mode.label(),
                        strategy.label()
                    ),
                    &image,
                    common::ANALYTIC_TOLERANCE,
                    |px, py| {
                        lengths[(py * size[0] + px) as usize].map(|l| UNIFORM.pixel(&settings, l))
                    },
                );
                straddling += s;
                worst = worst.max(w);
            }
        }
    }
    eprintln!("{name}: largest deviation {worst:.1e}; {straddling} pixels straddled an edge");
}

#[test]
fn eye_inside_the_volume() {
    let mut r = renderer();
    let c = bounds().center();
    let oblique = DVec3::new(1.0, 0.3, 0.2);
    let ortho = Projection::Orthographic { height_mm: 8.0 };
    check(
        &mut r,
        "inside-perspective",
        &look(c, c + oblique, WIDE),
        [40, 40],
        REACH,
    );
    check(
        &mut r,
        "inside-orthographic",
        &look(c, c + oblique, ortho),
        [40, 40],
        REACH,
    );
    // Off-centre, looking straight down −y: axis-parallel rays that start inside.
    let eye = DVec3::new(2.0, 9.0, 1.0);
    check(
        &mut r,
        "inside-along-y",
        &look(eye, eye - DVec3::Y, WIDE),
        [41, 41],
        REACH,
    );
}

#[test]
fn eye_on_a_face_an_edge_and_a_corner() {
    let mut r = renderer();
    let b = bounds();
    let c = b.center();
    let face = DVec3::new(b.min.x, c.y, c.z);
    check(
        &mut r,
        "face-looking-in",
        &look(face, c, WIDE),
        [40, 40],
        REACH,
    );
    let off_face = DVec3::new(b.min.x, 3.0, 1.0);
    check(
        &mut r,
        "face-oblique",
        &look(off_face, c, WIDE),
        [40, 40],
        REACH,
    );
    // Looking out of the volume from its face: nothing but background.
    let out = look(face, face - DVec3::new(1.0, 0.2, 0.1), WIDE);
    check(&mut r, "face-looking-out", &out, [24, 24], REACH);
    // Along the face: half the rays run inside the face plane's neighbourhood.
    let along = look(face, face + DVec3::new(0.0, 1.0, 0.3), WIDE);
    check(&mut r, "face-looking-along", &along, [40, 40], REACH);
    let edge = DVec3::new(b.min.x, b.min.y, c.z);
    check(&mut r, "edge", &look(edge, c, WIDE), [40, 40], REACH);
    check(&mut r, "corner-min", &look(b.min, c, WIDE), [40, 40], REACH);
    check(&mut r, "corner-max", &look(b.max, c, WIDE), [40, 40], REACH);
}

#[test]
fn rays_parallel_to_each_axis() {
    let mut r = renderer();
    let b = bounds();
    for preset in [
        ViewPreset::PlusX,
        ViewPreset::MinusX,
        ViewPreset::PlusY,
        ViewPreset::MinusY,
        ViewPreset::PlusZ,
        ViewPreset::MinusZ,
    ] {
        let (dir, up) = preset.direction_and_up();
        for kind in [ProjectionKind::Orthographic, ProjectionKind::Perspective] {
            // An odd size puts the middle pixel's ray on the axis through the centre.
            let camera = Camera::framing(&b, dir, up, kind);
            check(
                &mut r,
                &format!("{preset:?}-{kind:?}"),
                &camera,
                [33, 33],
                REACH,
            );
        }
    }
}

#[test]
fn rays_grazing_a_face() {
    let mut r = renderer();
    let b = bounds();
    let c = b.center();
    // Orthographic along +x, 33 rows: a view (33/32)·extent_z tall puts the centres of the first
    // and last rows exactly in the planes of the two z faces.
    let height_mm = b.size().z * 33.0 / 32.0;
    let ortho = look(
        c - DVec3::X * 40.0,
        c,
        Projection::Orthographic { height_mm },
    );
    check(&mut r, "ortho-rows-on-faces", &ortho, [33, 33], REACH);
    // Perspective with the eye in the plane of the top face, outside the box: the middle row
    // runs inside that plane, the rows below it enter at ever smaller angles.
    let eye = DVec3::new(b.min.x - 20.0, c.y, b.max.z);
    let grazing = look(eye, DVec3::new(c.x, c.y, b.max.z), WIDE);
    check(
        &mut r,
        "perspective-in-face-plane",
        &grazing,
        [33, 33],
        REACH,
    );
}

#[test]
fn eye_very_far_and_very_near() {
    let mut r = renderer();
    let b = bounds();
    let c = b.center();
    let dir = DVec3::new(1.0, 0.7, -0.4).normalize();
    let far = 1e6;
    // A field of view that frames the box from 10⁶ mm away.
    let fov_y_deg = 2.0 * (1.1 * b.radius() / far).atan().to_degrees();
    let perspective = look(c - dir * far, c, Projection::Perspective { fov_y_deg });
    // The f32 ray set-up loses digits in proportion to the distance: 10⁶ mm in f32 is good to
    // 0.06 mm, a tenth of a pixel here (0.6 mm per pixel), so the footprint is an eighth.
    check(&mut r, "far-perspective", &perspective, [40, 40], 0.125);
    let height_mm = 2.2 * b.radius();
    let ortho = look(c - dir * far, c, Projection::Orthographic { height_mm });
    check(&mut r, "far-orthographic", &ortho, [40, 40], 0.125);
    // 10⁻⁶ mm in front of the x = min face, looking in; then 10⁻⁶ mm behind it.
    for (name, dx) in [("near-outside", -1e-6), ("near-inside", 1e-6)] {
        let eye = DVec3::new(b.min.x + dx, c.y, c.z);
        check(&mut r, name, &look(eye, c, WIDE), [40, 40], REACH);
    }
}

/// A ball and an off-centre cube on the same box, so that sampling positions matter.
fn structured() -> Volume {
    let mut v = Vec::new();
    for z in 0..DIMS[2] {
        for y in 0..DIMS[1] {
            for x in 0..DIMS[0] {
                let p = DVec3::new(x as f64, y as f64, z as f64) * DVec3::from_array(SPACING);
                let ball = 700.0 * (1.0 - (p - bounds().center()).length() / 7.0).clamp(0.0, 1.0);
                let cube = if x < 4 && y < 4 && z < 3 { 900.0 } else { 0.0 };
                v.push((100.0 + ball + cube) as f32);
            }
        }
    }
    Volume::new(
        "structured",
        DIMS,
        SPACING,
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

#[test]
fn structured_volume_from_the_boundary_matches_the_reference() {
    let volume = structured();
    let tf = TransferFunction {
        opacity: vec![[100.0, 0.0], [300.0, 0.05], [1000.0, 0.4]],
        color: vec![
            [100.0, 0.3, 0.5, 1.0],
            [600.0, 1.0, 0.6, 0.3],
            [1000.0, 1.0, 1.0, 0.9],
        ],
        space: ValueSpace::Data,
    };
    let mut r = common::renderer();
    r.set_volume(&volume).expect("upload");
    r.set_transfer_function(&tf);
    let b = bounds();
    let c = b.center();
    let mut worst = 0.0f64;
    let cameras = [
        ("inside", look(c, c + DVec3::new(1.0, 0.3, 0.2), WIDE)),
        ("face", look(DVec3::new(b.min.x, 3.0, 1.0), c, WIDE)),
        ("edge", look(DVec3::new(b.min.x, b.min.y, c.z), c, WIDE)),
        ("corner", look(b.max, c, WIDE)),
    ];
    for (name, camera) in cameras {
        for mode in Mode::ALL {
            let settings = RenderSettings {
                mode,
                strategy: Strategy::RcT,
                iso: IsoSettings {
                    value: Some(500.0),
                    ..IsoSettings::default()
                },
                window: Some([100.0, 1000.0]),
                ..RenderSettings::default()
            };
            let expected = reference::render(&volume, &tf, &camera, [40, 40], &settings).image;
            for strategy in Strategy::ALL {
                for path in common::PATHS {
                    let settings = RenderSettings {
                        strategy,
                        path,
                        ..settings
                    };
                    let image = r
                        .render_image(&camera, [40, 40], &settings)
                        .expect("render");
                    // modes.rs's bounds: 4/255 (lookup table, f16 output; measured here at
                    // most 2.2e-3, RC included, which the reference's RC-t differs from by under
                    // 1/255); isosurfaces may flip up to 0.5 % of pixels where a ray grazes the
                    // surface (none seen).
                    let (max_abs, share) = if mode == Mode::Iso {
                        (1.0, 0.005)
                    } else {
                        (4.0 / 255.0, 0.0)
                    };
                    let d = common::assert_close(
                        &format!(
                            "camera-ref-{name}-{}-{}-{path:?}",
                            mode.label(),
                            strategy.label()
                        ),
                        &image,
                        &expected,
                        max_abs,
                        share,
                    );
                    worst = worst.max(d.max_abs);
                }
            }
        }
    }
    eprintln!("largest difference from the reference: {worst:.1e}");
}
