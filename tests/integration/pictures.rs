//! What a file asks the picture to be, drawn on the GPU and checked against the f64 reference or
//! the samples themselves: a colour volume in its own colours (3D and slices), a float volume
//! whose every other slice is NaN (the finite slices stay), and a MONOCHROME1 image's inverted
//! grey (the values unchanged).

use crate::common;

use common::{check_reference_within, colour_ramp, framing, renderer_for, settings};
use glam::DVec3;
use leapview::camera::{ProjectionKind, ViewPreset};
use leapview::mpr::{PatientFrame, Plane, PlaneKind, SliceView};
use leapview::render::slice::{LabelLook, SliceLook, SliceRenderer};
use leapview::render::volume_texture::VolumeTexture;
use leapview::settings::effects::{IsoSettings, Shading};
use leapview::settings::{Mode, RenderPath, RenderSettings, Strategy};
use leapview::transfer::{TransferFunction, ValueSpace};
use leapview::volume::{Colour, Provenance, Samples, ValueMapping, Volume};

const DIMS: [u32; 3] = [16, 14, 12];

/// A ball whose colour runs red to green along x and carries blue along z, in a dark box: a
/// colour volume whose luminance is the ball.
fn colour_ball() -> Volume {
    let mut channels: [Vec<u8>; 3] = Default::default();
    for z in 0..DIMS[2] {
        for y in 0..DIMS[1] {
            for x in 0..DIMS[0] {
                let p = DVec3::new(f64::from(x), f64::from(y), f64::from(z));
                let inside = (p - DVec3::new(7.5, 6.5, 5.5)).length() < 5.0;
                let (r, g, b) = if inside {
                    (255 - 15 * x as u8, 60 + 12 * x as u8, 20 * z as u8)
                } else {
                    (4, 4, 4)
                };
                channels[0].push(r);
                channels[1].push(g);
                channels[2].push(b);
            }
        }
    }
    let [r, g, b] = channels;
    let colour = Colour::new([Samples::U8(r), Samples::U8(g), Samples::U8(b)], 8).expect("equal");
    Volume::new_colour("colour ball", DIMS, [1.0, 1.1, 1.3], colour).expect("volume")
}

/// Opacity on luminance above the box's grey; its colours are never shown for a colour volume.
fn luminance_opacity() -> TransferFunction {
    TransferFunction {
        opacity: vec![[0.0, 0.0], [20.0, 0.0], [60.0, 0.4], [255.0, 0.6]],
        color: vec![[0.0, 0.0, 0.0, 1.0], [255.0, 0.0, 0.0, 1.0]],
        space: ValueSpace::Data,
    }
}

#[test]
fn a_colour_volume_shows_its_own_colours_in_dvr_and_isosurfaces() {
    let volume = colour_ball();
    let tf = luminance_opacity();
    let mut r = renderer_for(&volume, &tf);
    let camera = framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    for (mode, shading) in [
        (Mode::Dvr, Shading::Off),
        (Mode::Dvr, Shading::Phong),
        (Mode::Iso, Shading::Phong),
    ] {
        let base = RenderSettings {
            shading,
            iso: IsoSettings {
                value: Some(60.0),
                refine_iterations: 4,
            },
            ..settings(mode, Strategy::RcT, RenderPath::Compute)
        };
        // The texture unit blends the 8-bit colour channels at 8-bit precision (lavapipe
        // truncates the blend to 1/255), the reference in f64: a lit colour may differ by two
        // levels at a few pixels; isosurfaces may flip 0.5 % where a ray grazes the surface.
        let bounds = if mode == Mode::Iso {
            (1.0, 0.02)
        } else {
            (3.0 / 255.0, 0.02)
        };
        check_reference_within(
            &mut r,
            &format!("colour-{}-{shading:?}", mode.label()),
            (&volume, &tf, &camera),
            base,
            bounds,
        );
    }
    // Not the transfer function's pure blue: the ball's greens show through the background's
    // blue-grey.
    let image = r
        .render_image(
            &camera,
            [40, 40],
            &settings(Mode::Dvr, Strategy::RcT, RenderPath::Compute),
        )
        .expect("render");
    let centre = image.pixels[20 * 40 + 20];
    assert!(centre[1] > centre[2] + 0.1, "centre {centre:?}");
}

fn axial_view(volume: &Volume) -> (PatientFrame, SliceView) {
    let frame = PatientFrame::of(volume);
    let view = SliceView::fit(
        Plane::standard(PlaneKind::Axial, frame.centre()),
        &frame,
        None,
    );
    (frame, view)
}

fn look(window: [f64; 2], invert: bool) -> SliceLook {
    SliceLook {
        window,
        nearest: true,
        slab: None,
        leap: false,
        colour: false,
        invert,
        labels: LabelLook::default(),
    }
}

#[test]
fn a_colour_volume_slices_in_its_own_colours() {
    let ctx = common::gpu();
    let volume = colour_ball();
    let texture = VolumeTexture::upload(&ctx, &volume).expect("upload");
    assert_eq!(texture.encoding.format, wgpu::TextureFormat::Rgba8Unorm);
    let renderer = SliceRenderer::new(&ctx.device).expect("renderer");
    let (frame, view) = axial_view(&volume);
    let rgb = renderer
        .render_display(
            &ctx,
            &volume,
            &texture,
            None,
            None,
            None,
            &view,
            look([0.0, 255.0], false),
        )
        .expect("slice");
    // Every pixel that shows a voxel (nearest) shows that voxel's colour.
    let mut checked = 0;
    for (i, pixel) in rgb.iter().enumerate() {
        let p = view.to_patient(glam::DVec2::new(
            (i % view.size[0] as usize) as f64 + 0.5,
            (i / view.size[0] as usize) as f64 + 0.5,
        ));
        let Some([x, y, z]) = frame.voxel_index(frame.to_voxel(p)) else {
            continue;
        };
        let expected = volume.colour().expect("colour").rgb8(volume.index(x, y, z));
        let close = pixel.iter().zip(expected).all(|(a, b)| a.abs_diff(b) <= 1);
        assert!(
            close,
            "pixel {i}: {pixel:?}, voxel ({x}, {y}, {z}) is {expected:?}"
        );
        checked += 1;
    }
    assert!(checked > 100, "{checked} pixels showed the volume");
}

/// Every other slice NaN: interpolation used to let a NaN voxel erase its finite neighbours, and
/// the volume rendered blank. Now a sample takes its value from the finite voxels nearest it.
#[test]
fn every_other_slice_nan_leaves_the_finite_slices_visible() {
    let mut v = Vec::new();
    for z in 0..DIMS[2] {
        for y in 0..DIMS[1] {
            for x in 0..DIMS[0] {
                v.push(if z % 2 == 1 {
                    f32::NAN
                } else {
                    (100 + 40 * x + 7 * y) as f32
                });
            }
        }
    }
    let volume = Volume::new(
        "striped",
        DIMS,
        [1.0; 3],
        Samples::F32(v),
        ValueMapping::IDENTITY,
    )
    .expect("volume");
    let tf = colour_ramp(100.0, 800.0, 0.4);
    let mut r = renderer_for(&volume, &tf);
    for view in [ViewPreset::PlusX, ViewPreset::Oblique] {
        let camera = framing(&volume, view, ProjectionKind::Perspective);
        for mode in [Mode::Dvr, Mode::Mip, Mode::Iso] {
            let base = RenderSettings {
                iso: IsoSettings {
                    value: Some(300.0),
                    refine_iterations: 4,
                },
                ..settings(mode, Strategy::RcT, RenderPath::Compute)
            };
            // A sample where finite and NaN voxels weigh half each flips between a value and
            // missing as f32 and f64 positions round apart: a few pixels along the slabs' faces
            // (isosurfaces also flip where a ray grazes the surface).
            check_reference_within(
                &mut r,
                &format!("striped-{view:?}-{}", mode.label()),
                (&volume, &tf, &camera),
                base,
                (0.25, 0.02),
            );
        }
        let image = r
            .render_image(
                &camera,
                [40, 40],
                &settings(Mode::Dvr, Strategy::RcT, RenderPath::Compute),
            )
            .expect("render");
        let background = common::BACKGROUND.map(|c| c as f32);
        let shown = image
            .pixels
            .iter()
            .filter(|p| (0..3).any(|c| (p[c] - background[c]).abs() > 0.05))
            .count();
        assert!(
            shown > 200,
            "{view:?}: {shown} of 1600 pixels show the volume"
        );
    }
    // A slice through a NaN slice's middle shows nothing; a quarter voxel from a finite one,
    // that slice's values.
    let ctx = common::gpu();
    let texture = VolumeTexture::upload(&ctx, &volume).expect("upload");
    let renderer = SliceRenderer::new(&ctx.device).expect("renderer");
    let frame = PatientFrame::of(&volume);
    for (z, finite) in [(1.0, false), (1.75, true), (2.2, true)] {
        let at = frame.to_patient(DVec3::new(5.0, 5.0, z));
        let view = SliceView::fit(Plane::standard(PlaneKind::Axial, at), &frame, None);
        let image = renderer
            .render(
                &ctx,
                &volume,
                &texture,
                None,
                &view,
                SliceLook {
                    nearest: false,
                    ..look([100.0, 800.0], false)
                },
            )
            .expect("slice");
        let values = image.values.iter().filter(|v| v.is_finite()).count();
        assert_eq!(values > 0, finite, "z {z}: {values} finite pixels");
    }
}

#[test]
fn monochrome1_grey_is_inverted_and_its_values_are_not() {
    let ctx = common::gpu();
    let samples: Vec<u16> = (0..DIMS[0] * DIMS[1] * DIMS[2])
        .map(|i| (i % 200) as u16)
        .collect();
    let volume = Volume::new(
        "cr",
        DIMS,
        [1.0; 3],
        Samples::U16(samples),
        ValueMapping::IDENTITY,
    )
    .expect("volume")
    .with_provenance(Provenance {
        invert_grey: true,
        ..Provenance::default()
    });
    let texture = VolumeTexture::upload(&ctx, &volume).expect("upload");
    let renderer = SliceRenderer::new(&ctx.device).expect("renderer");
    let (_, view) = axial_view(&volume);
    let window = [0.0, 199.0];
    let plain = renderer
        .render(&ctx, &volume, &texture, None, &view, look(window, false))
        .expect("slice");
    let inverted = renderer
        .render(&ctx, &volume, &texture, None, &view, look(window, true))
        .expect("slice");
    assert_eq!(plain.values, inverted.values, "the values are the file's");
    let mut compared = 0;
    for ((a, b), v) in plain.grey.iter().zip(&inverted.grey).zip(&plain.values) {
        if v.is_finite() {
            assert_eq!(
                u16::from(*a) + u16::from(*b),
                255,
                "value {v}: grey {a} and {b}"
            );
            compared += 1;
        }
    }
    assert!(compared > 100);
}
