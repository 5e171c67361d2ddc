//! OME-Zarr stores at an address (`volume::zarr::remote`), served on loopback by an
//! S3-compatible server (moto, `scripts/python/s3_server.py`) that answers both S3 requests and
//! path-style HTTP range requests, by a plain HTTP file server with ranges
//! (`scripts/python/http_server.py`), by Google's Cloud Storage emulator
//! (`scripts/python/gcs_server.py`) and by Microsoft's Azure Blob emulator, Azurite
//! (`scripts/python/azure_server.py`): read over `s3://`, `http://`, `gs://` and `az://` they
//! give the voxels, facts and pictures of the same store in a folder, whole or brick by brick; a
//! chunk that fails to decode is said once and the rest renders; missing stores, buckets and
//! servers, and credentials the server refuses, are refused with the reason.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use leapview::volume::{LoadOptions, load_volume};

use crate::common;

/// Which server serves the store, so which settings `leapview` is given to reach it.
#[derive(Clone, Copy)]
enum Kind {
    /// moto's S3 server (or a plain file server).
    S3,
    /// The Cloud Storage emulator.
    Gcs,
    /// Azurite.
    Azure,
}

/// The object-store server, serving folders in bucket `bkt` until dropped.
struct Server {
    child: Child,
    port: u16,
    /// The access key and secret the server takes (`testing` where it checks none; for Azurite
    /// its account's key, the client's default).
    key: (String, String),
    kind: Kind,
}

impl Server {
    /// The S3 server, serving `folders` in bucket `bkt`.
    fn start(folders: &[&Path]) -> Self {
        let mut args = vec![Path::new("bkt")];
        args.extend_from_slice(folders);
        Self::run("s3_server.py", &args, Kind::S3)
    }

    /// The Cloud Storage emulator, serving `folders` in bucket `bkt`.
    fn gcs(folders: &[&Path]) -> Self {
        let mut args = vec![Path::new("bkt")];
        args.extend_from_slice(folders);
        Self::run("gcs_server.py", &args, Kind::Gcs)
    }

    /// Azurite, serving `folders` in container `bkt` and checking the requests' signatures.
    fn azure(folders: &[&Path]) -> Self {
        let mut args = vec![Path::new("bkt")];
        args.extend_from_slice(folders);
        Self::run("azure_server.py", &args, Kind::Azure)
    }

    /// The S3 server checking credentials: only its own user's key is taken.
    fn checking(folders: &[&Path]) -> Self {
        let mut args = vec![Path::new("--auth"), Path::new("bkt")];
        args.extend_from_slice(folders);
        Self::run("s3_server.py", &args, Kind::S3)
    }

    /// A plain HTTP file server of `folder`.
    fn files(folder: &Path) -> Self {
        Self::run("http_server.py", &[folder], Kind::S3)
    }

    fn run(script: &str, args: &[&Path], kind: Kind) -> Self {
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
            kind,
        }
    }

    fn http(&self, name: &str) -> String {
        format!("http://127.0.0.1:{}/bkt/{name}", self.port)
    }

    /// `leapview ARGS` with the server as its endpoint and its key.
    fn leapview(&self, args: &[&str]) -> std::process::Output {
        self.leapview_as(args, &self.key)
    }

    /// `leapview ARGS` with the server as its endpoint (through the variables its scheme's
    /// users set) and the access key and secret `key` (S3; for Azure the account key `key.1`).
    fn leapview_as(&self, args: &[&str], key: &(String, String)) -> std::process::Output {
        let endpoint = format!("http://127.0.0.1:{}", self.port);
        let mut command = Command::new(env!("CARGO_BIN_EXE_leapview"));
        command
            .args(args)
            .env("XDG_RUNTIME_DIR", std::env::temp_dir());
        match self.kind {
            Kind::S3 => command
                .env("AWS_ENDPOINT_URL", endpoint)
                .env("AWS_ALLOW_HTTP", "true")
                .env("AWS_ACCESS_KEY_ID", &key.0)
                .env("AWS_SECRET_ACCESS_KEY", &key.1)
                .env("AWS_REGION", "us-east-1"),
            // A public bucket: the emulator checks no credentials.
            Kind::Gcs => command
                .env("GOOGLE_BASE_URL", endpoint)
                .env("GOOGLE_ALLOW_HTTP", "true")
                .env("GOOGLE_SKIP_SIGNATURE", "true"),
            // The emulator's account; its key where the test gives none.
            Kind::Azure => {
                command
                    .env("AZURE_STORAGE_USE_EMULATOR", "true")
                    .env("AZURITE_BLOB_STORAGE_URL", endpoint);
                if key.1 != "testing" {
                    command.env("AZURE_STORAGE_ACCOUNT_KEY", &key.1);
                }
                &mut command
            }
        };
        command.output().expect("run the binary")
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
    let in_folder = local.display().to_string();
    let want = info(&common::leapview, &in_folder);
    let run = |args: &[&str]| server.leapview(args);
    assert_eq!(info(&run, s3), want);
    assert_eq!(info(&run, &http), want);
    let want = pixels_of(&common::leapview, &dir, &in_folder, "folder");
    assert!(
        pixels_of(&run, &dir, s3, "s3") == want,
        "the s3:// picture differs"
    );
    assert!(
        pixels_of(&run, &dir, &http, "http") == want,
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
        pixels_of(&run, &dir, &plain, "files") == want,
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

#[test]
fn a_store_over_gcs_and_azure_reads_and_renders_as_the_folder_does() {
    let dir = common::TempDir::new("remote-clouds");
    let local = store(&dir, "head.ome.zarr");
    let folder = local.display().to_string();
    let want_info = info(&common::leapview, &folder);
    let want = pixels_of(&common::leapview, &dir, &folder, "folder");
    let azure = Server::azure(&[&local]);
    for (server, address) in [
        (&Server::gcs(&[&local]), "gs://bkt/head.ome.zarr"),
        (&azure, "az://bkt/head.ome.zarr"),
    ] {
        let run = |args: &[&str]| server.leapview(args);
        assert_eq!(info(&run, address), want_info, "{address}");
        // Under a 1 MiB budget: brick by brick.
        let got = pixels_of(&run, &dir, address, &address[..2]);
        assert!(got == want, "the {address} picture differs");
    }
    // A trailing slash reads the same; the container's root is not a store.
    let run = |args: &[&str]| azure.leapview(args);
    assert_eq!(info(&run, "az://bkt/head.ome.zarr/"), want_info);
    let out = azure.leapview(&["info", "az://bkt"]);
    assert!(!out.status.success());
    assert!(
        common::stderr(&out).contains("not a Zarr store"),
        "{}",
        common::stderr(&out)
    );
}

#[test]
fn azure_credentials_the_emulator_refuses_are_said_with_the_variables_to_set() {
    let dir = common::TempDir::new("remote-azure-credentials");
    let local = store(&dir, "head.ome.zarr");
    let server = Server::azure(&[&local]);
    let address = "az://bkt/head.ome.zarr";
    // Another account key (base64, as keys are): Azurite checks the shared-key signature.
    let wrong = (
        "devstoreaccount1".to_string(),
        "bm90LXRoZS1rZXk=".to_string(),
    );
    let out = server.leapview_as(&["info", address], &wrong);
    assert!(!out.status.success(), "a wrong key was taken");
    let said = common::stderr(&out);
    assert!(said.contains("credentials"), "{said}");
    assert!(said.contains("AZURE_STORAGE_ACCOUNT_KEY"), "{said}");
    assert!(said.contains(address), "{said}");
    assert!(said.lines().count() <= 2, "{said}");
}

/// How `leapview` is run: on its own, or given a server's settings.
type Run<'a> = dyn Fn(&[&str]) -> std::process::Output + 'a;

/// The dims, range and spacing lines of `leapview info ADDRESS` under a 1 MiB budget.
fn info(run: &Run, address: &str) -> Vec<String> {
    let out = run(&["info", address, "--ram-budget", "1MiB"]);
    assert!(out.status.success(), "{address}: {}", common::stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let lines: Vec<String> = text
        .lines()
        .filter(|l| l.starts_with("dims:") || l.starts_with("range:") || l.starts_with("spacing:"))
        .map(str::to_string)
        .collect();
    assert_eq!(lines.len(), 3, "{text}");
    lines
}

/// The pixels of a 64×48 `leapview render ADDRESS` under a 1 MiB budget (brick by brick),
/// written in `dir` as `NAME.png`.
fn pixels_of(run: &Run, dir: &common::TempDir, address: &str, name: &str) -> Vec<u8> {
    let png = dir.path().join(format!("{name}.png"));
    let out = run(&[
        "render",
        address,
        "--out",
        &png.display().to_string(),
        "--size",
        "64x48",
        "--ram-budget",
        "1MiB",
    ]);
    assert!(out.status.success(), "{address}: {}", common::stderr(&out));
    let got = pixels(&png);
    assert!(got.iter().any(|&b| b > 0), "{address}: a blank picture");
    got
}
