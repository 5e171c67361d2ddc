//! OME-Zarr stores at an address (`volume::zarr::remote`), served on loopback by an
//! S3-compatible server (moto, `scripts/python/s3_server.py`) that answers both S3 requests and
//! path-style HTTP range requests, and by a plain HTTP file server with ranges
//! (`scripts/python/http_server.py`): read over `s3://` and `http://` they give the voxels, facts
//! and pictures of the same store in a folder, whole or brick by brick; a chunk that fails to decode
//! is said once and the rest renders; missing stores, buckets and servers, and credentials the
//! server refuses, are refused with the reason.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use leapview::volume::{LoadOptions, load_volume};

use crate::common;

/// The object-store server, serving folders in bucket `bkt` until dropped.
struct Server {
    child: Child,
    port: u16,
    /// The access key and secret the server takes (`testing` where it checks none).
    key: (String, String),
}

impl Server {
    /// The S3 server, serving `folders` in bucket `bkt`.
    fn start(folders: &[&Path]) -> Self {
        let mut args = vec![Path::new("bkt")];
        args.extend_from_slice(folders);
        Self::run("s3_server.py", &args)
    }

    /// The S3 server checking credentials: only its own user's key is taken.
    fn checking(folders: &[&Path]) -> Self {
        let mut args = vec![Path::new("--auth"), Path::new("bkt")];
        args.extend_from_slice(folders);
        Self::run("s3_server.py", &args)
    }

    /// A plain HTTP file server of `folder`.
    fn files(folder: &Path) -> Self {
        Self::run("http_server.py", &[folder])
    }

    fn run(script: &str, args: &[&Path]) -> Self {
        let mut child = Command::new(common::python())
            .arg(
                PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                    .join("scripts/python")
                    .join(script),
            )
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("start the server");
        let mut line = String::new();
        let stdout = child.stdout.take().expect("its output");
        BufReader::new(stdout)
            .read_line(&mut line)
            .expect("its port");
        let said: serde_json::Value =
            serde_json::from_str(&line).unwrap_or_else(|e| panic!("{line:?}: {e}"));
        let port = said["port"].as_u64().expect("a port") as u16;
        let text = |k: &str| said[k].as_str().unwrap_or("testing").to_string();
        Self {
            child,
            port,
            key: (text("key"), text("secret")),
        }
    }

    fn http(&self, name: &str) -> String {
        format!("http://127.0.0.1:{}/bkt/{name}", self.port)
    }

    /// `leapview ARGS` with the server as its S3 endpoint and its key.
    fn leapview(&self, args: &[&str]) -> std::process::Output {
        self.leapview_as(args, &self.key)
    }

    /// `leapview ARGS` with the server as its S3 endpoint and the access key and secret `key`.
    fn leapview_as(&self, args: &[&str], key: &(String, String)) -> std::process::Output {
        Command::new(env!("CARGO_BIN_EXE_leapview"))
            .args(args)
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .env(
                "AWS_ENDPOINT_URL",
                format!("http://127.0.0.1:{}", self.port),
            )
            .env("AWS_ALLOW_HTTP", "true")
            .env("AWS_ACCESS_KEY_ID", &key.0)
            .env("AWS_SECRET_ACCESS_KEY", &key.1)
            .env("AWS_REGION", "us-east-1")
            .output()
            .expect("run the binary")
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A generated head written as a store in `dir`, named `name`.
fn store(dir: &common::TempDir, name: &str) -> PathBuf {
    let path = dir.path().join(name);
    let out = common::leapview(&[
        "generate",
        "dense-head",
        "--dims",
        "60,50,70",
        "--type",
        "uint16",
        "--out",
        &path.display().to_string(),
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    path
}

fn pixels(path: &Path) -> Vec<u8> {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgba8()
        .into_raw()
}

#[test]
fn a_store_over_s3_and_http_reads_and_renders_as_the_folder_does() {
    let dir = common::TempDir::new("remote");
    let local = store(&dir, "head.ome.zarr");
    let server = Server::start(&[&local]);
    let http = server.http("head.ome.zarr");
    let folder = load_volume(&local, &LoadOptions::default()).expect("the folder");
    // Over HTTP, whole and brick by brick: the folder's voxels and facts.
    let whole = load_volume(Path::new(&http), &LoadOptions::default()).expect("over HTTP");
    assert_eq!(whole.dims(), folder.dims());
    assert_eq!(whole.spacing_mm(), folder.spacing_mm());
    assert!(whole.samples() == folder.samples(), "the voxels differ");
    let streamed = LoadOptions {
        ram_budget: Some(1),
        ..LoadOptions::default()
    };
    let bricks = load_volume(Path::new(&http), &streamed).expect("brick by brick");
    let source = bricks.streaming().expect("streamed");
    let level0 = source.read_box(0, [0; 3], folder.dims()).expect("read");
    assert!(
        Some(&level0) == folder.samples(),
        "the streamed voxels differ"
    );
    assert_eq!(bricks.histogram(), folder.histogram());
    // The command line over s3:// and http://: the folder's info and picture.
    let s3 = "s3://bkt/head.ome.zarr";
    let info = |address: &str| {
        let out = server.leapview(&["info", address, "--ram-budget", "1MiB"]);
        assert!(out.status.success(), "{address}: {}", common::stderr(&out));
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        text.lines()
            .filter(|l| {
                l.starts_with("dims:") || l.starts_with("range:") || l.starts_with("spacing:")
            })
            .map(str::to_string)
            .collect::<Vec<_>>()
    };
    let want = info(&local.display().to_string());
    assert_eq!(want.len(), 3, "{want:?}");
    assert_eq!(info(s3), want);
    assert_eq!(info(&http), want);
    let render = |address: &str, png: &str| {
        let out_png = dir.path().join(png);
        let out = server.leapview(&[
            "render",
            address,
            "--out",
            &out_png.display().to_string(),
            "--size",
            "64x48",
            "--ram-budget",
            "1MiB",
        ]);
        assert!(out.status.success(), "{address}: {}", common::stderr(&out));
        pixels(&out_png)
    };
    let want = render(&local.display().to_string(), "folder.png");
    assert!(want.iter().any(|&b| b > 0), "a blank picture");
    assert!(render(s3, "s3.png") == want, "the s3:// picture differs");
    assert!(
        render(&http, "http.png") == want,
        "the http:// picture differs"
    );
    // A plain file server that answers ranges: the same.
    let files = Server::files(dir.path());
    let plain = format!("http://127.0.0.1:{}/head.ome.zarr", files.port);
    let v = load_volume(Path::new(&plain), &streamed).expect("from the file server");
    let level0 = v
        .streaming()
        .expect("streamed")
        .read_box(0, [0; 3], folder.dims());
    assert!(
        Some(&level0.expect("read")) == folder.samples(),
        "the file server's voxels differ"
    );
    assert!(
        render(&plain, "files.png") == want,
        "the file server's picture differs"
    );
}

#[test]
fn remote_failures_say_what_failed_and_a_bad_chunk_is_said_once() {
    let dir = common::TempDir::new("remote-faults");
    let local = store(&dir, "broken.ome.zarr");
    // The first inner chunk of level 0's shard overwritten (its index, at the end, intact):
    // that chunk fails to decode, the others read.
    let shard = local.join("0/c/0/0/0");
    let mut bytes = std::fs::read(&shard).expect("the shard");
    bytes[..64].fill(0x5a);
    std::fs::write(&shard, bytes).expect("broken");
    let server = Server::start(&[&local]);
    let v = load_volume(
        Path::new(&server.http("broken.ome.zarr")),
        &LoadOptions::default(),
    )
    .expect("the rest of the store");
    let notes = v.provenance().notes.join(" | ");
    assert!(notes.contains("could not be read"), "{notes}");
    let refused = |address: &str, said: &str| {
        let e = load_volume(Path::new(address), &LoadOptions::default())
            .map(|_| ())
            .expect_err(said)
            .to_string();
        assert!(e.contains(said), "{address}: {e}");
        assert!(e.ends_with(address), "{e}");
    };
    refused(&server.http("no-such.ome.zarr"), "not a Zarr store");
    // A port where nothing listens: the request's failure, not a hang.
    let closed = {
        let l = std::net::TcpListener::bind("127.0.0.1:0").expect("a port");
        l.local_addr().expect("its address").port()
    };
    refused(
        &format!("http://127.0.0.1:{closed}/bkt/x.zarr"),
        "cannot be opened",
    );
    let out = server.leapview(&["info", "s3://no-such-bucket/x.zarr"]);
    assert!(!out.status.success());
    let said = common::stderr(&out);
    assert!(said.contains("s3://no-such-bucket/x.zarr"), "{said}");
    assert!(said.lines().count() <= 2, "{said}");
}

#[test]
fn credentials_the_server_refuses_are_said_and_its_own_key_reads() {
    let dir = common::TempDir::new("remote-credentials");
    let local = store(&dir, "head.ome.zarr");
    let server = Server::checking(&[&local]);
    let address = "s3://bkt/head.ome.zarr";
    let out = server.leapview(&["info", address]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    for key in [
        // A key the server does not know, and its own key with another secret.
        ("AKIAUNKNOWNKEY000000".to_string(), server.key.1.clone()),
        (server.key.0.clone(), "not-the-secret".to_string()),
    ] {
        let out = server.leapview_as(&["info", address], &key);
        assert!(!out.status.success(), "{key:?} was taken");
        let said = common::stderr(&out);
        assert!(said.contains("credentials"), "{key:?}: {said}");
        assert!(said.contains(address), "{key:?}: {said}");
        assert!(said.lines().count() <= 2, "{said}");
    }
}
