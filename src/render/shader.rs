//! WGSL composition: a tiny preprocessor over the modules in `shaders/` (`#include "dir/file"`,
//! relative to `shaders/`, included once; `#ifdef NAME` / `#ifndef NAME` / `#else` / `#endif`),
//! so each pipeline variant is compiled from exactly the code its key selects. One module is generated rather than read:
//! [`GENERATED_CONSTANTS`], the constants WGSL shares with Rust.

/// `(name, source)` for files of `shaders/`, compiled into the binary.
macro_rules! modules {
    ($($name:literal),* $(,)?) => {
        &[$(($name, include_str!(concat!("../../shaders/", $name)))),*]
    };
}

/// The shader modules, compiled into the binary, by folder: the entry points of every pipeline,
/// what they share, the ray loop (one file per loop kind), one module per mode family, leaping,
/// and the builders of the leaping structures.
const MODULES: &[(&str, &str)] = modules![
    "entry/raycast_fragment.wgsl",
    "entry/raycast_compute.wgsl",
    "entry/proxy_passes.wgsl",
    "entry/accumulate.wgsl",
    "entry/pack_rgba8.wgsl",
    "entry/slice.wgsl",
    "shared/common.wgsl",
    "shared/volume.wgsl",
    "shared/volume_geometry.wgsl",
    "shared/proxy.wgsl",
    "shared/classify.wgsl",
    "shared/labels.wgsl",
    "shared/label_texel.wgsl",
    "shared/stats.wgsl",
    "shared/shade.wgsl",
    "shared/shadow.wgsl",
    "shared/occlusion.wgsl",
    "shared/secondary.wgsl",
    "shared/preintegrate.wgsl",
    "march/march.wgsl",
    "march/plain.wgsl",
    "march/samplewise.wgsl",
    "march/runs.wgsl",
    "march/batch.wgsl",
    "march/parts.wgsl",
    "modes/dvr.wgsl",
    "modes/iso.wgsl",
    "modes/mip.wgsl",
    "modes/xray.wgsl",
    "leap/pyramid.wgsl",
    "leap/leap.wgsl",
    "build/params.wgsl",
    "build/minmax.wgsl",
    "build/emptiness.wgsl",
    "build/distance.wgsl",
    "build/labels.wgsl",
    "build/label_surface.wgsl",
    "shared/label_surface.wgsl",
];

/// A WGSL module from composed source.
pub(crate) fn shader_module(
    device: &wgpu::Device,
    label: &str,
    source: String,
) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    })
}

/// A compute pipeline of `module`'s `entry`, its layout derived from the shader.
pub(crate) fn compute_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: None,
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// Names of all shader modules.
pub fn module_names() -> impl Iterator<Item = &'static str> {
    MODULES.iter().map(|(name, _)| *name)
}

/// A malformed shader module: a bug in `shaders/`, reported with file and line.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ShaderError {
    /// `#include` of a module that does not exist.
    #[error("{file}:{line}: no shader module {name:?}")]
    UnknownModule {
        /// Including file.
        file: String,
        /// 1-based line.
        line: usize,
        /// Module asked for.
        name: String,
    },
    /// A directive the preprocessor does not know, or one out of place.
    #[error("{file}:{line}: bad directive {text:?}")]
    BadDirective {
        /// File.
        file: String,
        /// 1-based line.
        line: usize,
        /// The line.
        text: String,
    },
    /// An `#ifdef`/`#ifndef` without its `#endif`.
    #[error("{file}: unterminated #ifdef")]
    Unterminated {
        /// File.
        file: String,
    },
}

/// Composes `entry` with its includes, keeping only the code enabled by `defines`.
pub fn compose(entry: &str, defines: &[&str]) -> Result<String, ShaderError> {
    let mut out = String::new();
    let mut included = Vec::new();
    expand(entry, defines, &mut included, &mut out, None)?;
    Ok(out)
}

/// The module that holds the constants shared with Rust, generated from
/// [`super::gpu_data`] (it is not a file).
pub const GENERATED_CONSTANTS: &str = "generated/constants.wgsl";

fn source_of(name: &str) -> Option<std::borrow::Cow<'static, str>> {
    if name == GENERATED_CONSTANTS {
        return Some(super::gpu_data::wgsl_constants().into());
    }
    MODULES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, s)| (*s).into())
}

fn expand(
    name: &str,
    defines: &[&str],
    included: &mut Vec<String>,
    out: &mut String,
    from: Option<(&str, usize)>,
) -> Result<(), ShaderError> {
    if included.iter().any(|n| n == name) {
        return Ok(());
    }
    let source = source_of(name).ok_or_else(|| ShaderError::UnknownModule {
        file: from.map_or_else(String::new, |(f, _)| f.to_string()),
        line: from.map_or(0, |(_, l)| l),
        name: name.to_string(),
    })?;
    included.push(name.to_string());
    // Stack of (this branch active, any enclosing branch inactive).
    let mut stack: Vec<(bool, bool)> = Vec::new();
    let active = |stack: &[(bool, bool)]| stack.iter().all(|(on, _)| *on);
    for (i, line) in source.lines().enumerate() {
        let lineno = i + 1;
        let trimmed = line.trim();
        let bad = || ShaderError::BadDirective {
            file: name.to_string(),
            line: lineno,
            text: trimmed.to_string(),
        };
        if let Some(rest) = trimmed.strip_prefix("#ifdef ") {
            stack.push((defines.contains(&rest.trim()), false));
        } else if let Some(rest) = trimmed.strip_prefix("#ifndef ") {
            stack.push((!defines.contains(&rest.trim()), false));
        } else if trimmed == "#else" {
            let top = stack.last_mut().ok_or_else(bad)?;
            if top.1 {
                return Err(bad());
            }
            *top = (!top.0, true);
        } else if trimmed == "#endif" {
            stack.pop().ok_or_else(bad)?;
        } else if let Some(rest) = trimmed.strip_prefix("#include ") {
            if active(&stack) {
                let target = rest.trim().trim_matches('"');
                expand(target, defines, included, out, Some((name, lineno)))?;
            }
        } else if trimmed.starts_with('#') {
            return Err(bad());
        } else if active(&stack) {
            out.push_str(line);
            out.push('\n');
        }
    }
    if stack.is_empty() {
        Ok(())
    } else {
        Err(ShaderError::Unterminated {
            file: name.to_string(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn includes_once_and_honours_defines() {
        let plain = compose("march/march.wgsl", &["LOOP_PLAIN"]).expect("composes");
        assert_eq!(
            plain.matches("struct Frame").count(),
            1,
            "common.wgsl included once"
        );
        assert!(!plain.contains("atomicAdd"));
        assert!(!plain.contains("frame.termination_alpha"));
        let full = compose(
            "march/march.wgsl",
            &["MODE_DVR", "LOOP_PLAIN", "STATS", "EARLY_TERMINATION"],
        )
        .expect("composes");
        assert!(full.contains("atomicAdd"));
        assert!(full.contains("frame.termination_alpha"));
    }

    /// The folders of `shaders/` include one another without a circle (entry → march → modes,
    /// leap → shared): no folder includes back into one that includes it.
    #[test]
    fn folders_include_without_a_circle() {
        let folder = |name: &str| name.split('/').next().unwrap_or("").to_string();
        let mut arrows = std::collections::BTreeSet::new();
        for (name, source) in MODULES {
            for line in source.lines() {
                if let Some(included) = line.trim().strip_prefix("#include ") {
                    let (from, to) = (folder(name), folder(included.trim_matches('"')));
                    if from != to {
                        arrows.insert((from, to));
                    }
                }
            }
        }
        // Repeatedly drop folders that include nothing left: a circle is what remains.
        let mut left = arrows.clone();
        loop {
            let sources: std::collections::BTreeSet<_> =
                left.iter().map(|(f, _)| f.clone()).collect();
            let before = left.len();
            left.retain(|(_, to)| sources.contains(to));
            if left.len() == before {
                break;
            }
        }
        assert!(
            left.is_empty(),
            "folders in a circle: {left:?} (all: {arrows:?})"
        );
        assert!(
            arrows.contains(&("entry".into(), "march".into())),
            "{arrows:?}"
        );
    }

    #[test]
    fn unknown_module_is_reported() {
        assert!(matches!(
            compose("nope.wgsl", &[]),
            Err(ShaderError::UnknownModule { .. })
        ));
    }
}
