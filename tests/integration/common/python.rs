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

/// A Python script's reference samples: little-endian float64, x fastest (`<case>.f64`).
pub fn f64_file(path: &Path) -> Vec<f64> {
    std::fs::read(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
        .collect()
}

/// The `cases.json` a script wrote into `out`.
pub fn cases_json(out: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(out.join("cases.json")).expect("the cases"))
        .expect("JSON")
}

/// Fails unless `v` holds exactly `reference` (x fastest; NaN where NaN), naming `name` and the
/// first voxel that differs.
pub fn assert_values_exactly(name: &str, v: &leapview::volume::Volume, reference: &[f64]) {
    assert_eq!(reference.len() as u64, v.sample_count(), "{name}");
    let [nx, ny, _] = v.dims();
    for (i, &want) in reference.iter().enumerate() {
        let (x, y, z) = (i as u32 % nx, (i as u32 / nx) % ny, i as u32 / (nx * ny));
        let got = v.value(x, y, z);
        assert!(
            got == want || (got.is_nan() && want.is_nan()),
            "{name}: voxel ({x}, {y}, {z}) is {got}, the reference holds {want}"
        );
    }
}
