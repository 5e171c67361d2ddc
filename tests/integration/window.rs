//! The viewer window on a virtual X server (Xvfb) with Mesa's Vulkan CPU driver: it opens on the
//! generated phantom, renders only the frames something changed for, shows exactly the
//! renderer's pixels, saves its screenshot and closes itself (`LEAPVIEW_EXIT_AFTER_FRAMES`,
//! `LEAPVIEW_SCREENSHOT`). Needs `Xvfb` (`apt-get install xvfb`); fails, rather than skips,
//! without it.

use crate::common;

use std::os::unix::fs::PermissionsExt;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A virtual X server on a free display, stopped when dropped.
struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    fn start() -> Self {
        // Far from the :99 that scripts/screenshot.sh starts with.
        let number = (150..250)
            .find(|n| !Path::new(&format!("/tmp/.X{n}-lock")).exists())
            .expect("a free X display number");
        let display = format!(":{number}");
        let child = Command::new("Xvfb")
            .args([
                display.as_str(),
                "-screen",
                "0",
                "1280x800x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| {
                panic!("cannot start Xvfb ({e}); install it: apt-get install xvfb")
            });
        let socket = format!("/tmp/.X11-unix/X{number}");
        let deadline = Instant::now() + Duration::from_secs(10);
        while !Path::new(&socket).exists() {
            assert!(Instant::now() < deadline, "Xvfb did not start on {display}");
            std::thread::sleep(Duration::from_millis(50));
        }
        Self { child, display }
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Mesa's Vulkan CPU driver, where installed: real GPU drivers may not present to Xvfb.
fn lavapipe_icd() -> Option<String> {
    std::fs::read_dir("/usr/share/vulkan/icd.d")
        .ok()?
        .filter_map(Result::ok)
        .map(|e| e.path())
        .find(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("lvp_icd"))
        })
        .map(|p| p.display().to_string())
}

#[test]
fn window_renders_the_frames_asked_for_and_shows_the_renderers_pixels() {
    const FRAMES: usize = 3;
    let x = Xvfb::start();
    let dir = common::TempDir::new("window");
    // Mesa wants a private runtime folder.
    std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o700))
        .expect("chmod the runtime folder");
    let shot = dir.path().join("window.png");
    let log_path = dir.path().join("log.txt");
    let log_file = std::fs::File::create(&log_path).expect("create the log");
    let mut command = Command::new(env!("CARGO_BIN_EXE_leapview"));
    command
        .env("DISPLAY", &x.display)
        .env_remove("WAYLAND_DISPLAY")
        .env("XDG_RUNTIME_DIR", dir.path())
        .env("LEAPVIEW_BACKEND", "vulkan")
        .env("RUST_LOG", "warn,leapview=trace")
        .env("LEAPVIEW_EXIT_AFTER_FRAMES", FRAMES.to_string())
        .env("LEAPVIEW_SCREENSHOT", &shot)
        .stdout(Stdio::null())
        .stderr(log_file);
    if let Some(icd) = lavapipe_icd() {
        command.env("VK_ICD_FILENAMES", icd);
    }
    let mut app = command.spawn().expect("start the window");
    // Generating the phantom, timing both paths and three frames take about 10 s on lavapipe in
    // a debug build; 300 s leaves room for a loaded machine.
    let deadline = Instant::now() + Duration::from_secs(300);
    let status = loop {
        if let Some(status) = app.try_wait().expect("wait for the window") {
            break status;
        }
        if Instant::now() > deadline {
            let _ = app.kill();
            panic!("the window did not close itself within 300 s");
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    let log = std::fs::read_to_string(&log_path).expect("read the log");
    assert!(status.success(), "the window failed ({status}):\n{log}");

    let frames = log.matches("rendered volume frame").count();
    let passes = log.matches("egui pass").count();
    assert_eq!(frames, FRAMES, "{log}");
    // The first frame stays still until the screenshot, which waits for its refinement to the
    // default mean; frame 2 is turned away from at once, so it is never refined.
    let full = leapview::ui::state::DEFAULT_REFINE_FRAMES;
    assert_eq!(
        log.matches("refined volume frame 1 to").count() as u32,
        full - 1,
        "{log}"
    );
    assert_eq!(log.matches("refined volume frame 2 to").count(), 0, "{log}");
    let refined_at = log.find(&format!("mean of {full}/{full}"));
    let shot_at = log.find("saved the window");
    assert!(
        refined_at.zip(shot_at).is_some_and(|(r, s)| r < s),
        "the screenshot did not wait for the refinement:\n{log}"
    );
    // The screenshot waits for several passes without a new frame: passes alone render nothing.
    assert!(
        passes > frames + 3,
        "{passes} passes for {frames} frames:\n{log}"
    );

    let comparison = log
        .lines()
        .find(|l| l.contains("window vs rendered image"))
        .unwrap_or_else(|| panic!("no screenshot comparison in the log:\n{log}"));
    assert!(comparison.contains(" 0 differ"), "{comparison}");

    let image = image::open(&shot).expect("the screenshot is a PNG");
    assert_eq!((image.width(), image.height()), (1280, 800));
}
