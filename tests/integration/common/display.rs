//! A virtual X server (Xvfb) for the tests that open the real window.

use std::os::unix::fs::PermissionsExt;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// One window test at a time: two would pick the same free display number before either
/// server had taken it, and two windows on a CPU driver would slow each other down.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// The display number this process last started a server on (149 before the first: the search
/// starts at :150).
static LAST_DISPLAY: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(149);

/// A virtual X server on a free display, stopped when dropped; while it runs, no other window
/// test does.
pub struct Xvfb {
    child: Child,
    /// The display, e.g. `:150`.
    pub display: String,
    _turn: std::sync::MutexGuard<'static, ()>,
}

impl Xvfb {
    /// Starts one on the first free display from :150 on, after the last one this process used
    /// (waiting for any other window test to finish); panics without `Xvfb`.
    pub fn start() -> Self {
        let turn = ONE_AT_A_TIME.lock().unwrap_or_else(|p| p.into_inner());
        // Far from the :99 that scripts/screenshot.sh starts with.
        // From the display after the last one this process used: a server started at once on
        // the number of one just killed failed to come up within 10 s once in CI.
        let after = LAST_DISPLAY.load(std::sync::atomic::Ordering::Relaxed);
        let number = (1..=100)
            .map(|i| 150 + (after + i - 150) % 100)
            .find(|&n| !display_taken(n))
            .expect("a free X display number");
        LAST_DISPLAY.store(number, std::sync::atomic::Ordering::Relaxed);
        // A server that died without cleaning up leaves its lock and socket; the socket would
        // look like the new server's before it is up.
        let _ = std::fs::remove_file(format!("/tmp/.X{number}-lock"));
        let _ = std::fs::remove_file(format!("/tmp/.X11-unix/X{number}"));
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
        Self {
            child,
            display,
            _turn: turn,
        }
    }
}

/// Whether X display `n` is in use: its lock file names a process that is running (a lock that
/// cannot be read counts as in use).
fn display_taken(n: u32) -> bool {
    match std::fs::read_to_string(format!("/tmp/.X{n}-lock")) {
        Ok(text) => text
            .trim()
            .parse::<u32>()
            .map_or(true, |pid| Path::new(&format!("/proc/{pid}")).exists()),
        Err(e) => e.kind() != std::io::ErrorKind::NotFound,
    }
}

impl Xvfb {
    /// The `leapview` binary set up to open its window here: Vulkan (lavapipe where installed,
    /// since real GPU drivers may not present to Xvfb), `runtime_dir` as the private runtime
    /// folder Mesa wants (made private here).
    pub fn window_command(&self, runtime_dir: &Path) -> Command {
        std::fs::set_permissions(runtime_dir, std::fs::Permissions::from_mode(0o700))
            .expect("chmod the runtime folder");
        let mut command = Command::new(env!("CARGO_BIN_EXE_leapview"));
        command
            .env("DISPLAY", &self.display)
            .env_remove("WAYLAND_DISPLAY")
            .env("XDG_RUNTIME_DIR", runtime_dir)
            .env("LEAPVIEW_BACKEND", "vulkan");
        if let Some(icd) = lavapipe_icd() {
            command.env("VK_ICD_FILENAMES", icd);
        }
        command
    }
}

/// Waits until `app` exits, at most `timeout` (then kills it and fails, naming `what`).
pub fn wait_for_exit(app: &mut Child, timeout: Duration, what: &str) -> std::process::ExitStatus {
    let deadline = Instant::now() + timeout;
    loop {
        if let Some(status) = app.try_wait().expect("wait for the window") {
            return status;
        }
        if Instant::now() > deadline {
            let _ = app.kill();
            panic!("{what} did not close within {} s", timeout.as_secs());
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        // Killed, the server cannot remove its lock and socket: every run would leave one
        // display taken until none of the hundred tried is free.
        let number = self.display.trim_start_matches(':');
        let _ = std::fs::remove_file(format!("/tmp/.X{number}-lock"));
        let _ = std::fs::remove_file(format!("/tmp/.X11-unix/X{number}"));
    }
}

/// Mesa's Vulkan CPU driver, where installed: real GPU drivers may not present to Xvfb.
pub fn lavapipe_icd() -> Option<String> {
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
