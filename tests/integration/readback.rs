//! The 8-bit read-back (quantised on the GPU, what the benchmark's `render + read-back` time
//! reads) gives the bytes of the f32 read-back quantised on the CPU, on both paths and after the
//! image size changes (its buffers are kept between reads and rebuilt for a new size).

use crate::common;

use leapview::camera::{ProjectionKind, ViewPreset};
use leapview::render::FrameRequest;
use leapview::settings::{Mode, RenderPath, RenderSettings};
use leapview::transfer::presets::preset;
use leapview::volume::synthetic;

#[test]
fn the_8_bit_read_back_equals_the_f32_image_quantised() {
    let volume = synthetic::vessel_tree(48, 3).expect("volume");
    let mut r = common::renderer_for(&volume, &preset("mr-angio").expect("preset"));
    let camera = common::framing(&volume, ViewPreset::Oblique, ProjectionKind::Perspective);
    // Odd sizes: rows of neither 64 pixels (copy alignment) nor 8 (workgroups); the second
    // size rebuilds the kept buffers, the third reuses them.
    for size in [[53, 61], [97, 33], [97, 33]] {
        for (path, mode) in [
            (RenderPath::Compute, Mode::Dvr),
            (RenderPath::Fragment, Mode::Dvr),
            (RenderPath::Compute, Mode::Mip),
        ] {
            let settings = RenderSettings {
                path,
                mode,
                ..RenderSettings::default()
            };
            let request = FrameRequest {
                camera: &camera,
                size,
                settings: &settings,
                stats: false,
            };
            r.render_and_wait(&request).expect("render");
            let quantised = r.read_image().expect("read f32").to_rgba8();
            let packed = r.read_image_rgba8().expect("read 8-bit");
            let case = format!("{path:?} {mode:?} {size:?}");
            assert_eq!(packed.dimensions(), (size[0], size[1]), "{case}");
            // A picture, not a blank: many distinct grey levels.
            let mut levels: Vec<u8> = quantised.pixels().map(|p| p.0[0]).collect();
            levels.sort_unstable();
            levels.dedup();
            assert!(levels.len() > 8, "{case}: only {} levels", levels.len());
            let differing = packed
                .pixels()
                .zip(quantised.pixels())
                .filter(|(a, b)| a != b)
                .count();
            assert_eq!(differing, 0, "{case}: pixels that differ");
        }
    }
}
