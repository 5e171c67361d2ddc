//! Frames into series: frames of one series share `SeriesInstanceUID`, frame of reference, image
//! size, orientation, pixel spacing and pixel format; a series whose frames differ in any of these
//! is split into parts, each its own volume (PS3.3 C.7.6.2 makes positions comparable only within
//! one frame of reference and orientation). Pure: no file is touched.

use super::header::{FrameHeader, SeriesFacts};
use crate::volume::error::dicom::DicomError;

/// One series (or one part of a series), its frames in the order they were found.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// The series' facts, from its first frame.
    pub facts: SeriesFacts,
    /// Which part of the series this is (1, 2, … where its frames differ in size, orientation,
    /// spacing or frame of reference; 0 where the series is whole).
    pub part: u32,
    /// The frames.
    pub frames: Vec<FrameHeader>,
}

impl Series {
    /// Whether this series can be shown: grey or colour, 8 to 32 bits.
    fn is_shown(&self) -> bool {
        self.frames
            .first()
            .is_some_and(|f| f.pixel.unsupported().is_none())
    }

    /// A one-line description for lists: number, modality, description, slices, size, spacing.
    pub fn summary(&self, number: usize) -> String {
        let Some(first) = self.frames.first() else {
            return format!("{number}: (empty)");
        };
        let mut text = format!("{number}: {}", self.facts.modality_or_unknown());
        if let Some(n) = self.facts.number {
            text.push_str(&format!(" #{n}"));
        }
        if !self.facts.description.is_empty() {
            text.push_str(&format!(" \"{}\"", self.facts.description));
        }
        if self.part > 0 {
            text.push_str(&format!(" (part {})", self.part));
        }
        text.push_str(&format!(
            ", {} slice{}, {} x {}",
            self.frames.len(),
            if self.frames.len() == 1 { "" } else { "s" },
            first.columns,
            first.rows
        ));
        if let Some([row, col]) = first.pixel_spacing {
            text.push_str(&format!(
                ", {} x {} mm pixels",
                crate::text::number(col),
                crate::text::number(row)
            ));
        }
        if !self.is_shown() {
            text.push_str(", not an image LeapView shows");
        }
        text
    }
}

impl SeriesFacts {
    /// The modality, or `?` where the files say none.
    pub fn modality_or_unknown(&self) -> &str {
        if self.modality.is_empty() {
            "?"
        } else {
            &self.modality
        }
    }
}

/// What [`drop_copies`] kept and dropped.
#[derive(Debug, Default, PartialEq)]
pub struct Copies {
    /// The frames kept, in the order given.
    pub kept: Vec<FrameHeader>,
    /// The number of files whose frames were all dropped.
    pub files: usize,
    /// For each file whose frames were kept, the files holding copies of them, in file order:
    /// read in its place where it cannot be decoded.
    pub alternatives: Alternatives,
}

/// For a file (by index), the files holding copies of its objects: (file, whether its data set
/// is written implicit under an explicit syntax, as [`FrameHeader::implicit_vr`]).
pub type Alternatives = std::collections::BTreeMap<usize, Vec<(usize, bool)>>;

/// Drops copies of one object: frames of the same `SOPInstanceUID` (and frame number) found in
/// several files, as when one image is saved in several transfer syntaxes. The copy in `named`
/// (the file the user named) is kept, else the one in the first file; the others are kept as
/// alternatives to it.
pub fn drop_copies(frames: Vec<FrameHeader>, named: Option<usize>) -> Copies {
    use std::collections::{BTreeMap, HashMap};
    let mut keep: HashMap<(&str, u32), usize> = HashMap::new();
    for f in &frames {
        if f.instance_uid.is_empty() {
            continue;
        }
        let file = keep
            .entry((f.instance_uid.as_str(), f.frame))
            .or_insert(f.file);
        if Some(f.file) == named || (Some(*file) != named && f.file < *file) {
            *file = f.file;
        }
    }
    let kept_file = |f: &FrameHeader| {
        f.instance_uid.is_empty() || keep.get(&(f.instance_uid.as_str(), f.frame)) == Some(&f.file)
    };
    let mut alternatives: Alternatives = BTreeMap::new();
    let mut dropped_files: Vec<usize> = Vec::new();
    for f in frames.iter().filter(|f| !kept_file(f)) {
        dropped_files.push(f.file);
        if let Some(&kept) = keep.get(&(f.instance_uid.as_str(), f.frame)) {
            let list = alternatives.entry(kept).or_default();
            if !list.iter().any(|(file, _)| *file == f.file) {
                list.push((f.file, f.implicit_vr));
            }
        }
    }
    alternatives.values_mut().for_each(|l| l.sort_unstable());
    dropped_files.sort_unstable();
    dropped_files.dedup();
    let keep_mask: Vec<bool> = frames.iter().map(kept_file).collect();
    let kept = frames
        .into_iter()
        .zip(keep_mask)
        .filter_map(|(f, k)| k.then_some(f))
        .collect();
    Copies {
        kept,
        files: dropped_files.len(),
        alternatives,
    }
}

/// How the user picks a series of a folder (`--series`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SeriesChoice {
    /// The series' number in the listing `leapview info` prints (1-based).
    Number(usize),
    /// A `SeriesInstanceUID`.
    Uid(String),
}

impl SeriesChoice {
    /// Reads `--series`: a number is a position in the listing, anything else a UID.
    pub fn parse(text: &str) -> Self {
        let t = text.trim();
        match t.parse::<usize>() {
            Ok(n) => Self::Number(n),
            Err(_) => Self::Uid(t.to_string()),
        }
    }
}

impl std::fmt::Display for SeriesChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Number(n) => write!(f, "{n}"),
            Self::Uid(uid) => f.write_str(uid),
        }
    }
}

/// Rounds a coordinate for comparing headers: values equal to 1e-4 are one key.
fn key_of(v: f64) -> i64 {
    (v * 1e4).round() as i64
}

/// What frames of one volume must share.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
struct GroupKey {
    uid: String,
    frame_of_reference: String,
    size: [u32; 2],
    orientation: Option<[i64; 6]>,
    spacing: Option<[i64; 2]>,
    pixel: [u16; 4],
    signed: bool,
    photometric: super::header::Photometric,
}

fn group_key(f: &FrameHeader) -> GroupKey {
    GroupKey {
        uid: f.series.uid.clone(),
        frame_of_reference: f.series.frame_of_reference.clone(),
        size: [f.rows, f.columns],
        // Orientations equal to about 0.006° are one: scanners write them rounded.
        orientation: f.orientation.map(|o| o.map(|v| (v * 1e4).round() as i64)),
        spacing: f.pixel_spacing.map(|s| s.map(key_of)),
        pixel: [
            f.pixel.bits_allocated,
            f.pixel.bits_stored,
            f.pixel.high_bit,
            f.pixel.samples_per_pixel,
        ],
        signed: f.pixel.signed,
        photometric: f.pixel.photometric,
    }
}

/// Groups frames into series, ordered by series number, then UID, then part; the frames of each
/// keep the order given.
pub fn group(frames: Vec<FrameHeader>) -> Vec<Series> {
    let mut groups: Vec<(GroupKey, Vec<FrameHeader>)> = Vec::new();
    for f in frames {
        let key = group_key(&f);
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, g)) => g.push(f),
            None => groups.push((key, vec![f])),
        }
    }
    // Parts of one UID: the part with more frames first.
    groups.sort_by(|(a, fa), (b, fb)| {
        let number = |f: &[FrameHeader]| f.first().and_then(|h| h.series.number);
        number(fa)
            .unwrap_or(i64::MAX)
            .cmp(&number(fb).unwrap_or(i64::MAX))
            .then_with(|| a.uid.cmp(&b.uid))
            .then_with(|| fb.len().cmp(&fa.len()))
            .then_with(|| a.cmp(b))
    });
    let mut out: Vec<Series> = Vec::with_capacity(groups.len());
    for (key, frames) in groups {
        let parts = out.iter().filter(|s| s.facts.uid == key.uid).count() as u32;
        if parts == 1
            && let Some(first) = out.iter_mut().find(|s| s.facts.uid == key.uid)
        {
            first.part = 1;
        }
        let facts = frames.first().map(|f| f.series.clone()).unwrap_or_default();
        out.push(Series {
            facts,
            part: if parts > 0 { parts + 1 } else { 0 },
            frames,
        });
    }
    out
}

/// The series to open: the one asked for, else the one holding `file` (a file the user named),
/// else the grey image series with the most frames (the first of equals).
pub fn choose(
    series: &[Series],
    choice: Option<&SeriesChoice>,
    file: Option<usize>,
) -> Result<usize, DicomError> {
    let available = || {
        series
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let part = if s.part > 0 {
                    format!(" part {}", s.part)
                } else {
                    String::new()
                };
                format!("{} ({}{part})", i + 1, s.facts.uid)
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let no_such = |asked: String| DicomError::NoSuchSeries {
        asked,
        available: available(),
    };
    match choice {
        Some(SeriesChoice::Number(n)) => {
            if *n >= 1 && *n <= series.len() {
                Ok(n - 1)
            } else {
                Err(no_such(n.to_string()))
            }
        }
        Some(SeriesChoice::Uid(uid)) => series
            .iter()
            .enumerate()
            .filter(|(_, s)| s.facts.uid == *uid)
            .max_by_key(|(i, s)| (s.frames.len(), std::cmp::Reverse(*i)))
            .map(|(i, _)| i)
            .ok_or_else(|| no_such(uid.clone())),
        None => {
            if let Some(file) = file
                && let Some(i) = series
                    .iter()
                    .position(|s| s.frames.iter().any(|f| f.file == file))
            {
                return Ok(i);
            }
            // Grey volumes before colour ones (a secondary capture beside a scan), then the most
            // frames.
            series
                .iter()
                .enumerate()
                .filter(|(_, s)| s.is_shown())
                .max_by_key(|(i, s)| {
                    let grey = s
                        .frames
                        .first()
                        .is_some_and(|f| !f.pixel.photometric.is_colour());
                    (grey, s.frames.len(), std::cmp::Reverse(*i))
                })
                .or_else(|| {
                    series
                        .iter()
                        .enumerate()
                        .max_by_key(|(i, s)| (s.frames.len(), std::cmp::Reverse(*i)))
                })
                .map(|(i, _)| i)
                .ok_or_else(|| DicomError::NoImage {
                    skipped: "no series".into(),
                })
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::volume::dicom::header::{Photometric, PixelFormat, Rescale};

    /// An axial CT frame of 4 x 3 pixels at height `z`, in series `uid`, file `file`.
    pub(crate) fn frame(uid: &str, file: usize, z: f64) -> FrameHeader {
        FrameHeader {
            file,
            frame: 0,
            label: format!("IM{file:04}"),
            frames_in_file: 1,
            series: SeriesFacts {
                uid: uid.into(),
                modality: "CT".into(),
                frame_of_reference: "1.2.3".into(),
                ..SeriesFacts::default()
            },
            rows: 3,
            columns: 4,
            orientation: Some([1.0, 0.0, 0.0, 0.0, 1.0, 0.0]),
            patient_orientation: None,
            position: Some([-10.0, -20.0, z]),
            pixel_spacing: Some([0.5, 0.25]),
            slice_thickness: None,
            spacing_between_slices: None,
            pixel: PixelFormat {
                bits_allocated: 16,
                bits_stored: 12,
                high_bit: 11,
                signed: true,
                samples_per_pixel: 1,
                photometric: Photometric::Monochrome2,
                planar: false,
            },
            rescale: Rescale::IDENTITY,
            window: None,
            instance_number: None,
            instance_uid: format!("1.2.3.{file}"),
            transfer_syntax: "1.2.840.10008.1.2.1".into(),
            implicit_vr: false,
            mosaic: None,
        }
    }

    #[test]
    fn frames_group_by_uid_size_and_orientation() {
        let mut frames = vec![
            frame("a", 0, 0.0),
            frame("b", 1, 0.0),
            frame("a", 2, 1.0),
            frame("b", 3, 1.0),
            frame("b", 4, 2.0),
        ];
        // A scout of series a: another orientation, so another part.
        let mut scout = frame("a", 5, 0.0);
        scout.orientation = Some([0.0, 1.0, 0.0, 0.0, 0.0, -1.0]);
        frames.push(scout);
        let series = group(frames);
        assert_eq!(series.len(), 3);
        assert_eq!((series[0].facts.uid.as_str(), series[0].part), ("a", 1));
        assert_eq!(series[0].frames.len(), 2);
        assert_eq!((series[1].facts.uid.as_str(), series[1].part), ("a", 2));
        assert_eq!((series[2].facts.uid.as_str(), series[2].part), ("b", 0));
        // Default: the most frames; a named file's series; a number; a UID (its largest part).
        assert_eq!(choose(&series, None, None).ok(), Some(2));
        assert_eq!(choose(&series, None, Some(5)).ok(), Some(1));
        assert_eq!(
            choose(&series, Some(&SeriesChoice::Number(1)), None).ok(),
            Some(0)
        );
        assert_eq!(
            choose(&series, Some(&SeriesChoice::Uid("a".into())), None).ok(),
            Some(0)
        );
        let e = choose(&series, Some(&SeriesChoice::Number(4)), None);
        assert!(
            matches!(e, Err(DicomError::NoSuchSeries { ref available, .. }) if available.contains("3 (b)"))
        );
        assert!(choose(&series, Some(&SeriesChoice::Number(0)), None).is_err());
        assert_eq!(SeriesChoice::parse(" 2 "), SeriesChoice::Number(2));
        assert_eq!(
            SeriesChoice::parse("1.2.840.1"),
            SeriesChoice::Uid("1.2.840.1".into())
        );
        assert!(
            series[2]
                .summary(3)
                .starts_with("3: CT, 3 slices, 4 x 3, 0.25 x 0.5 mm")
        );
    }

    #[test]
    fn copies_of_one_object_count_once_and_the_named_one_is_kept() {
        let mut copy = frame("a", 7, 0.0);
        copy.instance_uid = "1.2.3.0".into();
        let frames = vec![frame("a", 0, 0.0), frame("a", 1, 1.0), copy];
        let copies = drop_copies(frames.clone(), None);
        assert_eq!(
            copies.kept.iter().map(|f| f.file).collect::<Vec<_>>(),
            vec![0, 1]
        );
        assert_eq!(copies.files, 1);
        assert_eq!(copies.alternatives.get(&0), Some(&vec![(7, false)]));
        let copies = drop_copies(frames, Some(7));
        assert_eq!(
            copies.kept.iter().map(|f| f.file).collect::<Vec<_>>(),
            vec![1, 7]
        );
        assert_eq!(copies.alternatives.get(&7), Some(&vec![(0, false)]));
    }

    #[test]
    fn colour_series_are_chosen_after_grey_ones() {
        let mut rgb: Vec<_> = (0..5).map(|i| frame("rgb", i, i as f64)).collect();
        for f in &mut rgb {
            f.pixel.samples_per_pixel = 3;
            f.pixel.photometric = Photometric::Rgb;
        }
        let mut frames = rgb;
        frames.push(frame("grey", 9, 0.0));
        let series = group(frames);
        let chosen = choose(&series, None, None).expect("a series");
        assert_eq!(series[chosen].facts.uid, "grey");
    }
}
