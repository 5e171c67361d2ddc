//! Each leaping run against RC-t on the same dataset, mode, path and image size: what the
//! leaping loop buys (fps ratio), what it costs per sample (samples per second against RC-t's),
//! how many samples it wastes (samples over the oracle's) and how far its frame time is from the
//! oracle floor (the oracle's samples taken at RC-t's per-sample rate).

use std::fmt::Write;

use serde::{Deserialize, Serialize};

use super::stats::RunSummary;

/// One leaping run measured against RC-t.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AgainstRcT {
    /// Dataset.
    pub dataset: String,
    /// Mode.
    pub mode: String,
    /// Path.
    pub path: String,
    /// Image size.
    pub size: [u32; 2],
    /// The leaping strategy (`RC-s`, `RC-s-df`).
    pub strategy: String,
    /// Its fps over RC-t's.
    pub fps_ratio: f64,
    /// Its samples per second over RC-t's.
    pub rate_ratio: Option<f64>,
    /// Its samples over the oracle's (samples with non-zero opacity, or that changed the pixel).
    pub oracle_ratio: Option<f64>,
    /// The oracle floor: the oracle's samples at RC-t's per-sample rate, milliseconds.
    pub floor_ms: Option<f64>,
    /// Its median frame time over the floor.
    pub over_floor: Option<f64>,
    /// Its median wall time, render + read-back, milliseconds.
    pub wall_ms: Option<f64>,
    /// RC-t's median wall time, render + read-back, milliseconds.
    pub rct_wall_ms: Option<f64>,
}

/// Every non-sweep leaping run that has an RC-t run beside it, in run order.
pub fn against_rc_t(runs: &[RunSummary]) -> Vec<AgainstRcT> {
    let same = |a: &RunSummary, b: &RunSummary| {
        let (a, b) = (&a.key, &b.key);
        (&a.dataset, &a.mode, &a.path, a.width, a.height, a.sweep)
            == (&b.dataset, &b.mode, &b.path, b.width, b.height, b.sweep)
    };
    let mut rows = Vec::new();
    for run in runs
        .iter()
        .filter(|r| !r.key.sweep && r.key.strategy.starts_with("RC-s"))
    {
        let Some(rct) = runs
            .iter()
            .find(|r| r.key.strategy == "RC-t" && same(r, run))
        else {
            continue;
        };
        let rct_rate = rct.gsamples_per_s();
        let known = |v: f64| (v.is_finite() && v > 0.0).then_some(v);
        let floor_ms = known(rct_rate).map(|rate| run.visible_per_frame / (rate * 1e6));
        rows.push(AgainstRcT {
            dataset: run.key.dataset.clone(),
            mode: run.key.mode.clone(),
            path: run.key.path.clone(),
            size: [run.key.width, run.key.height],
            strategy: run.key.strategy.clone(),
            fps_ratio: run.fps / rct.fps,
            rate_ratio: known(rct_rate).map(|r| run.gsamples_per_s() / r),
            oracle_ratio: run.oracle_ratio,
            over_floor: floor_ms.and_then(known).map(|f| run.median_ms / f),
            floor_ms,
            wall_ms: run.wall_median_ms,
            rct_wall_ms: rct.wall_median_ms,
        });
    }
    rows
}

fn opt(value: Option<f64>, digits: usize) -> String {
    value.map_or_else(|| "–".to_string(), |v| format!("{v:.digits$}"))
}

/// The table of [`against_rc_t`] in Markdown.
pub fn markdown(rows: &[AgainstRcT]) -> String {
    let mut md = String::from(
        "\n## Leaping against RC-t\n\nSame frames; rate = samples taken per second of frame time; \
         oracle floor = the oracle's samples at RC-t's rate; wall = render + read-back of the \
         image, median ms.\n\n\
         | dataset | mode | path | size | strategy | fps / RC-t | rate / RC-t | samples / oracle \
         | floor ms | ms / floor | wall ms | RC-t wall ms |\n\
         |---|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {}×{} | {} | {:.2} | {} | {} | {} | {} | {} | {} |",
            r.dataset,
            r.mode,
            r.path,
            r.size[0],
            r.size[1],
            r.strategy,
            r.fps_ratio,
            opt(r.rate_ratio, 2),
            opt(r.oracle_ratio, 2),
            opt(r.floor_ms, 3),
            opt(r.over_floor, 2),
            opt(r.wall_ms, 3),
            opt(r.rct_wall_ms, 3)
        );
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::record::RunKey;

    fn run(strategy: &str, median_ms: f64, samples: f64, visible: f64) -> RunSummary {
        RunSummary {
            key: RunKey {
                dataset: "d".into(),
                mode: "dvr".into(),
                strategy: strategy.into(),
                path: "compute".into(),
                width: 8,
                height: 8,
                block_vox: 4,
                sweep: false,
            },
            frames: 3,
            median_ms,
            p95_ms: median_ms,
            fps: 1000.0 / median_ms,
            stats_median_ms: None,
            wall_median_ms: Some(median_ms + 1.0),
            samples_per_frame: samples,
            visible_per_frame: visible,
            oracle_ratio: Some(samples / visible),
            samples_per_pixel: samples / 64.0,
            leaps_per_frame: 0.0,
            step_vox: 0.5,
            tf: "t".into(),
        }
    }

    #[test]
    fn ratios_and_the_oracle_floor_follow_from_the_two_runs() {
        // RC-t: 1e6 samples in 2 ms (0.5 G/s); RC-s: 2e5 samples in 1 ms (0.2 G/s), 1e5 visible.
        let runs = [run("RC-t", 2.0, 1e6, 1e5), run("RC-s", 1.0, 2e5, 1e5)];
        let rows = against_rc_t(&runs);
        assert_eq!(rows.len(), 1);
        let r = &rows[0];
        assert!((r.fps_ratio - 2.0).abs() < 1e-12);
        assert!((r.rate_ratio.expect("rate") - 0.4).abs() < 1e-12);
        assert!((r.oracle_ratio.expect("oracle") - 2.0).abs() < 1e-12);
        // 1e5 samples at 0.5 G/s = 0.2 ms; 1 ms is 5× that.
        assert!((r.floor_ms.expect("floor") - 0.2).abs() < 1e-12);
        assert!((r.over_floor.expect("over") - 5.0).abs() < 1e-9);
        assert_eq!((r.wall_ms, r.rct_wall_ms), (Some(2.0), Some(3.0)));
        assert!(markdown(&rows).contains("| d | dvr | compute | 8×8 | RC-s | 2.00 | 0.40 |"));
    }

    #[test]
    fn runs_without_rc_t_beside_them_are_left_out() {
        let mut other = run("RC-t", 2.0, 1e6, 1e5);
        other.key.width = 16;
        assert!(against_rc_t(&[other, run("RC-s", 1.0, 2e5, 1e5)]).is_empty());
    }
}
