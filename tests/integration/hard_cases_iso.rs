//! Hard isosurfaces and lighting (issue 7, item 5): iso values at the data minimum, the
//! maximum and a plateau, and zero gradients in the lit modes. The background where no ray may
//! cross, lighting that changes nothing where the gradient vanishes, the f64 reference
//! elsewhere; every strategy and both paths; no pixel may be NaN or infinite.

use crate::common;

use common::{check_reference, colour_ramp, framing, renderer_for, settings, variants};
use glam::DVec3;
use leapview::camera::{Aabb, Camera, ProjectionKind, ViewPreset};
use leapview::reference;
use leapview::settings::effects::{IsoSettings, Shading};
use leapview::settings::{Mode, RenderPath, RenderSettings, Strategy};
use leapview::volume::{Samples, ValueMapping, Volume, synthetic};

/// 16-bit terraces: a floor of 100 (the minimum), a box of 2000 (a plateau) holding a smaller
/// box of 4000 (the maximum), with sharp edges.
fn terraces() -> Volume {
    let dims = [14u32, 12, 10];
    let mut v = Vec::new();
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let inside = |lo: u32, hi: u32| [x, y, z].iter().all(|c| (lo..hi).contains(c));
                v.push(if inside(4, 7) {
                    4000u16
                } else if inside(2, 9) {
                    2000
                } else {
                    100
                });
            }
        }
    }
    Volume::new(
        "terraces",
        dims,
        [1.0, 1.1, 1.3],
        Samples::U16(v),
        ValueMapping::IDENTITY,
    )
    .expect("valid")
}

#[test]
fn iso_values_at_the_minimum_the_maximum_and_a_plateau() {
    let volume = terraces();
    let tf = colour_ramp(100.0, 4000.0, 0.5);
    let mut r = renderer_for(&volume, &tf);
    let camera = framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    let iso = |value: f64, shading| RenderSettings {
        iso: IsoSettings {
            value: Some(value),
            refine_iterations: 4,
        },
        shading,
        ..settings(Mode::Iso, Strategy::Rc, RenderPath::Compute)
    };
    // At the minimum every sample is at or above the iso value from the entry on: no crossing,
    // the background everywhere (bit for bit the pixel of a ray that misses the volume).
    for (strategy, path) in variants() {
        for shading in [Shading::Off, Shading::Phong] {
            let s = RenderSettings {
                strategy,
                path,
                ..iso(100.0, shading)
            };
            let image = r.render_image(&camera, [40, 40], &s).expect("render");
            let bg = image.get(0, 0);
            let name = format!("iso-min-{}-{path:?}-{shading:?}", strategy.label());
            common::assert_all_finite(&name, &image);
            let off = image.pixels.iter().filter(|p| **p != bg).count();
            assert_eq!(off, 0, "{name}: {off} pixels show a surface");
        }
    }
    // At the maximum the surface is the 4000 box's; at 2000 the plateau's.
    for value in [4000.0, 2000.0] {
        for shading in [Shading::Off, Shading::Phong] {
            let name = format!("iso-{value}-{shading:?}");
            check_reference(&mut r, &name, &volume, &tf, &camera, iso(value, shading));
        }
    }
}
#[test]
fn zero_gradients_leave_lit_modes_unlit() {
    // A constant volume: every gradient is exactly zero, so lighting changes no bit, in DVR
    // and in an isosurface at the constant (which no ray crosses: the background).
    let volume = synthetic::constant([9, 7, 5], [1.0, 0.5, 2.0], 40.0).expect("valid");
    let mut r = renderer_for(&volume, &common::uniform_tf(0.2, [0.9, 0.5, 0.1]));
    let camera = framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    for mode in [Mode::Dvr, Mode::Iso] {
        for (strategy, path) in variants() {
            let lit = RenderSettings {
                iso: IsoSettings {
                    value: Some(40.0),
                    refine_iterations: 4,
                },
                ..settings(mode, strategy, path)
            };
            let unlit = RenderSettings {
                shading: Shading::Off,
                ..lit
            };
            let a = r.render_image(&camera, [32, 32], &lit).expect("render");
            let b = r.render_image(&camera, [32, 32], &unlit).expect("render");
            common::assert_all_finite("zero-gradient", &a);
            assert_eq!(
                a, b,
                "constant, {mode:?} {strategy:?} {path:?}: lighting changed it"
            );
            if mode == Mode::Iso {
                assert!(a.pixels.iter().all(|p| *p == a.get(0, 0)), "no crossing");
            }
        }
    }
    // An isosurface whose hits lie where the gradient vanishes: values alternating 0, 1000,
    // 0, … along x (constant along y and z), iso 400. Voxels two apart are equal, so the central
    // differences are zero wherever both reads stay inside the volume (not within a voxel of an
    // x face). Seen mostly along y, the first crossings lie in the interior; the reference leaves
    // them unlit, and the GPU must too. Eight voxels across x, so that the reads one voxel either
    // side, at p ± 1/8 in texture coordinates, are exact in f32: with nine (±1/9, inexact) the
    // two reads round differently into the texture unit's 8-bit weights, 6.5 % of the hits get a
    // gradient of filter noise (a 1/256 step of the 0–1000 contrast) and lighting turns it into
    // a full normal. That is a precision limit of hardware filtering, not of this code.
    let alternating = Volume::new(
        "alternating",
        [8, 6, 4],
        [1.0; 3],
        Samples::F32(
            (0..8 * 6 * 4)
                .map(|i| if i % 8 % 2 == 1 { 1000.0 } else { 0.0 })
                .collect(),
        ),
        ValueMapping::IDENTITY,
    )
    .expect("valid");
    let tf = colour_ramp(0.0, 1000.0, 0.5);
    r.set_volume(&alternating).expect("upload");
    r.set_transfer_function(&tf);
    let bounds = Aabb::of_volume(alternating.dims(), alternating.spacing_mm());
    let dir = DVec3::new(0.35, 1.0, -0.3);
    let camera = Camera::framing(&bounds, dir, DVec3::Z, ProjectionKind::Perspective);
    let lit = RenderSettings {
        iso: IsoSettings {
            value: Some(400.0),
            refine_iterations: 4,
        },
        ..settings(Mode::Iso, Strategy::RcT, RenderPath::Compute)
    };
    let unlit = RenderSettings {
        shading: Shading::Off,
        ..lit
    };
    let reference_lit = reference::render(&alternating, &tf, &camera, [40, 40], &lit).image;
    let reference_unlit = reference::render(&alternating, &tf, &camera, [40, 40], &unlit).image;
    let bg = reference_lit.get(0, 0);
    let flat = (reference_lit.pixels.iter().zip(&reference_unlit.pixels))
        .filter(|(a, b)| a == b && **a != bg)
        .count();
    assert!(flat > 200, "only {flat} hits with a zero gradient");
    check_reference(&mut r, "zero-gradient-iso", &alternating, &tf, &camera, lit);
}
