//! What a TIFF's ImageDescription says of the stack, as microscopy software writes it: OME-XML
//! (OME-TIFF: the `Pixels` element's sizes, plane order and physical sizes) or ImageJ's
//! `key=value` lines (hyperstack sizes, slice spacing and unit). Pure, bounded text parsing.

use crate::volume::units::millimetres_per;

/// The stack's layout and voxel size as a description gives them.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Layout {
    /// Planes along z, channels and time points (1 where not said).
    pub z: u32,
    /// Channels.
    pub c: u32,
    /// Time points.
    pub t: u32,
    /// Which of z, c, t varies fastest after the plane, then next: e.g. `[Z, C, T]` for OME's
    /// `XYZCT`, `[C, Z, T]` for ImageJ.
    pub order: [Dim; 3],
    /// Millimetres per pixel along x and y, and between slices, where said.
    pub spacing_mm: [Option<f64>; 3],
    /// Which software's description it is.
    pub kind: &'static str,
}

/// An axis of planes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Dim {
    /// Slices.
    Z,
    /// Channels.
    C,
    /// Time points.
    T,
}

impl Layout {
    /// The page holding slice `z` of channel `c` at time point `t`.
    pub(super) fn page(&self, z: u32, c: u32, t: u32) -> u64 {
        let (mut page, mut stride) = (0u64, 1u64);
        for d in self.order {
            let (i, n) = match d {
                Dim::Z => (z, self.z),
                Dim::C => (c, self.c),
                Dim::T => (t, self.t),
            };
            page += u64::from(i) * stride;
            stride *= u64::from(n);
        }
        page
    }
}

/// The layout a description gives, `None` when it is neither OME-XML nor ImageJ's.
pub(super) fn layout(text: &str) -> Option<Layout> {
    let text = text.trim_start_matches('\u{feff}').trim();
    if text.starts_with('<') && text.contains("Pixels") {
        ome(text)
    } else if text.starts_with("ImageJ=") {
        Some(imagej(text))
    } else {
        None
    }
}

/// The attributes of the first `Pixels` element (any namespace prefix).
fn pixels_attributes(xml: &str) -> Option<Vec<(&str, &str)>> {
    let start = xml
        .match_indices("Pixels")
        .map(|(i, _)| i)
        .find(|&i| xml[..i].ends_with('<') || xml[..i].ends_with(':'))?;
    let rest = &xml[start + "Pixels".len()..];
    let end = rest.find('>')?;
    let mut attrs = Vec::new();
    let mut s = &rest[..end];
    while let Some(eq) = s.find('=') {
        let name = s[..eq].trim();
        let after = s[eq + 1..].trim_start();
        let quote = after.chars().next()?;
        if quote != '"' && quote != '\'' {
            return None;
        }
        let close = after[1..].find(quote)? + 1;
        attrs.push((name, &after[1..close]));
        s = &after[close + 1..];
    }
    Some(attrs)
}

fn ome(xml: &str) -> Option<Layout> {
    let attrs = pixels_attributes(xml)?;
    let get = |key: &str| attrs.iter().find(|(k, _)| *k == key).map(|(_, v)| *v);
    let size = |key: &str| {
        get(key)
            .and_then(|v| v.trim().parse::<u32>().ok())
            .filter(|&n| n > 0)
    };
    let order = match get("DimensionOrder").unwrap_or("XYZCT") {
        "XYZCT" => [Dim::Z, Dim::C, Dim::T],
        "XYZTC" => [Dim::Z, Dim::T, Dim::C],
        "XYCZT" => [Dim::C, Dim::Z, Dim::T],
        "XYCTZ" => [Dim::C, Dim::T, Dim::Z],
        "XYTCZ" => [Dim::T, Dim::C, Dim::Z],
        "XYTZC" => [Dim::T, Dim::Z, Dim::C],
        _ => return None,
    };
    // OME's default unit is the micrometre.
    let physical = |axis: &str| {
        let value: f64 = get(&format!("PhysicalSize{axis}"))?.trim().parse().ok()?;
        let unit = get(&format!("PhysicalSize{axis}Unit")).unwrap_or("µm");
        let mm = value * millimetres_per(unit)?;
        (mm.is_finite() && mm > 0.0).then_some(mm)
    };
    Some(Layout {
        z: size("SizeZ").unwrap_or(1),
        c: size("SizeC").unwrap_or(1),
        t: size("SizeT").unwrap_or(1),
        order,
        spacing_mm: [physical("X"), physical("Y"), physical("Z")],
        kind: "OME-XML",
    })
}

fn imagej(text: &str) -> Layout {
    let get = |key: &str| {
        text.lines()
            .filter_map(|l| l.split_once('='))
            .find(|(k, _)| k.trim() == key)
            .map(|(_, v)| v.trim())
    };
    let count = |key: &str| {
        get(key)
            .and_then(|v| v.parse::<u32>().ok())
            .filter(|&n| n > 0)
    };
    let (c, t) = (count("channels").unwrap_or(1), count("frames").unwrap_or(1));
    let z = count("slices")
        .unwrap_or_else(|| count("images").map_or(1, |n| (n / c.saturating_mul(t).max(1)).max(1)));
    let unit = get("unit").and_then(millimetres_per);
    let z_spacing = get("spacing")
        .and_then(|v| v.parse::<f64>().ok())
        .zip(unit)
        .map(|(s, u)| s * u)
        .filter(|s| s.is_finite() && *s > 0.0);
    Layout {
        z,
        c,
        t,
        order: [Dim::C, Dim::Z, Dim::T],
        // x and y come from the resolution tags, in the same unit.
        spacing_mm: [None, None, z_spacing],
        kind: "ImageJ",
    }
}

/// Millimetres per unit of ImageJ's `unit=` line, for the resolution tags.
pub(super) fn imagej_unit_mm(text: &str) -> Option<f64> {
    text.lines()
        .filter_map(|l| l.split_once('='))
        .find(|(k, _)| k.trim() == "unit")
        .and_then(|(_, v)| millimetres_per(v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ome_xml_gives_sizes_order_and_physical_sizes() {
        let xml = r#"<?xml version="1.0" encoding="UTF-8"?><OME xmlns="http://www.openmicroscopy.org/Schemas/OME/2016-06"><Image ID="Image:0"><Pixels DimensionOrder="XYCZT" ID="Pixels:0" SizeC="2" SizeT="3" SizeX="4" SizeY="5" SizeZ="6" Type="uint16" PhysicalSizeX="0.5" PhysicalSizeY="0.5" PhysicalSizeZ="2.0" PhysicalSizeZUnit="mm"><Channel ID="Channel:0:0"/></Pixels></Image></OME>"#;
        let l = layout(xml).expect("OME");
        assert_eq!((l.z, l.c, l.t), (6, 2, 3));
        assert_eq!(l.order, [Dim::C, Dim::Z, Dim::T]);
        assert_eq!(l.spacing_mm, [Some(0.0005), Some(0.0005), Some(2.0)]);
        // Slice 4 of channel 1 at time 2: c + 2 (z + 6 t).
        assert_eq!(l.page(4, 1, 2), 1 + 2 * (4 + 6 * 2));
    }

    #[test]
    fn imagej_lines_give_the_hyperstack_and_slice_spacing() {
        let text = "ImageJ=1.11a\nimages=24\nchannels=2\nslices=12\nhyperstack=true\nmode=grayscale\nunit=micron\nspacing=2.5\nloop=false\n";
        let l = layout(text).expect("ImageJ");
        assert_eq!((l.z, l.c, l.t), (12, 2, 1));
        assert_eq!(l.spacing_mm[2], Some(0.0025));
        assert_eq!(imagej_unit_mm(text), Some(1e-3));
        assert_eq!(l.page(3, 1, 0), 1 + 2 * 3);
        let plain = layout("ImageJ=1.53t\nimages=7\n").expect("ImageJ");
        assert_eq!((plain.z, plain.c, plain.t), (7, 1, 1));
    }

    #[test]
    fn other_or_broken_descriptions_give_nothing() {
        assert_eq!(layout("a scanner's comment"), None);
        assert_eq!(layout("<Pixels SizeZ=3"), None);
        assert_eq!(layout(r#"<Pixels DimensionOrder="ZZZ" SizeZ="3">"#), None);
        let l = layout(r#"<Pixels SizeZ="-3" SizeC="x" PhysicalSizeX="0">"#).expect("defaults");
        assert_eq!((l.z, l.c, l.spacing_mm[0]), (1, 1, None));
    }
}
