//! Stores LeapView writes (`leapview::volume::zarr::write`, `leapview convert`): read by
//! zarr-python and ome-zarr-py as other software reads them (`scripts/python/zarr_check.py`:
//! level 0 equal to the source, each coarser level the mean of the one before, scales and
//! translations per level), and read back by LeapView with every fact the source had.

use leapview::volume::zarr::write::write_ome_zarr;
use leapview::volume::{LoadOptions, load_volume};

use crate::common::{self, run_python};

#[test]
fn a_dicom_series_written_as_ome_zarr_opens_in_ome_zarr_py_and_back_with_its_facts() {
    let source = common::data_dir().join("dicom/ct_head_cthead");
    let v = load_volume(&source, &LoadOptions::default()).expect("the series");
    let out = common::TempDir::new("zarr-written");
    let store = out.path().join("head.ome.zarr");
    let written = write_ome_zarr(&v, &store, "the test", &|_| {}).expect("written");
    assert_eq!(
        written.levels,
        vec![[256, 256, 113], [128, 128, 57], [64, 64, 29], [32, 32, 15]]
    );
    let [nx, ny, nz] = v.dims();
    let mut values = Vec::with_capacity(v.sample_count() as usize * 8);
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                values.extend_from_slice(&v.value(x, y, z).to_le_bytes());
            }
        }
    }
    let values_path = out.path().join("values.f64");
    std::fs::write(&values_path, values).expect("values");
    run_python("zarr_check.py", &[&store, &values_path]);

    let back = load_volume(&store, &LoadOptions::default()).expect("read back");
    assert_eq!(back.dims(), v.dims());
    assert_eq!(back.spacing_mm(), v.spacing_mm());
    assert_eq!(back.scalar_type(), v.scalar_type());
    assert_eq!(back.mapping(), v.mapping());
    assert_eq!(
        back.orientation().map(|o| o.code()),
        v.orientation().map(|o| o.code())
    );
    assert_eq!(back.provenance().origin_lps, v.provenance().origin_lps);
    assert_eq!(back.provenance().window, v.provenance().window);
    assert_eq!(
        back.modality().map(|m| m.code()),
        v.modality().map(|m| m.code())
    );
    assert!(back.samples() == v.samples(), "the samples differ");

    // Never over an existing store; a refused write leaves nothing beside it.
    let e = write_ome_zarr(&v, &store, "again", &|_| {}).expect_err("exists");
    assert!(e.to_string().contains("exists already"), "{e}");
    let e =
        write_ome_zarr(&v, &out.path().join("no/such/x.zarr"), "", &|_| {}).expect_err("no folder");
    assert!(e.to_string().contains("does not exist"), "{e}");
    let mut names: Vec<String> = std::fs::read_dir(out.path())
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["head.ome.zarr", "values.f64"]);
}
