//! Slice views on the GPU against the f64 reference (`reference::slice`), and the same anatomy
//! stored in different orientations giving the same slices.

use crate::common;

use glam::DVec3;
use leapview::mpr::{PatientFrame, Plane, PlaneKind, Slab, SlabMode, SliceView};
use leapview::reference::slice::slice_values;
use leapview::render::context::GpuContext;
use leapview::render::slice::{LabelLook, SliceImage, SliceLook, SliceRenderer};
use leapview::render::volume_texture::VolumeTexture;
use leapview::volume::{Orientation, Provenance, Samples, ValueMapping, Volume};

const DIMS: [u32; 3] = [23, 19, 13];
const SPACING: [f64; 3] = [0.7, 1.1, 2.5];
/// A window whose ends are not whole numbers: integer values never fall exactly between two
/// grey levels, where f32 and f64 could round apart.
const WINDOW: [f64; 2] = [-1100.3, 400.1];

/// A CT-like int16 volume (HU = stored − 1024): ramps along every axis and a dense block, so
/// that a wrong axis, sign or offset shows. `flip` reverses the stored order along i and j.
fn anatomy(flip: [bool; 2]) -> Vec<i16> {
    let mut out = Vec::new();
    for z in 0..DIMS[2] as i32 {
        for y in 0..DIMS[1] as i32 {
            for x in 0..DIMS[0] as i32 {
                let ax = if flip[0] { DIMS[0] as i32 - 1 - x } else { x };
                let ay = if flip[1] { DIMS[1] as i32 - 1 - y } else { y };
                let block = (4..9).contains(&ax) && (3..12).contains(&ay) && (2..7).contains(&z);
                out.push((10 * ax + 70 * ay - 37 * z + if block { 900 } else { 0 }) as i16);
            }
        }
    }
    out
}

fn volume(code: &str, flip: [bool; 2], origin: [f64; 3]) -> Volume {
    let o = Orientation::parse_code(code).expect("code");
    Volume::new(
        code,
        DIMS,
        SPACING,
        Samples::I16(anatomy(flip)),
        ValueMapping {
            slope: 1.0,
            intercept: -1024.0,
        },
    )
    .expect("volume")
    .with_orientation(Some(o))
    .with_provenance(Provenance {
        origin_lps: Some(origin),
        ..Provenance::default()
    })
    .unmirrored()
}

/// The anatomy as an LPS file, and as RAS and LAS (mirrored) files of the same patient.
fn same_patient() -> [Volume; 3] {
    let last = [
        f64::from(DIMS[0] - 1) * SPACING[0],
        f64::from(DIMS[1] - 1) * SPACING[1],
    ];
    [
        volume("LPS", [false, false], [0.0, 0.0, 0.0]),
        // RAS: i runs to the right, j to the front: the file's first voxel is the LPS file's
        // last along i and j.
        volume("RAS", [true, true], [last[0], last[1], 0.0]),
        // LAS (a mirror image of RAS): stored reversed along i by the loader.
        volume("LAS", [false, true], [0.0, last[1], 0.0]),
    ]
}

fn views(frame: &PatientFrame) -> Vec<SliceView> {
    let at = frame.centre() + DVec3::new(0.3, -0.6, 1.1);
    let mut out: Vec<SliceView> = PlaneKind::STANDARD
        .iter()
        .map(|&k| SliceView::fit(Plane::standard(k, at), frame, None))
        .collect();
    let oblique = Plane::standard(PlaneKind::Coronal, at).tilted(DVec3::new(1.0, 0.0, 1.0), 0.5);
    out.push(SliceView::fit(oblique, frame, Some([97, 61])));
    // Zoomed in and panned, beyond the volume's edge.
    out.push(
        out[0]
            .zoomed(3.0, glam::DVec2::new(5.0, 5.0))
            .panned(glam::DVec2::new(4.0, -9.0)),
    );
    out
}

fn draw(ctx: &GpuContext, v: &Volume, view: &SliceView, nearest: bool) -> SliceImage {
    draw_slab(ctx, v, view, nearest, None)
}

fn draw_slab(
    ctx: &GpuContext,
    v: &Volume,
    view: &SliceView,
    nearest: bool,
    slab: Option<Slab>,
) -> SliceImage {
    let texture = VolumeTexture::upload(ctx, v).expect("upload");
    let look = SliceLook {
        window: WINDOW,
        nearest,
        slab,
        leap: true,
        colour: false,
        invert: false,
        labels: LabelLook::default(),
    };
    let renderer = SliceRenderer::new(&ctx.device).expect("pipeline");
    // Slabs leap over their bricks here, so the reference checks the leaping walk.
    let bricks = slab.and_then(|_| renderer.bricks_of(ctx, v, &texture));
    assert_eq!(bricks.is_some(), slab.is_some());
    renderer
        .render(ctx, v, &texture, bricks.as_ref(), view, look)
        .expect("slice")
}

/// Whether pixel centre `v` (voxel coordinates) lies within `eps` of where the answer changes:
/// the box's faces, or (nearest) a rounding boundary between voxels. f32 positions on the GPU
/// may fall on either side there.
fn on_a_boundary(v: DVec3, nearest: bool, eps: f64) -> bool {
    (0..3).any(|a| {
        let n = f64::from(DIMS[a]);
        let face = (v[a] + 0.5).abs() < eps || (v[a] - (n - 0.5)).abs() < eps;
        let rounding = nearest && ((v[a] + 0.5) - (v[a] + 0.5).round()).abs() < eps;
        face || rounding
    })
}

#[test]
fn slice_pixels_equal_the_f64_reference_in_every_orientation_trilinear_and_nearest() {
    let ctx = common::gpu();
    for v in same_patient() {
        let frame = PatientFrame::of(&v);
        for (n, view) in views(&frame).iter().enumerate() {
            let grid = view.voxel_grid(&frame);
            for nearest in [false, true] {
                let gpu = draw(&ctx, &v, view, nearest);
                let reference = slice_values(&v, view, nearest, None);
                let (mut worst, mut compared, mut skipped, mut inside) = (0.0f64, 0, 0, 0);
                for (i, r) in reference.iter().enumerate() {
                    let (x, y) = (
                        (i as u32 % view.size[0]) as f64,
                        (i as u32 / view.size[0]) as f64,
                    );
                    let at = grid.first + grid.step_x * x + grid.step_y * y;
                    if on_a_boundary(at, nearest, 1e-3) {
                        skipped += 1;
                        continue;
                    }
                    let g = gpu.values[i];
                    let r = (!r.is_nan()).then_some(*r);
                    match r {
                        None => assert!(
                            g.is_nan(),
                            "{} view {n}: pixel {i} outside, GPU {g}",
                            v.name()
                        ),
                        Some(r) => {
                            inside += 1;
                            worst = worst.max((f64::from(g) - r).abs());
                            let expected = leapview::mpr::grey(r, WINDOW);
                            let d = i32::from(gpu.grey[i]) - i32::from(expected);
                            assert!(
                                d.abs() <= i32::from(!nearest),
                                "{} view {n} nearest {nearest}: grey {} vs {expected}",
                                v.name(),
                                gpu.grey[i]
                            );
                        }
                    }
                    compared += 1;
                }
                // f32 positions and values: within a thousandth of a unit of the f64 answer
                // (the data span about 2900 units, the block steps 900 between voxels).
                let tolerance = if nearest { 1e-3 } else { 0.05 };
                assert!(
                    worst <= tolerance,
                    "{} view {n} nearest {nearest}: off by up to {worst}",
                    v.name()
                );
                assert!(
                    inside > 100,
                    "{} view {n}: the slice cuts the volume",
                    v.name()
                );
                // Fitted views put some rows exactly between two voxels (ties for nearest).
                assert!(
                    skipped * 4 <= compared,
                    "{} view {n}: {skipped} of {} pixels on a boundary",
                    v.name(),
                    compared + skipped
                );
            }
        }
    }
}

#[test]
fn the_same_patient_stored_as_lps_ras_or_mirrored_las_gives_the_same_slices() {
    let ctx = common::gpu();
    let [lps, ras, las] = same_patient();
    let frame = PatientFrame::of(&lps);
    for other in [&ras, &las] {
        let other_frame = PatientFrame::of(other);
        // The same box in the patient's frame.
        for c in frame.corners() {
            assert!(
                other_frame
                    .corners()
                    .iter()
                    .any(|o| (*o - c).length() < 1e-9),
                "{}: corner {c} missing",
                other.name()
            );
        }
        for (n, view) in views(&frame).iter().enumerate() {
            // Trilinear: no ties between neighbours, the same weights mirrored.
            let a = draw(&ctx, &lps, view, false);
            let b = draw(&ctx, other, view, false);
            let (mut worst, mut only_one) = (0.0f32, 0);
            for (x, y) in a.values.iter().zip(&b.values) {
                match (x.is_nan(), y.is_nan()) {
                    (false, false) => worst = worst.max((x - y).abs()),
                    (true, true) => {}
                    _ => only_one += 1,
                }
            }
            assert!(
                worst <= 0.01,
                "{} view {n}: off by up to {worst}",
                other.name()
            );
            // Pixels exactly on the box's faces may fall either side of them.
            assert!(
                only_one * 50 <= a.values.len(),
                "{} view {n}: {only_one} pixels inside one file and outside the other",
                other.name()
            );
        }
    }
}

#[test]
fn an_axial_view_puts_the_patients_right_on_the_left_and_the_front_on_top() {
    let ctx = common::gpu();
    let [lps, ..] = same_patient();
    let frame = PatientFrame::of(&lps);
    let view = SliceView::fit(
        Plane::standard(PlaneKind::Axial, frame.centre()),
        &frame,
        None,
    );
    let image = draw(&ctx, &lps, &view, true);
    let [w, h] = view.size.map(|s| s as usize);
    let at = |x: usize, y: usize| image.values[y * w + x];
    // Values rise by 10 a voxel towards the patient's left (+i in LPS): left to right on screen.
    assert!(at(w - 1, h / 2) > at(0, h / 2));
    // And by 70 a voxel towards the back (+j): the front is on top, so values rise downwards.
    assert!(at(w / 2, h - 1) > at(w / 2, 0));
}

#[test]
fn thick_slabs_equal_the_reference_for_mip_minip_and_mean() {
    let ctx = common::gpu();
    let [lps, _, las] = same_patient();
    for v in [lps, las] {
        let frame = PatientFrame::of(&v);
        let views = views(&frame);
        for mode in [SlabMode::Mip, SlabMode::MinIp, SlabMode::Mean] {
            let slab = Slab {
                thickness_mm: 7.3,
                mode,
            };
            for view in [&views[0], &views[3]] {
                let gpu = draw_slab(&ctx, &v, view, false, Some(slab));
                let reference = slice_values(&v, view, false, Some(slab));
                let thin = slice_values(&v, view, false, None);
                let (mut worst, mut thicker) = (0.0f64, 0);
                for ((g, r), t) in gpu.values.iter().zip(&reference).zip(&thin) {
                    if r.is_nan() || g.is_nan() {
                        continue;
                    }
                    worst = worst.max((f64::from(*g) - r).abs());
                    thicker += usize::from((r - t).abs() > 1.0);
                }
                assert!(worst <= 0.05, "{} {mode:?}: off by up to {worst}", v.name());
                // The slab differs from the thin slice (values change along every axis).
                assert!(thicker > 50, "{} {mode:?}: the slab looks thin", v.name());
            }
        }
    }
}

/// `leapview slice` writes the pixels a slice view shows: the f64 reference through the window,
/// for a file written by `leapview generate` and read back as a user's file.
#[test]
fn the_slice_command_writes_the_reference_pixels_and_refuses_bad_requests() {
    let dir = common::TempDir::new("slice-cli");
    let file = dir.path().join("phantom.nrrd");
    let out = common::leapview(&[
        "generate",
        "phantom",
        "--size",
        "24",
        "--out",
        file.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let volume = leapview::volume::load_volume(&file, &Default::default()).expect("load");
    let frame = PatientFrame::of(&volume);
    let at = frame.centre() + DVec3::new(0.0, 1.3, 0.0);
    let png = dir.path().join("coronal.png");
    let at_text = format!("{},{},{}", at.x, at.y, at.z);
    let out = common::leapview(&[
        "slice",
        file.to_str().expect("utf-8"),
        "--plane",
        "coronal",
        "--at",
        &at_text,
        "--nearest",
        "--window=-900.3,200.1",
        "--size",
        "50x40",
        "--out",
        png.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("edges: left R, right L, top S, bottom I"),
        "{text}"
    );
    let written = image::open(&png).expect("png").to_luma8();
    assert_eq!(written.dimensions(), (50, 40));
    let view = SliceView::fit(
        Plane::standard(PlaneKind::Coronal, at),
        &frame,
        Some([50, 40]),
    );
    let reference = slice_values(&volume, &view, true, None);
    let differing = written
        .pixels()
        .zip(&reference)
        .filter(|(p, r)| p.0[0] != leapview::mpr::grey(**r, [-900.3, 200.1]))
        .count();
    // Only pixels exactly between two voxels (f32 against f64 rounding) may differ.
    assert!(
        differing * 50 <= reference.len(),
        "{differing} pixels differ"
    );
    assert!(written.pixels().any(|p| p.0[0] > 0), "the phantom shows");

    let name = file.to_str().expect("utf-8");
    let target = dir.path().join("x.png");
    let target = target.to_str().expect("utf-8");
    for (args, expected) in [
        (
            vec!["--plane", "diagonal"],
            "--plane is axial, coronal, sagittal or a normal",
        ),
        (vec!["--plane", "0,0,0"], "normal must be"),
        (vec!["--at", "0,0,9999"], "does not cut the volume"),
        (vec!["--slab", "0"], "--slab must be a thickness above 0 mm"),
    ] {
        let mut all = vec!["slice", name, "--out", target];
        all.extend(args);
        let out = common::leapview(&all);
        assert_eq!(out.status.code(), Some(2), "{all:?}");
        assert!(
            common::stderr(&out).contains(expected),
            "{all:?}: {}",
            common::stderr(&out)
        );
    }
    let out = common::leapview(&[
        "slice",
        name,
        "--out",
        dir.path().join("x.jpg").to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(2));
}

/// The Seg3D MR head as its NIfTI original and as the DICOM series written from it (both by
/// other software, `../shared/data`): the same patient frame (the NIfTI's sform origin, the
/// series' ImagePositionPatient), so a slice through one patient point is the same picture from
/// either file, in every standard plane.
#[test]
fn the_nifti_and_dicom_twins_give_the_same_slice_through_the_same_patient_point() {
    let ctx = common::gpu();
    let data = common::data_dir();
    let nifti = leapview::volume::load_volume(
        &data.join("originals/VolumeRenderingData_seg3D_MR.nii.gz"),
        &Default::default(),
    )
    .expect("NIfTI");
    let dicom =
        leapview::volume::load_volume(&data.join("dicom/mr_head_t1_seg3d"), &Default::default())
            .expect("DICOM series");
    let (a, b) = (PatientFrame::of(&nifti), PatientFrame::of(&dicom));
    for c in a.corners() {
        assert!(
            b.corners().iter().any(|o| (*o - c).length() < 1e-3),
            "the NIfTI's corner {c} is not the series'"
        );
    }
    let at = a.centre() + DVec3::new(-12.3, 7.9, 20.4);
    for kind in PlaneKind::STANDARD {
        let view = SliceView::fit(Plane::standard(kind, at), &a, Some([160, 140]));
        let x = draw(&ctx, &nifti, &view, false);
        let y = draw(&ctx, &dicom, &view, false);
        let worst = x
            .values
            .iter()
            .zip(&y.values)
            .filter(|(p, q)| !p.is_nan() && !q.is_nan())
            .map(|(p, q)| (p - q).abs())
            .fold(0.0f32, f32::max);
        let shown = x.values.iter().filter(|v| **v > 10.0).count();
        assert!(shown > 1000, "{kind:?}: the slice shows the head");
        assert!(worst <= 1e-3, "{kind:?}: the twins differ by up to {worst}");
        assert_eq!(x.grey, y.grey, "{kind:?}: the same picture");
    }
}
