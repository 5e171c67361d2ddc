//! Helpers shared by the integration tests: the GPU, output folders, image comparison, and (in
//! `ui`) the harness of the UI tests.
#![allow(dead_code, unused_imports)]

mod analytic;
mod binary;
mod display;
mod files;
mod hard;
mod python;
pub mod scene;
pub use analytic::*;
pub use binary::*;
pub use display::*;
pub use files::*;
pub use hard::*;
pub use python::*;

use std::path::PathBuf;

use leapview::camera::Camera;
use leapview::counters::FrameCounters;
use leapview::imaging::{ImageDiff, ImageF32};
use leapview::render::raycast::auto_path;
use leapview::render::{FrameRequest, GpuContext, VolumeRenderer};
use leapview::settings::{RenderPath, RenderSettings};

/// A headless GPU context; fails the test with the install hint when no adapter exists (never a
/// silent skip).
pub fn gpu() -> GpuContext {
    match GpuContext::headless() {
        Ok(ctx) => ctx,
        Err(e) => panic!(
            "{e}\n(The tests render on the GPU; on a machine without one, Mesa's Vulkan CPU driver lavapipe works: `sudo apt-get install mesa-vulkan-drivers`.)"
        ),
    }
}

/// A renderer on a fresh headless context.
pub fn renderer() -> VolumeRenderer {
    VolumeRenderer::new(gpu()).unwrap_or_else(|e| panic!("renderer: {e}"))
}

/// Times both ray-loop paths on `r`'s volume so that frames with the path `auto` can render
/// (what every caller of the renderer does before its first `auto` frame).
pub fn choose_auto_path(r: &mut VolumeRenderer) {
    auto_path::choose(r, RenderPath::Auto).unwrap_or_else(|e| panic!("auto path: {e}"));
}

/// Renders with the statistics variant, then with the plain one; checks that counting changed
/// nothing in the image and returns the image and the counts.
pub fn render_counted(
    r: &mut VolumeRenderer,
    camera: &Camera,
    settings: RenderSettings,
    size: [u32; 2],
) -> (ImageF32, FrameCounters) {
    let request = FrameRequest {
        camera,
        size,
        settings: &settings,
        stats: true,
    };
    let (_, results) = r.render_and_wait(&request).expect("render");
    let counted = r.read_image().expect("read");
    let plain = r.render_image(camera, size, &settings).expect("render");
    assert_eq!(counted, plain, "stats variant changed the image");
    (plain, results.counters.expect("counters"))
}

/// Folder for images written by tests (actual, expected, difference).
pub fn output_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/test-output");
    std::fs::create_dir_all(&dir)
        .unwrap_or_else(|e| panic!("cannot create {}: {e}", dir.display()));
    dir
}

/// Writes `name-actual.png`, `name-expected.png` and `name-difference.png` (×16) and returns the
/// folder, for failure messages.
pub fn save_comparison(name: &str, actual: &ImageF32, expected: &ImageF32) -> PathBuf {
    let dir = output_dir();
    let save = |img: &ImageF32, suffix: &str| {
        let p = dir.join(format!("{name}-{suffix}.png"));
        img.save(&p).unwrap_or_else(|e| panic!("{e}"));
    };
    save(actual, "actual");
    save(expected, "expected");
    if actual.width == expected.width && actual.height == expected.height {
        save(&actual.difference_image(expected, 16.0), "difference");
    }
    dir
}

/// Directory of the shared real datasets (`../shared/data`, or `LEAPVIEW_DATA_DIR`). Panics with
/// the place it looked when missing: tests on real data never skip silently.
pub fn data_dir() -> PathBuf {
    let dir = std::env::var_os("LEAPVIEW_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data"));
    assert!(
        dir.is_dir(),
        "the shared datasets are missing: looked in {} (set LEAPVIEW_DATA_DIR)",
        dir.display()
    );
    dir
}

/// Asserts `diff` is within bounds, saving the images on failure.
pub fn assert_close(
    name: &str,
    actual: &ImageF32,
    expected: &ImageF32,
    max_abs: f64,
    max_share_over: f64,
) -> ImageDiff {
    let diff = actual
        .diff(expected)
        .unwrap_or_else(|| panic!("{name}: image sizes differ"));
    if diff.max_abs > max_abs || diff.share_over_1_255 > max_share_over || actual.has_non_finite() {
        let dir = save_comparison(name, actual, expected);
        panic!(
            "{name}: {diff:?} exceeds max_abs {max_abs} / share {max_share_over}; images in {}",
            dir.display()
        );
    }
    if std::env::var_os("LEAPVIEW_SAVE_IMAGES").is_some() {
        save_comparison(name, actual, expected);
    }
    diff
}

/// Compares `actual` with the golden image `tests/golden/{name}.png`.
///
/// With `LEAPVIEW_BLESS=1` the golden is (re)written instead. A missing golden fails the test.
/// Goldens are 8-bit; the tolerance absorbs their quantisation (1/510) and the texture-unit
/// filtering differences between drivers (8-bit interpolation weights on lavapipe and most GPUs,
/// more on some): at most 1 % of pixels may be off by more than 4/255, none by more than 32/255.
pub fn assert_golden(name: &str, actual: &ImageF32) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(format!("{name}.png"));
    if std::env::var_os("LEAPVIEW_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().expect("has parent")).expect("create tests/golden");
        actual.save(&path).unwrap_or_else(|e| panic!("{e}"));
        eprintln!("blessed {}", path.display());
        return;
    }
    assert!(
        path.exists(),
        "golden image {} is missing; render it with LEAPVIEW_BLESS=1 cargo test, then look at it",
        path.display()
    );
    let expected = ImageF32::read_png(&path).unwrap_or_else(|e| panic!("{e}"));
    // What a PNG can hold: a specular highlight above 1 was clamped in the golden too.
    let clamped = ImageF32 {
        pixels: actual
            .pixels
            .iter()
            .map(|p| p.map(|c| c.clamp(0.0, 1.0)))
            .collect(),
        ..actual.clone()
    };
    let actual = &clamped;
    let diff = actual
        .diff(&expected)
        .unwrap_or_else(|| panic!("{name}: size differs from the golden image"));
    let off_by_4: usize = actual
        .pixels
        .iter()
        .zip(&expected.pixels)
        .filter(|(a, b)| (0..3).any(|c| (a[c] - b[c]).abs() > 4.0 / 255.0))
        .count();
    let share = off_by_4 as f64 / actual.pixels.len() as f64;
    if diff.max_abs > 32.0 / 255.0 || share > 0.01 || actual.has_non_finite() {
        let dir = save_comparison(name, actual, &expected);
        panic!(
            "{name} differs from its golden image: {diff:?}, {:.2} % of pixels off by more than 4/255; actual and difference images in {}",
            100.0 * share,
            dir.display()
        );
    }
}
