#![no_main]
//! One DICOM file on arbitrary bytes, opened as a user opens a file (its folder holds only it):
//! dicom-rs's parser and decoders, then LeapView's tag reading and assembly.
#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let dir = common::scratch("dicom");
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join("f.dcm");
    if std::fs::write(&path, data).is_ok() {
        let _ = leapview::volume::load_volume(&path, &leapview::volume::LoadOptions::default());
    }
});
