//! `leapview shaders`: the driver's statistics of each ray-casting variant (registers,
//! instructions, spills), one row per variant and executable, for the variants the window and
//! the benchmark use (their default settings, the given modes, strategies, paths and image
//! sizes): compute pipelines, and the fragment path's graphics pipelines (the proxy's vertex
//! stage and the ray loop's fragment stage).

use anyhow::anyhow;
use leapview::render::PipelineKey;
use leapview::render::pipeline_stats::{Executable, PipelineStatsError, Stages, StatsDevice};
use leapview::render::raycast::variant::{COMPUTE_ENTRY, FRAGMENT_ENTRY, PROXY_VERTEX_ENTRY};
use leapview::settings::effects::Shading;
use leapview::settings::{ConcretePath, Mode, RenderPath, RenderSettings, Strategy};

use super::Failure;
use super::args::ShadersArgs;
use super::text::{outln, print_stdout};
use crate::cli::OrFail;

/// The fragment path's pipeline: the proxy's vertex stage and the ray loop's fragment stage.
const FRAGMENT_STAGES: Stages<'static> = Stages::Graphics {
    vertex: PROXY_VERTEX_ENTRY,
    fragment: FRAGMENT_ENTRY,
};

/// One variant and what the driver said of it.
#[derive(serde::Serialize)]
struct Row {
    mode: &'static str,
    strategy: &'static str,
    path: &'static str,
    /// The image size the variant is for (`None`: any; the fragment path's do not depend on it).
    size: Option<[u32; 2]>,
    /// Rays split into parts (images up to 2^19 pixels).
    split: bool,
    /// The preprocessor symbols it was compiled with.
    defines: Vec<&'static str>,
    executables: Vec<Executable>,
}

/// A variant and the image size it is for (`None` where it does not depend on it).
type Variant = (PipelineKey, Option<[u32; 2]>);

/// The distinct variants asked for, in the order asked (by path, then size, mode and strategy).
fn variants(args: &ShadersArgs) -> Result<Vec<Variant>, Failure> {
    let mut keys: Vec<Variant> = Vec::new();
    for &path in &args.paths {
        let path = match path {
            RenderPath::Compute => ConcretePath::Compute,
            RenderPath::Fragment => ConcretePath::Fragment,
            RenderPath::Auto => {
                return Err(Failure::BadInput(anyhow!(
                    "--paths takes compute and fragment: auto chooses between them when rendering"
                )));
            }
        };
        // Distinct within a path (`variants_on`); the path is part of the key.
        let on_compute = path == ConcretePath::Compute;
        keys.extend(
            variants_on(args, path)
                .into_iter()
                .map(|(key, size)| (key, on_compute.then_some(size))),
        );
    }
    Ok(keys)
}

/// The distinct variants asked for on `path`, in the order asked.
fn variants_on(args: &ShadersArgs, path: ConcretePath) -> Vec<(PipelineKey, [u32; 2])> {
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
            // `auto` runs one of two variants: both.
            let concrete = strategies.iter().flat_map(|&s| match s {
                Strategy::Auto => vec![Strategy::RcT, Strategy::leaping(mode)],
                s => vec![s],
            });
            for strategy in concrete {
                let mut settings = RenderSettings {
                    mode,
                    strategy,
                    ..RenderSettings::default()
                };
                if args.unlit {
                    settings.shading = Shading::Off;
                }
                let key =
                    PipelineKey::new(&settings, path, false, size).for_volume(false, args.bricked);
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
    let variants = variants(args)?;
    let device = StatsDevice::open(args.device.as_deref()).map_err(|e| match e {
        PipelineStatsError::NoSuchDevice { .. } => Failure::BadInput(e.into()),
        other => Failure::Other(other.into()),
    })?;
    let mut rows = Vec::new();
    for (key, size) in variants {
        let source = key.source().failed()?;
        let (stages, path) = match key.path {
            ConcretePath::Compute => (Stages::Compute(COMPUTE_ENTRY), "compute"),
            ConcretePath::Fragment => (FRAGMENT_STAGES, "fragment"),
        };
        let executables = device.statistics(&source, stages).map_err(|e| {
            Failure::Other(anyhow!(
                "{} {} {path}: {e}",
                key.mode.label(),
                key.strategy.label()
            ))
        })?;
        rows.push(Row {
            mode: key.mode.label(),
            strategy: key.strategy.label(),
            path,
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
        let mut text = serde_json::to_string_pretty(&value).failed()?;
        text.push('\n');
        text
    } else {
        table(device.name(), device.driver(), &rows)
    };
    print_stdout(&text).failed()
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
        "Ray-casting variants on {device} ({driver}), as the driver compiled them (the fragment \
         path's for any image size):\n"
    );
    outln!(
        out,
        "| mode | strategy | path | size | split | executable | subgroup | {} |",
        names.join(" | ")
    );
    outln!(
        out,
        "|---|---|---|---|---|---|---:|{}",
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
            let size = row
                .size
                .map_or_else(|| "any".to_string(), |[w, h]| format!("{w}×{h}"));
            outln!(
                out,
                "| {} | {} | {} | {} | {} | {} | {} | {} |",
                row.mode,
                row.strategy,
                row.path,
                size,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_lists_the_two_variants_it_chooses_between() {
        let args = ShadersArgs {
            modes: vec![Mode::Dvr, Mode::Mip],
            strategies: vec![Strategy::Auto],
            sizes: vec![[512, 512]],
            unlit: false,
            bricked: false,
            paths: vec![RenderPath::Compute],
            device: None,
            json: false,
        };
        let strategies: Vec<_> = variants_on(&args, ConcretePath::Compute)
            .iter()
            .map(|(k, _)| (k.mode, k.strategy))
            .collect();
        assert_eq!(
            strategies,
            [
                (Mode::Dvr, Strategy::RcT),
                (Mode::Dvr, Strategy::RcSDistance),
                (Mode::Mip, Strategy::RcT),
                (Mode::Mip, Strategy::RcS),
            ]
        );
    }
}
