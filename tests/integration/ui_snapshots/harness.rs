//! Helpers for the UI tests (`ui_snapshots.rs`): an `egui_kittest` harness that renders
//! with egui's wgpu renderer on the CPU adapter (lavapipe), the snapshot tolerance, and pointer
//! gestures at positions inside a canvas.

use egui::{Pos2, Rect, pos2};
use egui_kittest::wgpu::WgpuTestRenderer;
use egui_kittest::{HarnessBuilder, SnapshotOptions};
use leapview::volume::ValueRange;

/// Per-pixel tolerance of the snapshots, in dify's unit: the weighted squared YIQ distance on
/// 0–255 channels (egui_kittest hands it to dify as it is). A grey step of `d` levels scores
/// `0.505·d²`; any change of at most 2 levels per channel scores at most 2.02, 3 levels of grey
/// 4.5. Measured on Mesa 22.3 (Debian 12, as CI): lavapipe at 128-bit instead of native SIMD
/// width (`LP_NATIVE_VECTOR_WIDTH=128`) renders every snapshot bit for bit the same, and
/// llvmpipe through GL (`LEAPVIEW_BACKEND=gl`) differs in one pixel by one level (score < 0.6).
/// 2.5 leaves a level of margin for other Mesa and LLVM versions. What the snapshots are for
/// moves far more: drawing the handles half a point larger fails 97 pixels of `tf_editor`, 86
/// of them by more than 10, and a shifted label changes hundreds by tens of levels.
pub const SNAPSHOT_THRESHOLD: f32 = 2.5;

/// Pixels allowed past [`SNAPSHOT_THRESHOLD`]: none (none did in the measurements above; dify
/// already excuses anti-aliased edge pixels).
pub const SNAPSHOT_MAX_FAILED_PIXELS: usize = 0;

/// Builds egui's wgpu test renderer on a fresh device. The adapter: `LEAPVIEW_BACKEND=vulkan|gl`
/// forces a backend as everywhere else; otherwise Vulkan, then GL. Within a backend the CPU adapter
/// (lavapipe, llvmpipe) comes first, so that the snapshots are rasterised by the same code on every
/// machine that has it, with or without a GPU. No adapter fails the test with the install hint.
pub fn renderer() -> WgpuTestRenderer {
    WgpuTestRenderer::from_render_state(render_state())
}

/// egui's wgpu render state on a fresh device of the adapter [`renderer`] describes: for tests
/// that draw with the same device as the snapshots (the slice views).
pub fn render_state() -> egui_wgpu::RenderState {
    let order: &[wgpu::Backends] = match std::env::var("LEAPVIEW_BACKEND").as_deref() {
        Ok("gl") => &[wgpu::Backends::GL],
        Ok("vulkan") => &[wgpu::Backends::VULKAN],
        _ => &[wgpu::Backends::VULKAN, wgpu::Backends::GL],
    };
    for &backends in order {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = backends;
        let instance = wgpu::Instance::new(desc);
        let adapters = pollster::block_on(instance.enumerate_adapters(backends));
        let Some(adapter) = adapters
            .into_iter()
            .min_by_key(|a| a.get_info().device_type != wgpu::DeviceType::Cpu)
        else {
            continue;
        };
        let info = adapter.get_info();
        let (device, queue) =
            pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default()))
                .unwrap_or_else(|e| panic!("{} ({:?}): no device: {e}", info.name, info.backend));
        let config = egui_wgpu::WgpuConfiguration {
            wgpu_setup: egui_wgpu::WgpuSetup::Existing(egui_wgpu::WgpuSetupExisting {
                instance: instance.clone(),
                adapter,
                device,
                queue,
            }),
            ..Default::default()
        };
        let state = pollster::block_on(egui_wgpu::RenderState::create(
            &config,
            &instance,
            None,
            egui_wgpu::RendererOptions::PREDICTABLE,
        ))
        .unwrap_or_else(|e| panic!("{} ({:?}): egui renderer: {e}", info.name, info.backend));
        return state;
    }
    panic!(
        "no GPU adapter for the UI snapshots (tried {order:?}). Without a GPU, Mesa's Vulkan CPU \
         driver works: `sudo apt-get install mesa-vulkan-drivers`"
    );
}

/// A harness builder of `size` points (1 pixel per point, dark theme) that renders through
/// [`renderer`] and compares snapshots with the tolerance above.
pub fn harness<State>(size: [f32; 2]) -> HarnessBuilder<State> {
    harness_with(size, renderer())
}

/// [`harness`] rendering through `renderer`.
pub fn harness_with<State>(size: [f32; 2], renderer: WgpuTestRenderer) -> HarnessBuilder<State> {
    egui_kittest::Harness::builder()
        .with_size(size)
        .with_pixels_per_point(1.0)
        .with_theme(egui::Theme::Dark)
        // The synthetic cursor would cover what a snapshot shows; hover effects still show.
        .with_render_cursor(false)
        .with_options(
            SnapshotOptions::new()
                .threshold(SNAPSHOT_THRESHOLD)
                .max_failed_pixels(SNAPSHOT_MAX_FAILED_PIXELS),
        )
        .renderer(renderer)
}

/// Where the transfer-function editor draws `(value, alpha)` in its opacity canvas `canvas`:
/// values across the volume's `range` left to right, alpha bottom to top (a function in data
/// units, as the presets are).
pub fn canvas_pos(canvas: Rect, range: ValueRange, value: f64, alpha: f64) -> Pos2 {
    let s = range.normalize(value) as f32;
    pos2(
        canvas.left() + s * canvas.width(),
        canvas.bottom() - alpha as f32 * canvas.height(),
    )
}

/// Queues a primary click at `pos`, then takes the pointer away (no hover highlight in a
/// snapshot taken after it).
pub fn click_at<State>(h: &egui_kittest::Harness<'_, State>, pos: Pos2) {
    h.hover_at(pos);
    h.drag_at(pos);
    h.drop_at(pos);
}

/// Queues a primary-button drag from `from` to `to` in four moves, then takes the pointer away.
pub fn drag<State>(h: &egui_kittest::Harness<'_, State>, from: Pos2, to: Pos2) {
    h.hover_at(from);
    h.drag_at(from);
    for i in 1..=4 {
        h.hover_at(from.lerp(to, i as f32 / 4.0));
    }
    h.drop_at(to);
}
