//! WGSL composition: a tiny preprocessor over the modules in `shaders/` (`#include "file"`,
//! included once; `#ifdef NAME` / `#ifndef NAME` / `#else` / `#endif`), so each pipeline variant
//! is compiled from exactly the code its key selects.

/// `(name, source)` for files of `shaders/`, compiled into the binary.
macro_rules! modules {
    ($($name:literal),* $(,)?) => {
        &[$(($name, include_str!(concat!("../../shaders/", $name)))),*]
    };
}

/// The shader modules, compiled into the binary.
const MODULES: &[(&str, &str)] = modules![
    "common.wgsl",
    "proxy.wgsl",
    "proxy_passes.wgsl",
    "classify.wgsl",
    "stats.wgsl",
    "march.wgsl",
    "raycast_fragment.wgsl",
    "raycast_compute.wgsl",
    "leap_common.wgsl",
    "leap.wgsl",
    "build_minmax.wgsl",
    "build_emptiness.wgsl",
    "build_distance.wgsl",
    "shade.wgsl",
    "mode_dvr.wgsl",
    "preintegrate.wgsl",
    "mode_iso.wgsl",
    "mode_mip.wgsl",
    "mode_xray.wgsl",
    "accumulate.wgsl",
];

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

fn source_of(name: &str) -> Option<&'static str> {
    MODULES.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
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
        let plain = compose("march.wgsl", &[]).expect("composes");
        assert_eq!(
            plain.matches("struct Frame").count(),
            1,
            "common.wgsl included once"
        );
        assert!(!plain.contains("atomicAdd"));
        assert!(!plain.contains("frame.termination_alpha"));
        let full =
            compose("march.wgsl", &["MODE_DVR", "STATS", "EARLY_TERMINATION"]).expect("composes");
        assert!(full.contains("atomicAdd"));
        assert!(full.contains("frame.termination_alpha"));
    }

    #[test]
    fn unknown_module_is_reported() {
        assert!(matches!(
            compose("nope.wgsl", &[]),
            Err(ShaderError::UnknownModule { .. })
        ));
    }
}
