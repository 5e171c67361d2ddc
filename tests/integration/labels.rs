//! Segmentations read beside their image (`leapview::labels`), from files other software wrote:
//! the shared data's CT head labels (SimpleITK's NIfTI, Slicer's `.seg.nrrd` layout written by
//! pynrrd) on the DICOM series they were made from, the MR head's 120 parcels (nibabel) with their
//! ITK-SNAP label description, and nibabel's label volumes on other grids, whose labels on the
//! image's grid numpy computes from the affines alone (`scripts/python/label_files.py`), highdicom's
//! DICOM SEGs (overlapping, fractional, of another series: `scripts/python/seg_files.py`); and the
//! slice view's label fill, outlines and hiding against the labels under each pixel.

use std::path::Path;

use glam::DVec3;
use leapview::labels::{DropGuess, LabelMap, LabelOptions, guess_dropped, load_labels};
use leapview::mpr::{PatientFrame, Plane, PlaneKind, SliceView};
use leapview::render::labels::GpuLabels;
use leapview::render::slice::{LabelLook, SliceLook, SliceRenderer};
use leapview::render::volume_texture::VolumeTexture;
use leapview::volume::{LoadOptions, Volume, load_volume};

use crate::common;

fn image(path: &Path) -> Volume {
    load_volume(path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn labels(path: &Path, image: &Volume) -> LabelMap {
    load_labels(path, image, &LabelOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `(value, voxels)` of every segment.
fn counts(map: &LabelMap) -> Vec<(u16, u64)> {
    map.segments().iter().map(|s| (s.value, s.voxels)).collect()
}

#[test]
fn the_ct_heads_nifti_and_seg_nrrd_give_the_same_labels_on_its_dicom_series() {
    let data = common::data_dir();
    let series = image(&data.join("dicom/ct_head_cthead"));
    let nifti = labels(&data.join("labels/ct_head_cthead_labels.nii.gz"), &series);
    let seg = labels(&data.join("labels/ct_head_cthead.seg.nrrd"), &series);
    // The two files store the grid differently (NIfTI in RAS, the NRRD in LPS): on the series'
    // grid they agree voxel for voxel, none lost (the counts of the data's README).
    assert_eq!(nifti.dims(), series.dims());
    assert!(
        nifti.layers() == seg.layers(),
        "the two files' labels differ"
    );
    let want = vec![(1, 831_700), (2, 394_132), (3, 381_662)];
    // Dropped over the series: a .seg.nrrd or DICOM SEG is its labels; SimpleITK's NIfTI, named
    // "labels", is asked about; the MR's parcels, their names beside them, are labels; a CT of
    // another grid is an image, and so is the MR image of the dataset called "seg3D".
    let guess = |name: &str, dims: [u32; 3]| guess_dropped(&data.join(name), dims);
    let labelled = |g: DropGuess| matches!(g, DropGuess::Labels(_));
    let asked = |g: DropGuess| matches!(g, DropGuess::Ask(_));
    let dims = series.dims();
    assert!(labelled(guess("labels/ct_head_cthead.seg.nrrd", dims)));
    assert!(labelled(guess("labels/ct_head_cthead_seg.dcm", dims)));
    assert!(asked(guess("labels/ct_head_cthead_labels.nii.gz", dims)));
    assert!(labelled(guess(
        "labels/mr_head_t1_seg3d_parcels.nii.gz",
        dims
    )));
    assert_eq!(
        guess("cta_stent_128x128x256_int16.nrrd", dims),
        DropGuess::Image
    );
    let mr = "mr_head_t1_seg3d_160x232x160_uint8.nrrd";
    // Its stored values scale to fractions (slope 2.00784): an image, whatever its name says.
    assert_eq!(guess(mr, dims), DropGuess::Image);
    assert_eq!(counts(&nifti), want);
    assert_eq!(counts(&seg), want);
    assert!(nifti.notes().is_empty(), "{:?}", nifti.notes());
    // Names and colours: Slicer's fields in the .seg.nrrd, the palette for the NIfTI.
    let names: Vec<&str> = seg.segments().iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["soft tissue", "skull", "brain"]);
    assert_eq!(seg.segments()[0].colour, [227, 186, 158]);
    assert_eq!(nifti.segments()[0].name, "label 1");
    let colours: Vec<[u8; 3]> = nifti.segments().iter().map(|s| s.colour).collect();
    assert!(colours[0] != colours[1] && colours[1] != colours[2]);
    // The brain lies inside the skull: at the series' centre, brain; at a corner, nothing.
    let [nx, ny, nz] = series.dims().map(|d| d as usize);
    let centre = nx / 2 + nx * (ny / 2 + ny * (nz * 3 / 4));
    assert_eq!(
        seg.segment_at(0, centre).map(|s| s.name.as_str()),
        Some("brain")
    );
    assert!(seg.segment_at(0, 0).is_none());
    // highdicom's DICOM SEG of the same labels (3 binary segments, a frame per slice per
    // segment): the same voxels, its segment labels, its CIELab colours near Slicer's RGB.
    let dcm = labels(&data.join("labels/ct_head_cthead_seg.dcm"), &series);
    assert!(dcm.layers() == nifti.layers(), "the SEG's labels differ");
    assert_eq!(counts(&dcm), want);
    let dcm_names: Vec<&str> = dcm.segments().iter().map(|s| s.name.as_str()).collect();
    assert_eq!(dcm_names, names);
    for (a, b) in dcm.segments().iter().zip(seg.segments()) {
        let off = a
            .colour
            .iter()
            .zip(b.colour)
            .map(|(&x, y)| x.abs_diff(y))
            .max();
        assert!(
            off <= Some(4),
            "{}: {:?} against {:?}",
            a.name,
            a.colour,
            b.colour
        );
    }
    // The SEG over another scan (the MR series, another frame of reference) is refused.
    let mr = image(&data.join("dicom/mr_head_t1_seg3d"));
    let e = load_labels(
        &data.join("labels/ct_head_cthead_seg.dcm"),
        &mr,
        &LabelOptions::default(),
    )
    .map(|_| ())
    .expect_err("another scan")
    .to_string();
    assert!(e.contains("another scan"), "{e}");
}

#[test]
fn the_mr_heads_120_parcels_take_the_itk_snap_names_beside_them_and_nibabels_counts() {
    let data = common::data_dir();
    let mr = image(&data.join("originals/VolumeRenderingData_seg3D_MR.nii.gz"));
    let path = data.join("labels/mr_head_t1_seg3d_parcels.nii.gz");
    let parcels = labels(&path, &mr);
    assert_eq!(parcels.segments().len(), 120);
    let out = std::process::Command::new(common::python())
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/python/label_files.py"))
        .arg("--counts")
        .arg(&path)
        .output()
        .expect("nibabel");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let theirs: std::collections::BTreeMap<String, u64> =
        serde_json::from_slice(&out.stdout).expect("counts");
    let theirs: Vec<(u16, u64)> = theirs
        .into_iter()
        .map(|(k, v)| (k.parse().expect("a label"), v))
        .collect::<std::collections::BTreeMap<_, _>>()
        .into_iter()
        .collect();
    assert_eq!(counts(&parcels), theirs);
    // Names and colours from the ITK-SNAP file beside the labels.
    let first = &parcels.segments()[0];
    assert_eq!((first.value, first.name.as_str()), (1, "parcel 1"));
    assert_eq!(first.colour, [84, 130, 242]);
    assert!(
        parcels
            .segments()
            .iter()
            .all(|s| s.name == format!("parcel {}", s.value))
    );
}

#[test]
fn labels_on_another_grid_take_the_nearest_label_by_patient_position_and_bad_ones_are_refused() {
    let dir = common::TempDir::new("labels");
    common::run_python("label_files.py", &[dir.path()]);
    let cases = common::cases_json(dir.path());
    for case in cases.as_array().expect("cases") {
        let name = case["case"].as_str().expect("a name");
        let img = image(&dir.path().join(format!("{name}_image.nii.gz")));
        let path = dir.path().join(format!("{name}_labels.nii.gz"));
        let got = load_labels(&path, &img, &LabelOptions::default());
        if let Some(said) = case["refused"].as_str() {
            let e = got.map(|_| ()).expect_err(name).to_string();
            assert!(e.contains(said), "{name}: {e}");
            assert!(e.contains(&path.display().to_string()), "{name}: {e}");
            continue;
        }
        let map = got.unwrap_or_else(|e| panic!("{name}: {e}"));
        let want: Vec<u16> = std::fs::read(dir.path().join(format!("{name}_expected.u16")))
            .expect("expected")
            .chunks_exact(2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
            .collect();
        // numpy's order is the file's; LeapView stores a mirrored image's x reversed.
        let [nx, ny, nz] = img.dims().map(|d| d as usize);
        let mut mismatched = 0;
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let file_x = if img.reversed_i() { nx - 1 - x } else { x };
                    let i = x + nx * (y + ny * z);
                    let w = want[file_x + nx * (y + ny * z)];
                    mismatched += usize::from(map.layers()[0][i] != w);
                }
            }
        }
        assert_eq!(
            mismatched, 0,
            "{name}: {mismatched} voxels differ from numpy's"
        );
        assert!(
            want.iter().any(|&w| w != 0) && want.contains(&0),
            "{name}: a trivial case"
        );
        assert!(
            map.notes().iter().any(|n| n.contains("nearest label")),
            "{name}: {:?}",
            map.notes()
        );
    }
}

/// A NRRD of `sizes` with `fields` after the geometry (none where `placed` is false), holding
/// `voxels`.
fn nrrd(path: &Path, sizes: [u32; 3], placed: bool, fields: &str, voxels: &[u8]) {
    let geometry = if placed {
        "space: left-posterior-superior\nspace directions: (1,0,0) (0,1,0) (0,0,1)\n\
         space origin: (0,0,0)\n"
    } else {
        "spacings: 1 1 1\n"
    };
    let [x, y, z] = sizes;
    let mut bytes = format!(
        "NRRD0004\ntype: uint8\ndimension: 3\nsizes: {x} {y} {z}\nencoding: raw\n{geometry}{fields}\n"
    )
    .into_bytes();
    bytes.extend_from_slice(voxels);
    std::fs::write(path, bytes).expect("write");
}

#[test]
fn a_seg_nrrd_that_disagrees_with_its_voxels_and_grids_without_geometry_are_refused() {
    let dir = common::TempDir::new("labels-bad");
    let at = |name: &str| dir.path().join(name);
    let voxels: Vec<u8> = (0..24).map(|i| (i % 3) as u8).collect();
    nrrd(&at("image.nrrd"), [4, 3, 2], true, "", &voxels);
    let img = image(&at("image.nrrd"));
    let refused = |name: &str, said: &str| {
        let e = load_labels(&at(name), &img, &LabelOptions::default())
            .map(|_| ())
            .expect_err(name)
            .to_string();
        assert!(e.contains(said), "{name}: {e}");
    };
    // Label 2 in the voxels, only label 1 in the fields.
    let one = "Segment0_ID:=Segment_1\nSegment0_Name:=a\nSegment0_LabelValue:=1\n";
    nrrd(&at("two.seg.nrrd"), [4, 3, 2], true, one, &voxels);
    refused("two.seg.nrrd", "label 2");
    // A segment in a layer the file does not have.
    let layered = format!("{one}Segment1_Name:=b\nSegment1_LabelValue:=2\nSegment1_Layer:=1\n");
    nrrd(&at("layer.seg.nrrd"), [4, 3, 2], true, &layered, &voxels);
    refused("layer.seg.nrrd", "layer 1");
    // A colour that is no colour.
    let colour = format!("{one}Segment0_Color:=red\n");
    nrrd(&at("colour.seg.nrrd"), [4, 3, 2], true, &colour, &[0; 24]);
    refused("colour.seg.nrrd", "Segment0_Color");
    // Another grid and no geometry to match it by.
    nrrd(&at("loose.nrrd"), [5, 3, 2], false, "", &[1; 30]);
    refused("loose.nrrd", "no orientation");
    // The same grid without geometry: taken voxel for voxel, said.
    nrrd(&at("same.nrrd"), [4, 3, 2], false, "", &voxels);
    let map = labels(&at("same.nrrd"), &img);
    assert_eq!(counts(&map), [(1, 8), (2, 8)]);
    assert!(
        map.notes()[0].contains("voxel for voxel"),
        "{:?}",
        map.notes()
    );
}

#[test]
fn a_layered_seg_nrrd_from_pynrrd_gives_each_overlapping_layer_on_the_images_grid() {
    let dir = common::TempDir::new("labels-layered");
    common::run_python("layered_seg.py", &[dir.path()]);
    let at = |name: &str| dir.path().join(name);
    let img = image(&at("image.nii.gz"));
    let map = labels(&at("layered.seg.nrrd"), &img);
    assert_eq!(map.layers().len(), 2, "two layers");
    // The file's segments: (layer, value) → name, colour.
    let cases = common::cases_json(dir.path());
    let file: Vec<(u16, u16, String, [u8; 3])> = cases
        .as_array()
        .expect("segments")
        .iter()
        .map(|c| {
            let n = |v: &serde_json::Value| v.as_u64().expect("a number") as u16;
            let rgb: Vec<u8> = c["colour"]
                .as_array()
                .expect("a colour")
                .iter()
                .map(|v| n(v) as u8)
                .collect();
            (
                n(&c["layer"]),
                n(&c["value"]),
                c["name"].as_str().expect("a name").to_string(),
                [rgb[0], rgb[1], rgb[2]],
            )
        })
        .collect();
    let file_name = |layer: usize, value: u16| {
        file.iter()
            .find(|f| usize::from(f.0) == layer && f.1 == value)
            .map_or("", |f| f.2.as_str())
    };
    let our_name = |layer: usize, value: u16| {
        map.segments()
            .iter()
            .find(|s| usize::from(s.layer) == layer && s.value == value)
            .map_or("", |s| s.name.as_str())
    };
    // Each layer's segment under every voxel is numpy's, by name (a value two layers hold is
    // renumbered in the later one: the colour table is indexed by value).
    let [nx, ny, nz] = img.dims().map(|d| d as usize);
    for (k, layer) in map.layers().iter().enumerate() {
        let want: Vec<u16> = std::fs::read(at(&format!("layer{k}.u16")))
            .expect("expected")
            .chunks_exact(2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
            .collect();
        let mut mismatched = 0;
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let file_x = if img.reversed_i() { nx - 1 - x } else { x };
                    let w = file_name(k, want[file_x + nx * (y + ny * z)]);
                    mismatched += usize::from(our_name(k, layer[x + nx * (y + ny * z)]) != w);
                }
            }
        }
        assert_eq!(mismatched, 0, "layer {k}: voxels differ from numpy's");
    }
    let got: Vec<(u16, String, [u8; 3])> = map
        .segments()
        .iter()
        .map(|s| (s.layer, s.name.clone(), s.colour))
        .collect();
    let want: Vec<(u16, String, [u8; 3])> = file
        .iter()
        .map(|(layer, _, name, rgb)| (*layer, name.clone(), *rgb))
        .collect();
    assert_eq!(got, want);
    assert!(map.segments().iter().all(|s| s.voxels > 0));
    let mut values: Vec<u16> = map.segments().iter().map(|s| s.value).collect();
    values.sort_unstable();
    values.dedup();
    assert_eq!(values.len(), 4, "values unique across layers");
    assert!(
        map.notes()
            .iter()
            .any(|n| n.contains("layer 1's label 1 (tumour)")),
        "{:?}",
        map.notes()
    );
    // More layers than a segmentation may have: refused, saying why.
    let e = load_labels(&at("too_many.seg.nrrd"), &img, &LabelOptions::default())
        .map(|_| ())
        .expect_err("17 layers")
        .to_string();
    assert!(e.contains("at most 16 layers"), "{e}");
    // As a volume, a layered file is still no image.
    let e = load_volume(&at("layered.seg.nrrd"), &LoadOptions::default())
        .map(|_| ())
        .expect_err("4-D")
        .to_string();
    assert!(e.contains("--labels"), "{e}");
    // Dropped over the image: told apart by the headers nibabel and pynrrd wrote.
    let dims = img.dims();
    let guess = |name: &str| guess_dropped(&at(name), dims);
    assert!(matches!(guess("layered.seg.nrrd"), DropGuess::Labels(_)));
    assert!(matches!(guess("intent.nii.gz"), DropGuess::Labels(w) if w.contains("NIfTI")));
    assert!(matches!(guess("plain.nii.gz"), DropGuess::Ask(w) if w.contains("grid")));
    assert_eq!(guess("liver_seg.nii.gz"), DropGuess::Image, "floats");
    // The image itself, whole numbers on its own grid: asked about too.
    assert!(matches!(guess("image.nii.gz"), DropGuess::Ask(_)));
}

/// The stored index of the voxel nearest each pixel of `view` (row-major; `None` outside a
/// volume of `dims`), and whether the pixel's centre lies within 10⁻³ voxels of a tie (where f32
/// and f64 may round apart).
fn voxels_under(
    frame: &PatientFrame,
    view: &SliceView,
    dims: [u32; 3],
) -> Vec<(Option<usize>, bool)> {
    let grid = view.voxel_grid(frame);
    let [nx, ny, nz] = dims.map(i64::from);
    let mut out = Vec::new();
    for y in 0..view.size[1] {
        for x in 0..view.size[0] {
            let v = grid.first + grid.step_x * f64::from(x) + grid.step_y * f64::from(y);
            let near_tie = v
                .to_array()
                .iter()
                .any(|c| ((c - c.floor()) - 0.5).abs() < 1e-3);
            let [i, j, k] = v.to_array().map(|c| (c + 0.5).floor() as i64);
            let inside = (0..nx).contains(&i) && (0..ny).contains(&j) && (0..nz).contains(&k);
            out.push((inside.then(|| (i + nx * (j + ny * k)) as usize), near_tie));
        }
    }
    out
}

/// The first layer's label of the voxel nearest each pixel of `view` (0 outside), and whether
/// the pixel is near a tie.
fn labels_under(map: &LabelMap, frame: &PatientFrame, view: &SliceView) -> Vec<(u16, bool)> {
    voxels_under(frame, view, map.dims())
        .into_iter()
        .map(|(index, tie)| (index.map_or(0, |i| map.layers()[0][i]), tie))
        .collect()
}

/// A CT slice of nearest voxels in a soft-tissue window, labels `opacity` opaque, outlined or
/// not.
fn look(opacity: f32, outline: bool) -> SliceLook {
    SliceLook {
        window: [-100.0, 200.0],
        nearest: true,
        slab: None,
        leap: false,
        colour: false,
        invert: false,
        labels: LabelLook { opacity, outline },
    }
}

#[test]
fn a_slice_fills_each_shown_label_in_its_colour_and_outlines_its_edges() {
    let data = common::data_dir();
    let series = image(&data.join("dicom/ct_head_cthead"));
    let map = labels(&data.join("labels/ct_head_cthead.seg.nrrd"), &series);
    let ctx = common::gpu();
    let texture = VolumeTexture::upload(&ctx, &series).expect("upload");
    let renderer = SliceRenderer::new(&ctx.device).expect("pipeline");
    let gpu_labels = GpuLabels::new(&ctx.device, &ctx.queue, map.clone()).expect("labels");
    let frame = PatientFrame::of(&series);
    // Through the brain (slices 70 … 104 of 113 hold it), the skull and the soft tissue.
    let at = frame.centre() + DVec3::new(0.3, -0.2, 50.3);
    let view = SliceView::fit(
        Plane::standard(PlaneKind::Axial, at),
        &frame,
        Some([200, 180]),
    );
    let draw = |labels: Option<&GpuLabels>, look: SliceLook| {
        renderer
            .render_display(&ctx, &series, &texture, None, None, labels, &view, look)
            .expect("slice")
    };
    let plain = draw(None, look(1.0, false));
    let filled = draw(Some(&gpu_labels), look(1.0, false));
    let under = labels_under(&map, &frame, &view);
    let colour = |l: u16| {
        map.segments()
            .iter()
            .find(|s| s.value == l)
            .map(|s| s.colour)
            .expect("a segment")
    };
    // Opaque fill: a label's own colour where it is, the image where none is.
    let mut wrong = 0;
    let mut ties = 0;
    for (i, &(label, tie)) in under.iter().enumerate() {
        let want = if label == 0 { plain[i] } else { colour(label) };
        if filled[i] != want {
            if tie {
                ties += 1;
            } else {
                wrong += 1;
            }
        }
    }
    assert_eq!(
        wrong, 0,
        "{wrong} pixels away from ties differ ({ties} at ties)"
    );
    for l in 1..=3 {
        assert!(
            under.iter().any(|&(x, _)| x == l),
            "label {l} not in the view"
        );
    }
    // The skull hidden: its pixels show the image, the others still their labels.
    gpu_labels.show(&ctx.queue, &map, |s| s.name != "skull");
    let hidden = draw(Some(&gpu_labels), look(1.0, false));
    for (i, &(label, tie)) in under.iter().enumerate() {
        let want = if label == 0 || label == 2 {
            plain[i]
        } else {
            colour(label)
        };
        assert!(tie || hidden[i] == want, "pixel {i} (label {label})");
    }
    // Outlines only (no fill): coloured pixels are those whose neighbour's label differs.
    gpu_labels.show(&ctx.queue, &map, |_| true);
    let outlined = draw(Some(&gpu_labels), look(0.0, true));
    let [w, h] = view.size.map(|d| d as usize);
    let mut edges = 0;
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let i = x + w * y;
            let (label, tie) = under[i];
            let near = [i - 1, i + 1, i - w, i + w];
            if tie || near.iter().any(|&n| under[n].1) {
                continue;
            }
            let edge = label != 0 && near.iter().any(|&n| under[n].0 != label);
            let want = if edge { colour(label) } else { plain[i] };
            assert_eq!(outlined[i], want, "pixel ({x}, {y}), label {label}");
            edges += usize::from(edge);
        }
    }
    assert!(edges > 100, "only {edges} outline pixels");
}

#[test]
fn highdicom_segs_overlapping_fractional_and_of_another_series_are_read_or_refused() {
    let dir = common::TempDir::new("labels-seg");
    common::run_python("seg_files.py", &[dir.path()]);
    let cases = common::cases_json(dir.path());
    let series = image(&dir.path().join("series"));
    let frame = PatientFrame::of(&series);
    let coord = |key: &str| -> [f64; 3] {
        let v = cases[key].as_array().expect(key);
        std::array::from_fn(|a| v[a].as_f64().expect("a number"))
    };
    let (origin, spacing) = (coord("origin"), coord("spacing"));
    let dims: Vec<usize> = cases["dims"]
        .as_array()
        .expect("dims")
        .iter()
        .map(|d| d.as_u64().expect("a size") as usize)
        .collect();
    // Native, and compressed as highdicom writes them (binary: JPEG 2000; fractional: RLE,
    // JPEG-LS, JPEG 2000), each read to the same labels.
    for file in [
        "binary",
        "fractional",
        "binary_j2k",
        "fractional_rle",
        "fractional_jls",
        "fractional_j2k",
    ] {
        let map = labels(&dir.path().join(format!("{file}.dcm")), &series);
        for want in cases[file].as_array().expect("segments") {
            let number = want["number"].as_u64().expect("number") as u16;
            let segment = map
                .segments()
                .iter()
                .find(|s| s.value == number)
                .unwrap_or_else(|| panic!("{file}: no segment {number}"));
            assert_eq!(segment.name, want["label"].as_str().expect("label"));
            let rgb: Vec<u8> = want["rgb"]
                .as_array()
                .expect("rgb")
                .iter()
                .map(|c| c.as_u64().expect("a byte") as u8)
                .collect();
            let off = segment
                .colour
                .iter()
                .zip(&rgb)
                .map(|(a, b)| a.abs_diff(*b))
                .max();
            assert!(
                off <= Some(1),
                "{file} {number}: {:?} against {rgb:?}",
                segment.colour
            );
            // Membership voxel by voxel, in whichever layer holds the segment.
            let mask = std::fs::read(dir.path().join(format!("{file}_{number}.u8"))).expect("mask");
            let [nx, ny, nz] = series.dims();
            let mut wrong = 0;
            for k in 0..nz {
                for j in 0..ny {
                    for i in 0..nx {
                        let p =
                            frame.to_patient(DVec3::new(f64::from(i), f64::from(j), f64::from(k)));
                        let at = |a: usize| ((p[a] - origin[a]) / spacing[a]).round() as usize;
                        let want = mask[at(0) + dims[0] * (at(1) + dims[1] * at(2))] == 1;
                        let index = series.index(i, j, k);
                        let got = map.layers().iter().any(|l| l[index] == number);
                        wrong += usize::from(got != want);
                    }
                }
            }
            assert_eq!(wrong, 0, "{file} segment {number}: {wrong} voxels differ");
        }
    }
    // The two spheres overlap: two layers, both drawn in the slices (the later over the earlier).
    let binary = labels(&dir.path().join("binary.dcm"), &series);
    assert_eq!(binary.layers().len(), 2);
    let ctx = common::gpu();
    let texture = VolumeTexture::upload(&ctx, &series).expect("upload");
    let renderer = SliceRenderer::new(&ctx.device).expect("pipeline");
    let gpu_labels = GpuLabels::new(&ctx.device, &ctx.queue, binary.clone()).expect("labels");
    assert_eq!(gpu_labels.layers(), 2);
    let at = DVec3::from(origin) + DVec3::new(8.0, 8.5, 15.0);
    let view = SliceView::fit(
        Plane::standard(PlaneKind::Axial, at),
        &frame,
        Some([96, 80]),
    );
    let look = look(1.0, false);
    let drawn = renderer
        .render_display(
            &ctx,
            &series,
            &texture,
            None,
            None,
            Some(&gpu_labels),
            &view,
            look,
        )
        .expect("slice");
    let colour = |l: u16| {
        binary
            .segments()
            .iter()
            .find(|s| s.value == l)
            .map(|s| s.colour)
    };
    let (mut both, mut wrong) = (0, 0);
    for (pixel, (index, tie)) in voxels_under(&frame, &view, series.dims())
        .into_iter()
        .enumerate()
    {
        let Some(index) = index.filter(|_| !tie) else {
            continue;
        };
        let here: Vec<u16> = binary.layers().iter().map(|l| l[index]).collect();
        both += usize::from(here.iter().all(|&l| l != 0));
        // Opaque fill: the last layer's label where there is one.
        if let Some(want) = here
            .iter()
            .rev()
            .find(|&&l| l != 0)
            .and_then(|&l| colour(l))
        {
            wrong += usize::from(drawn[pixel] != want);
        }
    }
    assert!(both > 0, "the slice misses the overlap");
    assert_eq!(wrong, 0, "{wrong} labelled pixels differ");
    let fractional = labels(&dir.path().join("fractional.dcm"), &series);
    assert!(
        fractional.notes().iter().any(|n| n.contains("half")),
        "{:?}",
        fractional.notes()
    );
    // A SEG of the other series (the same frame of reference) is refused.
    let e = load_labels(
        &dir.path().join("other.dcm"),
        &series,
        &LabelOptions::default(),
    )
    .map(|_| ())
    .expect_err("another series")
    .to_string();
    assert!(e.contains("another scan") && e.contains("series"), "{e}");
    // SEGs that lie: refused with the reason, nothing allocated for the lie.
    for bad in cases["refused"].as_array().expect("refused") {
        let file = dir.path().join(bad["file"].as_str().expect("a file"));
        let e = load_labels(&file, &series, &LabelOptions::default())
            .map(|_| ())
            .expect_err("a lying SEG")
            .to_string();
        let said = bad["said"].as_str().expect("what to say");
        assert!(e.contains(said), "{}: {e}", file.display());
        assert!(leapview::labels::is_segmentation_file(&file));
    }
    assert!(!leapview::labels::is_segmentation_file(
        &dir.path().join("series/slice000.dcm")
    ));
    // A SEG cut short: its lengths are checked before dicom-rs reads it, and it is refused.
    let bytes = std::fs::read(dir.path().join("binary.dcm")).expect("the SEG");
    let cut = dir.path().join("cut.dcm");
    std::fs::write(&cut, &bytes[..3000]).expect("cut");
    let e = load_labels(&cut, &series, &LabelOptions::default())
        .map(|_| ())
        .expect_err("a cut SEG")
        .to_string();
    assert!(e.contains("cut short"), "{e}");
}
