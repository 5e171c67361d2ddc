//! Per dataset: the leaping structures' rebuild time after a transfer-function change, and the
//! image check (every RC-s variant against RC-t on one view, at most 1/255 apart).

use leapview::bench::BenchConfig;
use leapview::bench::config::DatasetSpec;
use leapview::bench::record::{IMAGE_TOLERANCE, ImageCheck, RebuildRecord};
use leapview::camera::Camera;
use leapview::render::{FrameRequest, RenderError, VolumeRenderer};
use leapview::settings::{Mode, RenderPath, RenderSettings, Strategy};
use leapview::transfer::TransferFunction;

use super::run::settings_for;

/// The path the rebuild is timed on: compute where configured (the rebuild is compute work
/// either way; the path only decides the frame around it).
fn rebuild_path(config: &BenchConfig) -> RenderPath {
    if config.paths.contains(&RenderPath::Compute) {
        RenderPath::Compute
    } else {
        config.paths[0]
    }
}

/// A transfer function that differs from `tf` by a hair, so that switching to it is a real
/// change (the renderer ignores setting an equal one) that leaves the empty blocks alike.
fn nudged(tf: &TransferFunction) -> TransferFunction {
    let mut other = tf.clone();
    for point in &mut other.opacity {
        point[1] *= 0.999;
    }
    other
}

/// Times `config.rebuild_repeats` transfer-function changes per leaping strategy in DVR.
pub fn rebuilds(
    renderer: &mut VolumeRenderer,
    config: &BenchConfig,
    spec: &DatasetSpec,
    tf: &TransferFunction,
    camera: &Camera,
) -> Result<Vec<RebuildRecord>, RenderError> {
    let alternate = [nudged(tf), tf.clone()];
    let mut records = Vec::new();
    for strategy in config.leaping_strategies() {
        let settings = settings_for(
            config,
            spec,
            (Mode::Dvr, strategy, rebuild_path(config)),
            config.block_vox,
        );
        let request = FrameRequest {
            camera,
            size: config.image_check_size,
            settings: &settings,
            stats: false,
        };
        renderer.render_and_wait(&request)?;
        let mut ms = Vec::new();
        for i in 0..config.rebuild_repeats {
            renderer.set_transfer_function(&alternate[i as usize % 2]);
            let (_, results) = renderer.render_and_wait(&request)?;
            ms.extend(results.rebuild_ms);
        }
        renderer.set_transfer_function(tf);
        records.push(RebuildRecord {
            dataset: spec.name.clone(),
            strategy: strategy.label().to_string(),
            block_vox: settings.leaf_block_vox(),
            ms,
        });
    }
    Ok(records)
}

/// Renders `camera` with RC-t and with each leaping variant in every configured mode and path
/// and compares the images.
pub fn image_checks(
    renderer: &mut VolumeRenderer,
    config: &BenchConfig,
    spec: &DatasetSpec,
    camera: &Camera,
) -> Result<Vec<ImageCheck>, RenderError> {
    let mut checks = Vec::new();
    let size = config.image_check_size;
    for &mode in &config.modes {
        for &path in &config.paths {
            let settings = |strategy| -> RenderSettings {
                settings_for(config, spec, (mode, strategy, path), config.block_vox)
            };
            let reference = renderer.render_image(camera, size, &settings(Strategy::RcT))?;
            for strategy in config.leaping_strategies() {
                if !BenchConfig::runs_in(strategy, mode) {
                    continue;
                }
                let image = renderer.render_image(camera, size, &settings(strategy))?;
                let max_abs = image.diff(&reference).map_or(f64::INFINITY, |d| d.max_abs);
                let passed = max_abs <= IMAGE_TOLERANCE && !image.has_non_finite();
                checks.push(ImageCheck {
                    dataset: spec.name.clone(),
                    mode: mode.label().to_string(),
                    path: format!("{path:?}").to_lowercase(),
                    strategy: strategy.label().to_string(),
                    max_abs,
                    passed,
                });
            }
        }
    }
    Ok(checks)
}
