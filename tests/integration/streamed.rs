//! OME-Zarr stores larger than the memory budget, read brick by brick (`volume::streamed`,
//! `volume::zarr::source`): every level's boxes equal the volume's own levels as LeapView
//! halves them, the statistics are the whole volume's (kept in the store), and images equal
//! those of the same volume held in memory, rendered at once or streamed frame by frame with
//! the bricks read off the frame's thread.

use std::sync::Arc;

use glam::DVec3;
use leapview::camera::{Aabb, Camera, ProjectionKind};
use leapview::render::VolumeRenderer;
use leapview::settings::{Bricking, Mode, RenderPath, RenderSettings, Strategy, Upload};
use leapview::volume::downsample::{Level, level_dims};
use leapview::volume::zarr::write::write_ome_zarr;
use leapview::volume::{LoadOptions, Samples, ValueMapping, Volume, load_volume};

use crate::common;
use crate::common::scene::tf;

/// A 16-bit volume of 70 × 52 × 45 (odd sizes: the levels' last voxels repeat) whose values
/// vary along every axis, with a ball of dense values: a misplaced brick or box shows.
fn structured() -> Volume {
    let dims = [70u32, 52, 45];
    let mut v = Vec::new();
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let p = DVec3::new(f64::from(x), f64::from(y), f64::from(z));
                let wave = 300.0 + 200.0 * (p.x * 0.21).sin() * (p.y * 0.17).cos();
                let d = (p - DVec3::new(30.0, 28.0, 22.0)).length() / 17.0;
                let ball = if d < 1.0 { 600.0 * (1.0 - d * d) } else { 0.0 };
                v.push((wave + ball + 30.0 * (p.z * 0.13).sin()) as u16);
            }
        }
    }
    Volume::new(
        "structured",
        dims,
        [0.8, 0.9, 1.2],
        Samples::U16(v),
        ValueMapping {
            slope: 2.0,
            intercept: -1024.0,
        },
    )
    .expect("valid")
}

/// `volume` written as an OME-Zarr store and opened again under a memory budget of one byte:
/// streamed.
fn streamed_copy(volume: &Volume, dir: &common::TempDir) -> Volume {
    let store = dir.path().join("v.ome.zarr");
    write_ome_zarr(volume, &store, "the test", &|_| {}).expect("written");
    let options = LoadOptions {
        ram_budget: Some(1),
        ..LoadOptions::default()
    };
    let streamed = load_volume(&store, &options).expect("opened");
    assert!(streamed.streaming().is_some(), "not streamed");
    streamed
}

fn renderer(volume: &Volume, streaming: bool) -> VolumeRenderer {
    let mut r = common::renderer();
    if streaming {
        r.set_residency_time(Some(std::time::Duration::ZERO));
    }
    let upload = Upload {
        bricking: Bricking::On,
        ..Upload::default()
    };
    r.set_volume_with(&Arc::new(volume.clone()), &upload)
        .expect("upload");
    r.set_transfer_function(&tf());
    r
}

#[test]
fn a_streamed_store_reads_every_level_as_leapview_halves_the_volume() {
    let volume = structured();
    let dir = common::TempDir::new("streamed-levels");
    let streamed = streamed_copy(&volume, &dir);
    assert_eq!(streamed.dims(), volume.dims());
    assert_eq!(streamed.spacing_mm(), volume.spacing_mm());
    assert_eq!(streamed.mapping(), volume.mapping());
    assert_eq!(streamed.samples(), None);
    // The statistics of every voxel, as the store kept them.
    assert!(streamed.exact_statistics());
    assert_eq!(streamed.value_range(), volume.value_range());
    assert_eq!(streamed.histogram(), volume.histogram());
    let notes = streamed.provenance().notes.join(" | ");
    assert!(notes.contains("brick by brick"), "{notes}");
    let source = streamed.streaming().expect("streamed");
    let mut level = Level {
        dims: volume.dims(),
        samples: volume.samples().expect("in memory").clone(),
        colour: None,
    };
    for k in 0..5u32 {
        let d = level_dims(volume.dims(), k);
        assert_eq!(level.dims, d);
        // The whole level, and a box straddling the store's chunks.
        let whole = source.read_box(k, [0; 3], d).expect("read");
        assert_eq!(whole, level.samples, "level {k}");
        let lo = d.map(|n| n / 3);
        let hi = d.map(|n| (n / 3 + 33).min(n));
        let part = source.read_box(k, lo, hi).expect("read");
        let want = common::box_values(&level.samples, d, lo, hi);
        let got: Vec<f64> = (0..part.len()).map(|i| part.get_f64(i)).collect();
        assert_eq!(got, want, "level {k}, box {lo:?}..{hi:?}");
        level = level.halved();
    }
    // A mirrored orientation reads x reversed, box by box.
    let code = leapview::volume::Orientation::parse_code("LAS").expect("code");
    let options = LoadOptions {
        ram_budget: Some(1),
        orientation: Some(code),
        ..LoadOptions::default()
    };
    let mirrored = load_volume(&dir.path().join("v.ome.zarr"), &options).expect("opened");
    assert!(mirrored.reversed_i());
    let row = mirrored
        .streaming()
        .expect("streamed")
        .read_box(0, [0, 5, 7], [70, 6, 8])
        .expect("read");
    for x in 0..70u32 {
        assert_eq!(row.get_f64(x as usize), {
            let stored = volume.samples().expect("in memory");
            stored.get_f64((69 - x + 70 * (5 + 52 * 7)) as usize)
        });
    }
}

#[test]
fn a_streamed_store_renders_as_the_volume_in_memory_at_once_and_frame_by_frame() {
    let volume = structured();
    let dir = common::TempDir::new("streamed-render");
    let streamed = streamed_copy(&volume, &dir);
    let camera = Camera::framing(
        &Aabb::of_volume(volume.dims(), volume.spacing_mm()),
        DVec3::new(0.3, -1.0, 0.4).normalize(),
        DVec3::Z,
        ProjectionKind::Perspective,
    );
    let mut held = renderer(&volume, false);
    let mut at_once = renderer(&streamed, false);
    let mut by_frames = renderer(&streamed, true);
    for mode in [Mode::Dvr, Mode::Mip, Mode::Iso] {
        let settings = RenderSettings {
            mode,
            strategy: Strategy::RcS,
            path: RenderPath::Compute,
            ..RenderSettings::default()
        };
        let want = held
            .render_image(&camera, [48, 40], &settings)
            .expect("render");
        let got = at_once
            .render_image(&camera, [48, 40], &settings)
            .expect("render");
        common::assert_close(&format!("{mode:?} at once"), &got, &want, 1e-6, 0.0);
        // Frame by frame, the bricks read on the readers' threads, until all have come.
        let mut frames = 0;
        let started = std::time::Instant::now();
        let last = loop {
            let image = by_frames
                .render_image(&camera, [48, 40], &settings)
                .expect("render");
            frames += 1;
            if by_frames.residency_complete() {
                break image;
            }
            assert!(
                started.elapsed().as_secs() < 120,
                "still streaming after {frames} frames"
            );
            std::thread::sleep(std::time::Duration::from_millis(2));
        };
        by_frames.set_residency_time(None);
        let waited = by_frames
            .render_image(&camera, [48, 40], &settings)
            .expect("render");
        by_frames.set_residency_time(Some(std::time::Duration::ZERO));
        // Within what streaming a volume held in memory comes to (bricks::streaming_while_…):
        // the tables the frames left are refreshed where level 0 changes them.
        common::assert_close(&format!("{mode:?} streamed"), &waited, &want, 1e-3, 0.0);
        assert!(
            last.pixels.iter().any(|p| p[3] > 0.0),
            "{mode:?}: a blank frame"
        );
    }
}

#[test]
fn a_streamed_store_is_never_one_texture_nor_written_as_if_whole_but_converts_slab_by_slab() {
    let volume = structured();
    let dir = common::TempDir::new("streamed-refusals");
    let streamed = streamed_copy(&volume, &dir);
    let mut r = common::renderer();
    let upload = Upload {
        bricking: Bricking::Off,
        ..Upload::default()
    };
    let e = r
        .set_volume_with(&Arc::new(streamed.clone()), &upload)
        .expect_err("one texture")
        .to_string();
    assert!(e.contains("brick by brick"), "{e}");
    let e = leapview::volume::nrrd::write::write_nrrd(&streamed, &dir.path().join("a.nrrd"), "")
        .expect_err("not whole")
        .to_string();
    assert!(e.contains("needs the whole volume in memory"), "{e}");
    // Written again as a store from its store, a slab at a time: the same voxels, levels and
    // statistics.
    let again = dir.path().join("again.ome.zarr");
    let written = write_ome_zarr(&streamed, &again, "the store", &|_| {}).expect("written");
    assert_eq!(written.levels[0], volume.dims());
    let back = load_volume(&again, &LoadOptions::default()).expect("opened");
    assert!(back.samples() == volume.samples(), "the voxels differ");
    assert_eq!(back.histogram(), volume.histogram());
}

#[test]
fn a_generated_head_of_any_shape_is_written_slab_by_slab_and_read_by_zarr_python() {
    use leapview::volume::synthetic::dense_head::DenseHead;
    let dir = common::TempDir::new("generated-store");
    let store = dir.path().join("head.ome.zarr");
    let out = common::leapview(&[
        "generate",
        "dense-head",
        "--dims",
        "70,40,300",
        "--type",
        "uint16",
        "--seed",
        "3",
        "--out",
        &store.display().to_string(),
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let v = load_volume(&store, &LoadOptions::default()).expect("opened");
    assert_eq!(v.dims(), [70, 40, 300]);
    let want = DenseHead::new([70, 40, 300], 3).slab_u16(0, 300);
    assert!(
        v.samples() == Some(&Samples::U16(want.clone())),
        "the voxels differ"
    );
    // The statistics counted while writing are every voxel's.
    let counted = Volume::new(
        "c",
        v.dims(),
        v.spacing_mm(),
        Samples::U16(want),
        ValueMapping::IDENTITY,
    )
    .expect("valid");
    assert_eq!(v.value_range(), counted.value_range());
    assert_eq!(v.histogram(), counted.histogram());
    let values: Vec<u8> = (0..v.sample_count() as usize)
        .flat_map(|i| v.samples().expect("in memory").get_f64(i).to_le_bytes())
        .collect();
    let values_path = dir.write("values.f64", &values);
    common::run_python("zarr_check.py", &[&store, &values_path]);
    // Other volumes, or other outputs, take --size.
    let out = common::leapview(&[
        "generate",
        "vessels",
        "--dims",
        "8,8,8",
        "--out",
        "x.ome.zarr",
    ]);
    assert!(!out.status.success());
    assert!(common::stderr(&out).contains("--dims gives the shape of dense-head"));
}

/// `leapview convert` when the disk fills part way (a file-size limit the process may not pass:
/// each write past it fails as on a full disk) or the process is killed: a clean one-line error
/// for the first, and for both no store at OUT and, after the error, no partial folder left.
#[test]
fn a_convert_that_cannot_finish_leaves_no_store_that_looks_whole() {
    let dir = common::TempDir::new("convert-fails");
    let input = dir.path().join("in.ome.zarr");
    let out = common::leapview(&[
        "generate",
        "dense-head",
        "--dims",
        "200,180,300",
        "--type",
        "uint16",
        "--out",
        &input.display().to_string(),
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let target = dir.path().join("out.ome.zarr");
    // Writes past 512 blocks fail with EFBIG (the signal that would kill the process ignored).
    let full = std::process::Command::new("sh")
        .arg("-c")
        .arg(r#"trap '' XFSZ; ulimit -f 512; exec "$0" "$@""#)
        .arg(env!("CARGO_BIN_EXE_leapview"))
        .args(["convert", &input.display().to_string()])
        .arg(&target)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .expect("run the binary");
    assert!(!full.status.success(), "a store written past the limit");
    let said = common::stderr(&full);
    let last = said.lines().last().unwrap_or_default();
    assert!(last.contains("large"), "{said}");
    assert!(!target.exists(), "a store at OUT after a failed write");
    let left: Vec<String> = std::fs::read_dir(dir.path())
        .expect("the folder")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("partial"))
        .collect();
    assert!(left.is_empty(), "left behind: {left:?}");
    // Killed part way: whatever it left is not at OUT.
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_leapview"))
        .args(["convert", &input.display().to_string()])
        .arg(&target)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("start the binary");
    let started = std::time::Instant::now();
    while !std::fs::read_dir(dir.path())
        .expect("the folder")
        .flatten()
        .any(|e| e.file_name().to_string_lossy().contains("partial"))
        && started.elapsed().as_secs() < 60
    {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let _ = child.kill();
    let status = child.wait().expect("its end");
    if status.success() {
        // It finished before the kill: then the store is whole.
        load_volume(&target, &LoadOptions::default()).expect("a whole store");
    } else {
        assert!(
            !target.exists(),
            "a store at OUT after the process was killed"
        );
    }
}
