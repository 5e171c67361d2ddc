//! `--strategy auto`, the default: time RC-t and the mode's leaping strategy on the frame's own
//! inputs and keep the faster. Both render the same image (within 1/255: the benchmark's image
//! check and the tests), so the choice only changes the time. Leaping wins on most volumes, but
//! not everywhere: RC-t was measured faster on some dense volumes at 512² and in some modes
//! (docs/benchmarks/nvidia-h200-auto), and which one wins depends on the volume, the
//! transfer function (what is empty), the mode and the image size, so it is measured, not
//! guessed. A CPU driver takes the leaping strategy untimed (its wall clock, the only clock it
//! has, follows the machine's load, as `auto_path` found).
//!
//! This is a caller of [`VolumeRenderer`], not a part of it: whoever renders with
//! [`Strategy::Auto`] runs [`choose`] before the frame (the renderer keeps the choice, and renders
//! an `auto` frame it has no choice for with the leaping strategy).

use std::time::Instant;

use crate::camera::Camera;
use crate::settings::{RenderSettings, Strategy};

use super::error::RenderError;
use super::renderer::VolumeRenderer;
use super::request::FrameRequest;
use super::strategy_choice::{ChoiceBasis, StrategyChoice};

/// Timed rounds of each strategy's frames on the views, alternating (a clock that changes
/// meanwhile changes both), after one untimed frame of each (which also builds its pipeline).
const ROUNDS: usize = 3;
/// The views timed, as turns about the camera's target from the view shown (degrees of azimuth
/// about its up axis): three, evenly around.
const VIEW_TURNS_DEG: [f64; 3] = [0.0, 120.0, 240.0];
/// Once a round of the two strategies' frames takes this long, one round is enough: the timing
/// costs the user a wait, and run-to-run noise is small against such frames.
const LONG_ROUND_MS: f64 = 100.0;

/// The concrete strategy a frame with `settings` at `size` runs, choosing it first for `auto`:
/// where the renderer has no settled choice for these inputs, both strategies are timed on
/// `camera` ([`measure`]) when `may_time`; otherwise (the user is dragging something, and a
/// frame must not wait) the last choice in the same mode is carried over, to be timed once
/// `may_time` allows.
pub fn choose(
    renderer: &mut VolumeRenderer,
    settings: &RenderSettings,
    size: [u32; 2],
    camera: &Camera,
    may_time: bool,
) -> Result<Strategy, RenderError> {
    if settings.strategy != Strategy::Auto {
        return Ok(settings.strategy.for_mode(settings.mode));
    }
    let key = renderer.choice_key(settings, size);
    let last = renderer.strategy_choice().copied();
    if let Some(c) = last.filter(|c| c.key == key && (c.basis.is_settled() || !may_time)) {
        return Ok(c.strategy);
    }
    let leaping = Strategy::leaping(settings.mode);
    let choice = if !may_time {
        let strategy = last
            .filter(|c| c.key.settings.mode == settings.mode)
            .map_or(leaping, |c| c.strategy);
        StrategyChoice {
            key,
            strategy,
            basis: ChoiceBasis::CarriedOver,
        }
    } else if skips_timing(renderer) {
        StrategyChoice {
            key,
            strategy: leaping,
            basis: ChoiceBasis::CpuDriver,
        }
    } else {
        measure(renderer, settings, size, camera)?
    };
    if choice.basis.is_settled() {
        log::info!("auto strategy: {}", choice.describe());
    } else {
        log::debug!("auto strategy: {}", choice.describe());
    }
    renderer.set_strategy_choice(choice);
    Ok(choice.strategy)
}

/// Whether [`choose`] with `may_time` would time the two strategies for a frame with `settings`
/// at `size`: `auto`, a GPU (not a CPU driver), and no settled choice for these inputs.
pub fn wants_timing(
    renderer: &VolumeRenderer,
    settings: &RenderSettings,
    size: [u32; 2],
    may_time: bool,
) -> bool {
    may_time
        && settings.strategy == Strategy::Auto
        && !skips_timing(renderer)
        && renderer
            .strategy_choice()
            .is_none_or(|c| c.key != renderer.choice_key(settings, size) || !c.basis.is_settled())
}

/// `LEAPVIEW_TIME_STRATEGY_ON_CPU=1` times the `auto` strategy on a CPU driver too: the choice is
/// then as arbitrary as that driver's clock, but the timing's way through the window and the
/// command line runs (the tests set it; a GPU always times).
pub const TIME_ON_CPU_VAR: &str = "LEAPVIEW_TIME_STRATEGY_ON_CPU";

/// Whether the renderer runs on a CPU driver whose `auto` strategy is not timed.
fn skips_timing(renderer: &VolumeRenderer) -> bool {
    renderer.context().adapter_info.device_type == wgpu::DeviceType::Cpu
        && std::env::var_os(TIME_ON_CPU_VAR).is_none_or(|v| v != "1")
}

/// Times RC-t and the leaping strategy of `settings`' mode at `size` (GPU timestamps; the wall
/// clock where the adapter has none) on `camera` and on the views `VIEW_TURNS_DEG` about its
/// target from it, and returns the choice for these inputs, without keeping it. A choice holds
/// until the settings change, whatever the camera does: the views stand for the others, where
/// one view alone was misleading: leaping chosen on one view was slower than RC-t over the orbit
/// in some cases, on three views with [`StrategyChoice::LEAPING_MARGIN`] in none
/// (docs/benchmarks/nvidia-h200-auto).
pub fn measure(
    renderer: &mut VolumeRenderer,
    settings: &RenderSettings,
    size: [u32; 2],
    camera: &Camera,
) -> Result<StrategyChoice, RenderError> {
    let key = renderer.choice_key(settings, size);
    let candidates =
        [Strategy::RcT, Strategy::leaping(settings.mode)].map(|strategy| RenderSettings {
            strategy,
            ..*settings
        });
    let views = VIEW_TURNS_DEG.map(|deg| {
        let mut view = *camera;
        view.orbit(deg, 0.0);
        view
    });
    for candidate in &candidates {
        renderer.render_and_wait(&request(camera, size, candidate))?;
    }
    let mut times = [Vec::with_capacity(ROUNDS), Vec::with_capacity(ROUNDS)];
    for _ in 0..ROUNDS {
        let mut round_ms = 0.0;
        for (candidate, times) in candidates.iter().zip(&mut times) {
            let mut sum_ms = 0.0;
            for view in &views {
                let start = Instant::now();
                let (_, results) = renderer.render_and_wait(&request(view, size, candidate))?;
                let wall_ms = start.elapsed().as_secs_f64() * 1e3;
                sum_ms += results.gpu_ms.unwrap_or(wall_ms);
                round_ms += wall_ms;
            }
            times.push(sum_ms / views.len() as f64);
        }
        if round_ms >= LONG_ROUND_MS {
            break;
        }
    }
    let [rct_ms, leaping_ms] = times.map(|mut t| median(&mut t));
    Ok(StrategyChoice::timed(key, rct_ms, leaping_ms))
}

fn request<'a>(
    camera: &'a Camera,
    size: [u32; 2],
    settings: &'a RenderSettings,
) -> FrameRequest<'a> {
    FrameRequest {
        camera,
        size,
        settings,
        stats: false,
    }
}

/// The median of `times` (NaN for none).
fn median(times: &mut [f64]) -> f64 {
    times.sort_by(f64::total_cmp);
    match times.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => times[n / 2],
        n => (times[n / 2 - 1] + times[n / 2]) / 2.0,
    }
}
