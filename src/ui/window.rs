//! How the window and its GPU device are created: eframe's wgpu renderer, a device with
//! LeapView's features and the adapter's own limits (`render::context::device_descriptor`), on
//! an adapter that can present to the window, Vulkan preferred and GL as the fallback.

use std::sync::Arc;

use crate::render::context::device_descriptor;

/// Backends to try: `LEAPVIEW_BACKEND=vulkan|gl` forces one (as for the command line), then
/// wgpu's own `WGPU_BACKEND`, else Vulkan with GL as the fallback.
fn backends() -> wgpu::Backends {
    match std::env::var("LEAPVIEW_BACKEND").as_deref() {
        Ok("gl") => wgpu::Backends::GL,
        Ok("vulkan") => wgpu::Backends::VULKAN,
        _ => wgpu::Backends::from_env().unwrap_or(wgpu::Backends::VULKAN | wgpu::Backends::GL),
    }
}

/// Picks the adapter for the window: one that can present to it, Vulkan before GL, then
/// discrete before integrated before virtual before CPU (the order `GpuContext::headless` uses).
fn select_adapter(
    adapters: &[wgpu::Adapter],
    surface: Option<&wgpu::Surface<'_>>,
) -> Result<wgpu::Adapter, String> {
    let rank = |a: &&wgpu::Adapter| {
        let info = a.get_info();
        let backend = u8::from(info.backend != wgpu::Backend::Vulkan);
        let kind = match info.device_type {
            wgpu::DeviceType::DiscreteGpu => 0,
            wgpu::DeviceType::IntegratedGpu => 1,
            wgpu::DeviceType::VirtualGpu => 2,
            wgpu::DeviceType::Cpu => 3,
            wgpu::DeviceType::Other => 4,
        };
        (backend, kind)
    };
    let best = adapters
        .iter()
        .filter(|a| surface.is_none_or(|s| a.is_surface_supported(s)))
        .filter(|a| crate::render::context::unsuitable(a).is_none())
        .min_by_key(rank)
        .cloned();
    best.ok_or_else(|| {
        let lacking = adapters.iter().find_map(|a| {
            let info = a.get_info();
            crate::render::context::unsuitable(a)
                .map(|why| format!("{} ({:?}): {why}", info.name, info.backend))
        });
        if let Some(lacking) = lacking {
            format!("{lacking}; install a Vulkan driver (scripts/setup-debian.sh)")
        } else if adapters.is_empty() {
            "no GPU adapter found (Vulkan, GL)".to_string()
        } else {
            let names: Vec<String> = adapters
                .iter()
                .map(|a| format!("{} ({:?})", a.get_info().name, a.get_info().backend))
                .collect();
            format!(
                "none of the adapters can draw to this window: {}",
                names.join(", ")
            )
        }
    })
}

/// eframe's options for a window titled `title`: size, drag-and-drop, the wgpu setup above,
/// and no dithering.
pub(crate) fn native_options(title: &str) -> eframe::NativeOptions {
    let mut setup = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    setup.instance_descriptor.backends = backends();
    setup.native_adapter_selector = Some(Arc::new(select_adapter));
    // The adapter's own limits and our optional features: large volumes need the full 3D texture
    // size, and GPU timing needs timestamp queries.
    setup.device_descriptor = Arc::new(device_descriptor);
    eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title(title)
            .with_app_id("leapview")
            .with_inner_size([1280.0, 800.0])
            .with_min_inner_size([480.0, 360.0])
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        wgpu_options: egui_wgpu::WgpuConfiguration {
            wgpu_setup: setup.into(),
            ..Default::default()
        },
        // Dithering adds noise to texture values between 8-bit levels: the view would no longer
        // show exactly what the PNG output holds.
        dithering: false,
        // Persistence comes in a later issue.
        persist_window: false,
        ..Default::default()
    }
}
