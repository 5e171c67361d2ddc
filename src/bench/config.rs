//! The benchmark configuration (`bench/config.json`): which datasets with which transfer
//! functions, and which modes, strategies, paths, resolutions, views and block sizes to measure.
//! Narrowing by filters and the `--quick` reduction are pure functions of it.

use std::path::{Path, PathBuf};

use clap::ValueEnum;
use serde::{Deserialize, Serialize};

use crate::settings::effects::Shading;
use crate::settings::{Mode, RenderPath, Strategy};

/// Why a configuration cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The file could not be read.
    #[error("cannot read the benchmark configuration ({error}): {}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// What the system said.
        error: std::io::Error,
    },
    /// The file is not a configuration.
    #[error("the benchmark configuration does not parse ({error}): {}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// What the parser said.
        error: serde_json::Error,
    },
    /// A filter or the block sweep names a dataset the configuration does not have.
    #[error("no dataset called {name:?} in the configuration (it has: {known})")]
    UnknownDataset {
        /// The name asked for.
        name: String,
        /// The names the configuration has.
        known: String,
    },
    /// A value is out of range or a list is empty.
    #[error("benchmark configuration: {0}")]
    Invalid(String),
}

/// Where a dataset's voxels come from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Source {
    /// A volume file, relative to the data folder (`--data-dir`).
    File {
        /// File name.
        file: String,
    },
    /// The generated sparse vessel tree (`volume::synthetic::vessel_tree`).
    VesselTree {
        /// Edge in voxels.
        n: u32,
        /// Random seed.
        seed: u64,
    },
    /// The generated dense MR-like head (`volume::synthetic::dense_head`).
    DenseHead {
        /// Edge in voxels.
        n: u32,
        /// Random seed.
        seed: u64,
    },
    /// The scene of the comparison with the peers (`volume::synthetic::peer_scene`).
    PeerScene {
        /// Edge in voxels.
        n: u32,
    },
}

/// One dataset and the transfer function a user would pick for it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DatasetSpec {
    /// Short name used in tables and filters.
    pub name: String,
    /// Where the voxels come from.
    pub source: Source,
    /// Transfer function: a JSON file relative to the configuration's folder, or a preset name.
    pub tf: String,
    /// Why this transfer function (a user's choice for the data, not one that flatters leaping).
    pub why: String,
    /// Skip (with a logged reason) rather than fail when the volume does not fit the adapter.
    #[serde(default)]
    pub optional: bool,
    /// Isosurface value in data units (default: the middle of the value range).
    #[serde(default)]
    pub iso_value: Option<f64>,
    /// MIP / X-ray window in data units (default: the whole value range).
    #[serde(default)]
    pub window: Option<[f64; 2]>,
}

/// The block-size sweep (the paper's Table 2).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockSweep {
    /// Datasets swept (the two sparsest).
    pub datasets: Vec<String>,
    /// Block edges in voxels.
    pub sizes: Vec<u32>,
    /// Modes swept.
    #[serde(with = "value_names")]
    pub modes: Vec<Mode>,
    /// Image size `[width, height]`.
    pub resolution: [u32; 2],
}

/// The whole configuration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BenchConfig {
    /// What this configuration is for.
    #[serde(default)]
    pub description: String,
    /// Datasets.
    pub datasets: Vec<DatasetSpec>,
    /// Modes.
    #[serde(with = "value_names")]
    pub modes: Vec<Mode>,
    /// Strategies (`rc-s-df` runs only in the modes it supports).
    #[serde(with = "value_names")]
    pub strategies: Vec<Strategy>,
    /// Ray-loop paths.
    #[serde(with = "value_names")]
    pub paths: Vec<RenderPath>,
    /// Image sizes `[width, height]`.
    pub resolutions: Vec<[u32; 2]>,
    /// Orbit views timed per run.
    pub views: u32,
    /// Orbit elevation in degrees.
    pub elevation_deg: f64,
    /// Untimed frames before each run's timed frames.
    pub warmup_frames: u32,
    /// Sample step in units of the smallest voxel spacing.
    pub step_vox: f64,
    /// Block edge in voxels outside the sweep; absent: each mode's and strategy's default
    /// (`settings::default_block_vox`), as a user gets it.
    #[serde(default)]
    pub block_vox: Option<u32>,
    /// Phong lighting in DVR and isosurface modes.
    pub phong: bool,
    /// Transfer-function changes timed per dataset for the rebuild table.
    pub rebuild_repeats: u32,
    /// Image size of the RC-t vs RC-s image check.
    pub image_check_size: [u32; 2],
    /// The block-size sweep.
    pub block_sweep: BlockSweep,
}

/// Narrowing a run from the command line; `None` keeps the configuration's list.
#[derive(Clone, Debug, Default)]
pub struct Filters {
    /// Dataset names.
    pub datasets: Option<Vec<String>>,
    /// Modes.
    pub modes: Option<Vec<Mode>>,
    /// Strategies.
    pub strategies: Option<Vec<Strategy>>,
    /// Paths.
    pub paths: Option<Vec<RenderPath>>,
    /// Block edge of every run outside the sweep, in place of the configuration's.
    pub block_vox: Option<u32>,
    /// Lighting (the configuration's `phong`), on or off.
    pub shading: Option<Shading>,
}

/// Edge of the generated volumes in a quick run: small enough for a CPU driver.
pub const QUICK_GENERATED_VOX: u32 = 64;
/// Views per run in a quick run.
pub const QUICK_VIEWS: u32 = 4;
/// Image size in a quick run.
pub const QUICK_SIZE: [u32; 2] = [128, 128];

impl BenchConfig {
    /// Reads and validates `path`.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|error| ConfigError::Read {
            path: path.to_path_buf(),
            error,
        })?;
        let config: Self = serde_json::from_str(&text).map_err(|error| ConfigError::Parse {
            path: path.to_path_buf(),
            error,
        })?;
        config.validate()?;
        Ok(config)
    }

    /// Checks ranges, non-empty lists and that the sweep names known datasets.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let invalid = |m: &str| Err(ConfigError::Invalid(m.to_string()));
        if self.datasets.is_empty() || self.modes.is_empty() || self.strategies.is_empty() {
            return invalid("datasets, modes and strategies must not be empty");
        }
        if self.paths.is_empty() || self.resolutions.is_empty() {
            return invalid("paths and resolutions must not be empty");
        }
        if self.views == 0 || self.views > 3600 {
            return invalid("views must be 1 to 3600");
        }
        let blocks = crate::accel::pyramid::BLOCK_SIZES;
        if self.block_vox.is_some_and(|b| !blocks.contains(&b))
            || self.block_sweep.sizes.iter().any(|b| !blocks.contains(b))
        {
            return invalid("block sizes must be 4, 8, 16, 32, 64 or 128");
        }
        let mut sizes = self
            .resolutions
            .iter()
            .chain([&self.image_check_size, &self.block_sweep.resolution]);
        if sizes.any(|s| s.contains(&0)) {
            return invalid("image sizes must not have a zero side");
        }
        for (i, d) in self.datasets.iter().enumerate() {
            if self.datasets[..i].iter().any(|o| o.name == d.name) {
                return invalid(&format!("dataset name {:?} appears twice", d.name));
            }
        }
        for name in &self.block_sweep.datasets {
            self.dataset(name)?;
        }
        Ok(())
    }

    /// The dataset called `name`.
    pub fn dataset(&self, name: &str) -> Result<&DatasetSpec, ConfigError> {
        self.datasets
            .iter()
            .find(|d| d.name == name)
            .ok_or_else(|| ConfigError::UnknownDataset {
                name: name.to_string(),
                known: self
                    .datasets
                    .iter()
                    .map(|d| d.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    /// Keeps only what `filters` names (the sweep keeps only remaining datasets) and takes its
    /// block edge and lighting where it gives them; the result is validated again.
    pub fn narrow(&mut self, filters: &Filters) -> Result<(), ConfigError> {
        if let Some(names) = &filters.datasets {
            for name in names {
                self.dataset(name)?;
            }
            self.datasets.retain(|d| names.contains(&d.name));
            self.block_sweep.datasets.retain(|d| names.contains(d));
        }
        if let Some(modes) = &filters.modes {
            self.modes.retain(|m| modes.contains(m));
            self.block_sweep.modes.retain(|m| modes.contains(m));
        }
        if let Some(strategies) = &filters.strategies {
            self.strategies.retain(|s| strategies.contains(s));
        }
        if let Some(paths) = &filters.paths {
            self.paths.retain(|p| paths.contains(p));
        }
        if let Some(block) = filters.block_vox {
            self.block_vox = Some(block);
        }
        if let Some(shading) = filters.shading {
            self.phong = shading == Shading::Phong;
        }
        if self.modes.is_empty() || self.strategies.is_empty() || self.paths.is_empty() {
            return Err(ConfigError::Invalid(
                "the filters leave no mode, strategy or path to run".into(),
            ));
        }
        self.validate()
    }

    /// The quick variant for CPU drivers and CI: the swept datasets and the generated ones
    /// (shrunk to [`QUICK_GENERATED_VOX`]³, optional ones dropped), DVR and MIP only,
    /// [`QUICK_VIEWS`] views at [`QUICK_SIZE`], one warm-up frame.
    pub fn quick(&mut self) {
        let swept = self.block_sweep.datasets.clone();
        self.datasets.retain(|d| match d.source {
            Source::File { .. } => swept.contains(&d.name),
            _ => !d.optional,
        });
        for d in &mut self.datasets {
            if let Source::VesselTree { n, .. }
            | Source::DenseHead { n, .. }
            | Source::PeerScene { n } = &mut d.source
            {
                *n = (*n).min(QUICK_GENERATED_VOX);
            }
        }
        self.modes.retain(|m| matches!(m, Mode::Dvr | Mode::Mip));
        self.views = self.views.min(QUICK_VIEWS);
        self.warmup_frames = self.warmup_frames.min(1);
        self.resolutions = vec![QUICK_SIZE];
        self.image_check_size = QUICK_SIZE;
        self.block_sweep.resolution = QUICK_SIZE;
        self.rebuild_repeats = self.rebuild_repeats.min(3);
    }

    /// The configured strategies that leap by name (`auto` stands for one of them or RC-t, each
    /// measured in its own right): what the block sweep, the rebuild timing and the image check
    /// go through.
    pub fn leaping_strategies(&self) -> impl Iterator<Item = Strategy> + '_ {
        self.strategies
            .iter()
            .copied()
            .filter(|s| s.leaps() && *s != Strategy::Auto)
    }

    /// Whether `strategy` can run in `mode` (the distance field leaps by the transfer function,
    /// the window or the iso value, so it exists for DVR, isosurfaces and the X-ray modes only).
    pub fn runs_in(strategy: Strategy, mode: Mode) -> bool {
        strategy.for_mode(mode) == strategy
    }
}

/// The command-line name of a value (`rc-s`, `dvr`, `compute`).
pub fn value_name<T: ValueEnum>(value: &T) -> String {
    value
        .to_possible_value()
        .map(|p| p.get_name().to_string())
        .unwrap_or_default()
}

/// Lists of enum values written by their command-line names.
mod value_names {
    use clap::ValueEnum;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer, T: ValueEnum>(values: &[T], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(values.iter().map(super::value_name))
    }

    pub fn deserialize<'de, D: Deserializer<'de>, T: ValueEnum>(d: D) -> Result<Vec<T>, D::Error> {
        Vec::<String>::deserialize(d)?
            .iter()
            .map(|n| T::from_str(n, true).map_err(serde::de::Error::custom))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn committed() -> BenchConfig {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("bench/config.json");
        BenchConfig::load(&path).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn committed_config_loads_and_round_trips() {
        let config = committed();
        assert!(config.datasets.len() >= 10, "eight scans and two generated");
        let text = serde_json::to_string(&config).expect("serialise");
        let back: BenchConfig = serde_json::from_str(&text).expect("parse");
        assert_eq!(back, config);
    }

    #[test]
    fn quick_keeps_swept_and_small_generated_datasets() {
        let mut config = committed();
        config.quick();
        for d in &config.datasets {
            match d.source {
                Source::File { .. } => assert!(config.block_sweep.datasets.contains(&d.name)),
                Source::VesselTree { n, .. }
                | Source::DenseHead { n, .. }
                | Source::PeerScene { n } => {
                    assert!(n <= QUICK_GENERATED_VOX && !d.optional)
                }
            }
        }
        assert_eq!(config.resolutions, vec![QUICK_SIZE]);
        config.validate().expect("still valid");
    }

    #[test]
    fn filters_narrow_and_reject_unknown_names() {
        let mut config = committed();
        let first = config.datasets[0].name.clone();
        let filters = Filters {
            datasets: Some(vec![first.clone()]),
            strategies: Some(vec![Strategy::RcT, Strategy::RcS]),
            ..Filters::default()
        };
        config.narrow(&filters).expect("narrow");
        assert_eq!(config.datasets.len(), 1);
        assert_eq!(config.strategies, vec![Strategy::RcT, Strategy::RcS]);
        let bad = Filters {
            datasets: Some(vec!["no-such".into()]),
            ..Filters::default()
        };
        assert!(matches!(
            config.narrow(&bad),
            Err(ConfigError::UnknownDataset { .. })
        ));
    }

    #[test]
    fn the_command_line_sets_the_block_edge_and_lighting_and_a_bad_edge_is_refused() {
        let mut config = committed();
        assert!(config.phong && config.block_vox.is_none());
        let overrides = Filters {
            block_vox: Some(8),
            shading: Some(Shading::Off),
            ..Filters::default()
        };
        config.narrow(&overrides).expect("narrow");
        assert_eq!(config.block_vox, Some(8));
        assert!(!config.phong);
        // Left out, the configuration's own stay.
        config.narrow(&Filters::default()).expect("narrow");
        assert_eq!(config.block_vox, Some(8));
        let bad = Filters {
            block_vox: Some(3),
            ..Filters::default()
        };
        assert!(matches!(
            config.narrow(&bad),
            Err(ConfigError::Invalid(m)) if m.contains("block sizes")
        ));
    }
}
