//! NRRD names of sample types and encodings: every spelling the format allows for the types
//! LeapView stores, and the encodings it decodes.

use crate::volume::decode::Encoding;
use crate::volume::error::VolumeError;
use crate::volume::samples::ScalarType;

/// Every NRRD spelling of the types LeapView stores.
pub(crate) fn parse_type(name: &str) -> Result<ScalarType, VolumeError> {
    let t = match name.trim().to_ascii_lowercase().as_str() {
        "uchar" | "unsigned char" | "uint8" | "uint8_t" => ScalarType::U8,
        // Teem reads a plain "char" as signed.
        "char" | "signed char" | "int8" | "int8_t" => ScalarType::I8,
        "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" => {
            ScalarType::U16
        }
        "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t" => {
            ScalarType::I16
        }
        "uint" | "unsigned int" | "uint32" | "uint32_t" => ScalarType::U32,
        "int" | "signed int" | "int32" | "int32_t" => ScalarType::I32,
        "float" => ScalarType::F32,
        "double" => ScalarType::F64,
        _ => {
            return Err(VolumeError::UnsupportedType {
                name: name.to_string(),
            });
        }
    };
    Ok(t)
}

/// `raw`, or `gzip`/`gz`; anything else (text, hex, bzip2, …) is refused.
pub(crate) fn parse_encoding(name: &str) -> Result<Encoding, VolumeError> {
    match name.to_ascii_lowercase().as_str() {
        "raw" => Ok(Encoding::Raw),
        "gzip" | "gz" => Ok(Encoding::Gzip),
        _ => Err(VolumeError::UnsupportedEncoding {
            name: name.to_string(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_spelling_of_every_type_is_known() {
        let spellings = [
            ("uchar", ScalarType::U8),
            ("unsigned char", ScalarType::U8),
            ("uint8", ScalarType::U8),
            ("uint8_t", ScalarType::U8),
            ("UINT8", ScalarType::U8),
            ("char", ScalarType::I8),
            ("signed char", ScalarType::I8),
            ("int8", ScalarType::I8),
            ("int8_t", ScalarType::I8),
            ("ushort", ScalarType::U16),
            ("unsigned short", ScalarType::U16),
            ("Unsigned Short Int", ScalarType::U16),
            ("uint16", ScalarType::U16),
            ("uint16_t", ScalarType::U16),
            ("short", ScalarType::I16),
            ("short int", ScalarType::I16),
            ("signed short", ScalarType::I16),
            ("signed short int", ScalarType::I16),
            ("int16", ScalarType::I16),
            ("int16_t", ScalarType::I16),
            ("uint", ScalarType::U32),
            ("unsigned int", ScalarType::U32),
            ("uint32", ScalarType::U32),
            ("uint32_t", ScalarType::U32),
            ("int", ScalarType::I32),
            ("signed int", ScalarType::I32),
            ("int32", ScalarType::I32),
            ("int32_t", ScalarType::I32),
            ("float", ScalarType::F32),
            ("double", ScalarType::F64),
        ];
        for (name, t) in spellings {
            assert_eq!(parse_type(name).ok(), Some(t), "{name}");
        }
        for name in [
            "int64",
            "uint64",
            "long long",
            "unsigned long long",
            "block",
            "foo",
        ] {
            assert!(matches!(
                parse_type(name),
                Err(VolumeError::UnsupportedType { .. })
            ));
        }
    }

    #[test]
    fn raw_and_gzip_are_the_encodings() {
        assert_eq!(parse_encoding("raw").ok(), Some(Encoding::Raw));
        assert_eq!(parse_encoding("GZIP").ok(), Some(Encoding::Gzip));
        assert_eq!(parse_encoding("gz").ok(), Some(Encoding::Gzip));
        for name in ["txt", "text", "ascii", "hex", "bz2", "bzip2", "zrl"] {
            let r = parse_encoding(name);
            assert!(
                matches!(r, Err(VolumeError::UnsupportedEncoding { .. })),
                "{name}"
            );
        }
    }
}
