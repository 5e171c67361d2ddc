//! The run loop: for one dataset, every mode × strategy × path × resolution (and the block-size
//! sweep) over an orbit of views, after a warm-up; a timing pass and a separate statistics pass
//! (the counting variants are slower, so they are never timed as the frame time).

use std::time::{Duration, Instant};

use leapview::bench::BenchConfig;
use leapview::bench::config::DatasetSpec;
use leapview::bench::record::{AutoChoice, FrameRecord, RunKey, RunRecord};
use leapview::camera::Camera;
use leapview::render::raycast::auto_strategy;
use leapview::render::raycast::strategy_choice::{ChoiceBasis, StrategyChoice};
use leapview::render::{FrameRequest, RenderError, VolumeRenderer};
use leapview::settings::effects::{IsoSettings, Shading};
use leapview::settings::{Mode, RenderPath, RenderSettings, Strategy};

use crate::cli::measuring::{timed_frame, timed_frame_read_back};

/// One run to do.
#[derive(Clone, Copy, Debug)]
pub struct Planned {
    /// Settings of every frame.
    pub settings: RenderSettings,
    /// Image size.
    pub size: [u32; 2],
    /// Whether it belongs to the block-size sweep.
    pub sweep: bool,
}

/// The settings of `spec` under `mode`, `strategy`, `path` and `block_vox` (`None`: the mode's and
/// strategy's default edge).
pub fn settings_for(
    config: &BenchConfig,
    spec: &DatasetSpec,
    (mode, strategy, path): (Mode, Strategy, RenderPath),
    block_vox: Option<u32>,
) -> RenderSettings {
    RenderSettings {
        mode,
        strategy,
        path,
        step_vox: config.step_vox,
        block_vox,
        shading: if config.phong {
            Shading::Phong
        } else {
            Shading::Off
        },
        iso: IsoSettings {
            value: spec.iso_value,
            ..IsoSettings::default()
        },
        window: spec.window,
        ..RenderSettings::default()
    }
}

/// Every run of `spec`: the main matrix, then its part of the block-size sweep.
pub fn plan(config: &BenchConfig, spec: &DatasetSpec) -> Vec<Planned> {
    let mut runs = Vec::new();
    for &size in &config.resolutions {
        for &mode in &config.modes {
            for &path in &config.paths {
                for &strategy in &config.strategies {
                    if BenchConfig::runs_in(strategy, mode) {
                        let settings =
                            settings_for(config, spec, (mode, strategy, path), config.block_vox);
                        runs.push(Planned {
                            settings,
                            size,
                            sweep: false,
                        });
                    }
                }
            }
        }
    }
    let sweep = &config.block_sweep;
    if sweep.datasets.contains(&spec.name) {
        for &mode in &sweep.modes {
            for &path in &config.paths {
                for strategy in config.leaping_strategies() {
                    if !BenchConfig::runs_in(strategy, mode) {
                        continue;
                    }
                    for &block in &sweep.sizes {
                        runs.push(Planned {
                            settings: settings_for(
                                config,
                                spec,
                                (mode, strategy, path),
                                Some(block),
                            ),
                            size: sweep.resolution,
                            sweep: true,
                        });
                    }
                }
            }
        }
    }
    runs
}

/// The shortest warm-up before a run is timed.
pub const WARMUP_TIME: Duration = Duration::from_millis(250);
/// The shortest warm-up of a dataset's first run, right after its upload: the GPU idled while
/// the volume was read or generated, and a few 512³ first runs still came out slow after
/// [`WARMUP_TIME`] (docs/benchmarks/README.md, "Warm-up").
pub const SETTLE_TIME: Duration = Duration::from_secs(1);
/// The most warm-up frames spent reaching the warm-up time.
const WARMUP_MAX_FRAMES: u32 = 5000;
/// Warm-up frames submitted between two waits: the GPU has the next frames queued while the
/// CPU waits, instead of idling between frames as the timed passes make it.
const WARMUP_BATCH: u32 = 8;

/// Runs `planned` over `cameras` after `warmup` frames and `warmup_time`: the timing pass, the render + read-back
/// pass, then the statistics pass (itself warmed up once so that building its pipeline is not in
/// the first frame).
pub fn measure(
    renderer: &mut VolumeRenderer,
    dataset: &str,
    tf: &str,
    planned: &Planned,
    cameras: &[(Camera, f64)],
    warmup: u32,
    warmup_time: Duration,
) -> Result<RunRecord, RenderError> {
    let request = |camera, stats| FrameRequest {
        camera,
        size: planned.size,
        settings: &planned.settings,
        stats,
    };
    let Some((first, _)) = cameras.first() else {
        return Err(RenderError::NoVolume);
    };
    // At least `warmup` frames and `warmup_time`: an idle GPU clocks down
    // (docs/benchmarks/nvidia-h200-ray-split, "The warm-up"), and a few sub-millisecond frames
    // do not bring it back up. The first frame builds the pipeline and names the path; the rest
    // go in batches without a wait, each sized by the last frames' time so as not to run much
    // past the warm-up time (the first frame's, pipeline build included, is an overestimate).
    let started = Instant::now();
    let path = timed_frame(renderer, &request(first, false))?.2;
    let mut per_frame = started.elapsed().as_secs_f64();
    let mut warmed = 1u32;
    while warmed < warmup || (started.elapsed() < warmup_time && warmed < WARMUP_MAX_FRAMES) {
        let left = warmup_time.saturating_sub(started.elapsed()).as_secs_f64();
        // `as` saturates (and takes NaN to 0); the clamp bounds it.
        let by_time = (left / per_frame.max(1e-6)).ceil() as u32;
        let batch = by_time
            .max(warmup.saturating_sub(warmed))
            .clamp(1, WARMUP_BATCH);
        let batch_started = Instant::now();
        for _ in 0..batch {
            renderer.render(&request(first, false))?;
        }
        renderer.collect_results(true);
        per_frame = batch_started.elapsed().as_secs_f64() / f64::from(batch);
        warmed += batch;
    }
    // `auto` chooses here, warm, as the window does when the frame's inputs change, from the
    // view half a step of the orbit past the first: the views it times (that one and two more
    // 120° on) are none of the orbit's, so the orbit tests the choice on views it did not see.
    // Every pass below renders what it chose.
    let auto = if planned.settings.strategy == Strategy::Auto {
        let mut between = *first;
        between.orbit(180.0 / cameras.len() as f64, 0.0);
        let started = Instant::now();
        auto_strategy::choose(renderer, &planned.settings, planned.size, &between, true)?;
        let choose_ms = started.elapsed().as_secs_f64() * 1e3;
        renderer
            .strategy_choice()
            .map(|c| auto_record(c, choose_ms))
    } else {
        None
    };
    let mut frames = Vec::with_capacity(cameras.len());
    for (view, (camera, azimuth)) in cameras.iter().enumerate() {
        let (ms, _, _) = timed_frame(renderer, &request(camera, false))?;
        frames.push(FrameRecord {
            view: view as u32,
            azimuth_deg: *azimuth,
            ms,
            stats_ms: None,
            wall_ms: None,
            samples: 0,
            visible_samples: 0,
            rays: 0,
            leaps: 0,
            lookups: None,
        });
    }
    // `auto` against RC-t view by view, one frame of each right after the other (the runs are
    // apart, and their spread at sub-millisecond frames is as large as the 2 % the comparison
    // allows).
    let auto = match auto {
        Some(mut a) => {
            let rct = RenderSettings {
                strategy: Strategy::RcT,
                ..planned.settings
            };
            for (camera, _) in cameras {
                let rct_request = FrameRequest {
                    settings: &rct,
                    ..request(camera, false)
                };
                let (rct_ms, _, _) = timed_frame(renderer, &rct_request)?;
                let (auto_ms, _, _) = timed_frame(renderer, &request(camera, false))?;
                a.paired_ms.push([rct_ms, auto_ms]);
            }
            Some(a)
        }
        None => None,
    };
    // Render + read-back as peers time it, in a pass of its own: waiting for each image between
    // frames lets the GPU clock down, which would slow the timing pass's frames.
    for (frame, (camera, _)) in frames.iter_mut().zip(cameras) {
        frame.wall_ms = Some(timed_frame_read_back(renderer, &request(camera, false))?.1);
    }
    timed_frame(renderer, &request(first, true))?;
    for (frame, (camera, _)) in frames.iter_mut().zip(cameras) {
        let (ms, results, _) = timed_frame(renderer, &request(camera, true))?;
        let c = results.counters.unwrap_or_default();
        frame.stats_ms = Some(ms);
        frame.samples = c.samples;
        frame.visible_samples = c.visible_samples;
        frame.rays = c.rays;
        frame.leaps = c.leaps;
        frame.lookups = Some(c.lookups);
    }
    let s = &planned.settings;
    Ok(RunRecord {
        key: RunKey {
            dataset: dataset.to_string(),
            mode: s.mode.label().to_string(),
            strategy: s.strategy.label().to_string(),
            path,
            width: planned.size[0],
            height: planned.size[1],
            block_vox: s.leaf_block_vox(),
            sweep: planned.sweep,
        },
        step_vox: s.step_vox,
        tf: tf.to_string(),
        frames,
        auto,
    })
}

/// The record of `choice`, which took `choose_ms`.
fn auto_record(choice: &StrategyChoice, choose_ms: f64) -> AutoChoice {
    let (rct_ms, leaping_ms) = match choice.basis {
        ChoiceBasis::Timed { rct_ms, leaping_ms } => (Some(rct_ms), Some(leaping_ms)),
        ChoiceBasis::CpuDriver | ChoiceBasis::CarriedOver => (None, None),
    };
    AutoChoice {
        strategy: choice.strategy.label().to_string(),
        rct_ms,
        leaping_ms,
        choose_ms,
        paired_ms: Vec::new(),
    }
}
