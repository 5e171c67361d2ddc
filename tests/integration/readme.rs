//! Every command in the `sh` blocks of README.md and then of docs/USER-GUIDE.md, run as a user
//! would, in order, in one empty folder (later commands use the files earlier ones wrote: the
//! guide's use the `phantom.nrrd` and `vessels.nrrd` the README's first commands write), joined
//! by `&&` as a shell would. Each must succeed, and every PNG a command writes must show something
//! besides its background. `text` blocks and other Markdown files are not run.
//!
//! What is substituted, and why:
//! - `leapview` and `target/release/leapview`: the binary this test suite built (a debug build:
//!   the same code).
//! - `cargo build …` and `cargo install …` (`--release`, `--locked`, `--path .`): not run; the
//!   suite's own build stands for them (a release build takes minutes on two cores, and CI builds
//!   once).
//! - `cargo test …`: not run: it is this test suite.
//! - `cargo run [--release] [--locked] [-- ARGS]`: the binary's window (with ARGS) on a virtual X
//!   server, closed by itself after its first frame (`LEAPVIEW_EXIT_AFTER_FRAMES=1`).
//! - `xvfb-run -a COMMAND`: COMMAND as above; the window runs on this test's own virtual X server.
//! - `scripts/setup-debian.sh [--tests]`: with `--check` added, so that it installs nothing and
//!   fails if anything is missing (CI ran it before the tests).
//! - `../shared/data`: the team's data folder ([`common::data_dir`], `$LEAPVIEW_DATA_DIR` where
//!   set).
//! - `NAME=value` before a command: set in its environment.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use leapview::imaging::ImageF32;

/// The commands of a Markdown file's `sh` blocks: comments dropped, continued lines joined, `&&`
/// chains split, each a list of words.
fn readme_commands(text: &str) -> Vec<Vec<String>> {
    let mut commands = Vec::new();
    let mut in_sh = false;
    let mut line = String::new();
    for raw in text.lines() {
        let trimmed = raw.trim();
        if trimmed.starts_with("```") {
            in_sh = !in_sh && trimmed == "```sh";
            continue;
        }
        if !in_sh || trimmed.starts_with('#') || trimmed.is_empty() {
            continue;
        }
        match trimmed.strip_suffix('\\') {
            Some(start) => {
                line.push_str(start);
                line.push(' ');
            }
            None => {
                line.push_str(trimmed);
                for part in line.split("&&") {
                    let words = words(part);
                    if !words.is_empty() {
                        commands.push(words);
                    }
                }
                line.clear();
            }
        }
    }
    assert!(
        line.is_empty(),
        "the text ends inside a continued line: {line}"
    );
    commands
}

/// Splits a command into words at spaces, keeping quoted text together (quotes removed).
fn words(command: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut word = String::new();
    let mut quote = None;
    let mut any = false;
    for c in command.chars() {
        match (quote, c) {
            (None, '"' | '\'') => {
                quote = Some(c);
                any = true;
            }
            (Some(q), c) if c == q => quote = None,
            (None, c) if c.is_whitespace() => {
                if any {
                    out.push(std::mem::take(&mut word));
                    any = false;
                }
            }
            (_, c) => {
                word.push(c);
                any = true;
            }
        }
    }
    if any {
        out.push(word);
    }
    out
}

/// What a documented command stands for here.
enum Run {
    /// The `leapview` binary with these arguments.
    Leapview(Vec<String>),
    /// The window with these arguments, closed after its first frame.
    Window(Vec<String>),
    /// A program from the repository with these arguments.
    Script(PathBuf, Vec<String>),
    /// Not run, for this reason.
    Skip(&'static str),
}

/// Applies the substitutions in the module documentation.
fn substitute(words: &[String], data: &str) -> (Vec<(String, String)>, Run) {
    let mut env = Vec::new();
    let mut rest: Vec<String> = words
        .iter()
        .map(|w| w.replace("../shared/data", data))
        .collect();
    while let Some((name, value)) = rest.first().and_then(|w| w.split_once('=')) {
        if !name.chars().all(|c| c.is_ascii_uppercase() || c == '_') {
            break;
        }
        env.push((name.to_string(), value.to_string()));
        rest.remove(0);
    }
    // `xvfb-run` starts a virtual X server for the command after it; the window below always runs
    // on one of this test's own.
    if rest.first().is_some_and(|w| w == "xvfb-run") {
        rest.remove(0);
        while let Some(flag) = rest.first().filter(|w| w.starts_with('-')) {
            assert!(
                flag == "-a" || flag == "--auto-servernum",
                "the docs run xvfb-run {flag}: say here what stands for it"
            );
            rest.remove(0);
        }
    }
    let args = |from: usize| rest[from..].to_vec();
    let run = match rest.first().map(String::as_str) {
        Some("leapview" | "target/release/leapview") => Run::Leapview(args(1)),
        Some("cargo") => match rest.get(1).map(String::as_str) {
            Some("run") => {
                let after = rest
                    .iter()
                    .position(|w| w == "--")
                    .map_or(rest.len(), |i| i + 1);
                Run::Window(args(after))
            }
            Some("build" | "install") => Run::Skip("the suite's own build stands for it"),
            Some("test") => Run::Skip("it is this test suite"),
            other => panic!("the docs run cargo {other:?}: say here what stands for it"),
        },
        Some(script) if script.starts_with("scripts/") => {
            let mut a = args(1);
            if script == "scripts/setup-debian.sh" {
                a.push("--check".into());
            }
            Run::Script(Path::new(env!("CARGO_MANIFEST_DIR")).join(script), a)
        }
        other => panic!("the docs run {other:?}: say here what stands for it"),
    };
    (env, run)
}

/// The PNG files a command names after `--out`.
fn png_outputs(args: &[String], dir: &Path) -> Vec<PathBuf> {
    args.windows(2)
        .filter(|w| w[0] == "--out" && w[1].ends_with(".png"))
        .map(|w| dir.join(&w[1]))
        .collect()
}

/// Runs the window with `args` and `env` on a virtual X server until it closes itself after one
/// frame.
fn run_window(args: &[String], env: &[(String, String)], dir: &Path) {
    let x = common::Xvfb::start();
    let runtime = dir.join("runtime");
    std::fs::create_dir_all(&runtime).expect("runtime folder");
    let mut app = x
        .window_command(&runtime)
        .args(args)
        .current_dir(dir)
        .envs(env.iter().map(|(k, v)| (k, v)))
        .env("LEAPVIEW_EXIT_AFTER_FRAMES", "1")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("start the window");
    let status = common::wait_for_exit(
        &mut app,
        Duration::from_secs(300),
        "the window of `cargo run --release`",
    );
    assert!(status.success(), "the window failed: {status}");
}

/// The documents whose `sh` blocks are run, in this order, and how many of each one's commands
/// must at least run (not skipped): fewer means the parser lost some.
const DOCUMENTS: [(&str, usize); 2] = [("README.md", 10), ("docs/USER-GUIDE.md", 15)];

#[test]
fn every_command_in_the_readme_and_the_guide_runs_and_draws_something() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let data = common::data_dir();
    let data = data.to_str().expect("utf-8 path");
    let dir = common::TempDir::new("readme");
    for (document, at_least) in DOCUMENTS {
        let text = std::fs::read_to_string(root.join(document))
            .unwrap_or_else(|e| panic!("read {document}: {e}"));
        let ran = run_commands(&readme_commands(&text), data, dir.path());
        assert!(
            ran >= at_least,
            "only {ran} commands of {document} ran (at least {at_least} expected)"
        );
    }
}

/// Runs `commands` in `dir`, in order, and checks what they write; returns how many ran.
fn run_commands(commands: &[Vec<String>], data: &str, dir: &Path) -> usize {
    let mut ran = 0;
    for words in commands {
        let shown = words.join(" ");
        let (env, run) = substitute(words, data);
        let (program, args) = match run {
            Run::Skip(why) => {
                eprintln!("not run: {shown} ({why})");
                continue;
            }
            Run::Window(args) => {
                let started = Instant::now();
                run_window(&args, &env, dir);
                eprintln!(
                    "ran in {:.1} s (the window, closed after its first frame): {shown}",
                    started.elapsed().as_secs_f64()
                );
                ran += 1;
                continue;
            }
            Run::Leapview(args) => (PathBuf::from(env!("CARGO_BIN_EXE_leapview")), args),
            Run::Script(path, args) => (path, args),
        };
        let started = Instant::now();
        let out = Command::new(&program)
            .args(&args)
            .envs(env)
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .current_dir(dir)
            .output()
            .unwrap_or_else(|e| panic!("cannot run {shown}: {e}"));
        assert!(
            out.status.success(),
            "`{shown}` failed ({}):\n{}\n{}",
            out.status,
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        for png in png_outputs(&args, dir) {
            let image = ImageF32::read_png(&png)
                .unwrap_or_else(|e| panic!("`{shown}` wrote no readable {}: {e}", png.display()));
            let background = image.pixels[0];
            let drawn = image
                .pixels
                .iter()
                .filter(|p| (0..3).any(|c| (p[c] - background[c]).abs() > 8.0 / 255.0))
                .count();
            assert!(
                drawn * 100 > image.pixels.len(),
                "`{shown}` drew almost nothing: {drawn} of {} pixels",
                image.pixels.len()
            );
            if std::env::var_os("LEAPVIEW_SAVE_IMAGES").is_some() {
                let kept = common::output_dir().join(format!(
                    "readme-{}",
                    png.file_name()
                        .and_then(|n| n.to_str())
                        .unwrap_or("out.png")
                ));
                std::fs::copy(&png, kept).expect("keep the image");
            }
        }
        eprintln!("ran in {:.1} s: {shown}", started.elapsed().as_secs_f64());
        ran += 1;
    }
    ran
}

#[test]
fn readme_commands_are_parsed_as_a_shell_would() {
    let text = "text\n```sh\n# a comment\nVAR=1 cargo run --release --locked -- a.nrrd\nleapview render \"a b.nrrd\" \\\n    --out x.png && leapview info x\n```\n```text\nnot a command\n```\n";
    let commands = readme_commands(text);
    assert_eq!(
        commands,
        [
            vec![
                "VAR=1",
                "cargo",
                "run",
                "--release",
                "--locked",
                "--",
                "a.nrrd"
            ],
            vec!["leapview", "render", "a b.nrrd", "--out", "x.png"],
            vec!["leapview", "info", "x"],
        ]
    );
    let (env, run) = substitute(&commands[0], "/data");
    assert_eq!(env, [("VAR".to_string(), "1".to_string())]);
    assert!(matches!(run, Run::Window(a) if a == ["a.nrrd"]));
    let (_, run) = substitute(&words("cargo run --release --locked"), "/d");
    assert!(matches!(run, Run::Window(a) if a.is_empty()));
    let (env, run) = substitute(&words("xvfb-run -a cargo run --release --locked"), "/d");
    assert!(env.is_empty());
    assert!(matches!(run, Run::Window(a) if a.is_empty()));
    for skipped in [
        "cargo build --release --locked",
        "cargo install --locked --path .",
        "cargo test --locked",
    ] {
        let (_, run) = substitute(&words(skipped), "/d");
        assert!(matches!(run, Run::Skip(_)), "{skipped}");
    }
    let (_, run) = substitute(&words("leapview info ../shared/data/x.nrrd"), "/d");
    assert!(matches!(run, Run::Leapview(a) if a == ["info", "/d/x.nrrd"]));
    let (_, run) = substitute(&words("scripts/setup-debian.sh --tests"), "/d");
    assert!(matches!(run, Run::Script(_, a) if a == ["--tests", "--check"]));
}
