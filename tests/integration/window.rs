//! The viewer window on a virtual X server (Xvfb) with Mesa's Vulkan CPU driver: it opens on the
//! generated phantom, renders only the frames something changed for, shows exactly the
//! renderer's pixels, saves its screenshot and closes itself (`LEAPVIEW_EXIT_AFTER_FRAMES`,
//! `LEAPVIEW_SCREENSHOT`). Needs `Xvfb` (`apt-get install xvfb`); fails, rather than skips,
//! without it.

use crate::common;

use std::process::Stdio;
use std::time::{Duration, Instant};

#[test]
fn window_renders_the_frames_asked_for_and_shows_the_renderers_pixels() {
    const FRAMES: usize = 3;
    let x = common::Xvfb::start();
    let dir = common::TempDir::new("window");
    let shot = dir.path().join("window.png");
    let log_path = dir.path().join("log.txt");
    let log_file = std::fs::File::create(&log_path).expect("create the log");
    let mut command = x.window_command(dir.path());
    command
        .env("RUST_LOG", "warn,leapview=trace")
        .env("LEAPVIEW_EXIT_AFTER_FRAMES", FRAMES.to_string())
        .env("LEAPVIEW_SCREENSHOT", &shot)
        .stdout(Stdio::null())
        .stderr(log_file);
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
