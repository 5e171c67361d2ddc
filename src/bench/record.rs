//! What a benchmark run records: the environment, each dataset, every frame of every run, the
//! rebuild timings and the image checks. `frames.json` is [`BenchResults`] as it is, so a report
//! can be redrawn (or several partial runs merged) without rendering again.

use serde::{Deserialize, Serialize};

/// Where and how the benchmark ran.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Environment {
    /// Adapter name.
    pub adapter: String,
    /// Adapter type (discrete GPU, CPU, …).
    pub device_type: String,
    /// Graphics backend (Vulkan, GL, …).
    pub backend: String,
    /// Driver name.
    pub driver: String,
    /// Driver version information.
    pub driver_info: String,
    /// Whether frame times come from GPU timestamp queries (otherwise CPU wall clock).
    pub gpu_timestamps: bool,
    /// The command line that produced the results.
    pub command_line: String,
    /// Whether this was a `--quick` run.
    pub quick: bool,
    /// LeapView version.
    pub version: String,
    /// Seconds since the Unix epoch when the run started.
    pub started_unix_s: u64,
}

/// A dataset as it was measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DatasetInfo {
    /// Short name.
    pub name: String,
    /// File name or generator description.
    pub source: String,
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
    /// Voxel spacing, millimetres.
    pub spacing_mm: [f64; 3],
    /// Stored sample type.
    pub scalar_type: String,
    /// Data value range `[min, max]`.
    pub value_range: [f64; 2],
    /// Transfer function (file or preset).
    pub tf: String,
    /// Why that transfer function.
    pub why: String,
    /// How the GPU held it (one texture, or bricks: count, level, memory, budget); absent in
    /// results written before it was recorded.
    #[serde(default)]
    pub gpu_layout: Option<String>,
    /// The segmentation shown in every run (its file, segments and view), if one was.
    #[serde(default)]
    pub labels: Option<String>,
}

/// What identifies a run: the dataset and every setting that was varied.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct RunKey {
    /// Dataset name.
    pub dataset: String,
    /// Mode (`dvr`, `mip`, …).
    pub mode: String,
    /// Strategy as the tables name it (`RC`, `RC-t`, `RC-s`, `RC-s-df`).
    pub strategy: String,
    /// Path that ran (`fragment` or `compute`).
    pub path: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Block edge in voxels.
    pub block_vox: u32,
    /// Whether the run belongs to the block-size sweep.
    pub sweep: bool,
}

/// One orbit view of a run: its time and, from the statistics pass, its sample counts.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameRecord {
    /// View index on the orbit.
    pub view: u32,
    /// Camera azimuth, degrees.
    pub azimuth_deg: f64,
    /// Frame time of the timing pass, milliseconds.
    pub ms: f64,
    /// Frame time of the statistics variant (slower: atomics), milliseconds.
    pub stats_ms: Option<f64>,
    /// Wall time of the timing pass's frame from submission until its image is read back to the
    /// CPU, milliseconds: what tools that time `render + read-back` report.
    #[serde(default)]
    pub wall_ms: Option<f64>,
    /// Samples taken.
    pub samples: u64,
    /// Samples with non-zero opacity (what any leaping scheme must still take: the oracle).
    pub visible_samples: u64,
    /// Rays that met the volume.
    pub rays: u64,
    /// Empty regions leapt.
    pub leaps: u64,
    /// Lookups in the leaping structure (`FrameCounters::lookups`); `None` in records made
    /// before it was counted.
    #[serde(default)]
    pub lookups: Option<u64>,
}

/// What the `auto` strategy stood for in a run (chosen once after the warm-up, as the window
/// chooses when its inputs change, from views off the orbit), what choosing took, and the run's
/// frames paired with RC-t's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AutoChoice {
    /// The strategy chosen (`RC-t`, `RC-s`, `RC-s-df`).
    pub strategy: String,
    /// RC-t's frame time as timed for the choice, milliseconds (`None`: not timed, a CPU driver).
    pub rct_ms: Option<f64>,
    /// The leaping strategy's frame time as timed for the choice, milliseconds.
    pub leaping_ms: Option<f64>,
    /// Wall time of the choice (both strategies' warm-up and timed frames), milliseconds: what a
    /// user waits once per volume, transfer function, mode and image size.
    pub choose_ms: f64,
    /// Per view of the orbit, an RC-t frame and then one of what `auto` chose, timed one right
    /// after the other, milliseconds: `[RC-t, auto]`. Two runs measured apart differ by a few
    /// per cent at sub-millisecond frames even for one shader; these pairs do not wait between
    /// the two, so their ratio is the comparison with RC-t that the clock's drift leaves alone.
    #[serde(default)]
    pub paired_ms: Vec<[f64; 2]>,
}

/// One run: a dataset under one combination of settings, over the whole orbit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    /// What was run.
    pub key: RunKey,
    /// Sample step, voxels.
    pub step_vox: f64,
    /// Transfer function name.
    pub tf: String,
    /// Every view's figures.
    pub frames: Vec<FrameRecord>,
    /// What `auto` stood for (runs of the `auto` strategy only).
    #[serde(default)]
    pub auto: Option<AutoChoice>,
}

/// Leaping-structure rebuild after a transfer-function change.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RebuildRecord {
    /// Dataset name.
    pub dataset: String,
    /// Strategy (the distance field rebuilds more).
    pub strategy: String,
    /// Block edge in voxels.
    pub block_vox: u32,
    /// Each timed rebuild, milliseconds.
    pub ms: Vec<f64>,
}

/// RC-s (a variant) against RC-t on one view: leaping must not change the image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImageCheck {
    /// Dataset name.
    pub dataset: String,
    /// Mode.
    pub mode: String,
    /// Path.
    pub path: String,
    /// Leaping variant compared with RC-t.
    pub strategy: String,
    /// Largest absolute per-channel difference, 0..1.
    pub max_abs: f64,
    /// Whether `max_abs` ≤ [`IMAGE_TOLERANCE`].
    pub passed: bool,
}

/// Largest per-channel difference leaping may cause: one 8-bit level (DESIGN.md: RC-s takes
/// exactly RC-t's contributing samples, so only float rounding may differ).
pub const IMAGE_TOLERANCE: f64 = 1.0 / 255.0;

/// A dataset that was not measured, and why.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Skipped {
    /// Dataset name.
    pub dataset: String,
    /// Why it was skipped.
    pub reason: String,
    /// Whether the configuration marked it optional (otherwise the skip is a failure).
    pub optional: bool,
    /// Whether its input was unusable (its file, its transfer function, or its size against the
    /// GPU's limits), rather than a run failing on the GPU.
    #[serde(default)]
    pub bad_input: bool,
}

/// Everything a benchmark run measured.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BenchResults {
    /// Where it ran.
    pub environment: Environment,
    /// Datasets measured.
    pub datasets: Vec<DatasetInfo>,
    /// Every run.
    pub runs: Vec<RunRecord>,
    /// Rebuild timings.
    pub rebuilds: Vec<RebuildRecord>,
    /// Image checks.
    pub image_checks: Vec<ImageCheck>,
    /// Datasets not measured.
    pub skipped: Vec<Skipped>,
}

impl BenchResults {
    /// Appends `other`'s datasets, runs, rebuilds, checks and skips (for merging partial runs);
    /// the environment's command lines are joined. Rebuilds of one dataset, strategy and block
    /// edge timed by several parts (each part times them: a compute part and a fragment part of
    /// the same datasets) are pooled into one record, so the report lists each once.
    pub fn merge(&mut self, other: Self) {
        if self.environment.adapter.is_empty() {
            self.environment = other.environment;
        } else {
            self.environment.command_line += " ; ";
            self.environment.command_line += &other.environment.command_line;
        }
        for d in other.datasets {
            if !self.datasets.iter().any(|o| o.name == d.name) {
                self.datasets.push(d);
            }
        }
        self.runs.extend(other.runs);
        for rebuild in other.rebuilds {
            let same = |o: &&mut RebuildRecord| {
                (&o.dataset, &o.strategy, o.block_vox)
                    == (&rebuild.dataset, &rebuild.strategy, rebuild.block_vox)
            };
            match self.rebuilds.iter_mut().find(same) {
                Some(pooled) => pooled.ms.extend(&rebuild.ms),
                None => self.rebuilds.push(rebuild),
            }
        }
        self.image_checks.extend(other.image_checks);
        self.skipped.extend(other.skipped);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rebuild(dataset: &str, strategy: &str, ms: &[f64]) -> RebuildRecord {
        RebuildRecord {
            dataset: dataset.into(),
            strategy: strategy.into(),
            block_vox: 4,
            ms: ms.to_vec(),
        }
    }

    /// Two parts that timed the same rebuilds merge into one record each, their timings pooled;
    /// a rebuild only one part timed stays as it was.
    #[test]
    fn merged_parts_pool_the_rebuilds_they_both_timed() {
        let part = |rebuilds| BenchResults {
            rebuilds,
            ..BenchResults::default()
        };
        let mut merged = BenchResults::default();
        merged.merge(part(vec![
            rebuild("head", "RC-s", &[0.031, 0.032]),
            rebuild("head", "RC-s-df", &[0.086]),
        ]));
        merged.merge(part(vec![
            rebuild("head", "RC-s", &[0.033]),
            rebuild("vessels", "RC-s", &[0.041]),
        ]));
        assert_eq!(
            merged.rebuilds,
            vec![
                rebuild("head", "RC-s", &[0.031, 0.032, 0.033]),
                rebuild("head", "RC-s-df", &[0.086]),
                rebuild("vessels", "RC-s", &[0.041]),
            ]
        );
    }
}
