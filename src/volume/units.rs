//! Length units as files name them: NGFF's unit names (OME-Zarr axes, OME-XML) and the spellings
//! microscopy software writes (ImageJ's `micron`, `um`, an escaped `\u00B5m`), in millimetres.

/// Millimetres per unit of a space axis named as NGFF names units (`micrometer`), or as
/// microscopy software writes them (`µm`, `um`, `micron`); `None` for a unit that is not a length.
pub(crate) fn millimetres_per(unit: &str) -> Option<f64> {
    Some(match unit.trim() {
        "angstrom" | "Å" => 1e-7,
        "attometer" => 1e-15,
        "centimeter" | "cm" => 10.0,
        "decimeter" | "dm" => 100.0,
        "exameter" => 1e21,
        "femtometer" | "fm" => 1e-12,
        "foot" => 304.8,
        "gigameter" => 1e12,
        "hectometer" => 1e5,
        "inch" => 25.4,
        "kilometer" | "km" => 1e6,
        "megameter" => 1e9,
        "meter" | "m" => 1e3,
        "micrometer" | "micrometre" | "µm" | "μm" | "um" | "micron" | "microns" | "\\u00B5m" => {
            1e-3
        }
        "mile" => 1_609_344.0,
        "millimeter" | "millimetre" | "mm" => 1.0,
        "nanometer" | "nanometre" | "nm" => 1e-6,
        "parsec" => 3.085_677_581_491_367e19,
        "petameter" => 1e18,
        "picometer" | "pm" => 1e-9,
        "terameter" => 1e15,
        "yard" => 914.4,
        "yoctometer" => 1e-21,
        "yottameter" => 1e27,
        "zeptometer" => 1e-18,
        "zettameter" => 1e24,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_convert_to_millimetres() {
        assert_eq!(millimetres_per("micrometer"), Some(1e-3));
        assert_eq!(millimetres_per("µm"), Some(1e-3));
        assert_eq!(millimetres_per("micron"), Some(1e-3));
        assert_eq!(millimetres_per(" millimeter "), Some(1.0));
        assert_eq!(millimetres_per("meter"), Some(1000.0));
        assert_eq!(millimetres_per("second"), None);
    }
}
