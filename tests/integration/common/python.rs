//! The Python that writes the tests' independent references (pydicom, nibabel): the repository's
//! `.venv`, which `scripts/setup-debian.sh --tests` makes from `scripts/python/requirements-tests.txt`,
//! or the interpreter `LEAPVIEW_PYTHON` names.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository's root.
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A Python with the test requirements; fails the test with the setup hint when there is none
/// (never a silent skip: these references are what the readers are checked against).
pub fn python() -> PathBuf {
    let python = std::env::var_os("LEAPVIEW_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join(".venv/bin/python"));
    let ok = Command::new(&python)
        .args(["-c", "import pydicom, nibabel, numpy"])
        .status()
        .is_ok_and(|s| s.success());
    assert!(
        ok,
        "no Python with pydicom and nibabel at {} (run scripts/setup-debian.sh --tests, or set \
         LEAPVIEW_PYTHON)",
        python.display()
    );
    python
}

/// Runs `scripts/python/<script>` with `args`; fails the test with its output if it fails.
pub fn run_python(script: &str, args: &[&Path]) {
    let out = Command::new(python())
        .arg(root().join("scripts/python").join(script))
        .args(args)
        .output()
        .expect("start Python");
    assert!(
        out.status.success(),
        "{script} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
