//! Segments as files describe them: Slicer's `.seg.nrrd` fields (`SegmentN_Name`, `_Color`,
//! `_LabelValue`, `_Layer`), an ITK-SNAP label description file
//! (`IDX R G B A VIS MSH "LABEL"`) and a Slicer colour table (`VALUE NAME R G B A`).

use std::collections::HashMap;

/// A segment as a file describes it.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Described {
    /// Its label value.
    pub value: u16,
    /// Its layer (0 but in a layered `.seg.nrrd`).
    pub layer: u16,
    /// Its name.
    pub name: String,
    /// Its colour, where given.
    pub colour: Option<[u8; 3]>,
}

/// Most segments a description may hold: one per label value.
const MOST_SEGMENTS: usize = 65_535;

/// The segments of a `.seg.nrrd`'s fields (`key_values`, its `:=` lines); none where the file
/// has no `Segment0_…` field (a plain NRRD).
pub(super) fn of_seg_nrrd(key_values: &HashMap<String, String>) -> Result<Vec<Described>, String> {
    let mut segments = Vec::new();
    for n in 0..MOST_SEGMENTS {
        let field = |name: &str| {
            key_values
                .get(&format!("Segment{n}_{name}"))
                .map(|v| v.trim())
        };
        if field("ID").is_none() && field("Name").is_none() && field("LabelValue").is_none() {
            break;
        }
        let number = |name: &str, default: u16| -> Result<u16, String> {
            field(name).map_or(Ok(default), |v| {
                v.parse::<u16>().map_err(|_| {
                    format!("Segment{n}_{name} is '{v}', not a whole number 0 … 65535")
                })
            })
        };
        // Slicer before 4.11 wrote no label value: segment N held N + 1.
        let value = number("LabelValue", u16::try_from(n + 1).unwrap_or(u16::MAX))?;
        if value == 0 {
            return Err(format!("Segment{n}_LabelValue is 0, which is no label"));
        }
        let colour =
            match field("Color") {
                None => None,
                Some(text) => Some(unit_rgb(text).ok_or_else(|| {
                    format!("Segment{n}_Color is '{text}', not three numbers 0 … 1")
                })?),
            };
        segments.push(Described {
            value,
            layer: number("Layer", 0)?,
            name: field("Name")
                .or_else(|| field("ID"))
                .map_or_else(|| format!("Segment {n}"), str::to_string),
            colour,
        });
    }
    Ok(segments)
}

/// Three numbers 0…1 as sRGB bytes.
fn unit_rgb(text: &str) -> Option<[u8; 3]> {
    let parts: Vec<f64> = text
        .split_whitespace()
        .map(str::parse)
        .collect::<Result<_, _>>()
        .ok()?;
    match parts[..] {
        [r, g, b] if [r, g, b].iter().all(|c| (0.0..=1.0).contains(c)) => {
            Some([r, g, b].map(|c| (c * 255.0).round() as u8))
        }
        _ => None,
    }
}

/// The segments of an ITK-SNAP label description file or a Slicer colour table (told apart
/// line by line: ITK-SNAP's names are quoted); label 0 ("Clear Label", "Background") is left
/// out. The reason, with the line, where a line is neither.
pub(super) fn of_table(text: &str) -> Result<Vec<Described>, String> {
    let mut segments = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let described = if let Some((numbers, quoted)) = line.split_once('"') {
            itk_snap(numbers, quoted)
        } else {
            colour_table(line)
        }
        .ok_or_else(|| {
            format!(
                "line {}: '{line}' is neither an ITK-SNAP label (IDX R G B A VIS MSH \"NAME\") \
                 nor a colour-table entry (VALUE NAME R G B A)",
                number + 1
            )
        })?;
        if described.value != 0 {
            segments.push(described);
        }
        if segments.len() > MOST_SEGMENTS {
            return Err(format!("more than {MOST_SEGMENTS} labels"));
        }
    }
    Ok(segments)
}

/// An ITK-SNAP line: `numbers` before the name's opening quote, `quoted` after it.
fn itk_snap(numbers: &str, quoted: &str) -> Option<Described> {
    let fields: Vec<&str> = numbers.split_whitespace().collect();
    // IDX R G B A VIS MSH: the colour 0…255, the alpha 0…1.
    let [value, r, g, b, _alpha, _visible, _mesh] = fields[..] else {
        return None;
    };
    let name = quoted
        .strip_suffix('"')
        .or_else(|| quoted.split('"').next())?;
    Some(Described {
        value: value.parse().ok()?,
        layer: 0,
        name: name.to_string(),
        colour: Some(bytes(r, g, b)?),
    })
}

/// A colour-table line: `VALUE NAME R G B [A]`, the colour 0…255.
fn colour_table(line: &str) -> Option<Described> {
    let fields: Vec<&str> = line.split_whitespace().collect();
    let (value, name, r, g, b) = match fields[..] {
        [value, name, r, g, b] | [value, name, r, g, b, _] => (value, name, r, g, b),
        _ => return None,
    };
    Some(Described {
        value: value.parse().ok()?,
        layer: 0,
        name: name.to_string(),
        colour: Some(bytes(r, g, b)?),
    })
}

/// Three numbers 0…255.
fn bytes(r: &str, g: &str, b: &str) -> Option<[u8; 3]> {
    Some([r.parse().ok()?, g.parse().ok()?, b.parse().ok()?])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seg_nrrd_fields_give_names_colours_values_and_layers() {
        let fields: HashMap<String, String> = [
            ("Segment0_ID", "Segment_1"),
            ("Segment0_Name", "soft tissue"),
            ("Segment0_Color", "0.89 0.73 0.62"),
            ("Segment0_LabelValue", "1"),
            ("Segment0_Layer", "0"),
            ("Segment1_ID", "Segment_7"),
            ("Segment1_LabelValue", "7"),
            ("Segment1_Layer", "1"),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
        let s = of_seg_nrrd(&fields).expect("read");
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].name, "soft tissue");
        assert_eq!(s[0].colour, Some([227, 186, 158]));
        assert_eq!((s[1].value, s[1].layer, s[1].colour), (7, 1, None));
        assert_eq!(s[1].name, "Segment_7");
        let mut bad = fields.clone();
        bad.insert("Segment1_LabelValue".into(), "70000".into());
        assert!(of_seg_nrrd(&bad).expect_err("too large").contains("70000"));
        bad.insert("Segment1_LabelValue".into(), "3".into());
        bad.insert("Segment1_Color".into(), "1 2 3".into());
        assert!(of_seg_nrrd(&bad).expect_err("colour").contains("Color"));
        assert!(of_seg_nrrd(&HashMap::new()).expect("none").is_empty());
    }

    #[test]
    fn itk_snap_and_colour_tables_are_read_line_by_line() {
        let snap = "# ITK-SnAP Label Description File\n\
                    0 0 0 0 0 0 0 \"Clear Label\"\n\
                    1 84 130 242 1 1 1 \"parcel 1\"\n\
                    12 1 2 3 0.5 0 1 \"a \\\"quoted\\\" name\"\n";
        let s = of_table(snap).expect("read");
        assert_eq!(s.len(), 2);
        assert_eq!((s[0].value, s[0].name.as_str()), (1, "parcel 1"));
        assert_eq!(s[0].colour, Some([84, 130, 242]));
        assert_eq!(s[1].value, 12);
        let slicer = "# Color table file\n0 Background 0 0 0 0\n3 liver 221 130 101 255\n";
        let s = of_table(slicer).expect("read");
        assert_eq!(s.len(), 1);
        assert_eq!((s[0].value, s[0].name.as_str()), (3, "liver"));
        let e = of_table("1 2 3\n").expect_err("neither");
        assert!(e.starts_with("line 1:"), "{e}");
        assert!(of_table("70000 x 1 2 3 255\n").is_err());
    }
}
