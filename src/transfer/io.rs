//! Reading, checking and writing transfer-function JSON files
//! (`{"opacity": [[value, alpha], …], "color": [[value, r, g, b], …]}`).

use std::path::{Path, PathBuf};

use super::TransferFunction;

/// A transfer function that cannot be used, and why.
#[derive(Debug, thiserror::Error)]
pub enum TransferError {
    /// The JSON does not have the expected shape.
    #[error("not a transfer-function file ({0})")]
    Json(#[from] serde_json::Error),
    /// A curve has no point.
    #[error("the {0} curve has no points")]
    Empty(&'static str),
    /// A value, opacity or colour component is NaN or infinite.
    #[error("the {0} curve holds a value that is not a finite number")]
    NotFinite(&'static str),
    /// An opacity or colour component outside 0..1.
    #[error("the {curve} curve has {what} {value} outside 0..1")]
    OutOfRange {
        /// `opacity` or `color`.
        curve: &'static str,
        /// What the number is (`an opacity`, `a colour component`).
        what: &'static str,
        /// The offending number.
        value: f64,
    },
    /// Points are not in ascending order of value.
    #[error("the {0} points must be sorted by value")]
    Unsorted(&'static str),
    /// No preset of that name.
    #[error("no preset called {name:?}; the presets are {known}")]
    UnknownPreset {
        /// The name asked for.
        name: String,
        /// Comma-separated list of preset names.
        known: String,
    },
    /// The file could not be read or written.
    #[error("cannot access the transfer-function file ({error}): {}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error (in the message, so not also a source to print twice).
        error: std::io::Error,
    },
    /// The path names a pipe, a device or a socket (reading one can block forever).
    #[error("this is not a regular file; only files are read: {}", .0.display())]
    NotRegularFile(PathBuf),
    /// The file was read but is not valid; the path is added last.
    #[error("{problem}: {}", path.display())]
    InFile {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        problem: Box<TransferError>,
    },
}

impl TransferFunction {
    /// Parses and validates a transfer function from JSON text.
    pub fn from_json_str(text: &str) -> Result<Self, TransferError> {
        let tf: Self = serde_json::from_str(text)?;
        tf.validate()?;
        Ok(tf)
    }

    /// The JSON text of this transfer function (pretty-printed).
    pub(crate) fn to_json_string(&self) -> String {
        // Serialising plain vectors of numbers cannot fail.
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// Reads and validates a transfer-function file.
    pub fn load(path: &Path) -> Result<Self, TransferError> {
        // Asked before opening: opening a named pipe blocks until someone writes to it.
        if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
            return Err(TransferError::NotRegularFile(path.to_path_buf()));
        }
        let text = std::fs::read_to_string(path).map_err(|source| TransferError::Io {
            path: path.to_path_buf(),
            error: source,
        })?;
        Self::from_json_str(&text).map_err(|problem| TransferError::InFile {
            path: path.to_path_buf(),
            problem: Box::new(problem),
        })
    }

    /// Writes this transfer function as JSON.
    pub fn save(&self, path: &Path) -> Result<(), TransferError> {
        std::fs::write(path, self.to_json_string()).map_err(|source| TransferError::Io {
            path: path.to_path_buf(),
            error: source,
        })
    }

    /// A preset name (see [`super::presets::NAMES`]) or the path of a JSON file.
    pub fn from_preset_or_file(arg: &str) -> Result<Self, TransferError> {
        match super::presets::preset(arg) {
            Ok(tf) => Ok(tf),
            Err(unknown) if !Path::new(arg).exists() && !arg.ends_with(".json") => Err(unknown),
            Err(_) => Self::load(Path::new(arg)),
        }
    }

    /// Checks that both curves are non-empty, finite, sorted and within 0..1.
    pub fn validate(&self) -> Result<(), TransferError> {
        check_curve(
            "opacity",
            "an opacity",
            self.opacity.iter().map(|p| p.as_slice()),
        )?;
        check_curve(
            "color",
            "a colour component",
            self.color.iter().map(|p| p.as_slice()),
        )
    }
}

fn check_curve<'a>(
    curve: &'static str,
    what: &'static str,
    points: impl Iterator<Item = &'a [f64]>,
) -> Result<(), TransferError> {
    let mut previous = f64::NEG_INFINITY;
    let mut any = false;
    for p in points {
        any = true;
        if p.iter().any(|x| !x.is_finite()) {
            return Err(TransferError::NotFinite(curve));
        }
        if p[0] < previous {
            return Err(TransferError::Unsorted(curve));
        }
        previous = p[0];
        if let Some(&value) = p[1..].iter().find(|x| !(0.0..=1.0).contains(*x)) {
            return Err(TransferError::OutOfRange { curve, what, value });
        }
    }
    if any {
        Ok(())
    } else {
        Err(TransferError::Empty(curve))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_through_json() {
        let tf = TransferFunction::grey_ramp();
        let back = TransferFunction::from_json_str(&tf.to_json_string()).expect("valid");
        assert_eq!(back, tf);
        let data = TransferFunction::from_json_str(
            r#"{"opacity": [[0, 0], [100, 0.5]], "color": [[0, 1, 0.5, 0]]}"#,
        )
        .expect("valid");
        assert_eq!(data.space, super::super::ValueSpace::Data);
        assert!(!data.to_json_string().contains("space"));
    }

    #[test]
    fn rejects_bad_curves() {
        let cases = [
            (r#"{"opacity": [], "color": [[0, 1, 1, 1]]}"#, "no points"),
            (
                r#"{"opacity": [[0, 1.5]], "color": [[0, 1, 1, 1]]}"#,
                "outside 0..1",
            ),
            (
                r#"{"opacity": [[5, 0], [1, 1]], "color": [[0, 1, 1, 1]]}"#,
                "sorted",
            ),
            (
                r#"{"opacity": [[0, 1]], "color": [[0, 1, 1]]}"#,
                "not a transfer-function",
            ),
            (r#"{"opacity": [[0, 1]]}"#, "not a transfer-function"),
        ];
        for (text, expected) in cases {
            let err = TransferFunction::from_json_str(text).expect_err(text);
            assert!(err.to_string().contains(expected), "{text}: {err}");
        }
    }
}
