//! The OME-NGFF image metadata of a Zarr group (`multiscales`, versions 0.1 to 0.5): the axes,
//! and each resolution level's array path and its scale and translation per axis. Only what the
//! attributes say is read here; the arrays' shapes are checked against it by the caller.

use serde_json::{Map, Value};

use crate::volume::error::zarr::ZarrError;

/// What an axis stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum AxisKind {
    /// A spatial axis (`z`, `y`, `x`).
    Space,
    /// Time points.
    Time,
    /// Channels.
    Channel,
    /// Anything else (`custom`, or no type given for a name LeapView does not know).
    Other,
}

/// One axis of the image, in the arrays' order.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Axis {
    /// Its name (`z`, `c`, …).
    pub name: String,
    /// What it stands for.
    pub kind: AxisKind,
    /// Its unit as written (`micrometer`), where given.
    pub unit: Option<String>,
}

/// One resolution level: the array and where its voxels lie.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Level {
    /// The array's path in the group (`0`, `s1`).
    pub path: String,
    /// Units per voxel along each axis, the multiscale's own scale applied (`None`: the
    /// metadata gives none, as before version 0.4).
    pub scale: Option<Vec<f64>>,
    /// The first voxel's centre along each axis, in the axes' units (zero where not given).
    pub translation: Vec<f64>,
}

/// The first multiscale image of a group's attributes.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Image {
    /// The NGFF version the metadata states, where it does.
    pub version: Option<String>,
    /// The image's name, where given.
    pub name: Option<String>,
    /// The axes (`None` before version 0.3: t, c, z, y, x by rule).
    pub axes: Option<Vec<Axis>>,
    /// The levels, finest first.
    pub levels: Vec<Level>,
    /// The display window of each channel (`omero.channels[].window`), where given.
    pub windows: Vec<Option<[f64; 2]>>,
}

/// The most levels a multiscale may list (a pyramid down to one voxel from 65536 needs 17).
const MAX_LEVELS: usize = 64;

/// The most axes an image may have (NGFF allows 2 to 5).
const MAX_AXES: usize = 5;

/// A scale and a translation, each where given.
type Transform = (Option<Vec<f64>>, Option<Vec<f64>>);

fn bad(reason: impl Into<String>) -> ZarrError {
    ZarrError::Metadata(reason.into())
}

/// The multiscale image that `attributes` describe (a group's `.zattrs`, or `zarr.json`'s
/// `attributes`, where version 0.5 nests everything under `ome`); `None` when they describe none.
pub(super) fn image(attributes: &Map<String, Value>) -> Result<Option<Image>, ZarrError> {
    let (root, version) = match attributes.get("ome") {
        Some(Value::Object(ome)) => (ome, ome.get("version").and_then(Value::as_str)),
        Some(_) => return Err(bad("'ome' is not an object")),
        None => (attributes, None),
    };
    let Some(multiscales) = root.get("multiscales") else {
        return Ok(None);
    };
    let first = match multiscales {
        Value::Array(list) => list
            .first()
            .ok_or_else(|| bad("'multiscales' is an empty list"))?,
        _ => return Err(bad("'multiscales' is not a list")),
    };
    let first = first
        .as_object()
        .ok_or_else(|| bad("'multiscales[0]' is not an object"))?;
    let version = version
        .or_else(|| first.get("version").and_then(Value::as_str))
        .map(str::to_string);
    let axes = first.get("axes").map(axes).transpose()?;
    let count = axes.as_ref().map(Vec::len);
    let global = match first.get("coordinateTransformations") {
        Some(t) => transformations(t, count, "the multiscale's coordinateTransformations")?,
        None => (None, None),
    };
    let datasets = match first.get("datasets") {
        Some(Value::Array(list)) if !list.is_empty() => list,
        Some(Value::Array(_)) => return Err(bad("'datasets' is an empty list")),
        Some(_) => return Err(bad("'datasets' is not a list")),
        None => return Err(bad("the multiscale has no 'datasets'")),
    };
    if datasets.len() > MAX_LEVELS {
        return Err(bad(format!(
            "{} datasets, more than the {MAX_LEVELS} LeapView reads",
            datasets.len()
        )));
    }
    let levels = datasets
        .iter()
        .enumerate()
        .map(|(i, d)| level(d, i, count, &global))
        .collect::<Result<Vec<_>, _>>()?;
    let windows = root
        .get("omero")
        .and_then(|o| o.get("channels"))
        .and_then(Value::as_array)
        .map(|channels| channels.iter().map(window).collect())
        .unwrap_or_default();
    Ok(Some(Image {
        version,
        name: first
            .get("name")
            .and_then(Value::as_str)
            .map(str::to_string),
        axes,
        levels,
        windows,
    }))
}

/// A channel's `window` (`start`, `end`), where both are finite and in order.
fn window(channel: &Value) -> Option<[f64; 2]> {
    let w = channel.get("window")?;
    let start = w.get("start")?.as_f64()?;
    let end = w.get("end")?.as_f64()?;
    (start.is_finite() && end.is_finite() && start < end).then_some([start, end])
}

/// The axes: objects with `name`, `type` and `unit` (0.4, 0.5) or plain names (0.3).
fn axes(value: &Value) -> Result<Vec<Axis>, ZarrError> {
    let list = value
        .as_array()
        .ok_or_else(|| bad("'axes' is not a list"))?;
    if list.is_empty() || list.len() > MAX_AXES {
        return Err(bad(format!(
            "{} axes; an image has 2 to {MAX_AXES}",
            list.len()
        )));
    }
    let axes = list
        .iter()
        .map(|a| match a {
            Value::String(name) => Ok(Axis {
                name: name.clone(),
                kind: kind_of(None, name),
                unit: None,
            }),
            Value::Object(o) => {
                let name = o
                    .get("name")
                    .and_then(Value::as_str)
                    .ok_or_else(|| bad("an axis has no 'name'"))?;
                Ok(Axis {
                    name: name.to_string(),
                    kind: kind_of(o.get("type").and_then(Value::as_str), name),
                    unit: o.get("unit").and_then(Value::as_str).map(str::to_string),
                })
            }
            _ => Err(bad("an axis is neither a name nor an object")),
        })
        .collect::<Result<Vec<_>, _>>()?;
    for (i, a) in axes.iter().enumerate() {
        if axes[..i].iter().any(|b| b.name == a.name) {
            return Err(bad(format!("axis '{}' is named twice", a.name)));
        }
    }
    Ok(axes)
}

/// An axis's kind from its `type`, or from its name where no type is given.
fn kind_of(kind: Option<&str>, name: &str) -> AxisKind {
    match kind {
        Some("space") => AxisKind::Space,
        Some("time") => AxisKind::Time,
        Some("channel") => AxisKind::Channel,
        Some(_) => AxisKind::Other,
        None => match name {
            "x" | "y" | "z" => AxisKind::Space,
            "t" => AxisKind::Time,
            "c" => AxisKind::Channel,
            _ => AxisKind::Other,
        },
    }
}

/// A dataset's path and transformations, the multiscale's own (`global`) applied after them.
fn level(
    dataset: &Value,
    index: usize,
    count: Option<usize>,
    global: &Transform,
) -> Result<Level, ZarrError> {
    let path = dataset
        .get("path")
        .and_then(Value::as_str)
        .ok_or_else(|| bad(format!("dataset {index} has no 'path'")))?;
    // A path leads into the group: no escape by `..`, no absolute path, no empty segment.
    let segments_ok = path
        .split('/')
        .all(|s| !s.is_empty() && s != "." && s != "..");
    if !segments_ok || path.contains('\\') {
        return Err(bad(format!(
            "dataset {index}'s path {path:?} does not name an array inside the group"
        )));
    }
    let (scale, translation) = match dataset.get("coordinateTransformations") {
        Some(t) => transformations(t, count, &format!("dataset {index}'s transformations"))?,
        None => (None, None),
    };
    let (global_scale, global_translation) = global;
    let len = scale
        .as_ref()
        .or(translation.as_ref())
        .or(global_scale.as_ref())
        .map(Vec::len);
    // Global after local: x' = g_s · (s · i + t) + g_t.
    let scale = match (scale, global_scale) {
        (Some(s), Some(g)) => Some(s.iter().zip(g).map(|(a, b)| a * b).collect()),
        (s, None) => s,
        (None, Some(g)) => Some(g.clone()),
    };
    let mut translation = translation.unwrap_or_else(|| vec![0.0; len.unwrap_or(0)]);
    if let Some(g) = global_scale {
        translation.iter_mut().zip(g).for_each(|(t, g)| *t *= g);
    }
    if let Some(g) = global_translation {
        if translation.is_empty() {
            translation = g.clone();
        } else {
            translation.iter_mut().zip(g).for_each(|(t, g)| *t += g);
        }
    }
    Ok(Level {
        path: path.to_string(),
        scale,
        translation,
    })
}

/// The scale and translation of a list of transformations (`identity` ones add nothing), each
/// with one value per axis (`count`, where the axes are known), scales positive and all finite.
fn transformations(
    value: &Value,
    count: Option<usize>,
    what: &str,
) -> Result<Transform, ZarrError> {
    let list = value
        .as_array()
        .ok_or_else(|| bad(format!("{what} is not a list")))?;
    let (mut scale, mut translation) = (None, None);
    for t in list {
        let kind = t
            .get("type")
            .and_then(Value::as_str)
            .ok_or_else(|| bad(format!("one of {what} has no 'type'")))?;
        let slot = match kind {
            "scale" => &mut scale,
            "translation" => &mut translation,
            "identity" => continue,
            other => {
                return Err(bad(format!(
                    "{what} holds a '{other}' transformation; LeapView reads scale and \
                     translation"
                )));
            }
        };
        if t.get("path").is_some() {
            return Err(bad(format!(
                "{what} keep their {kind} in a separate array, which LeapView does not read"
            )));
        }
        let values = t
            .get(kind)
            .and_then(Value::as_array)
            .ok_or_else(|| bad(format!("a {kind} of {what} has no list of values")))?
            .iter()
            .map(|v| v.as_f64().filter(|v| v.is_finite()))
            .collect::<Option<Vec<f64>>>()
            .ok_or_else(|| {
                bad(format!(
                    "a {kind} of {what} holds a value that is not a number"
                ))
            })?;
        if count.is_some_and(|n| n != values.len()) || values.is_empty() {
            return Err(bad(format!(
                "a {kind} of {what} has {} values for {} axes",
                values.len(),
                count.unwrap_or(0)
            )));
        }
        if kind == "scale" && values.iter().any(|&v| v <= 0.0) {
            return Err(bad(format!(
                "a scale of {what} is not positive: {values:?}"
            )));
        }
        if slot.replace(values).is_some() {
            return Err(bad(format!("{what} hold two of kind '{kind}'")));
        }
    }
    Ok((scale, translation))
}

/// What LeapView writes beside NGFF (`write.rs`, the `leapview` attribute) and reads back: the
/// facts NGFF has no field for. Each is taken only where it is well formed.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct LeapViewFacts {
    /// The patient orientation of the index axes.
    pub orientation: Option<crate::volume::orientation::Orientation>,
    /// The first voxel's centre (LPS, mm).
    pub origin_lps: Option<[f64; 3]>,
    /// Stored values to data units.
    pub mapping: Option<crate::volume::samples::ValueMapping>,
    /// The modality.
    pub modality: Option<crate::volume::modality::Modality>,
    /// The display window (data units).
    pub window: Option<[f64; 2]>,
    /// The whole volume's value range, histogram and count of non-finite samples.
    pub statistics: Option<Statistics>,
}

/// A volume's statistics as LeapView computed them when it wrote the store.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Statistics {
    /// The range of finite values (`None`: no value is finite).
    pub range: Option<crate::volume::stats::ValueRange>,
    /// The histogram over that range.
    pub histogram: crate::volume::stats::Histogram,
    /// NaN or infinite samples.
    pub non_finite: u64,
}

impl Statistics {
    /// The statistics of a `statistics` value, where well formed for `voxels` samples: the
    /// histogram's counts and the non-finite ones add up to them.
    fn of(value: &Value, voxels: u64) -> Option<Self> {
        use crate::volume::stats::{HISTOGRAM_BINS, Histogram, ValueRange};
        let range = match value.get("range")? {
            Value::Null => None,
            r => {
                let (min, max) = (r.get(0)?.as_f64()?, r.get(1)?.as_f64()?);
                (min.is_finite() && max.is_finite() && min <= max).then_some(())?;
                Some(ValueRange { min, max })
            }
        };
        let counts: Vec<u64> = (value.get("histogram")?.as_array()?.iter())
            .map(Value::as_u64)
            .collect::<Option<_>>()?;
        let non_finite = value.get("non_finite")?.as_u64()?;
        let total = counts
            .iter()
            .try_fold(non_finite, |a, &c| a.checked_add(c))?;
        (counts.len() == HISTOGRAM_BINS && total == voxels).then_some(())?;
        Some(Self {
            range,
            histogram: Histogram {
                range: range.unwrap_or(ValueRange { min: 0.0, max: 0.0 }),
                counts,
            },
            non_finite,
        })
    }
}

impl LeapViewFacts {
    /// The facts of a `leapview` attribute of an image of `voxels` samples (level 0).
    pub(super) fn of(value: &Value, voxels: u64) -> Self {
        use crate::volume::orientation::{Orientation, OrientationSource};
        let triple = |key: &str| -> Option<[f64; 3]> {
            let v: Vec<f64> = value
                .get(key)?
                .as_array()?
                .iter()
                .map(Value::as_f64)
                .collect::<Option<_>>()?;
            let t: [f64; 3] = v.try_into().ok()?;
            t.iter().all(|x| x.is_finite()).then_some(t)
        };
        let window = value.get("window").and_then(|w| {
            let lo = w.get(0)?.as_f64()?;
            let hi = w.get(1)?.as_f64()?;
            (lo.is_finite() && hi.is_finite() && lo < hi).then_some([lo, hi])
        });
        let mapping = value.get("value_mapping").and_then(|m| {
            let slope = m.get("slope")?.as_f64()?;
            let intercept = m.get("intercept")?.as_f64()?;
            (slope.is_finite() && slope != 0.0 && intercept.is_finite())
                .then_some(crate::volume::samples::ValueMapping { slope, intercept })
        });
        Self {
            orientation: value
                .get("orientation")
                .and_then(Value::as_str)
                .and_then(|c| Orientation::parse_code(c).ok())
                .map(|o| o.said_by(OrientationSource::Header)),
            origin_lps: triple("origin_lps"),
            mapping,
            modality: value
                .get("modality")
                .and_then(Value::as_str)
                .and_then(crate::volume::modality::Modality::parse),
            window,
            statistics: value
                .get("statistics")
                .and_then(|s| Statistics::of(s, voxels)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(json: &str) -> Result<Option<Image>, ZarrError> {
        let v: Value = serde_json::from_str(json).expect("test JSON");
        image(v.as_object().expect("object"))
    }

    const V04: &str = r#"{"multiscales": [{"version": "0.4", "name": "img",
        "axes": [{"name": "c", "type": "channel"}, {"name": "z", "type": "space", "unit": "micrometer"},
                 {"name": "y", "type": "space", "unit": "micrometer"}, {"name": "x", "type": "space", "unit": "micrometer"}],
        "datasets": [
          {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1, 2.0, 0.5, 0.5]}]},
          {"path": "1", "coordinateTransformations": [{"type": "scale", "scale": [1, 4.0, 1.0, 1.0]},
                                                      {"type": "translation", "translation": [0, 1.0, 0.25, 0.25]}]}],
        "coordinateTransformations": [{"type": "scale", "scale": [1, 2, 2, 2]}]}],
        "omero": {"channels": [{"window": {"start": 10, "end": 500}}, {"label": "no window"}]}}"#;

    #[test]
    fn version_0_4_gives_axes_levels_and_the_multiscale_scale_after_each_dataset() {
        let image = parse(V04).expect("valid").expect("an image");
        assert_eq!(image.version.as_deref(), Some("0.4"));
        assert_eq!(image.name.as_deref(), Some("img"));
        let axes = image.axes.expect("axes");
        assert_eq!(
            axes.iter().map(|a| a.kind).collect::<Vec<_>>(),
            [
                AxisKind::Channel,
                AxisKind::Space,
                AxisKind::Space,
                AxisKind::Space
            ]
        );
        assert_eq!(axes[1].unit.as_deref(), Some("micrometer"));
        assert_eq!(image.levels[0].path, "0");
        assert_eq!(image.levels[0].scale, Some(vec![1.0, 4.0, 1.0, 1.0]));
        assert_eq!(image.levels[0].translation, vec![0.0; 4]);
        assert_eq!(image.levels[1].scale, Some(vec![1.0, 8.0, 2.0, 2.0]));
        assert_eq!(image.levels[1].translation, vec![0.0, 2.0, 0.5, 0.5]);
        assert_eq!(image.windows, vec![Some([10.0, 500.0]), None]);
    }

    #[test]
    fn version_0_5_nests_under_ome_and_0_3_names_axes_only() {
        let v05 = format!(
            r#"{{"ome": {{"version": "0.5", {}}}}}"#,
            &V04[1..V04.len() - 1]
        );
        let image = parse(&v05).expect("valid").expect("an image");
        assert_eq!(image.version.as_deref(), Some("0.5"));
        assert_eq!(image.levels.len(), 2);
        let v03 = r#"{"multiscales": [{"version": "0.3", "axes": ["z", "y", "x"],
            "datasets": [{"path": "0"}, {"path": "1"}]}]}"#;
        let image = parse(v03).expect("valid").expect("an image");
        let axes = image.axes.expect("axes");
        assert!(axes.iter().all(|a| a.kind == AxisKind::Space));
        assert_eq!(image.levels[1].scale, None);
        assert!(parse(r#"{"other": 1}"#).expect("valid").is_none());
    }

    #[test]
    fn hostile_or_broken_metadata_is_refused_with_its_reason() {
        let cases = [
            (r#"{"multiscales": {}}"#, "not a list"),
            (r#"{"multiscales": []}"#, "empty list"),
            (r#"{"multiscales": [{"datasets": []}]}"#, "empty list"),
            (
                r#"{"multiscales": [{"datasets": [{"path": "../../etc"}]}]}"#,
                "inside the group",
            ),
            (
                r#"{"multiscales": [{"datasets": [{"path": "/abs"}]}]}"#,
                "inside the group",
            ),
            (
                r#"{"multiscales": [{"axes": ["z", "y", "x"], "datasets": [{"path": "0",
                "coordinateTransformations": [{"type": "scale", "scale": [1, 1]}]}]}]}"#,
                "2 values for 3 axes",
            ),
            (
                r#"{"multiscales": [{"datasets": [{"path": "0",
                "coordinateTransformations": [{"type": "scale", "scale": [1, 0, 1]}]}]}]}"#,
                "not positive",
            ),
            (
                r#"{"multiscales": [{"datasets": [{"path": "0",
                "coordinateTransformations": [{"type": "scale", "scale": [1, "a", 1]}]}]}]}"#,
                "not a number",
            ),
            (
                r#"{"multiscales": [{"datasets": [{"path": "0",
                "coordinateTransformations": [{"type": "affine", "affine": []}]}]}]}"#,
                "'affine'",
            ),
            (
                r#"{"multiscales": [{"axes": ["x", "x", "y"], "datasets": [{"path": "0"}]}]}"#,
                "named twice",
            ),
            (
                r#"{"multiscales": [{"axes": ["a","b","c","d","e","f"], "datasets": [{"path": "0"}]}]}"#,
                "6 axes",
            ),
        ];
        for (json, said) in cases {
            let e = parse(json).expect_err(json).to_string();
            assert!(e.contains(said), "{json}: {e}");
        }
        let many = format!(
            r#"{{"multiscales": [{{"datasets": [{}]}}]}}"#,
            vec![r#"{"path": "0"}"#; 65].join(",")
        );
        assert!(parse(&many).expect_err("65").to_string().contains("65"));
    }
}
