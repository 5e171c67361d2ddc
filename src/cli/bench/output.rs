//! Writes a benchmark's outputs: `frames.json` (everything measured), `frames.csv` (one row per
//! frame), `summary.json`, `tables.md` and the PNG plots.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;
use leapview::bench::{BenchResults, Summary};

/// Header of `frames.csv`.
const CSV_HEADER: &str = "dataset,mode,strategy,path,width,height,block_vox,sweep,view,azimuth_deg,ms,stats_ms,samples,visible_samples,rays,leaps,samples_per_pixel,wall_ms,lookups";

/// `frames.csv`: one row per timed view of every run.
pub fn frames_csv(results: &BenchResults) -> String {
    let mut csv = String::from(CSV_HEADER);
    csv.push('\n');
    for run in &results.runs {
        let k = &run.key;
        let pixels = k.width as f64 * k.height as f64;
        for f in &run.frames {
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{},{},{},{},{:.1},{:.4},{},{},{},{},{},{:.3},{},{}",
                k.dataset,
                k.mode,
                k.strategy,
                k.path,
                k.width,
                k.height,
                k.block_vox,
                k.sweep,
                f.view,
                f.azimuth_deg,
                f.ms,
                f.stats_ms.map_or(String::new(), |m| format!("{m:.4}")),
                f.samples,
                f.visible_samples,
                f.rays,
                f.leaps,
                f.samples as f64 / pixels,
                f.wall_ms.map_or(String::new(), |m| format!("{m:.4}")),
                f.lookups.map_or(String::new(), |l| l.to_string())
            );
        }
    }
    csv
}

fn write(path: PathBuf, text: &str) -> anyhow::Result<PathBuf> {
    std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
    Ok(path)
}

/// Writes the data files and tables into `out` (creating it); with `plots`, the PNGs too.
/// Returns the summary.
pub fn write_all(out: &Path, results: &BenchResults, plots: bool) -> anyhow::Result<Summary> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let summary = Summary::of(results);
    write(out.join("frames.json"), &serde_json::to_string(results)?)?;
    write(out.join("frames.csv"), &frames_csv(results))?;
    write(
        out.join("summary.json"),
        &serde_json::to_string_pretty(&summary)?,
    )?;
    write(
        out.join("tables.md"),
        &leapview::bench::tables::markdown(&summary),
    )?;
    if plots {
        super::plots::draw_all(out, &summary, results)?;
    }
    Ok(summary)
}

/// Reads `frames.json` from each of `dirs` and merges them.
pub fn merge(dirs: &[PathBuf]) -> anyhow::Result<BenchResults> {
    let mut merged = BenchResults::default();
    for dir in dirs {
        let path = dir.join("frames.json");
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        let results: BenchResults = serde_json::from_str(&text)
            .with_context(|| format!("{} is not a benchmark's frames.json", path.display()))?;
        merged.merge(results);
    }
    Ok(merged)
}
