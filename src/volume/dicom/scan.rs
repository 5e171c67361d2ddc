//! Finds the DICOM images under a path: a folder (searched recursively), one file of a series
//! (its folder is searched, the series holding the file is the default), or a DICOMDIR (its
//! folder). Files are read up to their pixel data, on all cores; what is not a DICOM image is
//! counted, not an error.

use std::path::{Path, PathBuf};

use dicom_dictionary_std::tags;
use dicom_object::OpenFileOptions;

use super::guard::{Encoding, ImplicitForExplicit};
use super::header::FrameHeader;
use super::tags::{Contents, contents};
use crate::parallel::parallel;
use crate::volume::error::dicom::DicomError;

/// Deepest folder nesting searched (PACS exports nest patient, study, series and more; a deeper
/// folder is counted and named in the message when nothing is found).
pub const MAX_DEPTH: usize = 32;
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
    /// For a file whose frames were kept, the files holding copies of them (by index into
    /// `files`): read in its place where it cannot be decoded.
    pub alternatives: super::series::Alternatives,
    /// Sub-folders that could not be listed, with the first one's reason.
    pub unreadable_folders: Vec<String>,
    /// Folders deeper than [`MAX_DEPTH`] below the one scanned, not searched.
    pub too_deep: usize,
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
        if let Some(first) = self.unreadable_folders.first() {
            parts.push(format!(
                "{} folder{} that could not be listed (first: {first})",
                self.unreadable_folders.len(),
                if self.unreadable_folders.len() == 1 {
                    ""
                } else {
                    "s"
                }
            ));
        }
        if self.too_deep > 0 {
            parts.push(format!(
                "{} folder{} more than {MAX_DEPTH} levels down, not searched",
                self.too_deep,
                if self.too_deep == 1 { "" } else { "s" }
            ));
        }
        parts.join(", ")
    }
}

/// Whether `path` is a file that starts like DICOM Part 10 (`DICM` after the 128-byte preamble).
pub(crate) fn looks_like_dicom(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 132];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok_and(|()| &head[128..132] == b"DICM")
}

/// What a walk through folders found: files, and folders passed over.
#[derive(Default)]
struct Walk {
    files: Vec<PathBuf>,
    unreadable_folders: Vec<String>,
    too_deep: usize,
}

/// A folder's entries, sorted.
fn list_folder(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)?
        .flatten()
        .map(|e| e.path())
        .collect();
    entries.sort();
    Ok(entries)
}

/// Lists the files under `dir` (`depth` levels below the folder scanned) through `list`; a
/// sub-folder that cannot be listed is passed over and named, the folder scanned itself is an
/// error.
fn collect_files(
    root: &Path,
    dir: &Path,
    depth: usize,
    walk: &mut Walk,
    list: &dyn Fn(&Path) -> std::io::Result<Vec<PathBuf>>,
) -> Result<(), DicomError> {
    let entries = match list(dir) {
        Ok(entries) => entries,
        Err(e) if depth > 0 => {
            walk.unreadable_folders
                .push(format!("{}: {e}", label(root, dir)));
            return Ok(());
        }
        Err(e) => {
            return Err(DicomError::Unreadable {
                file: dir.display().to_string(),
                reason: e.to_string(),
            });
        }
    };
    for path in entries {
        if walk.files.len() >= MAX_FILES {
            break;
        }
        // Symbolic links to folders are not followed: no cycles.
        let Ok(meta) = std::fs::symlink_metadata(&path) else {
            continue;
        };
        if meta.is_dir() {
            if depth < MAX_DEPTH {
                collect_files(root, &path, depth + 1, walk, list)?;
            } else {
                walk.too_deep += 1;
            }
        } else if std::fs::metadata(&path).is_ok_and(|m| m.is_file()) {
            walk.files.push(path);
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
    let mut walk = Walk::default();
    let files = if is_dir || is_dicomdir {
        collect_files(&root, &root, 0, &mut walk, &list_folder)?;
        std::mem::take(&mut walk.files)
    } else {
        // One file of a series: its siblings (not the folders below them).
        let entries = std::fs::read_dir(&root).map_err(|e| DicomError::Unreadable {
            file: root.display().to_string(),
            reason: e.to_string(),
        })?;
        let mut files: Vec<PathBuf> = entries
            .flatten()
            .map(|e| e.path())
            .filter(|p| std::fs::metadata(p).is_ok_and(|m| m.is_file()))
            .take(MAX_FILES)
            .collect();
        files.sort();
        files
    };
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
        unreadable_folders: walk.unreadable_folders,
        too_deep: walk.too_deep,
        ..Scan::default()
    };
    for (i, f) in found.into_iter().enumerate() {
        let Some(f) = f else { continue };
        match f {
            // A file the user named that cannot be an image says why; others are counted.
            Err(e) if Some(i) == named_file => return Err(e),
            Err(e) => scan.unreadable.push(e.to_string()),
            Ok(Found::Frames(frames)) => scan.frames.extend(frames),
            // The file the user named must be the one opened, or say why not.
            Ok(Found::NotDicom) if Some(i) == named_file => {
                return Err(DicomError::Unreadable {
                    file: label(&root, &files[i]),
                    reason: "it is not a DICOM file (no \"DICM\" after the 128-byte preamble)"
                        .into(),
                });
            }
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
    let dropped = super::series::drop_copies(std::mem::take(&mut scan.frames), named_file);
    scan.frames = dropped.kept;
    scan.copies = dropped.files;
    scan.alternatives = dropped.alternatives;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A folder tree made on disk, and a listing that fails for the folders named `locked`
    /// (as a folder without read permission does for anyone but root, who runs CI).
    #[test]
    fn a_sub_folder_that_cannot_be_listed_is_passed_over_and_named() {
        let root = std::env::temp_dir().join(format!("leapview-scan-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        for dir in ["a", "locked", "b/locked"] {
            std::fs::create_dir_all(root.join(dir)).expect("folders");
        }
        for file in ["a/1", "b/2", "locked/3", "4"] {
            std::fs::write(root.join(file), b"x").expect("files");
        }
        let list = |dir: &Path| {
            if dir.file_name().is_some_and(|n| n == "locked") {
                Err(std::io::Error::from(std::io::ErrorKind::PermissionDenied))
            } else {
                list_folder(dir)
            }
        };
        let mut walk = Walk::default();
        collect_files(&root, &root, 0, &mut walk, &list).expect("the root lists");
        let names: Vec<String> = walk.files.iter().map(|f| label(&root, f)).collect();
        assert_eq!(names, ["4", "a/1", "b/2"]);
        assert_eq!(walk.unreadable_folders.len(), 2);
        assert!(
            walk.unreadable_folders[0].starts_with("b/locked: "),
            "{:?}",
            walk.unreadable_folders
        );
        // The folder scanned itself is an error naming it.
        let mut walk = Walk::default();
        let e = collect_files(
            &root.join("locked"),
            &root.join("locked"),
            0,
            &mut walk,
            &list,
        );
        assert!(matches!(e, Err(DicomError::Unreadable { .. })));
        let _ = std::fs::remove_dir_all(&root);
    }
}
