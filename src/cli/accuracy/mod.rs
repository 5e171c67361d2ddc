//! `leapview accuracy`: for every quality knob, the GPU time and the error against a reference
//! image, per dataset; writes `results.json`, `results.csv`, `tables.md` and one Pareto plot
//! per dataset into the output folder (after each dataset, so an interrupted run keeps what it
//! measured).

pub mod args;
mod measure;
mod plot;

use std::path::Path;

use leapview::accuracy::Measurement;
use leapview::accuracy::results::{csv, markdown_table};
use leapview::bench::BenchConfig;
use leapview::bench::record::Environment;
use leapview::camera::Aabb;
use leapview::render::{GpuContext, VolumeRenderer};
use leapview::settings::{RenderSettings, Strategy};
use leapview::transfer::TransferFunction;
use leapview::transfer::presets::preset;
use leapview::volume::{ValueRange, synthetic::shepp_logan};
use serde::{Deserialize, Serialize};

pub use args::AccuracyArgs;

use super::Failure;
use super::datasets;
use super::measuring::{environment, orbit};
use crate::cli::OrFail;
use measure::{Dataset, Method, NotMeasured};

/// Name of the generated phantom measured against the f64 CPU reference.
const PHANTOM: &str = "phantom";
/// Edge of the phantom in voxels: small enough for the CPU reference at 1/16-voxel steps.
const PHANTOM_VOX: u32 = 48;
/// Largest image of the phantom (its reference runs on the CPU).
const PHANTOM_SIZE: u32 = 128;
/// Elevation of the views, degrees (as the benchmark's orbit).
const ELEVATION_DEG: f64 = 20.0;

/// What `results.json` holds.
#[derive(Serialize)]
struct Report<'a> {
    environment: &'a Environment,
    size: [u32; 2],
    views: u32,
    frames: u32,
    measurements: &'a [Measurement],
    not_measured: &'a [NotMeasured],
}

/// `results.json` read back (for --redraw).
#[derive(Deserialize)]
struct SavedReport {
    environment: Environment,
    size: [u32; 2],
    views: u32,
    frames: u32,
    measurements: Vec<Measurement>,
    not_measured: Vec<NotMeasured>,
}

/// Rewrites the tables and plots of `results` into `out`.
fn redraw(results: &Path, out: &Path) -> Result<(), Failure> {
    let text = std::fs::read_to_string(results)
        .map_err(|e| Failure::BadInput(anyhow::anyhow!("reading {}: {e}", results.display())))?;
    let r: SavedReport = serde_json::from_str(&text).map_err(|e| {
        Failure::BadInput(anyhow::anyhow!(
            "{} is not an accuracy report: {e}",
            results.display()
        ))
    })?;
    std::fs::create_dir_all(out)
        .map_err(|e| Failure::Other(anyhow::anyhow!("creating {}: {e}", out.display())))?;
    write(
        out,
        &r.environment,
        (r.size, r.views, r.frames),
        &r.measurements,
        &r.not_measured,
    )
}

/// Runs the command.
pub fn run(args: AccuracyArgs) -> Result<(), Failure> {
    if let Some(results) = &args.redraw {
        return redraw(results, &args.out);
    }
    let bad = |e: anyhow::Error| Failure::BadInput(e);
    let config = BenchConfig::load(&args.config).map_err(|e| bad(e.into()))?;
    let config_dir = args.config.parent().unwrap_or(Path::new(".")).to_path_buf();
    let wanted = |name: &str| {
        args.datasets
            .as_ref()
            .is_none_or(|names| names.iter().any(|n| n == name))
    };
    if let Some(names) = &args.datasets
        && let Some(unknown) = names
            .iter()
            .find(|n| *n != PHANTOM && !config.datasets.iter().any(|d| &d.name == *n))
    {
        return Err(bad(anyhow::anyhow!(
            "no dataset {unknown:?} in {} (nor the generated {PHANTOM:?})",
            args.config.display()
        )));
    }
    let (size, views, frames) = if args.quick {
        ([96, 96], 1, 1)
    } else {
        (args.size, args.views.max(1), args.frames.max(1))
    };
    let ctx = GpuContext::headless().failed()?;
    let env = environment(&ctx, args.quick);
    let max_3d = ctx.limits.max_texture_dimension_3d;
    let mut renderer = VolumeRenderer::new(ctx).failed()?;
    std::fs::create_dir_all(&args.out)
        .map_err(|e| Failure::Other(anyhow::anyhow!("creating {}: {e}", args.out.display())))?;
    eprintln!(
        "leapview accuracy on {} → {}",
        env.adapter,
        args.out.display()
    );
    let mut all = Vec::new();
    let mut not_measured = Vec::new();
    let mut progress = |what: &str| eprintln!("  {what}");

    if wanted(PHANTOM) {
        let volume = shepp_logan(PHANTOM_VOX).failed()?;
        let tf = preset("ct-bone").failed()?;
        let phantom_size = size.map(|s| s.min(PHANTOM_SIZE));
        let data = Dataset {
            name: PHANTOM,
            volume: &volume,
            tf: &tf,
            cpu_reference: true,
        };
        measure_one(
            &mut renderer,
            &data,
            None,
            (phantom_size, views, frames, args.path),
            (&mut all, &mut not_measured),
            &mut progress,
        )?;
        write(&args.out, &env, (size, views, frames), &all, &not_measured)?;
    }
    if !args.quick {
        for spec in config.datasets.iter().filter(|d| wanted(&d.name)) {
            progress(&format!("{}: loading", spec.name));
            let loaded = match datasets::load(spec, &args.data_dir, &config_dir, max_3d) {
                Ok(l) => l,
                Err(e) => {
                    not_measured.push(NotMeasured {
                        what: spec.name.clone(),
                        why: format!("{e:#}"),
                    });
                    continue;
                }
            };
            if let Err(e) = renderer.set_volume(&loaded.volume) {
                not_measured.push(NotMeasured {
                    what: spec.name.clone(),
                    why: e.to_string(),
                });
                continue;
            }
            let data = Dataset {
                name: &spec.name,
                volume: &loaded.volume,
                tf: &loaded.tf,
                cpu_reference: false,
            };
            measure_one(
                &mut renderer,
                &data,
                spec.iso_value,
                (size, views, frames, args.path),
                (&mut all, &mut not_measured),
                &mut progress,
            )?;
            write(&args.out, &env, (size, views, frames), &all, &not_measured)?;
        }
    }
    for n in &not_measured {
        eprintln!("not measured: {}: {}", n.what, n.why);
    }
    eprintln!("wrote {}", args.out.display());
    Ok(())
}

/// Measures `data` over an orbit and appends its measurements.
fn measure_one(
    renderer: &mut VolumeRenderer,
    data: &Dataset,
    iso_value: Option<f64>,
    (size, views, frames, path): ([u32; 2], u32, u32, leapview::settings::RenderPath),
    (all, not_measured): (&mut Vec<Measurement>, &mut Vec<NotMeasured>),
    progress: &mut dyn FnMut(&str),
) -> Result<(), Failure> {
    let volume = data.volume;
    let bounds = Aabb::of_volume(volume.dims(), volume.spacing_mm());
    let cameras: Vec<_> = orbit(&bounds, views, ELEVATION_DEG)
        .into_iter()
        .map(|(c, _)| c)
        .collect();
    // One strategy for every variant, the leaping one `auto` stands for untimed: a choice timed
    // per variant would put a change of strategy on the time axis beside the knob's own cost.
    let mut base = RenderSettings {
        path,
        strategy: Strategy::RcSDistance,
        ..RenderSettings::default()
    };
    base.iso.value =
        Some(iso_value.unwrap_or_else(|| iso_of(data.tf, volume.normalization_range())));
    let method = Method {
        base,
        cameras: &cameras,
        size,
        frames,
    };
    // The dataset's own transfer function, then a thin shell around the iso value: the sharp
    // feature large steps alias and pre-integration is for.
    let range = volume.normalization_range();
    let thin = thin_shell(
        data.tf,
        base.iso.value.unwrap_or(range.denormalize(0.5)),
        range,
    );
    let thin_name = format!("{}-thin", data.name);
    let runs = [
        *data,
        Dataset {
            name: &thin_name,
            tf: &thin,
            ..*data
        },
    ];
    for run in &runs {
        let (measured, skipped) = measure::measure(renderer, run, &method, progress)
            .map_err(|e| Failure::Other(anyhow::anyhow!("{}: {e}", run.name)))?;
        all.extend(measured);
        not_measured.extend(skipped.into_iter().map(|n| NotMeasured {
            what: format!("{}: {}", run.name, n.what),
            why: n.why,
        }));
    }
    Ok(())
}

/// Half-width of the thin shell, as a share of the value range.
const THIN_HALF_WIDTH: f64 = 0.005;

/// A shell one hundredth of the value range wide around `iso` (peak opacity 0.9 per voxel), in
/// `tf`'s colour there.
fn thin_shell(tf: &TransferFunction, iso: f64, range: ValueRange) -> TransferFunction {
    let w = THIN_HALF_WIDTH * range.width();
    let [r, g, b] = tf.color_at(iso, range);
    TransferFunction {
        opacity: vec![[iso - w, 0.0], [iso, 0.9], [iso + w, 0.0]],
        color: vec![[iso, r, g, b]],
        space: leapview::transfer::ValueSpace::Data,
    }
}

/// An iso value for a dataset without one: where the transfer function first reaches half its
/// largest opacity (the surface the DVR image shows).
fn iso_of(tf: &TransferFunction, range: ValueRange) -> f64 {
    let values: Vec<f64> = (0..=1024)
        .map(|i| range.denormalize(i as f64 / 1024.0))
        .collect();
    let peak = values
        .iter()
        .map(|&v| tf.opacity_at(v, range))
        .fold(0.0, f64::max);
    values
        .iter()
        .copied()
        .find(|&v| tf.opacity_at(v, range) >= 0.5 * peak && peak > 0.0)
        .unwrap_or_else(|| range.denormalize(0.5))
}

/// Writes results.json, results.csv, tables.md and the plots.
fn write(
    out: &Path,
    env: &Environment,
    (size, views, frames): ([u32; 2], u32, u32),
    all: &[Measurement],
    not_measured: &[NotMeasured],
) -> Result<(), Failure> {
    let io = |path: &Path, e: std::io::Error| {
        Failure::Other(anyhow::anyhow!("writing {}: {e}", path.display()))
    };
    let report = Report {
        environment: env,
        size,
        views,
        frames,
        measurements: all,
        not_measured,
    };
    let json = serde_json::to_string_pretty(&report).failed()?;
    let path = out.join("results.json");
    std::fs::write(&path, json).map_err(|e| io(&path, e))?;
    let path = out.join("results.csv");
    std::fs::write(&path, csv(all)).map_err(|e| io(&path, e))?;
    let mut md = format!(
        "# Accuracy against time\n\nAdapter: **{}** ({}, {}), GPU timestamps: {}. Images {}×{} \
         (the phantom at most {PHANTOM_SIZE}²), {views} views, median of {frames} frames per \
         view. Command: `{}`.\n\nError: against the reference (f64 CPU ray caster for the \
         phantom; a GPU render for the scans; both at 1/16-voxel steps, \
         pre-integrated, without early termination, fourth-order gradients, {} iso refinement \
         steps, f32 texels on the GPU), over all views. ● = on the Pareto front \
         (DVR rows and isosurface rows separately).\n",
        env.adapter,
        env.backend,
        env.driver,
        env.gpu_timestamps,
        size[0],
        size[1],
        env.command_line,
        leapview::settings::effects::MAX_ISO_REFINEMENT,
    );
    let mut names: Vec<&str> = all.iter().map(|m| m.dataset.as_str()).collect();
    names.dedup();
    for name in &names {
        let rows: Vec<&Measurement> = all.iter().filter(|m| m.dataset == *name).collect();
        md.push_str(&format!("\n## {name}\n\n![{name}](pareto-{name}.png)\n\n"));
        md.push_str(&markdown_table(&rows));
        plot::draw(&out.join(format!("pareto-{name}.png")), name, &rows).map_err(Failure::Other)?;
    }
    if !not_measured.is_empty() {
        md.push_str("\n## Not measured\n\n");
        for n in not_measured {
            md.push_str(&format!("- {}: {}\n", n.what, n.why));
        }
    }
    let path = out.join("tables.md");
    std::fs::write(&path, md).map_err(|e| io(&path, e))?;
    Ok(())
}
