//! Which texture format holds a volume and how its stored values become texels.
//!
//! The shader works on normalised values `s` in `[0, 1]` over the volume's normalisation range
//! (data units). Integer volumes keep their exact stored values in unorm texels (`s` is then an
//! affine function of the texel, `s = texel * scale + bias`); float formats hold `s` directly.
//! Non-finite samples become [`MISSING`], far below 0, so that any interpolation touching one
//! stays negative and the shader renders it transparent (hardware filter weights are multiples
//! of 1/256, so a non-zero weight on `MISSING` gives at most −65504/256 + 1 < 0).

use crate::settings::TexturePrecision;
use crate::volume::colour::Colour;
use crate::volume::downsample::Level;
use crate::volume::{Samples, ScalarType, ValueMapping, ValueRange, Volume};

/// Texel value of a NaN or infinite sample (the most negative finite f16).
pub const MISSING: f32 = -65504.0;

/// Normalised values below this come from interpolation touching a [`MISSING`] texel: the shaders
/// treat such samples as missing (transparent) and the pyramid build leaves them out. Any
/// non-zero hardware filter weight on `MISSING` (at least 1/256) gives at most −65504/256 + 1,
/// far below it; finite values are at least 0.
pub const MISSING_BELOW: f32 = -0.5;

/// How a volume is laid out in its texture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexelEncoding {
    /// The texture format.
    pub format: wgpu::TextureFormat,
    /// `s = texel * scale + bias`, with `s` the normalised value.
    pub scale: f32,
    /// See `scale`.
    pub bias: f32,
    /// A precision warning to log, when the format loses information.
    pub warning: Option<&'static str>,
}

/// The format `precision` forces, `None` for `Auto`.
pub(crate) fn forced_format(precision: TexturePrecision) -> Option<wgpu::TextureFormat> {
    match precision {
        TexturePrecision::Auto => None,
        TexturePrecision::Unorm8 => Some(wgpu::TextureFormat::R8Unorm),
        TexturePrecision::Unorm16 => Some(wgpu::TextureFormat::R16Unorm),
        TexturePrecision::Float32 => Some(wgpu::TextureFormat::R32Float),
    }
}

/// Formats to try for a scalar type, best first.
pub(super) fn candidates(
    scalar: ScalarType,
    has_non_finite: bool,
) -> &'static [wgpu::TextureFormat] {
    use wgpu::TextureFormat::{R8Unorm, R16Float, R16Unorm, R32Float};
    match scalar {
        ScalarType::U8 | ScalarType::I8 => &[R8Unorm],
        ScalarType::U16 | ScalarType::I16 => &[R16Unorm, R32Float, R16Float],
        ScalarType::U32 | ScalarType::I32 => &[R32Float, R16Unorm, R16Float],
        // Only a signed float format can hold the MISSING marker.
        ScalarType::F32 | ScalarType::F64 if has_non_finite => &[R32Float, R16Float],
        ScalarType::F32 | ScalarType::F64 => &[R32Float, R16Unorm, R16Float],
    }
}

/// Picks the format and encoding for `volume` given which formats the adapter can filter.
pub(super) fn choose_encoding(
    volume: &Volume,
    filterable: impl Fn(wgpu::TextureFormat) -> bool,
) -> TexelEncoding {
    if volume.colour().is_some() {
        // Luminance in red, the colour in green, blue and alpha: one filtered fetch gives both.
        return encoding_for(volume, wgpu::TextureFormat::Rgba8Unorm);
    }
    let scalar = volume.scalar_type();
    let options = candidates(scalar, volume.may_be_non_finite());
    // R16Float is filterable everywhere (WebGPU core), so the last candidate always works.
    let format = options
        .iter()
        .copied()
        .find(|&f| filterable(f))
        .unwrap_or(wgpu::TextureFormat::R16Float);
    encoding_for(volume, format)
}

/// The encoding of `volume` in `format`: exact integers where the format is the scalar type's
/// natural unorm, else the normalised value (quantised in a unorm format).
pub(super) fn encoding_for(volume: &Volume, format: wgpu::TextureFormat) -> TexelEncoding {
    let scalar = volume.scalar_type();
    let range = volume.normalization_range();
    let mapping = volume.mapping();
    let w = range.width();
    let (scale, bias) = match (format, integer_offset(scalar)) {
        (
            wgpu::TextureFormat::R8Unorm
            | wgpu::TextureFormat::Rgba8Unorm
            | wgpu::TextureFormat::R16Unorm,
            Some((offset, max)),
        ) if max as f64 == unorm_max(format) => {
            // texel = (stored + offset) / max  ⇒  stored = texel * max − offset.
            let m = unorm_max(format);
            let scale = m * mapping.slope / w;
            let bias = (mapping.apply(-offset) - range.min) / w;
            (scale, bias)
        }
        // Float formats and quantised unorm hold s itself.
        _ => (1.0, 0.0),
    };
    let warning = match format {
        wgpu::TextureFormat::R16Float => Some(
            "this adapter cannot filter 16-bit normalised or 32-bit float textures; the volume is \
             stored as 16-bit float (about 3 significant digits)",
        ),
        wgpu::TextureFormat::R16Unorm if scalar.size_bytes() > 2 => {
            Some("32-bit values are quantised to 65536 levels over the value range")
        }
        wgpu::TextureFormat::R8Unorm if scalar.size_bytes() > 1 => {
            Some("values are quantised to 256 levels over the value range")
        }
        _ => None,
    };
    TexelEncoding {
        format,
        scale: scale as f32,
        bias: bias as f32,
        warning,
    }
}

/// How a texel of `volume` in `format` becomes a value in data units, as exactly as the format
/// allows: `value = u × scale + bias` with `u = round(texel × max)` for unorm formats (their
/// texels are integers `u / max`; for 8- and 16-bit integer volumes `u` is the stored value
/// plus an offset, so the value is exact) and `u = texel` for float formats (`max` = 0).
pub fn texel_units(volume: &Volume, format: wgpu::TextureFormat) -> (f64, f64, f64) {
    let range = volume.normalization_range();
    let mapping = volume.mapping();
    match (format, integer_offset(volume.scalar_type())) {
        (
            wgpu::TextureFormat::R8Unorm
            | wgpu::TextureFormat::Rgba8Unorm
            | wgpu::TextureFormat::R16Unorm,
            Some((offset, max)),
        ) if max as f64 == unorm_max(format) => {
            (unorm_max(format), mapping.slope, mapping.apply(-offset))
        }
        // Quantised: the texel holds the normalised value.
        (
            wgpu::TextureFormat::R8Unorm
            | wgpu::TextureFormat::Rgba8Unorm
            | wgpu::TextureFormat::R16Unorm,
            _,
        ) => {
            let max = unorm_max(format);
            (max, range.width() / max, range.min)
        }
        _ => (0.0, range.width(), range.min),
    }
}

/// For 8- and 16-bit integers: the offset that makes stored values non-negative and the largest
/// texel integer of their natural unorm format.
fn integer_offset(scalar: ScalarType) -> Option<(f64, u32)> {
    match scalar {
        ScalarType::U8 => Some((0.0, 255)),
        ScalarType::I8 => Some((128.0, 255)),
        ScalarType::U16 => Some((0.0, 65535)),
        ScalarType::I16 => Some((32768.0, 65535)),
        _ => None,
    }
}

fn unorm_max(format: wgpu::TextureFormat) -> f64 {
    match format {
        wgpu::TextureFormat::R8Unorm | wgpu::TextureFormat::Rgba8Unorm => 255.0,
        _ => 65535.0,
    }
}

/// Bytes per texel of the volume formats.
pub(crate) fn bytes_per_texel(format: wgpu::TextureFormat) -> usize {
    match format {
        wgpu::TextureFormat::R8Unorm => 1,
        wgpu::TextureFormat::R16Unorm | wgpu::TextureFormat::R16Float => 2,
        // R32Float, and a colour volume's Rgba8Unorm.
        _ => 4,
    }
}

/// Samples to encode as texels: a volume's own, or a coarser level of it, decoded with the
/// volume's mapping and normalisation range (every level shares its encoding).
#[derive(Clone, Copy)]
pub(super) struct TexelSource<'a> {
    samples: &'a Samples,
    colour: Option<&'a Colour>,
    mapping: ValueMapping,
    norm: ValueRange,
}

impl<'a> TexelSource<'a> {
    /// `volume`'s samples held in memory (a streamed volume's: its preview; its bricks are
    /// encoded [`Self::with_samples`] read from its store).
    pub(super) fn of(volume: &'a Volume) -> Self {
        Self {
            samples: volume.held().0,
            colour: volume.colour(),
            mapping: volume.mapping(),
            norm: volume.normalization_range(),
        }
    }

    /// `samples` (a box of a level read from the store), encoded as these are.
    pub(super) fn with_samples(self, samples: &'a Samples) -> Self {
        Self { samples, ..self }
    }

    /// `level`'s samples, encoded as `volume`'s are.
    pub(super) fn level(volume: &'a Volume, level: &'a Level) -> Self {
        Self {
            samples: &level.samples,
            colour: level.colour.as_ref(),
            ..Self::of(volume)
        }
    }
}

/// Appends the texels of samples `range` of `source` in `encoding` to `out` (little-endian).
pub(super) fn encode_texels(
    source: &TexelSource<'_>,
    encoding: &TexelEncoding,
    range: std::ops::Range<usize>,
    out: &mut Vec<u8>,
) {
    use wgpu::TextureFormat as F;
    let norm = source.norm;
    let mapping = source.mapping;
    let normalized = |stored: f64| -> f32 {
        let v = mapping.apply(stored);
        if v.is_finite() {
            norm.normalize(v) as f32
        } else {
            MISSING
        }
    };
    let exact = encoding.scale != 1.0
        || encoding.bias != 0.0
        || matches!(source.samples.scalar_type(), ScalarType::U8);
    match (encoding.format, source.samples, source.colour) {
        (F::Rgba8Unorm, Samples::U8(v), Some(colour)) => range.for_each(|i| {
            let [r, g, b] = colour.rgb8(i);
            out.extend_from_slice(&[v[i], r, g, b]);
        }),
        (F::R8Unorm, Samples::U8(v), _) => out.extend_from_slice(&v[range]),
        (F::R8Unorm, Samples::I8(v), _) => {
            out.extend(v[range].iter().map(|&x| (x as i16 + 128) as u8))
        }
        (F::R16Unorm, Samples::U16(v), _) if exact => v[range]
            .iter()
            .for_each(|x| out.extend_from_slice(&x.to_le_bytes())),
        (F::R16Unorm, Samples::I16(v), _) if exact => v[range]
            .iter()
            .for_each(|&x| out.extend_from_slice(&((x as i32 + 32768) as u16).to_le_bytes())),
        (F::R16Unorm, samples, _) => range.for_each(|i| {
            let q = (normalized(samples.get_f64(i)).clamp(0.0, 1.0) * 65535.0).round() as u16;
            out.extend_from_slice(&q.to_le_bytes())
        }),
        // Not made by `choose_encoding` (colour volumes have 8-bit luminance): grey colour.
        (F::Rgba8Unorm, samples, _) => range.for_each(|i| {
            let q = (normalized(samples.get_f64(i)).clamp(0.0, 1.0) * 255.0).round() as u8;
            out.extend_from_slice(&[q, q, q, q]);
        }),
        (F::R8Unorm, samples, _) => range.for_each(|i| {
            out.push((normalized(samples.get_f64(i)).clamp(0.0, 1.0) * 255.0).round() as u8)
        }),
        (F::R16Float, samples, _) => range.for_each(|i| {
            out.extend_from_slice(
                &half::f16::from_f32(normalized(samples.get_f64(i))).to_le_bytes(),
            )
        }),
        (_, samples, _) => {
            range.for_each(|i| out.extend_from_slice(&normalized(samples.get_f64(i)).to_le_bytes()))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::ValueMapping;

    fn volume(samples: Samples, mapping: ValueMapping) -> Volume {
        let n = samples.len() as u32;
        Volume::new("t", [n, 1, 1], [1.0; 3], samples, mapping).expect("valid")
    }

    /// Decodes texel `i` as the GPU would (unorm: integer / max) and applies the encoding.
    fn decoded(v: &Volume, e: &TexelEncoding, i: usize) -> f64 {
        let mut bytes = Vec::new();
        encode_texels(&TexelSource::of(v), e, i..i + 1, &mut bytes);
        let texel = match e.format {
            wgpu::TextureFormat::R8Unorm => bytes[0] as f64 / 255.0,
            wgpu::TextureFormat::R16Unorm => {
                u16::from_le_bytes([bytes[0], bytes[1]]) as f64 / 65535.0
            }
            wgpu::TextureFormat::R16Float => {
                half::f16::from_le_bytes([bytes[0], bytes[1]]).to_f64()
            }
            _ => f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]) as f64,
        };
        texel * e.scale as f64 + e.bias as f64
    }

    #[test]
    fn every_type_and_format_decodes_to_the_normalised_value() {
        let m = ValueMapping {
            slope: 2.0,
            intercept: -7.0,
        };
        let cases = [
            Samples::U8(vec![0, 17, 255]),
            Samples::I8(vec![-128, 5, 127]),
            Samples::U16(vec![3, 1000, 3272]),
            Samples::I16(vec![-1024, 40, 3071]),
            Samples::U32(vec![0, 70000, 4_000_000]),
            Samples::I32(vec![-5, 0, 5]),
            Samples::F32(vec![-1.5, 0.25, 8.0]),
            Samples::F64(vec![-1e3, 0.0, 1e3]),
        ];
        use wgpu::TextureFormat as F;
        for samples in cases {
            let v = volume(samples, m);
            for allowed in [
                [F::R8Unorm, F::R16Unorm, F::R32Float],
                [F::R8Unorm, F::R16Float, F::R16Float],
            ] {
                let e = choose_encoding(&v, |f| allowed.contains(&f));
                let norm = v.normalization_range();
                for i in 0..3 {
                    let expected = norm.normalize(v.value(i as u32, 0, 0));
                    // f32 scale/bias round at ~1e-7 relative; f16 holds 11 significant bits;
                    // 32-bit integers quantised to 16 bits are within half a level (1/131070).
                    let tol = match e.format {
                        F::R16Float => 1e-3,
                        F::R16Unorm if v.scalar_type().size_bytes() > 2 => 1.0 / 131070.0,
                        _ => 1e-6,
                    };
                    let got = decoded(&v, &e, i);
                    assert!(
                        (got - expected).abs() <= tol,
                        "{:?} {:?} #{i}: {got} vs {expected}",
                        v.scalar_type(),
                        e.format
                    );
                }
            }
        }
    }

    #[test]
    fn every_type_decodes_in_every_forced_precision_within_its_quantisation() {
        let m = ValueMapping {
            slope: 0.5,
            intercept: 3.0,
        };
        let cases = [
            Samples::U8(vec![0, 17, 200, 255]),
            Samples::I16(vec![-1024, 40, 41, 3071]),
            Samples::U16(vec![0, 1, 65534, 65535]),
            Samples::F32(vec![-1.5, 0.25, 0.2500001, 8.0]),
            Samples::F64(vec![-1e3, 0.0, 1e-9, 1e3]),
        ];
        for samples in cases {
            let v = volume(samples, m);
            let norm = v.normalization_range();
            for precision in TexturePrecision::ALL {
                let Some(format) = forced_format(precision) else {
                    continue;
                };
                let e = encoding_for(&v, format);
                assert_eq!(e.format, format);
                for i in 0..4 {
                    let expected = norm.normalize(v.value(i as u32, 0, 0));
                    // Half a level of the format (exact integers decode within f32 rounding,
                    // which is far below that); f32 holds the value to ~1e-7.
                    let tol = match format {
                        wgpu::TextureFormat::R8Unorm => 0.5 / 255.0 + 1e-6,
                        wgpu::TextureFormat::R16Unorm => 0.5 / 65535.0 + 1e-6,
                        _ => 1e-6,
                    };
                    let got = decoded(&v, &e, i);
                    assert!(
                        (got - expected).abs() <= tol,
                        "{:?} {precision:?} #{i}: {got} vs {expected}",
                        v.scalar_type()
                    );
                }
            }
        }
    }

    #[test]
    fn non_finite_samples_become_missing_in_a_signed_format() {
        let v = volume(
            Samples::F32(vec![0.0, f32::NAN, 1.0, f32::NEG_INFINITY]),
            ValueMapping::IDENTITY,
        );
        let e = choose_encoding(&v, |f| f != wgpu::TextureFormat::R32Float);
        assert_eq!(e.format, wgpu::TextureFormat::R16Float);
        assert_eq!(decoded(&v, &e, 1), MISSING as f64);
        assert_eq!(decoded(&v, &e, 3), MISSING as f64);
        assert_eq!(decoded(&v, &e, 2), 1.0);
    }
}
