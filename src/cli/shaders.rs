//! `leapview shaders`: the driver's statistics of each compute ray-casting variant (registers,
//! instructions, spills), one row per variant, for the variants the window and the benchmark
//! use (their default settings, the given modes, strategies and image sizes).

use anyhow::anyhow;
use leapview::render::PipelineKey;
use leapview::render::pipeline_stats::{Executable, PipelineStatsError, StatsDevice};
use leapview::render::raycast::variant::COMPUTE_ENTRY;
use leapview::settings::effects::Shading;
use leapview::settings::{ConcretePath, Mode, RenderSettings, Strategy};

use super::Failure;
use super::args::ShadersArgs;
use super::text::{outln, print_stdout};

/// One variant and what the driver said of it.
#[derive(serde::Serialize)]
struct Row {
    mode: &'static str,
    strategy: &'static str,
    size: [u32; 2],
    /// Rays split into parts (images up to 2^19 pixels).
    split: bool,
    /// The preprocessor symbols it was compiled with.
    defines: Vec<&'static str>,
    executables: Vec<Executable>,
}

/// The distinct variants asked for, in the order asked.
fn variants(args: &ShadersArgs) -> Vec<(PipelineKey, [u32; 2])> {
    let modes = if args.modes.is_empty() {
        Mode::ALL.to_vec()
    } else {
        args.modes.clone()
    };
    let strategies = if args.strategies.is_empty() {
        vec![Strategy::RcT, Strategy::RcS, Strategy::RcSDistance]
    } else {
        args.strategies.clone()
    };
    let mut keys: Vec<(PipelineKey, [u32; 2])> = Vec::new();
    for &size in &args.sizes {
        for &mode in &modes {
            for &strategy in &strategies {
                let mut settings = RenderSettings {
                    mode,
                    strategy,
                    ..RenderSettings::default()
                };
                if args.unlit {
                    settings.shading = Shading::Off;
                }
                let key = PipelineKey::new(&settings, ConcretePath::Compute, false, size);
                if !keys.iter().any(|(k, _)| *k == key) {
                    keys.push((key, size));
                }
            }
        }
    }
    keys
}

/// Runs the command.
pub fn run(args: &ShadersArgs) -> Result<(), Failure> {
    let device = StatsDevice::open(args.device.as_deref()).map_err(|e| match e {
        PipelineStatsError::NoSuchDevice { .. } => Failure::BadInput(e.into()),
        other => Failure::Other(other.into()),
    })?;
    let mut rows = Vec::new();
    for (key, size) in variants(args) {
        let source = key.source().map_err(|e| Failure::Other(e.into()))?;
        let executables = device
            .compute_statistics(&source, COMPUTE_ENTRY)
            .map_err(|e| {
                Failure::Other(anyhow!(
                    "{} {}: {e}",
                    key.mode.label(),
                    key.strategy.label()
                ))
            })?;
        rows.push(Row {
            mode: key.mode.label(),
            strategy: key.strategy.label(),
            size,
            split: key.split,
            defines: key.defines(),
            executables,
        });
    }
    let text = if args.json {
        let value = serde_json::json!({
            "device": device.name(),
            "driver": device.driver(),
            "variants": rows,
        });
        let mut text =
            serde_json::to_string_pretty(&value).map_err(|e| Failure::Other(e.into()))?;
        text.push('\n');
        text
    } else {
        table(device.name(), device.driver(), &rows)
    };
    print_stdout(&text).map_err(|e| Failure::Other(e.into()))
}

/// A Markdown table: a row per variant (and executable, where a pipeline has more than one), a
/// column per statistic, in the order the driver first gave them.
fn table(device: &str, driver: &str, rows: &[Row]) -> String {
    let mut names: Vec<&str> = Vec::new();
    for row in rows {
        for exe in &row.executables {
            for s in &exe.statistics {
                if !names.contains(&s.name.as_str()) {
                    names.push(&s.name);
                }
            }
        }
    }
    let mut out = String::new();
    outln!(
        out,
        "Compute ray-casting variants on {device} ({driver}), as the driver compiled them:\n"
    );
    outln!(
        out,
        "| mode | strategy | size | split | executable | subgroup | {} |",
        names.join(" | ")
    );
    outln!(
        out,
        "|---|---|---|---|---|---:|{}",
        "---:|".repeat(names.len())
    );
    for row in rows {
        for exe in &row.executables {
            let values: Vec<String> = names
                .iter()
                .map(|name| {
                    exe.statistics
                        .iter()
                        .find(|s| s.name == *name)
                        .map_or_else(|| "–".to_string(), |s| s.value.to_string())
                })
                .collect();
            outln!(
                out,
                "| {} | {} | {}×{} | {} | {} | {} | {} |",
                row.mode,
                row.strategy,
                row.size[0],
                row.size[1],
                if row.split { "yes" } else { "no" },
                exe.name,
                exe.subgroup_size,
                values.join(" | ")
            );
        }
    }
    if let Some(first) = rows.first().and_then(|r| r.executables.first()) {
        outln!(out, "\nWhat the driver means by each:");
        for s in &first.statistics {
            outln!(out, "- {}: {}", s.name, s.description);
        }
    }
    out
}
