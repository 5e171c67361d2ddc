//! The meaning of NRRD header fields: type, dimension, sizes, spacing, encoding, byte order, skips,
//! data file, and the value scaling kept in key/value pairs.

use crate::volume::decode::Encoding;
use crate::volume::error::VolumeError;
use crate::volume::{samples::ScalarType, samples::ValueMapping};

use super::header::HeaderText;
use super::names::{parse_encoding, parse_type};

use crate::volume::{modality::Modality, orientation::Orientation};

const NRRD: &str = "NRRD";

/// Everything the header says that LeapView uses.
#[derive(Clone, Debug, PartialEq)]
pub struct NrrdHeader {
    /// Samples along x, y, z as declared (a leading axis of size 1 in 4-D files is dropped).
    pub dims: [u64; 3],
    /// Interleaved layers: the leading axis of a 4-D file read as layers (Slicer's `.seg.nrrd`
    /// with overlapping segments), else 1.
    pub layers: u64,
    /// Stored type.
    pub scalar_type: ScalarType,
    /// How the data are encoded.
    pub encoding: Encoding,
    /// Whether multi-byte samples are big-endian.
    pub big_endian: bool,
    /// Spacing in millimetres (1 where the header gives none).
    pub spacing_mm: [f64; 3],
    /// Anatomical orientation, from an anatomical `space` and `space directions`.
    pub orientation: Option<Orientation>,
    /// `space origin` in an anatomical space, as LPS millimetres (the first voxel's centre).
    pub origin_lps: Option<[f64; 3]>,
    /// Stored values to data units.
    pub mapping: ValueMapping,
    /// The `modality:=…` key/value, where there is one.
    pub modality: Option<Modality>,
    /// The detached data file as written, if any.
    pub data_file: Option<String>,
    /// Lines to skip at the start of the data file (as stored).
    pub line_skip: u64,
    /// Bytes to skip after the lines (decompressed bytes for gzip); `None` for `-1`: the data are
    /// the last bytes of the file.
    pub byte_skip: Option<u64>,
}

/// Most interleaved layers a 4-D file may hold (as many as a DICOM SEG's overlapping segments).
pub(crate) const MOST_LAYERS: u64 = 16;

/// Interprets the fields of a header; `layered` accepts a 4-D file's leading axis as layers.
pub(crate) fn interpret(text: &HeaderText, layered: bool) -> Result<NrrdHeader, VolumeError> {
    let field = |name: &'static str| text.fields.get(name).map(String::as_str);
    let required = |name: &'static str, why: &'static str| {
        field(name).ok_or(VolumeError::MissingField {
            format: NRRD,
            field: name,
            why,
        })
    };

    let scalar_type = parse_type(required("type", "")?)?;
    let dimension_text = required("dimension", "")?;
    let dimension: usize = dimension_text
        .parse()
        .map_err(|_| bad_field("dimension", dimension_text, "it must be a whole number"))?;
    let sizes_text = required("sizes", "")?;
    let sizes = parse_sizes(sizes_text, dimension)?;
    // Axes to keep: all three of a 3-D file, or the last three of a 4-D file whose first is 1.
    let (first, layers) = match (dimension, sizes.as_slice()) {
        (3, _) => (0, 1),
        (4, [1, ..]) => (1, 1),
        (4, [n, ..]) if layered && *n <= MOST_LAYERS => (1, *n),
        (4, [_, ..]) if layered => {
            return Err(bad_field(
                "sizes",
                sizes_text,
                &format!("at most {MOST_LAYERS} layers (its first axis) in a segmentation"),
            ));
        }
        (4, _) => {
            return Err(VolumeError::UnsupportedDimension {
                dimension: dimension_text.to_string(),
                hint: " (or 4-D with a first axis of size 1); a segmentation in layers (Slicer's \
                       4-D .seg.nrrd) opens as the labels of an image: --labels FILE, or File › \
                       Open segmentation…",
            });
        }
        _ => {
            return Err(VolumeError::UnsupportedDimension {
                dimension: dimension_text.to_string(),
                hint: " (or 4-D with a first axis of size 1)",
            });
        }
    };
    let dims = [sizes[first], sizes[first + 1], sizes[first + 2]];

    let encoding_text = required("encoding", "")?;
    let encoding = parse_encoding(encoding_text)?;
    let big_endian = match field("endian") {
        Some(e) if e.eq_ignore_ascii_case("little") => false,
        Some(e) if e.eq_ignore_ascii_case("big") => true,
        Some(e) => return Err(bad_field("endian", e, "it must be 'little' or 'big'")),
        None if scalar_type.size_bytes() > 1 => {
            return Err(VolumeError::MissingField {
                format: NRRD,
                field: "endian",
                why: " for multi-byte samples",
            });
        }
        None => false,
    };

    let (spacing_mm, directions) = match (field("space directions"), field("spacings")) {
        (Some(directions), _) => parse_space_directions(directions, dimension, first)?,
        (None, Some(spacings)) => (parse_spacings(spacings, dimension, first)?, None),
        (None, None) => ([1.0; 3], None),
    };
    let orientation = directions.and_then(|d| orientation_of(field("space"), d));
    let origin_lps = field("space origin")
        .map(|o| origin_of(field("space"), o))
        .transpose()?
        .flatten();

    let data_file = match (field("data file"), field("datafile")) {
        (Some(f), _) | (None, Some(f)) => Some(parse_data_file(f)?),
        (None, None) => None,
    };
    let line_skip = match field("line skip") {
        Some(v) => v.parse::<u64>().map_err(|_| {
            bad_field(
                "line skip",
                v,
                "it must be a whole number of lines, 0 or more",
            )
        })?,
        None => 0,
    };
    let byte_skip =
        match field("byte skip") {
            Some("-1") if encoding == Encoding::Raw => None,
            Some("-1") => {
                return Err(bad_field(
                    "byte skip",
                    "-1",
                    "-1 (data at the end of the file) is only possible with raw encoding",
                ));
            }
            Some(v) => Some(v.parse::<u64>().map_err(|_| {
                bad_field("byte skip", v, "it must be a whole number of bytes, or -1")
            })?),
            None => Some(0),
        };

    Ok(NrrdHeader {
        dims,
        layers,
        scalar_type,
        encoding,
        big_endian,
        spacing_mm,
        orientation,
        mapping: parse_mapping(text)?,
        modality: text
            .key_values
            .get("modality")
            .and_then(|m| Modality::parse(m)),
        data_file,
        line_skip,
        byte_skip,
        origin_lps,
    })
}

/// `space origin: (x,y,z)` in the anatomical `space` as LPS millimetres; `None` for a space that
/// is not anatomical (the origin then says nothing about the patient).
fn origin_of(space: Option<&str>, text: &str) -> Result<Option<[f64; 3]>, VolumeError> {
    let bad = || {
        bad_field(
            "space origin",
            text,
            "it must be one vector such as (0,0,0)",
        )
    };
    let inside = text
        .trim()
        .strip_prefix('(')
        .and_then(|t| t.strip_suffix(')'))
        .ok_or_else(bad)?;
    let v = inside
        .split(',')
        .map(|c| c.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<Vec<f64>>>()
        .and_then(|v| <[f64; 3]>::try_from(v.as_slice()).ok())
        .ok_or_else(bad)?;
    // Signs turning the space's axes into LPS.
    let flip = match space.map(str::to_ascii_lowercase).as_deref() {
        Some("right-anterior-superior" | "ras") => [-1.0, -1.0, 1.0],
        Some("left-posterior-superior" | "lps") => [1.0, 1.0, 1.0],
        Some("left-anterior-superior" | "las") => [1.0, -1.0, 1.0],
        _ => return Ok(None),
    };
    Ok(Some([0, 1, 2].map(|a| v[a] * flip[a])))
}

fn parse_sizes(text: &str, dimension: usize) -> Result<Vec<u64>, VolumeError> {
    let expected = "they must be positive whole numbers, one per axis";
    let sizes = text
        .split_whitespace()
        .map(|s| s.parse::<u64>().ok().filter(|&n| n > 0))
        .collect::<Option<Vec<u64>>>()
        .ok_or_else(|| bad_field("sizes", text, expected))?;
    if sizes.len() != dimension {
        return Err(bad_field(
            "sizes",
            text,
            &format!("it should list {dimension} sizes, as 'dimension' says"),
        ));
    }
    Ok(sizes)
}

/// `spacings: 1 1 2` (`nan` for an axis without one).
fn parse_spacings(text: &str, dimension: usize, first: usize) -> Result<[f64; 3], VolumeError> {
    let values = text
        .split_whitespace()
        .map(|s| s.parse::<f64>().ok())
        .collect::<Option<Vec<f64>>>()
        .filter(|v| v.len() == dimension)
        .ok_or_else(|| {
            bad_field(
                "spacings",
                text,
                "it must hold one number (or nan) per axis",
            )
        })?;
    Ok(std::array::from_fn(|a| {
        usable_spacing(values[first + a], "spacings")
    }))
}

/// The three axis vectors of `space directions`, one per index axis.
type Columns = [[f64; 3]; 3];

/// The orientation of axes with `directions` in the anatomical `space` (`right-anterior-superior`
/// or `RAS`, `left-posterior-superior` or `LPS`, `left-anterior-superior` or `LAS`); `None` for
/// other spaces (scanner, 3D-right-handed) or none.
fn orientation_of(space: Option<&str>, directions: [[f64; 3]; 3]) -> Option<Orientation> {
    // Signs turning the space's axes into RAS.
    let flip = match space?.to_ascii_lowercase().as_str() {
        "right-anterior-superior" | "ras" => [1.0, 1.0, 1.0],
        "left-posterior-superior" | "lps" => [-1.0, -1.0, 1.0],
        "left-anterior-superior" | "las" => [-1.0, 1.0, 1.0],
        _ => return None,
    };
    Orientation::from_ras_columns(directions.map(|c| [0, 1, 2].map(|r| c[r] * flip[r])))
}

/// `space directions: (1,0,0) (0,1,0) (0,0,2)`, `none` for a non-spatial axis; the spacing is the
/// length of each vector. Also returns the three vectors when they are 3-vectors.
fn parse_space_directions(
    text: &str,
    dimension: usize,
    first: usize,
) -> Result<([f64; 3], Option<Columns>), VolumeError> {
    let expected = "it must hold one vector such as (1,0,0), or none, per axis";
    let bad = || bad_field("space directions", text, expected);
    let mut lengths = Vec::new();
    let mut vectors = Vec::new();
    let mut rest = text.trim_start();
    while !rest.is_empty() {
        if let Some(after) = rest.strip_prefix("none") {
            lengths.push(f64::NAN);
            vectors.push(None);
            rest = after.trim_start();
        } else if let Some(after) = rest.strip_prefix('(') {
            let (inside, after) = after.split_once(')').ok_or_else(bad)?;
            let components = inside
                .split(',')
                .map(|c| c.trim().parse::<f64>().ok())
                .collect::<Option<Vec<f64>>>()
                .ok_or_else(bad)?;
            lengths.push(components.iter().map(|c| c * c).sum::<f64>().sqrt());
            vectors.push(<[f64; 3]>::try_from(components.as_slice()).ok());
            rest = after.trim_start();
        } else {
            return Err(bad());
        }
    }
    if lengths.len() != dimension {
        return Err(bad());
    }
    let spacing = std::array::from_fn(|a| usable_spacing(lengths[first + a], "space directions"));
    let columns = [0, 1, 2].map(|a| vectors[first + a]);
    let columns = match columns {
        [Some(x), Some(y), Some(z)] => Some([x, y, z]),
        _ => None,
    };
    Ok((spacing, columns))
}

/// A spacing as the volume needs it: positive and finite. Negative spacings (flipped axes) keep
/// their magnitude; a missing (`nan`, `none`) spacing is 1 mm; a zero or infinite one is 1 mm
/// with a warning, as in the NIfTI reader.
fn usable_spacing(value: f64, field: &str) -> f64 {
    let magnitude = value.abs();
    if magnitude.is_finite() && magnitude > 0.0 {
        magnitude
    } else {
        if !value.is_nan() {
            log::warn!("NRRD '{field}' gives an unusable spacing {value}; using 1 mm");
        }
        1.0
    }
}

/// `data file: NAME` (single file). The multi-file forms `LIST` and `FORMAT MIN MAX STEP` are
/// refused.
fn parse_data_file(text: &str) -> Result<String, VolumeError> {
    let multi = text == "LIST"
        || text.starts_with("LIST ")
        || (text.contains('%') && text.split_whitespace().count() >= 4);
    if multi || text.is_empty() {
        return Err(bad_field(
            "data file",
            text,
            "LeapView reads data kept in a single file (multi-file LIST and numbered-file forms \
             are not supported)",
        ));
    }
    Ok(text.to_string())
}

/// `nifti_scl_slope`/`nifti_scl_inter`, else `rescale_slope`/`rescale_intercept`. A slope of 0 or
/// one that is not finite means "no scaling", as in NIfTI.
fn parse_mapping(text: &HeaderText) -> Result<ValueMapping, VolumeError> {
    // A finite number under the first of `keys` present; `None` when neither is.
    let number = |keys: [&str; 2], finite: bool| -> Result<Option<f64>, VolumeError> {
        let Some((key, value)) = keys
            .iter()
            .find_map(|&k| text.key_values.get(k).map(|v| (k, v.trim())))
        else {
            return Ok(None);
        };
        match value.parse::<f64>() {
            Ok(x) if x.is_finite() || !finite => Ok(Some(x)),
            _ => Err(bad_field(key, value, "it must be a finite number")),
        }
    };
    let slope = number(["nifti_scl_slope", "rescale_slope"], false)?.unwrap_or(1.0);
    let intercept = number(["nifti_scl_inter", "rescale_intercept"], true)?.unwrap_or(0.0);
    if slope == 0.0 || !slope.is_finite() {
        log::info!("NRRD value scaling slope {slope} means no scaling");
        return Ok(ValueMapping::IDENTITY);
    }
    Ok(ValueMapping { slope, intercept })
}

fn bad_field(field: &str, value: &str, expected: &str) -> VolumeError {
    let shown: String = value.chars().take(60).collect();
    VolumeError::BadField {
        format: NRRD,
        field: field.to_string(),
        value: shown,
        expected: expected.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(lines: &[&str]) -> Result<NrrdHeader, VolumeError> {
        let text = format!("NRRD0004\n{}\n\n", lines.join("\n"));
        let (text, _, _) = super::super::header::read_header_text(&mut text.as_bytes())?;
        interpret(&text, false)
    }

    const BASE: [&str; 3] = ["dimension: 3", "sizes: 4 5 6", "encoding: raw"];

    fn with(extra: &[&str]) -> Result<NrrdHeader, VolumeError> {
        header(&[&BASE[..], extra].concat())
    }

    #[test]
    fn space_directions_give_the_spacing() {
        let h = with(&[
            "type: uint8",
            "space directions: (0.5,0,0) (0,-3,4) ( 0 , 0 , 2 )",
        ]);
        assert_eq!(h.expect("valid").spacing_mm, [0.5, 5.0, 2.0]);
        let h = with(&["type: uint8", "spacings: 0.5 nan -2"]);
        assert_eq!(h.expect("valid").spacing_mm, [0.5, 1.0, 2.0]);
        let h = with(&["type: uint8", "space directions: (1,0,0) (0,1,0)"]);
        assert!(matches!(h, Err(VolumeError::BadField { .. })), "{h:?}");
    }

    #[test]
    fn a_four_d_file_with_a_unit_first_axis_is_a_volume() {
        let h = header(&[
            "type: float",
            "endian: big",
            "dimension: 4",
            "sizes: 1 4 5 6",
            "encoding: gzip",
            "space directions: none (2,0,0) (0,3,0) (0,0,4)",
        ])
        .expect("valid");
        assert_eq!((h.dims, h.spacing_mm), ([4, 5, 6], [2.0, 3.0, 4.0]));
        assert!(h.big_endian);
        let h = header(&[
            "type: uint8",
            "dimension: 4",
            "sizes: 2 4 5 6",
            "encoding: raw",
        ]);
        assert!(
            matches!(h, Err(VolumeError::UnsupportedDimension { .. })),
            "{h:?}"
        );
    }

    #[test]
    fn multi_byte_types_need_an_endian() {
        let h = with(&["type: int16"]);
        assert!(matches!(
            h,
            Err(VolumeError::MissingField {
                field: "endian",
                ..
            })
        ));
        assert!(with(&["type: int8"]).is_ok());
    }

    #[test]
    fn skips_data_files_and_scaling() {
        let h = with(&[
            "type: uint8",
            "byte skip: -1",
            "line skip: 2",
            "datafile: x.raw",
            "rescale_intercept:=-1024",
        ])
        .expect("valid");
        assert_eq!(h.byte_skip, None);
        assert_eq!(h.line_skip, 2);
        assert_eq!(h.data_file.as_deref(), Some("x.raw"));
        assert_eq!(
            h.mapping,
            ValueMapping {
                slope: 1.0,
                intercept: -1024.0
            }
        );
        let h = header(&[
            "type: uint8",
            "dimension: 3",
            "sizes: 4 5 6",
            "encoding: gz",
            "byte skip: -1",
        ]);
        assert!(matches!(h, Err(VolumeError::BadField { .. })), "{h:?}");
        let h = with(&["type: uint8", "data file: LIST"]);
        assert!(matches!(h, Err(VolumeError::BadField { .. })), "{h:?}");
        let h = with(&["type: uint8", "data file: slice%03d.raw 1 10 1"]);
        assert!(matches!(h, Err(VolumeError::BadField { .. })), "{h:?}");
        let h = with(&["type: uint8", "nifti_scl_slope:=0", "nifti_scl_inter:=5"]);
        assert_eq!(h.expect("valid").mapping, ValueMapping::IDENTITY);
    }

    #[test]
    fn space_origin_is_read_as_lps() {
        let h = with(&[
            "type: uint8",
            "space: right-anterior-superior",
            "space directions: (1,0,0) (0,1,0) (0,0,1)",
            "space origin: (10, -20.5, 30)",
        ])
        .expect("header");
        assert_eq!(h.origin_lps, Some([-10.0, 20.5, 30.0]));
        let h =
            with(&["type: uint8", "space: scanner-xyz", "space origin: (1,2,3)"]).expect("header");
        assert_eq!(h.origin_lps, None, "not an anatomical space");
        assert!(with(&["type: uint8", "space: LPS", "space origin: (1,2)"]).is_err());
    }
}
