//! Figures of a run (median and p95 frame time, fps, samples per pixel, the oracle ratio) and of
//! the paper's tables: Table 1 (fps of each strategy and RC-s's speed-up over RC-t per dataset)
//! and Table 2 (the block-size sweep).

use serde::{Deserialize, Serialize};

use super::record::{AutoChoice, RunKey, RunRecord};
use crate::counters::FrameCounters;

/// The `q`-quantile (0..1) by nearest rank of `values`; `None` when empty.
pub fn quantile(values: &[f64], q: f64) -> Option<f64> {
    let mut sorted: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if sorted.is_empty() {
        return None;
    }
    sorted.sort_by(f64::total_cmp);
    let rank = (q.clamp(0.0, 1.0) * sorted.len() as f64).ceil() as usize;
    Some(sorted[rank.clamp(1, sorted.len()) - 1])
}

/// The median (the lower middle value for an even count, so it is always a measured frame).
pub fn median(values: &[f64]) -> Option<f64> {
    quantile(values, 0.5)
}

/// The paper's speed-up of `fps` over `base_fps`: `(fps − base) / base`.
pub fn speed_up(fps: f64, base_fps: f64) -> f64 {
    (fps - base_fps) / base_fps
}

/// One run summarised.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    /// What was run.
    pub key: RunKey,
    /// Frames timed.
    pub frames: usize,
    /// Median frame time, milliseconds.
    pub median_ms: f64,
    /// 95th-percentile frame time, milliseconds.
    pub p95_ms: f64,
    /// Frames per second at the median time.
    pub fps: f64,
    /// Median frame time of the statistics variant, milliseconds.
    pub stats_median_ms: Option<f64>,
    /// Median wall time of render + read-back, milliseconds (where it was measured).
    #[serde(default)]
    pub wall_median_ms: Option<f64>,
    /// Samples taken per frame, averaged over the views.
    #[serde(default)]
    pub samples_per_frame: f64,
    /// Samples with non-zero opacity (the oracle's samples) per frame, averaged over the views.
    #[serde(default)]
    pub visible_per_frame: f64,
    /// Samples per pixel, averaged over the views.
    pub samples_per_pixel: f64,
    /// Samples over the oracle's samples (non-zero opacity), over all views.
    pub oracle_ratio: Option<f64>,
    /// Empty regions leapt per frame.
    pub leaps_per_frame: f64,
    /// Lookups in the leaping structure per ray (`None` without rays, or in records made before
    /// lookups were counted).
    #[serde(default)]
    pub lookups_per_ray: Option<f64>,
    /// Sample step, voxels.
    pub step_vox: f64,
    /// Transfer function.
    pub tf: String,
    /// What `auto` stood for (runs of the `auto` strategy only).
    #[serde(default)]
    pub auto: Option<AutoChoice>,
}

impl RunSummary {
    /// Samples taken per second of frame time, in billions (the loop's per-sample rate).
    pub(crate) fn gsamples_per_s(&self) -> f64 {
        self.samples_per_frame / (self.median_ms * 1e6)
    }

    /// Summarises `run`; `None` when it has no frames.
    pub fn of(run: &RunRecord) -> Option<Self> {
        let times: Vec<f64> = run.frames.iter().map(|f| f.ms).collect();
        let stats: Vec<f64> = run.frames.iter().filter_map(|f| f.stats_ms).collect();
        let walls: Vec<f64> = run.frames.iter().filter_map(|f| f.wall_ms).collect();
        let median_ms = median(&times)?;
        let mut total = FrameCounters::default();
        for f in &run.frames {
            total.add(&FrameCounters {
                samples: f.samples,
                visible_samples: f.visible_samples,
                rays: f.rays,
                leaps: f.leaps,
                lookups: f.lookups.unwrap_or(0),
                ..FrameCounters::default()
            });
        }
        let n = run.frames.len();
        Some(Self {
            key: run.key.clone(),
            frames: n,
            median_ms,
            p95_ms: quantile(&times, 0.95).unwrap_or(median_ms),
            fps: 1000.0 / median_ms,
            stats_median_ms: median(&stats),
            wall_median_ms: median(&walls),
            samples_per_frame: total.samples as f64 / n as f64,
            visible_per_frame: total.visible_samples as f64 / n as f64,
            samples_per_pixel: total.samples_per_pixel([run.key.width, run.key.height], n),
            oracle_ratio: total.oracle_ratio(),
            leaps_per_frame: total.leaps as f64 / n as f64,
            lookups_per_ray: (total.rays > 0 && run.frames.iter().all(|f| f.lookups.is_some()))
                .then(|| total.lookups as f64 / total.rays as f64),
            step_vox: run.step_vox,
            tf: run.tf.clone(),
            auto: run.auto.clone(),
        })
    }
}

/// The strategies' names in Table 1's column order.
pub const TABLE1_STRATEGIES: [&str; 4] = ["RC", "RC-t", "RC-s", "RC-s-df"];

/// One row of Table 1: a dataset under one mode, path and image size.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Table1Row {
    /// Dataset.
    pub dataset: String,
    /// Mode.
    pub mode: String,
    /// Path.
    pub path: String,
    /// Image size.
    pub size: [u32; 2],
    /// Fps per strategy, in [`TABLE1_STRATEGIES`] order (`None` where not run).
    pub fps: [Option<f64>; 4],
    /// RC-s over RC-t as in the paper: `(fps RC-s − fps RC-t) / fps RC-t`.
    pub speed_up_rc_s: Option<f64>,
    /// RC-s over RC-t as a plain ratio `fps RC-s / fps RC-t`.
    pub ratio_rc_s: Option<f64>,
    /// RC-s-df over RC-t, as in the paper.
    pub speed_up_rc_s_df: Option<f64>,
    /// RC-s-df over RC-t as a plain ratio.
    pub ratio_rc_s_df: Option<f64>,
    /// RC-s's samples over the oracle's.
    pub oracle_ratio_rc_s: Option<f64>,
}

/// Table 1 from the non-sweep runs, one row per dataset × mode × path × size, in run order.
pub fn table1(summaries: &[RunSummary]) -> Vec<Table1Row> {
    let mut rows: Vec<Table1Row> = Vec::new();
    for s in summaries.iter().filter(|s| !s.key.sweep) {
        let k = &s.key;
        let size = [k.width, k.height];
        let Some(column) = TABLE1_STRATEGIES.iter().position(|n| *n == k.strategy) else {
            continue;
        };
        let same = |r: &Table1Row| {
            r.dataset == k.dataset && r.mode == k.mode && r.path == k.path && r.size == size
        };
        let index = match rows.iter().position(same) {
            Some(i) => i,
            None => {
                rows.push(Table1Row {
                    dataset: k.dataset.clone(),
                    mode: k.mode.clone(),
                    path: k.path.clone(),
                    size,
                    fps: [None; 4],
                    speed_up_rc_s: None,
                    ratio_rc_s: None,
                    speed_up_rc_s_df: None,
                    ratio_rc_s_df: None,
                    oracle_ratio_rc_s: None,
                });
                rows.len() - 1
            }
        };
        rows[index].fps[column] = Some(s.fps);
        if k.strategy == "RC-s" {
            rows[index].oracle_ratio_rc_s = s.oracle_ratio;
        }
    }
    for row in &mut rows {
        let (rct, rcs, df) = (row.fps[1], row.fps[2], row.fps[3]);
        row.speed_up_rc_s = rct.zip(rcs).map(|(t, s)| speed_up(s, t));
        row.ratio_rc_s = rct.zip(rcs).map(|(t, s)| s / t);
        row.speed_up_rc_s_df = rct.zip(df).map(|(t, s)| speed_up(s, t));
        row.ratio_rc_s_df = rct.zip(df).map(|(t, s)| s / t);
    }
    rows
}

/// Table 2: the sweep's runs, grouped by dataset, mode, strategy and path, blocks ascending.
pub fn table2(summaries: &[RunSummary]) -> Vec<Vec<&RunSummary>> {
    let mut groups: Vec<Vec<&RunSummary>> = Vec::new();
    for s in summaries.iter().filter(|s| s.key.sweep) {
        let k = &s.key;
        let same = |g: &Vec<&RunSummary>| {
            let o = &g[0].key;
            (&o.dataset, &o.mode, &o.strategy, &o.path, o.width, o.height)
                == (&k.dataset, &k.mode, &k.strategy, &k.path, k.width, k.height)
        };
        match groups.iter_mut().find(|g| same(g)) {
            Some(g) => g.push(s),
            None => groups.push(vec![s]),
        }
    }
    for g in &mut groups {
        g.sort_by_key(|s| s.key.block_vox);
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_are_measured_values() {
        let v = [5.0, 1.0, 3.0, 2.0, 4.0];
        assert_eq!(median(&v), Some(3.0));
        assert_eq!(quantile(&v, 0.95), Some(5.0));
        assert_eq!(quantile(&v, 0.0), Some(1.0));
        assert_eq!(median(&[2.0, 1.0]), Some(1.0));
        assert_eq!(median(&[]), None);
    }

    #[test]
    fn speed_up_is_the_papers() {
        // The paper's engine row: RC-t 10 fps, RC-s 16.9 fps → 69 %.
        assert!((speed_up(16.9, 10.0) - 0.69).abs() < 1e-12);
        assert_eq!(speed_up(10.0, 10.0), 0.0);
    }
}
