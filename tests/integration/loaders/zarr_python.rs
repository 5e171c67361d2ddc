//! OME-Zarr stores written by zarr-python and ome-zarr-py (`scripts/python/zarr_stores.py`):
//! NGFF 0.4 on Zarr v2 (blosc, gzip, absent chunks, channels) and 0.5 on Zarr v3 (sharded zstd,
//! gzip, a time axis, float with NaN), a plain array, ome-zarr-py's own pyramid and a chunk that
//! fails to decode, each read with the values, spacing and origin the writer holds; and the
//! stores LeapView must refuse, each with a message that says why.

use leapview::volume::{LoadOptions, VolumeIndex, load_volume};
use serde_json::Value;

use crate::common::{self, run_python};

fn options(case: &Value) -> LoadOptions {
    let index = |key: &str| case.get(key).and_then(Value::as_u64).map(|n| n as u32);
    LoadOptions {
        volume: index("time").filter(|&t| t > 0),
        channel: index("channel").filter(|&c| c > 0),
        ..LoadOptions::default()
    }
}

#[test]
fn stores_written_by_zarr_python_and_ome_zarr_open_with_their_values() {
    let out = common::TempDir::new("zarr");
    run_python("zarr_stores.py", &[out.path()]);
    let all = common::cases_json(out.path());
    let cases = all["cases"].as_array().expect("cases");
    assert!(cases.len() >= 7, "{} cases", cases.len());
    for case in cases {
        let name = case["name"].as_str().expect("a name");
        let path = out.path().join(case["store"].as_str().expect("a store"));
        let v = load_volume(&path, &options(case)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let numbers = |key: &str| -> Vec<f64> {
            serde_json::from_value(case[key].clone()).unwrap_or_else(|e| panic!("{key}: {e}"))
        };
        let dims: Vec<u32> = numbers("dims").iter().map(|&d| d as u32).collect();
        assert_eq!(v.dims().to_vec(), dims, "{name}");
        let (spacing, want) = (v.spacing_mm(), numbers("spacing"));
        assert!(
            (0..3).all(|a| (spacing[a] - want[a]).abs() <= 1e-9 * want[a]),
            "{name}: spacing {spacing:?}, the store's {want:?}"
        );
        let (origin, want) = (
            v.provenance().origin_lps.expect("an origin"),
            numbers("origin_lps"),
        );
        assert!(
            (0..3).all(|a| (origin[a] - want[a]).abs() < 1e-12),
            "{name}: origin {origin:?}, the store's {want:?}"
        );
        // No patient orientation in NGFF: the views assume RAS.
        assert_eq!(v.file_orientation(), None, "{name}");
        let times = case["times"].as_u64().expect("times") as u32;
        let time = case["time"].as_u64().expect("time") as u32;
        let expected = (times > 1).then_some(VolumeIndex {
            chosen: time,
            count: times,
        });
        assert_eq!(v.provenance().volumes, expected, "{name}");
        let notes = v.provenance().notes.join(" | ");
        match case["note"].as_str() {
            Some(said) => assert!(notes.contains(said), "{name}: notes {notes:?}"),
            None => assert!(notes.is_empty(), "{name}: unexpected notes {notes:?}"),
        }
        let reference = common::f64_file(&out.path().join(format!("{name}.f64")));
        common::assert_values_exactly(name, &v, &reference);
        // Streamed (a memory budget of one byte): the same voxels, box by box, and every
        // coarser level of LeapView's shape, whatever levels the store holds.
        let budget = LoadOptions {
            ram_budget: Some(1),
            ..options(case)
        };
        let s = load_volume(&path, &budget).unwrap_or_else(|e| panic!("{name} streamed: {e}"));
        let source = s.streaming().expect("streamed");
        let whole = source.read_box(0, [0; 3], v.dims()).expect("level 0");
        let held = v.samples().expect("in memory");
        assert_eq!(whole.len(), held.len(), "{name}");
        for i in 0..held.len() {
            let (a, b) = (whole.get_f64(i), held.get_f64(i));
            assert!(
                a == b || (a.is_nan() && b.is_nan()),
                "{name}: voxel {i}: {a} {b}"
            );
        }
        for k in 1..4 {
            let d = leapview::volume::downsample::level_dims(v.dims(), k);
            let level = source.read_box(k, [0; 3], d).expect("a level");
            assert_eq!(
                level.len() as u64,
                d.iter().map(|&n| u64::from(n)).product::<u64>()
            );
        }
    }
    for bad in all["errors"].as_array().expect("errors") {
        let path = out.path().join(bad["store"].as_str().expect("a store"));
        let said = bad["said"].as_str().expect("words");
        let e = load_volume(&path, &options(bad))
            .map(|_| ())
            .expect_err(said)
            .to_string();
        assert!(e.contains(said), "{}: {e}", path.display());
        assert!(e.ends_with(&path.display().to_string()), "{e}");
    }
}
