//! Finds the DICOM images under a path: a folder (searched recursively), one file of a series
//! (its folder is searched, the series holding the file is the default), or a DICOMDIR (its
//! folder). Files are read up to their pixel data, on all cores; what is not a DICOM image is
//! counted, not an error.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use dicom_dictionary_std::tags;
use dicom_object::OpenFileOptions;

use super::error::DicomError;
use super::guard::{Encoding, ImplicitForExplicit};
use super::header::FrameHeader;
use super::tags::{Contents, contents};

/// Deepest folder nesting searched.
pub const MAX_DEPTH: usize = 16;
/// Most files looked at under one folder.
pub const MAX_FILES: usize = 200_000;

/// What a scan found.
#[derive(Debug, Default)]
pub struct Scan {
    /// The files, as [`FrameHeader::file`] indexes them.
    pub files: Vec<PathBuf>,
    /// The image frames of every file, in file order.
    pub frames: Vec<FrameHeader>,
    /// The file the user named, where they named one (its index in `files`).
    pub named_file: Option<usize>,
    /// Files that are not DICOM, by count.
    pub not_dicom: usize,
    /// DICOM files that are not images, by what they are, with a count each.
    pub not_images: Vec<(&'static str, usize)>,
    /// DICOM files that could not be read, with the first one's message.
    pub unreadable: Vec<String>,
    /// Files that hold copies of objects found in other files (same `SOPInstanceUID`).
    pub copies: usize,
}

impl Scan {
    /// What was passed over, in words (`12 files that are not DICOM, 1 DICOMDIR`); empty when
    /// nothing was.
    pub fn skipped(&self) -> String {
        let mut parts = Vec::new();
        if self.not_dicom > 0 {
            parts.push(format!(
                "{} file{} that {} not DICOM",
                self.not_dicom,
                if self.not_dicom == 1 { "" } else { "s" },
                if self.not_dicom == 1 { "is" } else { "are" }
            ));
        }
        if self.copies > 0 {
            parts.push(format!(
                "{} file{} holding copies of images found in other files (same SOPInstanceUID)",
                self.copies,
                if self.copies == 1 { "" } else { "s" }
            ));
        }
        for (what, count) in &self.not_images {
            parts.push(format!("{count} x {what}"));
        }
        if let Some(first) = self.unreadable.first() {
            parts.push(format!(
                "{} unreadable (first: {first})",
                self.unreadable.len()
            ));
        }
        parts.join(", ")
    }
}

/// Whether `path` is a file that starts like DICOM Part 10 (`DICM` after the 128-byte preamble).
pub fn looks_like_dicom(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 132];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok_and(|()| &head[128..132] == b"DICM")
}

fn collect_files(dir: &Path, depth: usize, out: &mut Vec<PathBuf>) -> Result<(), DicomError> {
    let entries = std::fs::read_dir(dir).map_err(|e| DicomError::Unreadable {
        file: dir.display().to_string(),
        reason: e.to_string(),
    })?;
    let mut entries: Vec<_> = entries.flatten().map(|e| e.path()).collect();
    entries.sort();
    for path in entries {
        if out.len() >= MAX_FILES {
            break;
        }
        // Symbolic links to folders are not followed: no cycles.
        let Ok(meta) = std::fs::symlink_metadata(&path) else {
            continue;
        };
        if meta.is_dir() {
            if depth < MAX_DEPTH {
                collect_files(&path, depth + 1, out)?;
            }
        } else if std::fs::metadata(&path).is_ok_and(|m| m.is_file()) {
            out.push(path);
        }
    }
    Ok(())
}

/// The name a file goes by in messages: its path below the scanned folder.
fn label(root: &Path, path: &Path) -> String {
    path.strip_prefix(root)
        .ok()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(path)
        .display()
        .to_string()
}

/// One file's frames, or why it has none.
enum Found {
    Frames(Vec<FrameHeader>),
    NotDicom,
    NotImage(&'static str),
    Unreadable(String),
}

fn read_header(path: &Path, file: usize, name: &str) -> Result<Found, DicomError> {
    if !looks_like_dicom(path) {
        return Ok(Found::NotDicom);
    }
    let bytes = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    // dicom-rs allocates what a length says before reading: lying lengths are refused first.
    let encoding = match super::guard::check_lengths(path) {
        Ok(encoding) => encoding,
        Err(reason) => return Ok(Found::Unreadable(reason)),
    };
    let options = OpenFileOptions::new().read_until(tags::PIXEL_DATA);
    let opened = match encoding {
        Encoding::AsDeclared => options.open_file(path),
        Encoding::ImplicitForExplicit => {
            log::info!(
                "{name}: its meta information says explicit VR, its data set is implicit VR: read as implicit"
            );
            options
                .transfer_syntax_index(ImplicitForExplicit)
                .open_file(path)
        }
    };
    let obj = match opened {
        Ok(obj) => obj,
        Err(e) => return Ok(Found::Unreadable(super::pixels::error_chain(&e))),
    };
    if encoding == Encoding::ImplicitForExplicit {
        return Ok(match contents(&obj, file, name, bytes)? {
            Contents::Image(mut frames) => {
                for f in &mut frames {
                    f.implicit_vr = true;
                }
                Found::Frames(frames)
            }
            Contents::NotImage(what) => Found::NotImage(what),
        });
    }
    Ok(match contents(&obj, file, name, bytes)? {
        Contents::Image(frames) => Found::Frames(frames),
        Contents::NotImage(what) => Found::NotImage(what),
    })
}

/// Runs `work(i)` for `i` in `0..count` on every core; results in order. Stops early (remaining
/// items `None`) once `stop` says so.
pub fn parallel<R: Send>(
    count: usize,
    stop: &(dyn Fn() -> bool + Sync),
    work: &(dyn Fn(usize) -> R + Sync),
) -> Vec<Option<R>> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(count.max(1));
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<R>>> = Mutex::new((0..count).map(|_| None).collect());
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= count || stop() {
                        break;
                    }
                    let r = work(i);
                    if let Ok(mut all) = results.lock() {
                        all[i] = Some(r);
                    }
                }
            });
        }
    });
    results.into_inner().unwrap_or_default()
}

/// Scans `path` (a folder, a DICOM file, a DICOMDIR) for image frames.
pub fn scan(path: &Path, cancelled: &(dyn Fn() -> bool + Sync)) -> Result<Scan, DicomError> {
    let is_dir = std::fs::metadata(path).is_ok_and(|m| m.is_dir());
    let is_dicomdir = path
        .file_name()
        .is_some_and(|n| n.eq_ignore_ascii_case("DICOMDIR"));
    let root = if is_dir {
        path.to_path_buf()
    } else {
        path.parent()
            .filter(|p| !p.as_os_str().is_empty())
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
    };
    let mut files = Vec::new();
    if is_dir || is_dicomdir {
        collect_files(&root, 0, &mut files)?;
    } else {
        // One file of a series: its siblings (not the folders below them).
        let entries = std::fs::read_dir(&root).map_err(|e| DicomError::Unreadable {
            file: root.display().to_string(),
            reason: e.to_string(),
        })?;
        files = entries
            .flatten()
            .map(|e| e.path())
            .filter(|p| std::fs::metadata(p).is_ok_and(|m| m.is_file()))
            .take(MAX_FILES)
            .collect();
        files.sort();
    }
    let named_file = (!is_dir && !is_dicomdir)
        .then(|| files.iter().position(|f| f.file_name() == path.file_name()))
        .flatten();
    let found = parallel(files.len(), cancelled, &|i| {
        read_header(&files[i], i, &label(&root, &files[i]))
    });
    if cancelled() {
        return Err(DicomError::Cancelled);
    }
    let mut scan = Scan {
        named_file,
        ..Scan::default()
    };
    for (i, f) in found.into_iter().enumerate() {
        let Some(f) = f else { continue };
        match f {
            // A file the user named that cannot be an image says why; others are counted.
            Err(e) if Some(i) == named_file => return Err(e),
            Err(e) => scan.unreadable.push(e.to_string()),
            Ok(Found::Frames(frames)) => scan.frames.extend(frames),
            Ok(Found::NotDicom) => scan.not_dicom += 1,
            Ok(Found::NotImage(what)) => {
                if Some(i) == named_file && !is_dicomdir {
                    return Err(DicomError::NotAnImage {
                        file: label(&root, &files[i]),
                        what: what.to_string(),
                    });
                }
                match scan.not_images.iter_mut().find(|(w, _)| *w == what) {
                    Some((_, n)) => *n += 1,
                    None => scan.not_images.push((what, 1)),
                }
            }
            Ok(Found::Unreadable(reason)) => {
                if Some(i) == named_file {
                    return Err(DicomError::Unreadable {
                        file: label(&root, &files[i]),
                        reason,
                    });
                }
                scan.unreadable
                    .push(format!("{}: {reason}", label(&root, &files[i])))
            }
        }
    }
    scan.files = files;
    let (frames, copies) = super::series::drop_copies(std::mem::take(&mut scan.frames), named_file);
    scan.frames = frames;
    scan.copies = copies;
    if scan.frames.is_empty() {
        return Err(DicomError::NoImage {
            skipped: match scan.skipped() {
                s if s.is_empty() => "the folder is empty".into(),
                s => s,
            },
        });
    }
    Ok(scan)
}
