//! `summary.json` and `tables.md`: Table 1, Table 2, the rebuild times, the image check and the
//! environment, computed from [`BenchResults`] alone.

use std::fmt::Write;

use serde::{Deserialize, Serialize};

use super::record::{BenchResults, DatasetInfo, Environment, IMAGE_TOLERANCE, ImageCheck, Skipped};
use super::stats::{RunSummary, TABLE1_STRATEGIES, Table1Row, median, table1, table2};
use super::targets::{AgainstRcT, against_rc_t};

/// A rebuild timing summarised.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RebuildSummary {
    /// Dataset.
    pub dataset: String,
    /// Strategy.
    pub strategy: String,
    /// Block edge, voxels.
    pub block_vox: u32,
    /// Median rebuild, milliseconds.
    pub median_ms: Option<f64>,
    /// Slowest rebuild, milliseconds.
    pub max_ms: Option<f64>,
}

/// Everything `summary.json` holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Where it ran.
    pub environment: Environment,
    /// Datasets.
    pub datasets: Vec<DatasetInfo>,
    /// Every run summarised.
    pub runs: Vec<RunSummary>,
    /// Table 1.
    pub table1: Vec<Table1Row>,
    /// Every leaping run against RC-t.
    #[serde(default)]
    pub against_rc_t: Vec<AgainstRcT>,
    /// Rebuild times.
    pub rebuilds: Vec<RebuildSummary>,
    /// Image checks.
    pub image_checks: Vec<ImageCheck>,
    /// Image checks over the tolerance.
    pub image_check_failures: usize,
    /// Datasets not measured.
    pub skipped: Vec<Skipped>,
}

impl Summary {
    /// Summarises `results`.
    pub fn of(results: &BenchResults) -> Self {
        let runs: Vec<RunSummary> = results.runs.iter().filter_map(RunSummary::of).collect();
        let rebuilds = results
            .rebuilds
            .iter()
            .map(|r| RebuildSummary {
                dataset: r.dataset.clone(),
                strategy: r.strategy.clone(),
                block_vox: r.block_vox,
                median_ms: median(&r.ms),
                max_ms: r.ms.iter().copied().reduce(f64::max),
            })
            .collect();
        Self {
            environment: results.environment.clone(),
            datasets: results.datasets.clone(),
            table1: table1(&runs),
            against_rc_t: against_rc_t(&runs),
            runs,
            rebuilds,
            image_check_failures: results.image_checks.iter().filter(|c| !c.passed).count(),
            image_checks: results.image_checks.clone(),
            skipped: results.skipped.clone(),
        }
    }
}

fn opt(value: Option<f64>, digits: usize) -> String {
    value.map_or("–".into(), |v| format!("{v:.digits$}"))
}

fn percent(value: Option<f64>) -> String {
    value.map_or("–".into(), |v| format!("{:+.1} %", 100.0 * v))
}

/// The Markdown report.
pub fn markdown(summary: &Summary) -> String {
    let mut md = String::new();
    let env = &summary.environment;
    let _ = writeln!(md, "# LeapView benchmark: {}\n", env.adapter);
    if env.quick {
        let _ = writeln!(
            md,
            "**Quick run** (few views, small images, a subset of datasets and modes): for checking that the benchmark works, not for comparing GPUs.\n"
        );
    }
    if env.device_type == "Cpu" {
        let _ = writeln!(
            md,
            "**Rendered by a CPU driver ({}): these are CPU times, not GPU times.**\n",
            env.driver
        );
    }
    let failures = summary.image_check_failures;
    if failures > 0 {
        let _ = writeln!(
            md,
            "**IMAGE CHECK FAILED: {failures} of {} leaping images differ from RC-t by more than 1/255** (see the image check below).\n",
            summary.image_checks.len()
        );
    } else if !summary.image_checks.is_empty() {
        let _ = writeln!(
            md,
            "Image check: all {} leaping images are within 1/255 of RC-t.\n",
            summary.image_checks.len()
        );
    }
    for s in &summary.skipped {
        let what = if s.optional { "skipped" } else { "FAILED" };
        let _ = writeln!(md, "- Dataset {} {what}: {}", s.dataset, s.reason);
    }
    write_table1(&mut md, &summary.table1);
    md.push_str(&super::targets::default_markdown(&summary.against_rc_t));
    md.push_str(&super::targets::markdown(&summary.against_rc_t));
    write_table2(&mut md, &summary.runs);
    write_rebuilds(&mut md, &summary.rebuilds);
    write_checks(&mut md, &summary.image_checks);
    write_environment(&mut md, summary);
    md
}

fn write_table1(md: &mut String, rows: &[Table1Row]) {
    let _ = writeln!(
        md,
        "\n## Table 1: frames per second by strategy\n\nMedian over the orbit; speed-up as in the paper, (fps RC-s − fps RC-t) / fps RC-t, and as a plain ratio; oracle = RC-s samples / samples with non-zero opacity.\n"
    );
    let mut groups: Vec<(&str, &str, [u32; 2])> = Vec::new();
    for r in rows {
        let g = (r.mode.as_str(), r.path.as_str(), r.size);
        if !groups.contains(&g) {
            groups.push(g);
        }
    }
    for (mode, path, size) in groups {
        let _ = writeln!(md, "\n### {mode}, {path} path, {}×{}\n", size[0], size[1]);
        let _ = writeln!(
            md,
            "| dataset | {} | RC-s speed-up | RC-s ratio | RC-s-df speed-up | RC-s-df ratio | RC-s oracle |",
            TABLE1_STRATEGIES.map(|s| format!("{s} fps")).join(" | ")
        );
        let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
        for r in rows
            .iter()
            .filter(|r| (r.mode.as_str(), r.path.as_str(), r.size) == (mode, path, size))
        {
            let fps = r.fps.map(|f| opt(f, 1)).join(" | ");
            let _ = writeln!(
                md,
                "| {} | {fps} | {} | {}× | {} | {}× | {} |",
                r.dataset,
                percent(r.speed_up_rc_s),
                opt(r.ratio_rc_s, 2),
                percent(r.speed_up_rc_s_df),
                opt(r.ratio_rc_s_df, 2),
                opt(r.oracle_ratio_rc_s, 2)
            );
        }
    }
}

fn write_table2(md: &mut String, runs: &[RunSummary]) {
    let groups = table2(runs);
    if groups.is_empty() {
        return;
    }
    let _ = writeln!(
        md,
        "\n## Table 2: block-size sweep\n\nMedian ms per frame (fps, samples per pixel) for each block edge; best in bold.\n"
    );
    let mut blocks: Vec<u32> = groups.iter().flatten().map(|s| s.key.block_vox).collect();
    blocks.sort_unstable();
    blocks.dedup();
    let header: Vec<String> = blocks.iter().map(|b| format!("{b}³")).collect();
    let _ = writeln!(
        md,
        "| dataset | mode | strategy | path | size | {} |",
        header.join(" | ")
    );
    let _ = writeln!(md, "|---|---|---|---|---|{}", "---:|".repeat(blocks.len()));
    for g in &groups {
        let k = &g[0].key;
        let best = g.iter().map(|s| s.median_ms).fold(f64::INFINITY, f64::min);
        let cells: Vec<String> = blocks
            .iter()
            .map(|b| match g.iter().find(|s| s.key.block_vox == *b) {
                Some(s) => {
                    let cell = format!(
                        "{:.3} ({:.0} fps, {:.1} spp)",
                        s.median_ms, s.fps, s.samples_per_pixel
                    );
                    if s.median_ms == best {
                        format!("**{cell}**")
                    } else {
                        cell
                    }
                }
                None => "–".into(),
            })
            .collect();
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {}×{} | {} |",
            k.dataset,
            k.mode,
            k.strategy,
            k.path,
            k.width,
            k.height,
            cells.join(" | ")
        );
    }
}

fn write_rebuilds(md: &mut String, rebuilds: &[RebuildSummary]) {
    if rebuilds.is_empty() {
        return;
    }
    let _ = writeln!(
        md,
        "\n## Rebuild after a transfer-function change\n\nGPU time of the emptiness table and node flags (and the distance field for RC-s-df).\n\n| dataset | strategy | block | median ms | max ms |\n|---|---|---:|---:|---:|"
    );
    for r in rebuilds {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} |",
            r.dataset,
            r.strategy,
            r.block_vox,
            opt(r.median_ms, 3),
            opt(r.max_ms, 3)
        );
    }
}

fn write_checks(md: &mut String, checks: &[ImageCheck]) {
    if checks.is_empty() {
        return;
    }
    let _ = writeln!(
        md,
        "\n## Image check: leaping against RC-t\n\nOne view per dataset and mode; largest per-channel difference in 8-bit levels (limit {:.0}).\n\n| dataset | mode | path | variant | max diff (/255) | result |\n|---|---|---|---|---:|---|",
        IMAGE_TOLERANCE * 255.0
    );
    for c in checks {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.3} | {} |",
            c.dataset,
            c.mode,
            c.path,
            c.strategy,
            c.max_abs * 255.0,
            if c.passed { "pass" } else { "**FAIL**" }
        );
    }
}

fn write_environment(md: &mut String, summary: &Summary) {
    let e = &summary.environment;
    let timer = if e.gpu_timestamps {
        "GPU timestamp queries"
    } else {
        "CPU wall clock (no timestamp queries)"
    };
    let _ = writeln!(
        md,
        "\n## Environment\n\n- adapter: {} ({}, {})\n- driver: {} {}\n- timing: {timer}\n- leapview {}\n- command: `{}`\n\n| dataset | source | dims | spacing mm | type | on the GPU | TF | why |\n|---|---|---|---|---|---|---|---|",
        e.adapter, e.device_type, e.backend, e.driver, e.driver_info, e.version, e.command_line
    );
    for d in &summary.datasets {
        let _ = writeln!(
            md,
            "| {} | {} | {}×{}×{} | {:.3}, {:.3}, {:.3} | {} | {} | {} | {} |",
            d.name,
            match &d.labels {
                Some(l) => format!("{}, labels {l}", d.source),
                None => d.source.clone(),
            },
            d.dims[0],
            d.dims[1],
            d.dims[2],
            d.spacing_mm[0],
            d.spacing_mm[1],
            d.spacing_mm[2],
            d.scalar_type,
            d.gpu_layout.as_deref().unwrap_or("not recorded"),
            d.tf,
            d.why
        );
    }
}
