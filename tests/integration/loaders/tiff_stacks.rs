//! TIFF stacks written by tifffile (`scripts/python/tiff_stacks.py`): a multi-page stack with a
//! resolution in centimetres, OME-TIFF with channels and physical sizes, a tiled float ImageJ
//! hyperstack, a folder of slices in natural order and a BigTIFF, each read with the values and
//! spacing tifffile wrote; and the files LeapView must refuse, each with a message that says why.

use leapview::volume::{LoadOptions, load_volume};
use serde_json::Value;

use crate::common::{self, run_python};

#[test]
fn stacks_written_by_tifffile_open_with_their_values_and_spacing() {
    let out = common::TempDir::new("tiff");
    run_python("tiff_stacks.py", &[out.path()]);
    let all = common::cases_json(out.path());
    let options = |case: &Value| LoadOptions {
        channel: case["channel"]
            .as_u64()
            .map(|c| c as u32)
            .filter(|&c| c > 0),
        ..LoadOptions::default()
    };
    let cases = all["cases"].as_array().expect("cases");
    assert!(cases.len() >= 5, "{} cases", cases.len());
    for case in cases {
        let name = case["name"].as_str().expect("a name");
        let path = out.path().join(case["path"].as_str().expect("a path"));
        let v = load_volume(&path, &options(case)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let numbers = |key: &str| -> Vec<f64> {
            serde_json::from_value(case[key].clone()).unwrap_or_else(|e| panic!("{key}: {e}"))
        };
        let dims: Vec<u32> = numbers("dims").iter().map(|&d| d as u32).collect();
        assert_eq!(v.dims().to_vec(), dims, "{name}");
        let (spacing, want) = (v.spacing_mm(), numbers("spacing"));
        assert!(
            (0..3).all(|a| (spacing[a] - want[a]).abs() <= 1e-9 * want[a]),
            "{name}: spacing {spacing:?}, tifffile's {want:?}"
        );
        let notes = v.provenance().notes.join(" | ");
        match case["note"].as_str() {
            Some(said) => assert!(notes.contains(said), "{name}: notes {notes:?}"),
            None => assert!(notes.is_empty(), "{name}: unexpected notes {notes:?}"),
        }
        let reference = common::f64_file(&out.path().join(format!("{name}.f64")));
        common::assert_values_exactly(name, &v, &reference);
    }
    for bad in all["errors"].as_array().expect("errors") {
        let path = out.path().join(bad["path"].as_str().expect("a path"));
        let said = bad["said"].as_str().expect("words");
        let e = load_volume(&path, &options(bad))
            .map(|_| ())
            .expect_err(said)
            .to_string();
        assert!(e.contains(said), "{}: {e}", path.display());
    }
}
