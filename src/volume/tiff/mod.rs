//! TIFF stacks as micro-CT and microscopy write them, through the `tiff` crate: a multi-page
//! TIFF (pages are slices), OME-TIFF (sizes, plane order and physical sizes from its OME-XML: one
//! channel and time point chosen), ImageJ hyperstacks (slice spacing and unit from their
//! description), or a folder of 2-D slices in natural order (`slice_2` before `slice_10`).
//! Greyscale, 8/16/32-bit integers (signed or not), 16/32/64-bit floats; any compression the crate
//! reads (LZW, deflate, PackBits, zstd, JPEG), strips or tiles, BigTIFF. TIFF has no patient
//! orientation: the views assume RAS.

mod description;
mod stream;

use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use tiff::ColorType;
use tiff::decoder::{Decoder, DecodingResult, Limits, ifd::Value};
use tiff::tags::Tag;

use super::error::VolumeError;
use super::limits;
use super::load::LoadOptions;
use super::model::{Provenance, Volume, VolumeIndex};
use super::samples::{Samples, ScalarType, ValueMapping};
use stream::{Opened, Pages};

type TiffDecoder = Decoder<BufReader<File>>;

/// Whether `name` is a TIFF file's name.
pub(crate) fn is_tiff_name(name: &str) -> bool {
    let lower = name.to_ascii_lowercase();
    [".tif", ".tiff", ".btf", ".tf8"]
        .iter()
        .any(|e| lower.ends_with(e))
}

/// The TIFF files of a folder, in natural order, where they are most of its files (a stack of
/// slices); `None` otherwise.
pub(crate) fn stack_files(dir: &Path) -> Option<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir).ok()?;
    let mut others = 0usize;
    let mut tiffs = Vec::new();
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') || !entry.file_type().is_ok_and(|t| t.is_file()) {
            continue;
        }
        if is_tiff_name(&name) {
            tiffs.push(entry.path());
        } else {
            others += 1;
        }
    }
    if tiffs.is_empty() || tiffs.len() <= others {
        return None;
    }
    tiffs.sort_by(|a, b| natural(&a.to_string_lossy(), &b.to_string_lossy()));
    Some(tiffs)
}

/// Compares names with runs of digits taken as numbers (`s2` before `s10`).
fn natural(a: &str, b: &str) -> std::cmp::Ordering {
    fn runs(s: &str) -> Vec<(bool, &str)> {
        let mut out = Vec::new();
        let mut start = 0;
        let bytes = s.as_bytes();
        for i in 1..=bytes.len() {
            if i == bytes.len() || bytes[i].is_ascii_digit() != bytes[start].is_ascii_digit() {
                out.push((bytes[start].is_ascii_digit(), &s[start..i]));
                start = i;
            }
        }
        out
    }
    let (ra, rb) = (runs(a), runs(b));
    for (x, y) in ra.iter().zip(&rb) {
        let order = match (x, y) {
            ((true, p), (true, q)) => {
                let (p, q) = (p.trim_start_matches('0'), q.trim_start_matches('0'));
                p.len().cmp(&q.len()).then_with(|| p.cmp(q))
            }
            ((_, p), (_, q)) => p.cmp(q),
        };
        if order.is_ne() {
            return order;
        }
    }
    ra.len().cmp(&rb.len()).then_with(|| a.cmp(b))
}

fn bad(reason: impl Into<String>) -> VolumeError {
    VolumeError::BadHeader {
        format: "TIFF",
        reason: reason.into(),
    }
}

fn tiff_error(e: tiff::TiffError) -> VolumeError {
    match e {
        tiff::TiffError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
            bad("the file ends before its directory says it does")
        }
        tiff::TiffError::IoError(e) => VolumeError::Io { source: e },
        e => bad(e.to_string()),
    }
}

fn open(path: &Path) -> Result<TiffDecoder, VolumeError> {
    let (file, _) = super::decode::open_file(path)?;
    let mut limits = Limits::default();
    // One page at a time, as large as the machine's memory allows.
    limits.decoding_buffer_size = usize::try_from(limits::max_volume_bytes()).unwrap_or(usize::MAX);
    limits.intermediate_buffer_size = limits.decoding_buffer_size;
    Ok(Decoder::new(BufReader::new(file))
        .map_err(tiff_error)?
        .with_limits(limits))
}

/// The width, height and sample type of the decoder's current page.
fn page_shape(decoder: &mut TiffDecoder) -> Result<PageShape, VolumeError> {
    let (w, h) = decoder.dimensions().map_err(tiff_error)?;
    let bits = match decoder.colortype().map_err(tiff_error)? {
        ColorType::Gray(bits) => bits,
        other => {
            return Err(VolumeError::UnsupportedType {
                name: format!("{other:?} colour TIFF pages (greyscale stacks are read)"),
            });
        }
    };
    let format = decoder
        .find_tag_unsigned::<u16>(Tag::SampleFormat)
        .map_err(tiff_error)?
        .unwrap_or(1);
    let scalar = match (format, bits) {
        (1, 8) => ScalarType::U8,
        (1, 16) => ScalarType::U16,
        (1, 32) => ScalarType::U32,
        (2, 8) => ScalarType::I8,
        (2, 16) => ScalarType::I16,
        (2, 32) => ScalarType::I32,
        (3, 16 | 32) => ScalarType::F32,
        (3, 64) => ScalarType::F64,
        _ => {
            return Err(VolumeError::UnsupportedType {
                name: format!("{bits}-bit TIFF samples of format {format}"),
            });
        }
    };
    Ok((w, h, scalar))
}

/// Appends a decoded page to `samples` (of the stack's type).
fn append(samples: &mut Samples, page: DecodingResult) -> Result<(), VolumeError> {
    match (samples, page) {
        (Samples::U8(v), DecodingResult::U8(p)) => v.extend_from_slice(&p),
        (Samples::U16(v), DecodingResult::U16(p)) => v.extend_from_slice(&p),
        (Samples::U32(v), DecodingResult::U32(p)) => v.extend_from_slice(&p),
        (Samples::I8(v), DecodingResult::I8(p)) => v.extend_from_slice(&p),
        (Samples::I16(v), DecodingResult::I16(p)) => v.extend_from_slice(&p),
        (Samples::I32(v), DecodingResult::I32(p)) => v.extend_from_slice(&p),
        (Samples::F32(v), DecodingResult::F32(p)) => v.extend_from_slice(&p),
        (Samples::F32(v), DecodingResult::F16(p)) => v.extend(p.iter().map(|h| h.to_f32())),
        (Samples::F64(v), DecodingResult::F64(p)) => v.extend_from_slice(&p),
        _ => {
            return Err(bad(
                "a page's samples are of another type than the first page's",
            ));
        }
    }
    Ok(())
}

/// Empty samples of `scalar` with room for `count`, or the error that they do not fit.
fn reserved(scalar: ScalarType, count: u64) -> Result<Samples, VolumeError> {
    let bytes = count.saturating_mul(scalar.size_bytes() as u64);
    let out_of_memory = || VolumeError::OutOfMemory { bytes };
    let n = usize::try_from(count).map_err(|_| out_of_memory())?;
    macro_rules! empty {
        ($variant:ident) => {{
            let mut v = Vec::new();
            v.try_reserve_exact(n).map_err(|_| out_of_memory())?;
            Samples::$variant(v)
        }};
    }
    Ok(match scalar {
        ScalarType::U8 => empty!(U8),
        ScalarType::I8 => empty!(I8),
        ScalarType::U16 => empty!(U16),
        ScalarType::I16 => empty!(I16),
        ScalarType::U32 => empty!(U32),
        ScalarType::I32 => empty!(I32),
        ScalarType::F32 => empty!(F32),
        ScalarType::F64 => empty!(F64),
    })
}

/// The page's description text, where it has one in UTF-8.
fn description_of(decoder: &mut TiffDecoder) -> Option<String> {
    match decoder.find_tag(Tag::ImageDescription) {
        Ok(Some(Value::Ascii(text))) => Some(text),
        _ => None,
    }
}

/// Millimetres per pixel along x and y from the resolution tags: pixels per unit, the unit the
/// ImageJ description names (`unit_mm`), else ResolutionUnit centimetre; inches (72 dpi and the
/// like) say nothing of a specimen.
fn resolution_mm(decoder: &mut TiffDecoder, unit_mm: Option<f64>) -> [Option<f64>; 2] {
    let unit = unit_mm.or_else(
        || match decoder.find_tag_unsigned::<u16>(Tag::ResolutionUnit) {
            Ok(Some(3)) => Some(10.0),
            _ => None,
        },
    );
    let per_unit = |decoder: &mut TiffDecoder, tag| match decoder.find_tag(tag) {
        Ok(Some(Value::Rational(n, d))) if n > 0 && d > 0 => Some(f64::from(n) / f64::from(d)),
        Ok(Some(Value::Double(v))) if v > 0.0 => Some(v),
        Ok(Some(Value::Float(v))) if v > 0.0 => Some(f64::from(v)),
        _ => None,
    };
    let x = per_unit(decoder, Tag::XResolution);
    let y = per_unit(decoder, Tag::YResolution);
    [x, y].map(|r| {
        let mm = unit? / r?;
        (mm.is_finite() && mm > 0.0).then_some(mm)
    })
}

/// Spacing from what the stack says, each missing axis filled and the fill said in a note.
fn spacing(said: [Option<f64>; 3], notes: &mut Vec<String>) -> [f64; 3] {
    match said {
        [Some(x), Some(y), Some(z)] => [x, y, z],
        [Some(x), y, None] => {
            notes.push(
                "the stack names no slice spacing: taken as the pixel spacing (isotropic voxels)"
                    .into(),
            );
            [x, y.unwrap_or(x), x]
        }
        [x, y, z] => {
            if x.is_none() {
                notes.push("the stack names no pixel size: taken as 1 mm".into());
            }
            let xy = x.or(y).unwrap_or(1.0);
            [x.unwrap_or(xy), y.unwrap_or(xy), z.unwrap_or(xy)]
        }
    }
}

/// A stack being read: pages of one shape and type appended in order, the load's progress and
/// cancellation checked at each.
struct Stack<'a> {
    shape: (u32, u32, ScalarType),
    dims: [u32; 3],
    samples: Samples,
    page_bytes: u64,
    progress: Option<&'a super::progress::LoadProgress>,
}

impl<'a> Stack<'a> {
    /// Room for `z` pages like the decoder's current one, once the limits and the load's
    /// admission check allow it.
    fn new(
        decoder: &mut TiffDecoder,
        z: u64,
        progress: Option<&'a super::progress::LoadProgress>,
    ) -> Result<Self, VolumeError> {
        let shape @ (w, h, scalar) = page_shape(decoder)?;
        let (dims, bytes) = limits::check_dims([u64::from(w), u64::from(h), z], scalar)?;
        limits::admit(progress, dims, scalar, false)?;
        let samples = reserved(scalar, u64::from(w) * u64::from(h) * z)?;
        if let Some(p) = progress {
            p.start(bytes);
        }
        Ok(Self {
            shape,
            dims,
            samples,
            page_bytes: bytes / z.max(1),
            progress,
        })
    }

    /// Appends the decoder's current page; `what` names it where it differs from the first.
    fn add(
        &mut self,
        decoder: &mut TiffDecoder,
        what: impl Fn() -> String,
    ) -> Result<(), VolumeError> {
        if self.progress.is_some_and(|p| p.is_cancelled()) {
            return Err(VolumeError::Cancelled);
        }
        same_shape(decoder, self.shape, what)?;
        append(&mut self.samples, decoder.read_image().map_err(tiff_error)?)?;
        if let Some(p) = self.progress {
            p.advance(self.page_bytes);
        }
        Ok(())
    }
}

/// Opens a TIFF file: a multi-page stack, OME-TIFF or an ImageJ hyperstack.
pub(crate) fn load_file(
    path: &Path,
    name: String,
    options: &LoadOptions,
) -> Result<Volume, VolumeError> {
    let progress = options.progress.as_deref();
    let mut decoder = open(path)?;
    let text = description_of(&mut decoder);
    let layout = text.as_deref().and_then(description::layout);
    let mut notes = Vec::new();
    let (pages, volumes, channels) = match &layout {
        Some(l) => {
            let pick = |asked: Option<u32>, count: u32, what: &'static str, flag: &str| {
                let i = asked.unwrap_or(0);
                if i >= count {
                    return Err(bad(format!(
                        "there is no {what} {}: the stack has {count} ({flag} 1 to {count})",
                        i + 1
                    )));
                }
                Ok((count > 1).then_some(VolumeIndex { chosen: i, count }))
            };
            let t = pick(options.volume, l.t, "time point", "--volume")?;
            let c = pick(options.channel, l.c, "channel", "--channel")?;
            let (ti, ci) = (t.map_or(0, |v| v.chosen), c.map_or(0, |v| v.chosen));
            let pages: Vec<u64> = (0..l.z).map(|z| l.page(z, ci, ti)).collect();
            (pages, t, c)
        }
        None => {
            if options.channel.is_some_and(|c| c > 0) {
                return Err(bad("the stack has one channel (--channel 1)"));
            }
            let mut count = 1u64;
            while decoder.more_images() && count < u64::from(limits::MAX_DIMENSION) {
                decoder.next_image().map_err(tiff_error)?;
                count += 1;
            }
            decoder.seek_to_image(0).map_err(tiff_error)?;
            ((0..count).collect(), None, None)
        }
    };
    let unit = text.as_deref().and_then(description::imagej_unit_mm);
    let [rx, ry] = resolution_mm(&mut decoder, unit);
    let said = match &layout {
        Some(l) if l.kind == "OME-XML" => l.spacing_mm,
        Some(l) => [rx, ry, l.spacing_mm[2]],
        None => [rx, ry, None],
    };
    let spacing = spacing(said, &mut notes);
    let read = match streams(&mut decoder, pages.len(), options)? {
        Some((shape, budget)) => {
            let pages = Pages::File {
                path: path.to_path_buf(),
                pages,
            };
            Read::streamed(pages, shape, budget, progress)?
        }
        None => {
            let mut stack = Stack::new(&mut decoder, pages.len() as u64, progress)?;
            for &page in &pages {
                let index = usize::try_from(page).map_err(|_| bad("too many pages"))?;
                decoder.seek_to_image(index).map_err(tiff_error)?;
                stack.add(&mut decoder, || format!("page {}", page + 1))?;
            }
            Read::Whole(stack)
        }
    };
    finish(name, read, spacing, notes, volumes, channels)
}

/// How a stack's samples were read.
enum Read<'a> {
    Whole(Stack<'a>),
    /// Streamed under a memory budget of so many bytes.
    Streamed(Box<Opened>, u64),
}

impl Read<'_> {
    /// The stack `pages` of `shape`, streamed under `budget` bytes.
    fn streamed(
        pages: Pages,
        shape: PageShape,
        budget: u64,
        progress: Option<&super::progress::LoadProgress>,
    ) -> Result<Self, VolumeError> {
        let opened = stream::open_streamed(pages, shape, budget, progress)?;
        Ok(Self::Streamed(Box::new(opened), budget))
    }
}

/// A page's width, height and sample type.
type PageShape = (u32, u32, ScalarType);

/// Refuses the decoder's page where its shape is not the first page's, `first`; `what` names it.
fn same_shape(
    decoder: &mut TiffDecoder,
    first: PageShape,
    what: impl Fn() -> String,
) -> Result<(), VolumeError> {
    let (pw, ph, ps) = page_shape(decoder)?;
    let (w, h, scalar) = first;
    if (pw, ph, ps) != first {
        return Err(bad(format!(
            "{} is {pw} x {ph} {ps}, the first {w} x {h} {scalar}",
            what()
        )));
    }
    Ok(())
}

/// The shape of the decoder's page and the memory budget, where a stack of `count` such pages
/// is larger than the budget (`--ram-budget`) or the memory available: it is streamed.
fn streams(
    decoder: &mut TiffDecoder,
    count: usize,
    options: &LoadOptions,
) -> Result<Option<(PageShape, u64)>, VolumeError> {
    let shape @ (w, h, scalar) = page_shape(decoder)?;
    let (dims, bytes) =
        limits::check_dims_within([u64::from(w), u64::from(h), count as u64], scalar, u64::MAX)?;
    let budget = options
        .ram_budget
        .unwrap_or_else(limits::default_ram_budget);
    let available = limits::available_memory_bytes().unwrap_or(u64::MAX);
    if bytes <= budget && bytes <= available {
        return Ok(None);
    }
    limits::admit(options.progress.as_deref(), dims, scalar, false)?;
    Ok(Some((shape, budget)))
}

/// Opens a folder of 2-D TIFF slices (`files`, in order: [`stack_files`]).
pub(crate) fn load_folder(
    files: &[PathBuf],
    name: String,
    options: &LoadOptions,
) -> Result<Volume, VolumeError> {
    let progress = options.progress.as_deref();
    let first = files
        .first()
        .ok_or_else(|| bad("the folder holds no TIFF file"))?;
    let mut decoder = open(first)?;
    let text = description_of(&mut decoder);
    let unit = text.as_deref().and_then(description::imagej_unit_mm);
    let [rx, ry] = resolution_mm(&mut decoder, unit);
    let mut notes = vec![format!(
        "{} slices, one TIFF file each, in natural order",
        files.len()
    )];
    let spacing = spacing([rx, ry, None], &mut notes);
    let read = match streams(&mut decoder, files.len(), options)? {
        Some((shape, budget)) => {
            Read::streamed(Pages::Folder(files.to_vec()), shape, budget, progress)?
        }
        None => {
            let mut stack = Stack::new(&mut decoder, files.len() as u64, progress)?;
            let name_of = |file: &Path| {
                file.file_name()
                    .unwrap_or_default()
                    .to_string_lossy()
                    .into_owned()
            };
            stack.add(&mut decoder, || name_of(first))?;
            for file in &files[1..] {
                stack.add(&mut open(file)?, || name_of(file))?;
            }
            Read::Whole(stack)
        }
    };
    finish(name, read, spacing, notes, None, None)
}

fn finish(
    name: String,
    read: Read,
    spacing: [f64; 3],
    mut notes: Vec<String>,
    volumes: Option<VolumeIndex>,
    channels: Option<VolumeIndex>,
) -> Result<Volume, VolumeError> {
    let volume = match read {
        Read::Whole(stack) => Volume::new(
            name,
            stack.dims,
            spacing,
            stack.samples,
            ValueMapping::IDENTITY,
        )?,
        Read::Streamed(opened, budget) => {
            let dims = opened.streamed.dims();
            let scalar = opened.streamed.preview().samples.scalar_type();
            let bytes = super::streamed::voxels(dims) * scalar.size_bytes() as u64;
            let (level, [hx, hy, hz]) = opened.first_held;
            let [px, py, pz] = opened.streamed.preview().dims;
            let preview = opened.streamed.preview_level();
            let statistics = match &opened.statistics {
                Some(_) => format!(
                    "range and histogram of every voxel, counted in that pass; percentiles \
                     from level {preview} ({px} x {py} x {pz} voxels)"
                ),
                None => {
                    format!("statistics and info from level {preview} ({px} x {py} x {pz} voxels)")
                }
            };
            notes.push(format!(
                "read from the stack brick by brick as the view needs them ({} of samples, more \
                 than the {} memory budget; --ram-budget sets it); level {level} ({hx} x {hy} x \
                 {hz} voxels) and coarser held, halved from every slice in one pass at opening; \
                 {statistics}",
                crate::text::bytes(bytes),
                crate::text::bytes(budget),
            ));
            let volume =
                Volume::streamed(name, dims, spacing, opened.streamed, ValueMapping::IDENTITY)?;
            match opened.statistics {
                Some((range, histogram, non_finite)) => {
                    volume.with_statistics(range, histogram, non_finite)
                }
                None => volume,
            }
        }
    };
    Ok(volume.with_provenance(Provenance {
        notes,
        volumes,
        channels,
        ..Provenance::default()
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_sort_with_their_numbers() {
        let mut names = vec!["s10.tif", "s2.tif", "s1.tif", "s02b.tif", "a.tif"];
        names.sort_by(|a, b| natural(a, b));
        assert_eq!(names, ["a.tif", "s1.tif", "s2.tif", "s02b.tif", "s10.tif"]);
    }

    #[test]
    fn missing_spacing_is_filled_and_said() {
        let mut notes = Vec::new();
        assert_eq!(
            spacing([Some(0.5), Some(0.5), Some(2.0)], &mut notes),
            [0.5, 0.5, 2.0]
        );
        assert!(notes.is_empty());
        assert_eq!(
            spacing([Some(0.5), None, None], &mut notes),
            [0.5, 0.5, 0.5]
        );
        assert!(notes[0].contains("slice spacing"));
        notes.clear();
        assert_eq!(spacing([None, None, None], &mut notes), [1.0, 1.0, 1.0]);
        assert!(notes[0].contains("1 mm"));
    }
}
