//! The faults a new user found in the first hour (issue 16, item 5), each as the user met it:
//! a closed pipe, named pipes, outputs refused only after rendering, an image past the GPU's
//! memory, a noisy headless start, and messages that blamed the wrong thing.

use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

use leapview::volume::error::VolumeError;
use leapview::volume::{LoadOptions, ScalarType, load_volume};

use crate::common::{NiftiSpec, TempDir, fails, gzip, leapview, nrrd_file, stderr};

/// A small valid NRRD volume.
fn small_volume(dir: &TempDir) -> std::path::PathBuf {
    let lines = [
        "type: uint8",
        "dimension: 3",
        "sizes: 8 8 8",
        "encoding: raw",
    ];
    let data: Vec<u8> = (0..512).map(|i| (i % 251) as u8).collect();
    dir.write("small.nrrd", &nrrd_file(&lines, &data))
}

/// Runs `f` on another thread; fails the test when it has not returned within `limit` (what
/// used to happen with named pipes: an open that never returns).
fn within<T: Send + 'static>(limit: Duration, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(limit)
        .unwrap_or_else(|_| panic!("still blocked after {limit:?}"))
}

fn mkfifo(path: &Path) {
    let ok = Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo")
        .success();
    assert!(ok, "mkfifo {}", path.display());
}

#[test]
fn info_into_a_closed_pipe_exits_quietly() {
    let dir = TempDir::new("pipe");
    let file = small_volume(&dir);
    // The reader is gone before the command writes: its write fails with a broken pipe.
    let mut child = Command::new(env!("CARGO_BIN_EXE_leapview"))
        .args(["info", file.to_str().expect("utf-8")])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    drop(child.stdout.take());
    let status = child.wait().expect("wait");
    let mut err = String::new();
    child
        .stderr
        .take()
        .expect("stderr")
        .read_to_string(&mut err)
        .expect("read stderr");
    assert!(status.success(), "exit {status}: {err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn named_pipes_are_refused_instead_of_read_forever() {
    let dir = TempDir::new("fifo");
    let fifo = dir.path().join("volume.nrrd");
    mkfifo(&fifo);
    let path = fifo.clone();
    let e = within(Duration::from_secs(10), move || {
        load_volume(&path, &LoadOptions::default()).expect_err("a pipe")
    });
    assert!(
        matches!(
            e.problem,
            VolumeError::NotRegularFile { kind: "named pipe" }
        ),
        "{e}"
    );
    // A detached header whose data file is a pipe.
    let data = dir.path().join("data.raw");
    mkfifo(&data);
    let header = dir.write(
        "h.nhdr",
        b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: data.raw\n",
    );
    let e = within(Duration::from_secs(10), move || {
        load_volume(&header, &LoadOptions::default()).expect_err("a pipe")
    });
    assert!(
        matches!(&e.problem, VolumeError::DataFileNotRegular { name, .. } if name == "data.raw"),
        "{e}"
    );
    // A transfer-function file that is a pipe.
    let tf = dir.path().join("tf.json");
    mkfifo(&tf);
    let r = within(Duration::from_secs(10), move || {
        leapview::transfer::TransferFunction::load(&tf).is_err()
    });
    assert!(r, "a pipe is no transfer function");
    // A device reads as one, not as an empty file.
    let e = fails(Path::new("/dev/zero"));
    assert!(
        matches!(e, VolumeError::NotRegularFile { kind: "device" }),
        "{e}"
    );
}

#[test]
fn outputs_that_cannot_be_written_are_refused_before_anything_is_loaded() {
    let dir = TempDir::new("outputs");
    // The input does not exist either: the output is checked first, so that is what is said.
    let missing = dir.path().join("no-such-volume.nrrd");
    for (out, says) in [
        (dir.path().join("image.jpg"), "unsupported image format"),
        (
            dir.path().join("no-such-folder").join("image.png"),
            "folder to write the image into does not exist",
        ),
    ] {
        let o = leapview(&[
            "render",
            missing.to_str().expect("utf-8"),
            "--out",
            out.to_str().expect("utf-8"),
        ]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains(says), "{}", stderr(&o));
    }
}

#[test]
fn an_image_past_the_gpus_memory_is_one_clear_line() {
    let dir = TempDir::new("huge-image");
    let file = small_volume(&dir);
    let out = dir.path().join("huge.png");
    let o = leapview(&[
        "render",
        file.to_str().expect("utf-8"),
        "--out",
        out.to_str().expect("utf-8"),
        "--size",
        "16384x16384",
        "--path",
        "compute",
    ]);
    let err = stderr(&o);
    assert!(!err.contains("Validation Error"), "{err}");
    // An adapter with memory for it renders it; one without (lavapipe) says so in one line.
    if !o.status.success() {
        assert_eq!(o.status.code(), Some(2), "{err}");
        let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
        assert_eq!(lines.len(), 1, "{err}");
        assert!(lines[0].contains("16384×16384"), "{err}");
    }
}

#[test]
fn a_headless_render_prints_nothing_about_a_missing_display() {
    let dir = TempDir::new("quiet");
    let file = small_volume(&dir);
    let out = dir.path().join("quiet.png");
    let o = Command::new(env!("CARGO_BIN_EXE_leapview"))
        .args([
            "render",
            file.to_str().expect("utf-8"),
            "--out",
            out.to_str().expect("utf-8"),
            "--size",
            "32x32",
            "--refine",
            "4",
        ])
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("run");
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(!err.contains("XDG_RUNTIME_DIR"), "{err}");
    // A refinement reports its frames.
    assert!(err.contains("refining: 4/4 frames"), "{err}");
}

#[test]
fn messages_blame_what_is_wrong() {
    let dir = TempDir::new("messages");
    let lines = [
        "type: uint8",
        "dimension: 3",
        "sizes: 4 4 4",
        "encoding: gzip",
    ];
    let data: Vec<u8> = (0..64).collect();
    // A corrupt gzip stream is corrupt data, not a header with wrong sizes.
    let mut stream = gzip(&data);
    let middle = stream.len() / 2;
    stream[middle] ^= 0xff;
    stream[middle + 1] ^= 0xff;
    let e = fails(&dir.write("corrupt.nrrd", &nrrd_file(&lines, &stream)));
    assert!(matches!(e, VolumeError::CorruptGzip { .. }), "{e}");
    // A comment may hold any bytes.
    let mut latin1 = b"NRRD0004\n# caf\xe9\ntype: uint8\ndimension: 3\nsizes: 4 4 4\n".to_vec();
    latin1.extend_from_slice(b"encoding: raw\n\n");
    latin1.extend_from_slice(&data);
    let path = dir.write("latin1.nrrd", &latin1);
    load_volume(&path, &LoadOptions::default()).expect("a Latin-1 comment is fine");
    // A multi-file LIST is said to be unsupported, not a syntax error in the names.
    let list = dir.write(
        "list.nhdr",
        b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 4 2\nencoding: raw\ndata file: LIST\na.raw\nb.raw\n",
    );
    let e = fails(&list);
    assert!(e.to_string().contains("not supported"), "{e}");
    // A NIfTI dim[0] valid in neither byte order is reported as written.
    let mut spec = NiftiSpec::new(ScalarType::U8, [4, 4, 4], [1.0; 3]);
    spec.dim[0] = 9;
    let e = fails(&dir.write("dim9.nii", &spec.file(&data)));
    let text = e.to_string();
    assert!(text.contains("'9'") && !text.contains("2304"), "{text}");
    // A missing transfer-function file says what the system said once.
    let volume = small_volume(&dir);
    let o = leapview(&[
        "render",
        volume.to_str().expect("utf-8"),
        "--out",
        dir.path().join("x.png").to_str().expect("utf-8"),
        "--tf",
        dir.path().join("none.json").to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        stderr(&o).matches("os error 2").count(),
        1,
        "{}",
        stderr(&o)
    );
    // `info` prints numbers without float noise.
    let o = leapview(&["info", volume.to_str().expect("utf-8")]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success());
    for line in out.lines().filter(|l| l.starts_with("percentiles")) {
        assert!(
            line.split_whitespace()
                .filter(|w| w.parse::<f64>().is_ok())
                .all(|w| w.len() < 10),
            "a number too long to be meant: {line}"
        );
    }
}

#[test]
fn an_adapter_that_cannot_run_the_renderer_is_refused_with_what_to_do() {
    // Mesa's GL driver (what wgpu falls back to without a Vulkan driver) cannot render to RGBA32F:
    // that used to surface as "cannot hold the textures of a 192×192 image … Validation Error".
    // Now such an adapter is passed over, and when it is the only one the message says what is
    // missing and what to install. (Where GL can do it, the render succeeds.)
    let dir = TempDir::new("gl-adapter");
    let file = small_volume(&dir);
    let out = dir.path().join("gl.png");
    let o = Command::new(env!("CARGO_BIN_EXE_leapview"))
        .arg("render")
        .arg(&file)
        .arg("--out")
        .arg(&out)
        .args(["--size", "32x32"])
        .env("LEAPVIEW_BACKEND", "gl")
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .expect("run");
    let err = stderr(&o);
    if o.status.success() {
        assert!(out.exists(), "{err}");
        return;
    }
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("leapview:")).collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(
        lines[0].contains("Install a Vulkan driver") || lines[0].contains("no GPU adapter"),
        "{err}"
    );
    assert!(!err.contains("Validation Error"), "{err}");
}
