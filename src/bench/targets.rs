//! Each leaping run against RC-t on the same dataset, mode, path and image size: what the
//! leaping loop buys (fps ratio), what it costs per sample (samples per second against RC-t's),
//! how many samples it wastes (samples over the oracle's) and how far its frame time is from the
//! oracle floor (the oracle's samples taken at RC-t's per-sample rate).

use std::fmt::Write;

use serde::{Deserialize, Serialize};

use super::stats::RunSummary;
use crate::settings::{Mode, RenderSettings, Strategy};

/// A leaping run counts as at least as fast as RC-t from this fps ratio on (2 % for the runs'
/// own spread, as issue 14 sets it).
pub const AS_FAST_AS_RC_T: f64 = 0.98;

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
    /// Its lookups in the leaping structure per ray: what it pays for the samples it removes.
    #[serde(default)]
    pub lookups_per_ray: Option<f64>,
    /// What `auto` stood for in the run (`auto` runs only).
    #[serde(default)]
    pub chose: Option<String>,
    /// Its fps over RC-t's from frames timed in pairs, one right after the other on each view
    /// (the median of RC-t's time over its own; `auto` runs that recorded pairs only).
    #[serde(default)]
    pub paired_ratio: Option<f64>,
}

impl AgainstRcT {
    /// The strategy as the tables show it: `auto → RC-t` for `auto`.
    fn strategy_cell(&self) -> String {
        match &self.chose {
            Some(c) => format!("{} → {c}", self.strategy),
            None => self.strategy.clone(),
        }
    }
}

/// Every non-sweep run of a leaping strategy or of `auto` that has an RC-t run beside it, in run
/// order.
pub(crate) fn against_rc_t(runs: &[RunSummary]) -> Vec<AgainstRcT> {
    let same = |a: &RunSummary, b: &RunSummary| {
        let (a, b) = (&a.key, &b.key);
        (&a.dataset, &a.mode, &a.path, a.width, a.height, a.sweep)
            == (&b.dataset, &b.mode, &b.path, b.width, b.height, b.sweep)
    };
    let mut rows = Vec::new();
    for run in runs.iter().filter(|r| {
        !r.key.sweep
            && (r.key.strategy.starts_with("RC-s") || r.key.strategy == Strategy::Auto.label())
    }) {
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
            lookups_per_ray: run.lookups_per_ray,
            chose: run.auto.as_ref().map(|a| a.strategy.clone()),
            paired_ratio: run.auto.as_ref().and_then(|a| {
                let mut ratios: Vec<f64> = a.paired_ms.iter().map(|[r, t]| r / t).collect();
                median(&mut ratios)
            }),
        });
    }
    rows
}

/// How the strategy a user gets by default did against RC-t over the volumes of one mode, path
/// and image size.
#[derive(Clone, Debug, PartialEq)]
pub struct DefaultAgainstRcT {
    /// Mode.
    pub mode: String,
    /// Path.
    pub path: String,
    /// Image size.
    pub size: [u32; 2],
    /// The default strategy of the mode (`RenderSettings::default()`'s, as the mode runs it).
    pub strategy: String,
    /// Volumes measured with both.
    pub volumes: usize,
    /// Volumes where its fps is at least [`AS_FAST_AS_RC_T`] × RC-t's.
    pub as_fast: usize,
    /// The median of its fps over RC-t's.
    pub median_ratio: f64,
    /// The volume where it did worst, and its ratio there.
    pub worst: (String, f64),
    /// Of the volumes with frames timed in pairs with RC-t's ([`AgainstRcT::paired_ratio`]): how
    /// many, how many at least [`AS_FAST_AS_RC_T`] × RC-t's fps that way, and the median ratio.
    pub paired: Option<(usize, usize, f64)>,
}

/// The default strategy's rows of `rows`, gathered per mode, path and size (in first-seen order).
fn default_against_rc_t(rows: &[AgainstRcT]) -> Vec<DefaultAgainstRcT> {
    let default = RenderSettings::default().strategy;
    let mut groups: Vec<(DefaultAgainstRcT, Vec<f64>, Vec<f64>)> = Vec::new();
    for row in rows {
        let Some(mode) = Mode::ALL.into_iter().find(|m| m.label() == row.mode) else {
            continue;
        };
        let strategy = default.for_mode(mode).label();
        if row.strategy != strategy {
            continue;
        }
        let found = groups
            .iter()
            .position(|(g, _, _)| (&g.mode, &g.path, g.size) == (&row.mode, &row.path, row.size));
        let index = found.unwrap_or_else(|| {
            groups.push((
                DefaultAgainstRcT {
                    mode: row.mode.clone(),
                    path: row.path.clone(),
                    size: row.size,
                    strategy: strategy.to_string(),
                    volumes: 0,
                    as_fast: 0,
                    median_ratio: f64::NAN,
                    worst: (row.dataset.clone(), f64::INFINITY),
                    paired: None,
                },
                Vec::new(),
                Vec::new(),
            ));
            groups.len() - 1
        });
        let (group, ratios, paired) = &mut groups[index];
        paired.extend(row.paired_ratio);
        group.volumes += 1;
        group.as_fast += usize::from(row.fps_ratio >= AS_FAST_AS_RC_T);
        if row.fps_ratio < group.worst.1 {
            group.worst = (row.dataset.clone(), row.fps_ratio);
        }
        ratios.push(row.fps_ratio);
    }
    groups
        .into_iter()
        .map(|(mut group, mut ratios, mut paired)| {
            group.median_ratio = median(&mut ratios).unwrap_or(f64::NAN);
            let as_fast = paired.iter().filter(|&&r| r >= AS_FAST_AS_RC_T).count();
            group.paired = median(&mut paired).map(|m| (paired.len(), as_fast, m));
            group
        })
        .collect()
}

/// The median of `values` (`None` for none).
fn median(values: &mut [f64]) -> Option<f64> {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(values[n / 2]),
        _ => Some((values[n / 2 - 1] + values[n / 2]) / 2.0),
    }
}

/// The table of [`default_against_rc_t`] in Markdown (empty without rows).
pub(crate) fn default_markdown(rows: &[AgainstRcT]) -> String {
    let groups = default_against_rc_t(rows);
    if groups.is_empty() {
        return String::new();
    }
    let mut md = format!(
        "\n## The default strategy against RC-t\n\nPer mode, path and size: the volumes where the \
         strategy a user gets by default renders at least {AS_FAST_AS_RC_T}× RC-t's fps, the \
         median of its fps over RC-t's, and the volume where it does worst, from the two runs' \
         medians; then the same count and median from frames timed in pairs, an RC-t frame and \
         one of the default's right after it on each view (`auto` runs; the runs are measured \
         apart, and at sub-millisecond frames their spread is as large as the 2 % allowed).\n\n\
         | mode | path | size | default | ≥ {AS_FAST_AS_RC_T}× RC-t | median | worst | paired ≥ \
         {AS_FAST_AS_RC_T}× | paired median |\n\
         |---|---|---|---|---:|---:|---|---:|---:|\n"
    );
    for g in groups {
        let (paired_count, paired_median) = g.paired.map_or_else(
            || ("–".to_string(), "–".to_string()),
            |(n, fast, m)| (format!("{fast} of {n}"), format!("{m:.2}")),
        );
        let _ = writeln!(
            md,
            "| {} | {} | {}×{} | {} | {} of {} | {:.2} | {} {:.2} | {paired_count} | \
             {paired_median} |",
            g.mode,
            g.path,
            g.size[0],
            g.size[1],
            g.strategy,
            g.as_fast,
            g.volumes,
            g.median_ratio,
            g.worst.0,
            g.worst.1
        );
    }
    md
}

fn opt(value: Option<f64>, digits: usize) -> String {
    value.map_or_else(|| "–".to_string(), |v| format!("{v:.digits$}"))
}

/// The table of [`against_rc_t`] in Markdown.
pub fn markdown(rows: &[AgainstRcT]) -> String {
    let mut md = String::from(
        "\n## Leaping against RC-t\n\nSame frames; rate = samples taken per second of frame time; \
         oracle floor = the oracle's samples at RC-t's rate; wall = render + read-back of the \
         image, median ms; lookups = questions the leaping loop asked of its structure per ray \
         (one per block, or cube of blocks with the distance field, entered).\n\n\
         | dataset | mode | path | size | strategy | fps / RC-t | rate / RC-t | samples / oracle \
         | floor ms | ms / floor | wall ms | RC-t wall ms | lookups / ray |\n\
         |---|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {}×{} | {} | {:.2} | {} | {} | {} | {} | {} | {} | {} |",
            r.dataset,
            r.mode,
            r.path,
            r.size[0],
            r.size[1],
            r.strategy_cell(),
            r.fps_ratio,
            opt(r.rate_ratio, 2),
            opt(r.oracle_ratio, 2),
            opt(r.floor_ms, 3),
            opt(r.over_floor, 2),
            opt(r.wall_ms, 3),
            opt(r.rct_wall_ms, 3),
            opt(r.lookups_per_ray, 1)
        );
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::record::{AutoChoice, RunKey};

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
            lookups_per_ray: None,
            step_vox: 0.5,
            tf: "t".into(),
            auto: None,
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
    fn the_default_summary_counts_the_default_strategy_only() {
        let mut rows = Vec::new();
        // Per dataset: RC-t's and auto's medians from their runs, auto's frames paired with
        // RC-t's on three views (none for "c"), and RC-s's median.
        for (dataset, rct_ms, df_ms, pairs, s_ms) in [
            ("a", 2.0, 1.0, vec![[2.0, 1.0], [2.2, 1.0], [1.8, 1.0]], 3.0),
            (
                "b",
                1.0,
                1.01,
                vec![[1.0, 1.0], [1.0, 1.03], [1.0, 0.99]],
                0.5,
            ),
            ("c", 1.0, 1.5, vec![], 0.5),
        ] {
            let mut auto = run("auto", df_ms, 2e5, 1e5);
            auto.auto = Some(AutoChoice {
                strategy: "RC-s-df".into(),
                rct_ms: Some(rct_ms),
                leaping_ms: Some(df_ms),
                choose_ms: 1.0,
                paired_ms: pairs,
            });
            let mut runs = [
                run("RC-t", rct_ms, 1e6, 1e5),
                auto,
                run("RC-s", s_ms, 2e5, 1e5),
            ];
            for r in &mut runs {
                r.key.dataset = dataset.into();
            }
            rows.extend(against_rc_t(&runs));
        }
        let groups = default_against_rc_t(&rows);
        assert_eq!(groups.len(), 1);
        let g = &groups[0];
        // DVR's default is auto (here standing for RC-s-df): 2×, 0.990× (as fast, within the
        // 2 %) and 0.667× RC-t.
        assert_eq!(g.strategy, "auto");
        assert_eq!((g.volumes, g.as_fast), (3, 2));
        assert!((g.median_ratio - 1.0 / 1.01).abs() < 1e-12);
        assert_eq!(g.worst.0, "c");
        assert!((g.worst.1 - 1.0 / 1.5).abs() < 1e-12);
        // Paired: a's per-view ratios 2.0, 2.2, 1.8 (median 2.0); b's 1.0, 0.971, 1.010
        // (median 1.0, as fast); c has none.
        let (n, fast, paired_median) = g.paired.expect("pairs");
        assert_eq!((n, fast), (2, 2));
        assert!((paired_median - 1.5).abs() < 1e-12);
        assert_eq!(rows[1].paired_ratio, None, "RC-s has no pairs");
        assert!(
            default_markdown(&rows).contains(
                "| dvr | compute | 8×8 | auto | 2 of 3 | 0.99 | c 0.67 | 2 of 2 | 1.50 |"
            )
        );
        assert!(markdown(&rows).contains("| a | dvr | compute | 8×8 | auto → RC-s-df | 2.00 |"));
        assert!(default_markdown(&[]).is_empty());
    }

    #[test]
    fn runs_without_rc_t_beside_them_are_left_out() {
        let mut other = run("RC-t", 2.0, 1e6, 1e5);
        other.key.width = 16;
        assert!(against_rc_t(&[other, run("RC-s", 1.0, 2e5, 1e5)]).is_empty());
    }
}
