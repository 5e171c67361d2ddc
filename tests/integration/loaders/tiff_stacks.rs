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

/// Each stack of `stacks_written_by_tifffile_…` opened under a memory budget it exceeds: read
/// brick by brick (`volume::tiff::stream`), every level's boxes equal the stack read whole and
/// halved as LeapView halves it, with no level held (a budget of one byte) and with the coarse
/// levels held (a budget of half the samples); 8- and 16-bit statistics are every voxel's; and
/// a streamed stack converts to an OME-Zarr store slab by slab, voxel for voxel.
#[test]
fn stacks_larger_than_the_memory_budget_are_read_brick_by_brick_with_the_same_values() {
    use leapview::volume::ScalarType;
    use leapview::volume::downsample::{Level, level_dims};
    let out = common::TempDir::new("tiff-streamed");
    run_python("tiff_stacks.py", &[out.path()]);
    let all = common::cases_json(out.path());
    for case in all["cases"].as_array().expect("cases") {
        let name = case["name"].as_str().expect("a name");
        let path = out.path().join(case["path"].as_str().expect("a path"));
        let channel = case["channel"]
            .as_u64()
            .map(|c| c as u32)
            .filter(|&c| c > 0);
        let whole = load_volume(
            &path,
            &LoadOptions {
                channel,
                ..LoadOptions::default()
            },
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        let bytes = whole.sample_count() * whole.scalar_type().size_bytes() as u64;
        for budget in [1, bytes / 2] {
            let options = LoadOptions {
                channel,
                ram_budget: Some(budget),
                ..LoadOptions::default()
            };
            let v = load_volume(&path, &options).unwrap_or_else(|e| panic!("{name}: {e}"));
            let what = format!("{name} under {budget} bytes");
            let streamed = v
                .streaming()
                .unwrap_or_else(|| panic!("{what}: not streamed"));
            assert_eq!(v.dims(), whole.dims(), "{what}");
            assert_eq!(v.spacing_mm(), whole.spacing_mm(), "{what}");
            let notes = v.provenance().notes.join(" | ");
            assert!(notes.contains("brick by brick"), "{what}: {notes}");
            let counted = matches!(
                v.scalar_type(),
                ScalarType::U8 | ScalarType::I8 | ScalarType::U16 | ScalarType::I16
            );
            assert_eq!(v.exact_statistics(), counted, "{what}");
            if counted {
                assert_eq!(v.value_range(), whole.value_range(), "{what}");
                assert_eq!(v.histogram(), whole.histogram(), "{what}");
            }
            let mut level = Level {
                dims: whole.dims(),
                samples: whole.samples().expect("in memory").clone(),
                colour: None,
            };
            for k in 0..6u32 {
                let d = level_dims(whole.dims(), k);
                let all = streamed.read_box(k, [0; 3], d).expect("read");
                assert!(all == level.samples, "{what}: level {k} differs");
                // A box straddling strips, tiles and slices.
                let lo = d.map(|n| n / 3);
                let hi = d.map(|n| (n / 3 + 9).min(n));
                let part = streamed.read_box(k, lo, hi).expect("read");
                let want = common::box_values(&level.samples, d, lo, hi);
                assert_eq!(part.len(), want.len(), "{what}: level {k}");
                for (i, want) in want.into_iter().enumerate() {
                    let got = part.get_f64(i);
                    assert!(
                        got == want || (got.is_nan() && want.is_nan()),
                        "{what}: level {k} box {lo:?}..{hi:?} sample {i} is {got}, not {want}"
                    );
                }
                level = level.halved();
            }
        }
        // Converted from the stack a slab at a time.
        let options = LoadOptions {
            channel,
            ram_budget: Some(1),
            ..LoadOptions::default()
        };
        let v = load_volume(&path, &options).expect("opened");
        let store = out.path().join(format!("{name}.ome.zarr"));
        leapview::volume::zarr::write::write_ome_zarr(&v, &store, name, &|_| {})
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let back = load_volume(&store, &LoadOptions::default()).expect("opened");
        let reference = common::f64_file(&out.path().join(format!("{name}.f64")));
        common::assert_values_exactly(name, &back, &reference);
    }
}
