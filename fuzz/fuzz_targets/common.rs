//! Writes a fuzz input to a file in memory-backed /dev/shm (the loaders read files) and loads
//! it: any error is fine, a panic, a hang or an oversized allocation is a finding.

use std::path::PathBuf;

/// A per-process file named `name` in /dev/shm (or the temp folder).
pub fn scratch(name: &str) -> PathBuf {
    let dir = if std::path::Path::new("/dev/shm").is_dir() {
        PathBuf::from("/dev/shm")
    } else {
        std::env::temp_dir()
    };
    dir.join(format!("leapview-fuzz-{}-{name}", std::process::id()))
}

/// Loads `data` written as a file named `name`.
#[allow(dead_code)] // not every target loads a single file
pub fn load_bytes(name: &str, data: &[u8]) {
    let path = scratch(name);
    if std::fs::write(&path, data).is_ok() {
        let _ = leapview::volume::load_volume(&path, &leapview::volume::LoadOptions::default());
    }
}
