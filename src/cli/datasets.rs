//! Turns the configuration's datasets into volumes and transfer functions: reads the scans from
//! the data folder, generates the synthetic ones, and refuses (with a reason) a volume the
//! adapter cannot hold before spending time generating it.

use std::path::Path;

use anyhow::Context;
use leapview::bench::config::{DatasetSpec, Source};
use leapview::bench::record::DatasetInfo;
use leapview::transfer::TransferFunction;
use leapview::volume::synthetic::{dense_head, peer_scene, vessel_tree};
use leapview::volume::{Volume, load_volume};

/// A dataset ready to be measured.
pub struct Loaded {
    /// The voxels.
    pub volume: std::sync::Arc<Volume>,
    /// Its transfer function.
    pub tf: TransferFunction,
    /// What the report says about it.
    pub info: DatasetInfo,
}

/// Reads the transfer function `spec.tf`: a JSON file relative to `config_dir`, or a preset.
pub fn transfer_function(
    spec: &DatasetSpec,
    config_dir: &Path,
) -> anyhow::Result<TransferFunction> {
    let tf = if spec.tf.ends_with(".json") {
        TransferFunction::load(&config_dir.join(&spec.tf))?
    } else {
        TransferFunction::from_preset_or_file(&spec.tf)?
    };
    Ok(tf)
}

/// Loads or generates `spec`'s volume; fails without generating when one side exceeds
/// `max_texture_3d`.
pub fn load(
    spec: &DatasetSpec,
    data_dir: &Path,
    config_dir: &Path,
    max_texture_3d: u32,
) -> anyhow::Result<Loaded> {
    let tf = transfer_function(spec, config_dir)
        .with_context(|| format!("transfer function of {}", spec.name))?;
    let too_big = |n: u32| {
        anyhow::anyhow!(
            "{n} voxels per side exceed this adapter's 3D texture limit of {max_texture_3d}"
        )
    };
    let (volume, source) = match &spec.source {
        Source::File { file } => {
            let path = data_dir.join(file);
            let volume = load_volume(&path, &Default::default())
                .with_context(|| format!("loading {} (is --data-dir right?)", spec.name))?;
            (volume, file.clone())
        }
        Source::VesselTree { n, seed } => {
            if *n > max_texture_3d {
                return Err(too_big(*n));
            }
            let source = format!("generated vessel tree {n}³, seed {seed}");
            (vessel_tree(*n, *seed)?, source)
        }
        Source::PeerScene { n } => {
            if *n > max_texture_3d {
                return Err(too_big(*n));
            }
            (peer_scene(*n)?, format!("generated peer scene {n}³"))
        }
        Source::DenseHead { n, seed } => {
            if *n > max_texture_3d {
                return Err(too_big(*n));
            }
            let source = format!("generated dense head {n}³, seed {seed}");
            (dense_head(*n, *seed)?, source)
        }
    };
    let range = volume.normalization_range();
    let info = DatasetInfo {
        name: spec.name.clone(),
        source,
        dims: volume.dims(),
        spacing_mm: volume.spacing_mm(),
        scalar_type: volume.scalar_type().name().to_string(),
        value_range: [range.min, range.max],
        tf: spec.tf.clone(),
        why: spec.why.clone(),
        gpu_layout: None,
        labels: None,
    };
    Ok(Loaded {
        volume: std::sync::Arc::new(volume),
        tf,
        info,
    })
}
