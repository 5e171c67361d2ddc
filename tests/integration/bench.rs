//! `leapview bench` end to end on a tiny generated vessel tree: the outputs exist and parse,
//! Table 1's speed-ups follow from the measured frame times, `frames.csv` has a row per view of
//! every run, and leaping passes the image check.

use crate::common;

use std::path::Path;
use std::process::Command;

use leapview::bench::stats::median;
use leapview::bench::{BenchResults, Summary, speed_up};

/// Views per run and block sizes swept by the test configuration.
const VIEWS: usize = 3;
const SWEEP: [u32; 2] = [4, 8];

fn config_json() -> String {
    serde_json::json!({
        "datasets": [{
            "name": "tiny_vessels",
            "source": {"kind": "vessel-tree", "n": 32, "seed": 7},
            "tf": "mr-angio",
            "why": "vessels preset for an angiogram-like volume"
        }],
        "modes": ["dvr"],
        "strategies": ["rc", "rc-t", "rc-s", "rc-s-df"],
        "paths": ["compute", "fragment"],
        "resolutions": [[40, 32]],
        "views": VIEWS,
        "elevation_deg": 20,
        "warmup_frames": 1,
        "step_vox": 0.5,
        "block_vox": 8,
        "phong": true,
        "rebuild_repeats": 2,
        "image_check_size": [40, 32],
        "block_sweep": {"datasets": ["tiny_vessels"], "sizes": SWEEP, "modes": ["dvr"], "resolution": [40, 32]}
    })
    .to_string()
}

/// `leapview bench` with `config`, its volume files in `data`, its results into `out`.
fn bench_command(config: &Path, data: &Path, out: &Path) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_leapview"));
    command
        .args(["bench", "--config"])
        .arg(config)
        .arg("--data-dir")
        .arg(data)
        .arg("--out")
        .arg(out);
    command
}

fn read(path: &std::path::Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn quick_bench_writes_consistent_outputs() {
    let dir = common::TempDir::new("bench");
    let config = dir.write("config.json", config_json().as_bytes());
    let out = dir.path().join("out");
    let status = bench_command(&config, dir.path(), &out)
        .status()
        .expect("run leapview bench");
    assert!(status.success(), "leapview bench failed: {status}");

    let results: BenchResults =
        serde_json::from_str(&read(&out.join("frames.json"))).expect("frames.json parses");
    let summary: Summary =
        serde_json::from_str(&read(&out.join("summary.json"))).expect("summary.json parses");
    let tables = read(&out.join("tables.md"));
    assert!(tables.contains("Table 1") && tables.contains("Table 2"));
    for png in ["frame_time.png", "block_size.png", "time_vs_samples.png"] {
        let img = image::open(out.join(png)).unwrap_or_else(|e| panic!("{png}: {e}"));
        assert!(
            img.width() > 100 && img.height() > 100,
            "{png} is too small"
        );
    }

    // Runs: 4 strategies × 2 paths, plus the sweep: 2 leaping strategies × 2 paths × 2 blocks.
    let runs = 4 * 2 + 2 * 2 * SWEEP.len();
    assert_eq!(results.runs.len(), runs);
    let csv = read(&out.join("frames.csv"));
    assert_eq!(
        csv.lines().count(),
        1 + runs * VIEWS,
        "header + one row per view"
    );

    // Table 1 follows from the frames: fps = 1000 / median ms, speed-up = (s − t) / t.
    assert_eq!(summary.table1.len(), 2, "one row per path");
    for row in &summary.table1 {
        let fps_of = |strategy: &str| {
            let run = results
                .runs
                .iter()
                .find(|r| !r.key.sweep && r.key.path == row.path && r.key.strategy == strategy)
                .unwrap_or_else(|| panic!("no {strategy} run on {}", row.path));
            let ms: Vec<f64> = run.frames.iter().map(|f| f.ms).collect();
            1000.0 / median(&ms).expect("frames")
        };
        let (rct, rcs) = (fps_of("RC-t"), fps_of("RC-s"));
        // summary.json went through serde_json, which parses floats to within an ulp or two
        // (not correctly rounded), so compare with a relative tolerance far above that.
        let close = |a: Option<f64>, b: f64| {
            let a = a.expect("value present");
            assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{a} vs {b}");
        };
        close(row.fps[1], rct);
        close(row.fps[2], rcs);
        close(row.speed_up_rc_s, (rcs - rct) / rct);
        close(row.speed_up_rc_s, speed_up(rcs, rct));
        close(row.ratio_rc_s, rcs / rct);
    }

    // Leaping takes fewer samples than RC-t on a sparse tree, and never changes the image.
    let spp = |strategy: &str| {
        summary
            .runs
            .iter()
            .find(|r| !r.key.sweep && r.key.strategy == strategy)
            .map(|r| r.samples_per_pixel)
            .expect("run")
    };
    assert!(spp("RC-s") < spp("RC-t"), "RC-s must skip empty space");
    assert_eq!(
        summary.image_checks.len(),
        2 * 2,
        "2 paths × 2 leaping variants"
    );
    assert_eq!(
        summary.image_check_failures, 0,
        "{:?}",
        summary.image_checks
    );
    assert_eq!(summary.rebuilds.len(), 2);
}

/// A configuration of one dataset whose transfer-function file is missing, `optional` or not.
fn config_with_a_missing_tf(optional: bool) -> String {
    serde_json::json!({
        "datasets": [{
            "name": "lost_tf",
            "source": {"kind": "vessel-tree", "n": 16, "seed": 3},
            "tf": "tf/no-such-file.json",
            "why": "its transfer function is not there",
            "optional": optional
        }],
        "modes": ["dvr"],
        "strategies": ["rc-t", "rc-s-df"],
        "paths": ["compute"],
        "resolutions": [[16, 16]],
        "views": 1,
        "elevation_deg": 20,
        "warmup_frames": 1,
        "step_vox": 0.5,
        "phong": false,
        "rebuild_repeats": 1,
        "image_check_size": [16, 16],
        "block_sweep": {"datasets": [], "sizes": [4], "modes": ["dvr"], "resolution": [16, 16]}
    })
    .to_string()
}

#[test]
fn a_dataset_that_cannot_be_measured_fails_the_run_unless_optional() {
    for optional in [false, true] {
        let dir = common::TempDir::new("bench-missing-tf");
        let config = dir.write("config.json", config_with_a_missing_tf(optional).as_bytes());
        let out = dir.path().join("out");
        let output = bench_command(&config, dir.path(), &out)
            .output()
            .expect("run leapview bench");
        let stderr = String::from_utf8_lossy(&output.stderr);
        // The results are written either way, the skip recorded with its reason.
        let tables = read(&out.join("tables.md"));
        assert!(tables.contains("no-such-file.json"), "{tables}");
        if optional {
            assert!(output.status.success(), "{stderr}");
            assert!(stderr.contains("no leaping images to check"), "{stderr}");
        } else {
            // A missing file is bad input: status 2, naming the dataset.
            assert_eq!(output.status.code(), Some(2), "{stderr}");
            assert!(
                stderr.contains("FAILED: lost_tf") && stderr.contains("not measured (lost_tf)"),
                "{stderr}"
            );
            assert!(!stderr.contains("image check: all"), "{stderr}");
        }
    }
}

/// `bench --stream` of a 256³ vessel tree under half its size as the GPU budget, its image
/// `size` pixels: the CSV's rows (the levels column, "0, 2", holds commas of its own: count
/// from the end) and the summary.
fn stream_rows(dir: &common::TempDir, size: &str) -> (Vec<Vec<String>>, String, u64) {
    let volume = dir.path().join("vessels.nhdr");
    if !volume.exists() {
        let status = Command::new(env!("CARGO_BIN_EXE_leapview"))
            .args(["generate", "vessels", "--size", "256", "--out"])
            .arg(&volume)
            .status()
            .expect("generate");
        assert!(status.success());
    }
    let out = dir.path().join(format!("out-{size}"));
    // The 256³ uint8 volume's size (of which a quarter goes to the leaping structures, a
    // quarter to the frame's targets and a sixteenth to the upload's staging): the tree's bricks
    // at full resolution fit, more of them than one upload batch (16), the whole volume's
    // bricks and aprons do not.
    let budget = 256u64.pow(3) / 1000 * 1000;
    let output = Command::new(env!("CARGO_BIN_EXE_leapview"))
        .args(["bench", "--stream"])
        .arg(&volume)
        .args([
            "--gpu-budget",
            &format!("{}KB", budget / 1000),
            "--stream-frames",
            "3",
        ])
        .args(["--stream-ms", "0", "--stream-size", size, "--out"])
        .arg(&out)
        .output()
        .expect("bench --stream");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let csv = read(&out.join("stream.csv"));
    let rows = (csv.lines().skip(1))
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (rows, read(&out.join("stream.md")), budget)
}

/// `bench --stream` on a vessel tree larger than its budget, seen large enough that its voxels need
/// level 0: the orbit renders while bricks are missing, the still frames end once none is, the
/// memory never passes the budget, and the summary says so.
#[test]
fn stream_measures_an_orbit_while_bricks_arrive() {
    let dir = common::TempDir::new("bench-stream");
    let (rows, summary, budget) = stream_rows(&dir, "320x320");
    // Counted from the end: the levels column holds commas. The last is the process's resident
    // memory, then what wgpu's allocator held (lavapipe's Vulkan reports it), bytes resident,
    // missing, wanted.
    let column = |row: &Vec<String>, from_end: usize| -> u64 {
        row[row.len() - from_end].parse().expect("number")
    };
    let (missing, bytes, held, rss) = (4, 3, 2, 1);
    // The process holds at least what lavapipe's allocator holds for it (its memory is ours).
    assert!(
        rows.iter().all(|r| column(r, rss) >= column(r, held)),
        "{rows:?}"
    );
    assert!(
        summary.contains("- process memory (resident): peak"),
        "{summary}"
    );
    assert_eq!(
        rows.iter().filter(|r| r[0] == "orbit").count(),
        3,
        "{rows:?}"
    );
    let last = rows.last().expect("rows");
    assert_eq!(column(last, missing), 0, "{rows:?}");
    assert!(rows.iter().any(|r| column(r, missing) > 0), "{rows:?}");
    assert!(rows.iter().all(|r| column(r, bytes) <= budget), "{rows:?}");
    // The allocator holds at least the bricks resident.
    assert!(
        rows.iter().all(|r| column(r, held) >= column(r, bytes)),
        "{rows:?}"
    );
    assert!(
        summary.contains("- wgpu's memory allocator held"),
        "{summary}"
    );
    assert!(summary.contains("- complete at"), "{summary}");
    // The frames after the first up to the one completing the stream (the frame after the last
    // with a brick missing), their slowest as the rows give it.
    let orbit: Vec<&Vec<String>> = rows.iter().filter(|r| r[0] == "orbit").collect();
    let last_missing = orbit.iter().rposition(|r| column(r, missing) > 0);
    let until = last_missing.map_or(1, |i| (i + 2).min(orbit.len()));
    let slowest = orbit[1..until]
        .iter()
        .map(|r| r[3].parse::<f64>().expect("wall ms"))
        .fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(
        summary.contains(&format!(": slowest {slowest:.2} ms, ")),
        until > 1,
        "{summary}"
    );
    // Its levels column ends in the levels read: level 0 among them.
    let levels = |r: &Vec<String>| r[8..r.len() - 6].join(",");
    assert!(
        levels(last).trim_matches('"').split(", ").any(|l| l == "0"),
        "{rows:?}"
    );

    // The same seen in 48 × 32 pixels: a voxel of level 0 is a tenth of a pixel, so the
    // bricks are held three levels coarser (a voxel of 8 still under a pixel), and far fewer.
    let (small, _, _) = stream_rows(&dir, "48x32");
    let last_small = small.last().expect("rows");
    assert!(
        !levels(last_small)
            .trim_matches('"')
            .split(", ")
            .any(|l| l == "0"),
        "{small:?}"
    );
    assert!(
        column(last_small, bytes) < column(last, bytes),
        "{small:?} against {rows:?}"
    );
}

/// `bench --labels`: the CT head with its Slicer segmentation (pynrrd) shown as surfaces in every
/// run; leaping stays exact with them (the image check), the report names them; a segmentation
/// over several datasets is refused.
#[test]
fn bench_measures_a_dataset_with_its_segmentation() {
    let data = common::data_dir();
    let dir = common::TempDir::new("bench-labels");
    let config = serde_json::json!({
        "datasets": [
            {"name": "ct_head", "source": {"kind": "file", "file": "ct_head_cthead_256x256x113_uint16.nrrd"},
             "tf": "ct-bone", "why": "bone"},
            {"name": "tiny_vessels", "source": {"kind": "vessel-tree", "n": 32, "seed": 7},
             "tf": "mr-angio", "why": "vessels"}
        ],
        "modes": ["dvr", "mip"],
        "strategies": ["rc-t", "rc-s"],
        "paths": ["compute"],
        "resolutions": [[40, 32]],
        "views": 1,
        "elevation_deg": 20,
        "warmup_frames": 1,
        "step_vox": 0.5,
        "phong": true,
        "rebuild_repeats": 1,
        "image_check_size": [40, 32],
        "block_sweep": {"datasets": [], "sizes": [8], "modes": ["dvr"], "resolution": [40, 32]}
    })
    .to_string();
    let config = dir.write("config.json", config.as_bytes());
    let out = dir.path().join("out");
    let labels = data.join("labels/ct_head_cthead.seg.nrrd");
    let run = |datasets: &str| {
        bench_command(&config, &data, &out)
            .args([
                "--datasets",
                datasets,
                "--label-view",
                "surfaces",
                "--label-opacity",
                "0.5",
                "--labels",
            ])
            .arg(&labels)
            .output()
            .expect("run leapview bench")
    };
    let both = run("ct_head,tiny_vessels");
    assert_eq!(both.status.code(), Some(2));
    let err = String::from_utf8_lossy(&both.stderr);
    assert!(err.contains("one dataset"), "{err}");
    let one = run("ct_head");
    assert!(
        one.status.success(),
        "{}",
        String::from_utf8_lossy(&one.stderr)
    );
    let results: BenchResults =
        serde_json::from_str(&read(&out.join("frames.json"))).expect("frames.json parses");
    let labelled = results.datasets[0]
        .labels
        .as_deref()
        .expect("labels recorded");
    assert!(
        labelled.contains("3 segments")
            && labelled.contains("Surfaces")
            && labelled.contains("opacity 0.5"),
        "{labelled}"
    );
    assert!(read(&out.join("tables.md")).contains("labels ct_head_cthead.seg.nrrd"));
    let summary: Summary =
        serde_json::from_str(&read(&out.join("summary.json"))).expect("summary.json parses");
    assert!(!summary.image_checks.is_empty());
    assert_eq!(
        summary.image_check_failures, 0,
        "{:?}",
        summary.image_checks
    );
}
