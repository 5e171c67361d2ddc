//! Slice views on the shared scans (written by other software): the slab bricks against a
//! brute-force min/max, leaping slabs against slabs that take every sample, and the window's
//! display variant (the texture unit's trilinear) against the exact variant.

use crate::common;

use glam::DVec3;
use leapview::mpr::{PatientFrame, Plane, PlaneKind, Slab, SlabMode, SliceView};
use leapview::render::gpu_data::SLAB_BRICK;
use leapview::render::slice::{LabelLook, SliceLook, SliceRenderer};
use leapview::render::volume_texture::{VolumeTexture, texel_units};
use leapview::volume::{Volume, load_volume};

/// A sparse angiogram (uint8), a dense CT (uint16) and an int16 CTA: every unorm encoding.
const SCANS: [&str; 3] = [
    "cta_avm_337x319x154_uint8.nrrd",
    "ct_head_cthead_256x256x113_uint16.nrrd",
    "cta_stent_128x128x256_int16.nrrd",
];

fn load(name: &str) -> Volume {
    load_volume(&common::data_dir().join(name), &Default::default())
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Axial, coronal and an oblique plane through a point off the centre, 96 x 80 pixels.
fn views(frame: &PatientFrame) -> Vec<SliceView> {
    let at = frame.centre() + DVec3::new(3.1, -2.7, 1.9);
    let oblique = Plane::with_normal([0.3, -0.5, 0.8], at).expect("plane");
    [
        Plane::standard(PlaneKind::Axial, at),
        Plane::standard(PlaneKind::Coronal, at),
        oblique,
    ]
    .into_iter()
    .map(|p| SliceView::fit(p, frame, Some([96, 80])))
    .collect()
}

fn window_of(v: &Volume) -> [f64; 2] {
    let r = v.value_range().expect("values");
    [
        r.min + 0.13 * (r.max - r.min),
        r.min + 0.71 * (r.max - r.min),
    ]
}

#[test]
fn slab_bricks_hold_the_min_and_max_of_their_voxels_extended_by_one() {
    let ctx = common::gpu();
    let renderer = SliceRenderer::new(&ctx.device).expect("pipeline");
    for name in SCANS {
        let v = load(name);
        let texture = VolumeTexture::upload(&ctx, &v).expect("upload");
        let (_, scale, bias) = texel_units(&v, texture.encoding.format);
        let bricks = renderer
            .bricks_of(&ctx, &v, &texture)
            .expect("bricks")
            .read(&ctx)
            .expect("read");
        let dims = v.dims();
        let b_vox = SLAB_BRICK;
        let nodes = dims.map(|d| d.div_ceil(b_vox));
        assert_eq!(bricks.len(), nodes.iter().product::<u32>() as usize);
        let mut checked = 0;
        // Every 7th brick, brute force over its voxels extended by one on every side.
        for (index, got) in bricks.iter().enumerate().step_by(7) {
            let i = index as u32;
            let b = [
                i % nodes[0],
                (i / nodes[0]) % nodes[1],
                i / (nodes[0] * nodes[1]),
            ];
            let lo = b.map(|n| (n * b_vox).saturating_sub(1));
            let hi: [u32; 3] = std::array::from_fn(|a| ((b[a] + 1) * b_vox).min(dims[a] - 1));
            let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for x in lo[0]..=hi[0] {
                        let value = v.value(x, y, z);
                        min = min.min(value);
                        max = max.max(value);
                    }
                }
            }
            for (u, want) in [(got[0], min), (got[1], max)] {
                let value = f64::from(u) * scale + bias;
                assert!(
                    (value - want).abs() <= 1e-4 * want.abs().max(1.0),
                    "{name}: brick {b:?} holds {value}, its voxels {want}"
                );
            }
            checked += 1;
        }
        assert!(checked > 1000, "{name}: {checked} bricks checked");
    }
}

#[test]
fn leaping_slabs_equal_slabs_that_take_every_sample() {
    let ctx = common::gpu();
    let renderer = SliceRenderer::new(&ctx.device).expect("pipeline");
    for name in SCANS {
        let v = load(name);
        let texture = VolumeTexture::upload(&ctx, &v).expect("upload");
        let bricks = renderer.bricks_of(&ctx, &v, &texture).expect("bricks");
        let frame = PatientFrame::of(&v);
        // f32 rounding of the texel units u (up to 65535): what two sums may part by.
        let (texel_max, scale, _) = texel_units(&v, texture.encoding.format);
        let rounding = 1e-5 * (texel_max * scale).abs();
        for mode in [SlabMode::Mip, SlabMode::MinIp, SlabMode::Mean] {
            for (k, view) in views(&frame).iter().enumerate() {
                let look = SliceLook {
                    window: window_of(&v),
                    nearest: k == 1,
                    slab: Some(Slab {
                        thickness_mm: 21.0 + k as f64,
                        mode,
                    }),
                    leap: true,
                    colour: false,
                    invert: false,
                    labels: LabelLook::default(),
                };
                let leaping = renderer
                    .render(&ctx, &v, &texture, Some(&bricks), view, look)
                    .expect("slab");
                let every = renderer
                    .render(&ctx, &v, &texture, None, view, look)
                    .expect("slab");
                let off = every
                    .values
                    .iter()
                    .zip(&leaping.values)
                    .fold(0.0f64, |w, (a, b)| {
                        assert_eq!(a.is_nan(), b.is_nan(), "{name} {mode:?} view {k}");
                        if a.is_nan() {
                            w
                        } else {
                            w.max(f64::from((a - b).abs()))
                        }
                    });
                // MIP and MinIP take the same samples where they can matter: equal bit for
                // bit. The mean adds constant bricks in one product: rounding only.
                let allowed = if mode == SlabMode::Mean {
                    rounding
                } else {
                    0.0
                };
                assert!(
                    off <= allowed,
                    "{name} {mode:?} view {k}: leaping is off by {off} (allowed {allowed})"
                );
                assert!(leaping.values.iter().any(|x| !x.is_nan()), "{name}: empty");
            }
        }
    }
}

#[test]
fn the_window_shows_the_exact_slice_within_a_grey_level() {
    let ctx = common::gpu();
    let renderer = SliceRenderer::new(&ctx.device).expect("pipeline");
    for name in SCANS {
        let v = load(name);
        let texture = VolumeTexture::upload(&ctx, &v).expect("upload");
        let bricks = renderer.bricks_of(&ctx, &v, &texture).expect("bricks");
        let frame = PatientFrame::of(&v);
        for slab in [
            None,
            Some(Slab {
                thickness_mm: 15.0,
                mode: SlabMode::Mip,
            }),
        ] {
            for (k, view) in views(&frame).iter().enumerate() {
                for nearest in [false, true] {
                    let look = SliceLook {
                        window: window_of(&v),
                        nearest,
                        slab,
                        leap: true,
                        colour: false,
                        invert: false,
                        labels: LabelLook::default(),
                    };
                    let exact = renderer
                        .render(&ctx, &v, &texture, Some(&bricks), view, look)
                        .expect("exact");
                    let shown: Vec<u8> = renderer
                        .render_display(&ctx, &v, &texture, Some(&bricks), None, None, view, look)
                        .expect("display")
                        .iter()
                        .map(|p| p[0])
                        .collect();
                    let diffs: Vec<i32> = exact
                        .grey
                        .iter()
                        .zip(&shown)
                        .map(|(&a, &b)| (i32::from(a) - i32::from(b)).abs())
                        .collect();
                    let worst = diffs.iter().copied().max().unwrap_or(0);
                    let off = diffs.iter().filter(|&&d| d > 0).count();
                    let what = format!("{name} view {k} slab {slab:?} nearest {nearest}");
                    if nearest {
                        // The same texel loads in both variants.
                        assert_eq!(worst, 0, "{what}");
                    } else {
                        // The texture unit's weights have 8 fractional bits for 8-bit texels
                        // (llvmpipe, most GPUs): the display samples within 1/512 voxel of the
                        // exact point, a few grey levels apart on steep edges through a narrow
                        // window; lavapipe: up to 3 levels on 1.4 % (thin) and 6.6 % (slab) of
                        // the angiogram's pixels, none on the 16-bit scans.
                        assert!(worst <= 4, "{what}: off by up to {worst} grey levels");
                        assert!(off * 10 <= diffs.len(), "{what}: {off} pixels differ");
                    }
                    assert!(shown.iter().any(|&g| g > 0), "{what}: black");
                }
            }
        }
    }
}

/// Colouring by the transfer function: each pixel is the grey of the exact slice blended with the
/// function's colour by its opacity at the pixel's value, on a CT with a preset that hides air
/// and soft tissue and shows bone.
#[test]
fn slices_coloured_by_the_transfer_function_blend_its_colour_by_its_opacity() {
    let ctx = common::gpu();
    let renderer = SliceRenderer::new(&ctx.device).expect("pipeline");
    let v = load("ct_head_cthead_256x256x113_uint16.nrrd");
    let kind = leapview::transfer::fit::DataKind::of(&v);
    let tf = leapview::transfer::fit::resolve("auto", &kind)
        .expect("tf")
        .tf;
    let texture = VolumeTexture::upload(&ctx, &v).expect("upload");
    let colours = renderer.colour_table(&ctx.device, &ctx.queue, &tf, &v);
    let frame = PatientFrame::of(&v);
    let range = v.normalization_range();
    let (mut coloured, mut grey) = (0, 0);
    for view in views(&frame) {
        let look = SliceLook {
            window: window_of(&v),
            nearest: true,
            slab: None,
            leap: true,
            colour: true,
            invert: false,
            labels: LabelLook::default(),
        };
        let exact = renderer
            .render(&ctx, &v, &texture, None, &view, look)
            .expect("exact");
        let shown = renderer
            .render_display(&ctx, &v, &texture, None, Some(&colours), None, &view, look)
            .expect("display");
        for ((value, g), rgb) in exact.values.iter().zip(&exact.grey).zip(&shown) {
            let (want, alpha) = if value.is_nan() {
                ([0.0; 3], 0.0)
            } else {
                let value = f64::from(*value);
                let a = tf.opacity_at(value, range).clamp(0.0, 1.0);
                let c = tf.color_at(value, range);
                let grey = f64::from(*g) / 255.0;
                (c.map(|c| grey + (c - grey) * a), a)
            };
            for (got, want) in rgb.iter().zip(want) {
                let off = (f64::from(*got) - want * 255.0).abs();
                // The table's 4096 entries, its 16-bit floats and the blend in f32.
                assert!(off <= 2.0, "{rgb:?} against {want:?} (opacity {alpha})");
            }
            if alpha > 0.5 {
                coloured += 1;
            } else if alpha == 0.0 && *g > 0 {
                grey += 1;
            }
        }
    }
    assert!(
        coloured > 100 && grey > 100,
        "{coloured} coloured, {grey} grey pixels"
    );
}
