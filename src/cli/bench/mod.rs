//! `leapview bench`: the paper's Tables 1 and 2 on the configured datasets, the rebuild time
//! after a transfer-function change and an image check of every leaping variant against RC-t.
//! Results are written after each dataset, so an interrupted run keeps what it measured.

pub mod args;
mod checks;
mod output;
pub(crate) mod plots;
mod progress;
pub(crate) mod run;
mod stream;

use std::path::{Path, PathBuf};

use leapview::bench::record::{Environment, Skipped};
use leapview::bench::{BenchConfig, BenchResults, Filters};
use leapview::camera::Aabb;
use leapview::render::raycast::auto_path;
use leapview::render::{GpuContext, VolumeRenderer};
use leapview::settings::{RenderPath, Upload};

pub use args::BenchArgs;

use super::measuring::environment;
use super::{Failure, datasets};
use crate::cli::OrFail;
use progress::Progress;

/// Warm-up frames of a dataset's first run, right after its upload.
const SETTLE_FRAMES: u32 = 30;

/// Runs the command.
pub fn run(args: BenchArgs, raw: &crate::cli::args::RawArgs) -> Result<(), Failure> {
    if let Some(dirs) = &args.merge {
        let out = args
            .out
            .clone()
            .ok_or_else(|| Failure::BadInput(anyhow::anyhow!("--merge needs --out")))?;
        let results = output::merge(dirs).map_err(Failure::BadInput)?;
        let summary = output::write_all(&out, &results, true)?;
        return finish(&out, &summary);
    }
    if let Some(file) = &args.stream {
        return stream::run(&args, file, raw);
    }
    let mut config = BenchConfig::load(&args.config).bad_input()?;
    if args.quick {
        config.quick();
    }
    let filters = Filters {
        datasets: args.datasets.clone(),
        modes: args.modes.clone(),
        strategies: args.strategies.clone(),
        paths: args.paths.clone(),
        block_vox: args.block,
        shading: args.shading,
    };
    config.narrow(&filters).bad_input()?;
    if args.labels.is_some() && config.datasets.len() != 1 {
        return Err(Failure::BadInput(anyhow::anyhow!(
            "--labels shows one segmentation over one dataset, and --datasets leaves {}: name \
             the one it belongs to",
            config.datasets.len()
        )));
    }
    let config_dir = args.config.parent().unwrap_or(Path::new(".")).to_path_buf();
    let ctx = GpuContext::headless().failed()?;
    let environment = environment(&ctx, args.quick);
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| default_out(&environment));
    let max_3d = ctx.limits.max_texture_dimension_3d;
    let mut renderer = VolumeRenderer::new(ctx).failed()?;
    let mut results = BenchResults {
        environment,
        ..BenchResults::default()
    };
    eprintln!(
        "leapview bench on {} → {}",
        results.environment.adapter,
        out.display()
    );
    let units: usize = config
        .datasets
        .iter()
        .map(|d| run::plan(&config, d).len() + 1)
        .sum();
    let mut progress = Progress::new(units as u64);
    for spec in &config.datasets {
        let mut runs = run::plan(&config, spec);
        if args.labels.is_some() {
            for planned in &mut runs {
                planned.settings.labels = args.label_view;
            }
        }
        progress.show(&format!("{}: loading", spec.name));
        let skip = |reason: String, bad_input: bool| Skipped {
            dataset: spec.name.clone(),
            reason,
            optional: spec.optional,
            bad_input,
        };
        let loaded = match datasets::load(spec, &args.data_dir, &config_dir, max_3d) {
            Ok(l) => l,
            Err(e) => {
                progress.note(&format!("skipping {}: {e:#}", spec.name));
                results.skipped.push(skip(format!("{e:#}"), true));
                progress.advance(runs.len() as u64 + 1);
                continue;
            }
        };
        if let Err(e) = renderer.set_volume_with(
            &loaded.volume,
            &Upload {
                bricking: args.bricks,
                gpu_budget: args.gpu.gpu_budget,
                ..Upload::default()
            },
        ) {
            progress.note(&format!("skipping {}: {e}", spec.name));
            results.skipped.push(skip(e.to_string(), e.is_bad_input()));
            progress.advance(runs.len() as u64 + 1);
            continue;
        }
        renderer.set_transfer_function(&loaded.tf);
        let labelled = match &args.labels {
            Some(path) => Some(show_labels(
                &mut renderer,
                path,
                &loaded.volume,
                (args.label_view, args.label_opacity),
            )?),
            None => None,
        };
        if config.paths.contains(&RenderPath::Auto)
            && let Err(e) = auto_path::choose(&mut renderer, RenderPath::Auto)
        {
            progress.note(&format!("skipping {}: {e}", spec.name));
            results.skipped.push(skip(e.to_string(), e.is_bad_input()));
            progress.advance(runs.len() as u64 + 1);
            continue;
        }
        let bounds = Aabb::of_volume(loaded.volume.dims(), loaded.volume.spacing_mm());
        let cameras = super::measuring::orbit(&bounds, config.views, config.elevation_deg);
        let mut info = loaded.info;
        info.gpu_layout = renderer.volume_texture().map(|t| t.describe());
        info.labels = labelled;
        results.datasets.push(info);
        for (index, planned) in runs.iter().enumerate() {
            let s = &planned.settings;
            progress.show(&format!(
                "{} {} {} {:?} {}×{}{}",
                spec.name,
                s.mode.label(),
                s.strategy.label(),
                s.path,
                planned.size[0],
                planned.size[1],
                if planned.sweep {
                    format!(" block {}", s.leaf_block_vox())
                } else {
                    String::new()
                }
            ));
            match run::measure(
                &mut renderer,
                &spec.name,
                &spec.tf,
                planned,
                &cameras,
                // The first run after an upload warms up longer: three frames were not enough
                // right after a 512³ upload (docs/benchmarks/README.md, "Warm-up").
                if index == 0 {
                    config.warmup_frames.max(SETTLE_FRAMES)
                } else {
                    config.warmup_frames
                },
                if index == 0 {
                    run::SETTLE_TIME
                } else {
                    run::WARMUP_TIME
                },
            ) {
                Ok(record) => {
                    // Which bricks a mode held differs by mode: said once per mode.
                    let first_of_mode = index == 0 || runs[index - 1].settings.mode != s.mode;
                    if let Some(t) = renderer.volume_texture().filter(|t| t.view.bricked)
                        && first_of_mode
                    {
                        progress.note(&format!(
                            "{} {}: on the GPU: {}",
                            spec.name,
                            s.mode.label(),
                            t.describe()
                        ));
                    }
                    results.runs.push(record);
                }
                Err(e) => {
                    let what = format!(
                        "{} {} {:?} {}×{}: {e}",
                        s.mode.label(),
                        s.strategy.label(),
                        s.path,
                        planned.size[0],
                        planned.size[1]
                    );
                    progress.note(&format!("{}: {what}", spec.name));
                    results.skipped.push(skip(what, e.is_bad_input()));
                }
            }
            progress.advance(1);
        }
        progress.show(&format!("{}: rebuild times and image check", spec.name));
        let camera = &cameras[0].0;
        let checked =
            checks::rebuilds(&mut renderer, &config, spec, &loaded.tf, camera).and_then(|r| {
                results.rebuilds.extend(r);
                checks::image_checks(&mut renderer, &config, spec, camera)
            });
        match checked {
            Ok(c) => results.image_checks.extend(c),
            Err(e) => results
                .skipped
                .push(skip(format!("rebuild/image check: {e}"), e.is_bad_input())),
        }
        progress.advance(1);
        output::write_all(&out, &results, false)?;
    }
    progress.finish();
    let summary = output::write_all(&out, &results, true)?;
    finish(&out, &summary)
}

/// Prints where the results are and fails loudly when an image check failed or a dataset the
/// configuration does not mark optional was not measured (status 2 where each such dataset's
/// input was unusable, else 1), after the results are written.
fn finish(out: &Path, summary: &leapview::bench::Summary) -> Result<(), Failure> {
    eprintln!("results in {}", out.display());
    let failed: Vec<_> = summary.skipped.iter().filter(|s| !s.optional).collect();
    for s in &failed {
        eprintln!("FAILED: {}: {}", s.dataset, s.reason);
    }
    if summary.image_check_failures > 0 {
        return Err(Failure::Other(anyhow::anyhow!(
            "IMAGE CHECK FAILED: {} of {} leaping images differ from RC-t by more than 1/255 (see {})",
            summary.image_check_failures,
            summary.image_checks.len(),
            out.join("tables.md").display()
        )));
    }
    if !failed.is_empty() {
        let mut names: Vec<&str> = failed.iter().map(|s| s.dataset.as_str()).collect();
        names.dedup();
        let error = anyhow::anyhow!(
            "{} of the configuration's datasets not measured ({}): see FAILED above",
            names.len(),
            names.join(", ")
        );
        return Err(if failed.iter().all(|s| s.bad_input) {
            Failure::BadInput(error)
        } else {
            Failure::Other(error)
        });
    }
    if summary.image_checks.is_empty() {
        eprintln!("image check: no leaping images to check");
    } else {
        eprintln!(
            "image check: all {} leaping images within 1/255 of RC-t",
            summary.image_checks.len()
        );
    }
    Ok(())
}

/// `docs/benchmarks/<adapter name as a slug>[-quick]`.
fn default_out(env: &Environment) -> PathBuf {
    let mut slug: String = env
        .adapter
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect();
    while slug.contains("--") {
        slug = slug.replace("--", "-");
    }
    let slug = slug.trim_matches('-');
    let suffix = if env.quick { "-quick" } else { "" };
    PathBuf::from("docs/benchmarks").join(format!("{slug}{suffix}"))
}

/// Reads the segmentation at `path` onto `volume`'s grid and shows every segment over it in the
/// renderer; returns what the report says of it.
fn show_labels(
    renderer: &mut VolumeRenderer,
    path: &Path,
    volume: &leapview::volume::Volume,
    (view, opacity): (leapview::settings::LabelView, f64),
) -> Result<String, Failure> {
    let map = std::sync::Arc::new(crate::cli::label_args::read_labels(path, None, volume)?);
    let ctx = renderer.context();
    let gpu = leapview::render::labels::GpuLabels::new(&ctx.device, &ctx.queue, map.clone())
        .map_err(|e| Failure::BadInput(anyhow::anyhow!("{}: {e}", path.display())))?;
    let alpha = (opacity * 255.0).round() as u8;
    gpu.show_styled(&ctx.queue, &map, |s| {
        [s.colour[0], s.colour[1], s.colour[2], alpha]
    });
    renderer
        .set_labels(Some(std::sync::Arc::new(gpu)))
        .map_err(|e| Failure::BadInput(anyhow::anyhow!("{}: {e}", path.display())))?;
    Ok(format!(
        "{} ({} segments, view {view:?}, opacity {opacity})",
        map.name(),
        map.segments().len()
    ))
}
