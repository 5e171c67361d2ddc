//! Typed storage of a volume's samples, in the type the file stored them.

/// Samples each task of [`Samples::fold_f64`] takes: large enough that a task's overhead is
/// nothing beside it, small enough that all cores share a 256³ volume.
const FOLD_CHUNK: usize = 1 << 18;

/// The stored type of a volume's samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ScalarType {
    /// Unsigned 8-bit integer.
    U8,
    /// Signed 8-bit integer.
    I8,
    /// Unsigned 16-bit integer.
    U16,
    /// Signed 16-bit integer.
    I16,
    /// Unsigned 32-bit integer.
    U32,
    /// Signed 32-bit integer.
    I32,
    /// 32-bit IEEE float.
    F32,
    /// 64-bit IEEE float.
    F64,
}

impl ScalarType {
    /// Size of one sample in bytes.
    pub fn size_bytes(self) -> usize {
        match self {
            Self::U8 | Self::I8 => 1,
            Self::U16 | Self::I16 => 2,
            Self::U32 | Self::I32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }

    /// The name used by NRRD headers and the command line (`uint8`, `int16`, `float`…).
    pub fn name(self) -> &'static str {
        match self {
            Self::U8 => "uint8",
            Self::I8 => "int8",
            Self::U16 => "uint16",
            Self::I16 => "int16",
            Self::U32 => "uint32",
            Self::I32 => "int32",
            Self::F32 => "float",
            Self::F64 => "double",
        }
    }
}

impl ScalarType {
    /// Parses a type name as the command line takes it: `uint8`/`u8`, `int8`/`i8`, `uint16`/`u16`,
    /// `int16`/`i16`, `uint32`/`u32`, `int32`/`i32`, `float`/`f32`, `double`/`f64`.
    pub fn from_name(name: &str) -> Option<Self> {
        Some(match name.trim().to_ascii_lowercase().as_str() {
            "uint8" | "u8" | "uchar" => Self::U8,
            "int8" | "i8" => Self::I8,
            "uint16" | "u16" | "ushort" => Self::U16,
            "int16" | "i16" | "short" => Self::I16,
            "uint32" | "u32" | "uint" => Self::U32,
            "int32" | "i32" | "int" => Self::I32,
            "float" | "f32" | "float32" => Self::F32,
            "double" | "f64" | "float64" => Self::F64,
            _ => return None,
        })
    }
}

impl std::fmt::Display for ScalarType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A volume's samples in their stored type, x fastest.
#[derive(Clone, Debug, PartialEq)]
pub enum Samples {
    /// Unsigned 8-bit samples.
    U8(Vec<u8>),
    /// Signed 8-bit samples.
    I8(Vec<i8>),
    /// Unsigned 16-bit samples.
    U16(Vec<u16>),
    /// Signed 16-bit samples.
    I16(Vec<i16>),
    /// Unsigned 32-bit samples.
    U32(Vec<u32>),
    /// Signed 32-bit samples.
    I32(Vec<i32>),
    /// 32-bit float samples (may hold NaN or ±Inf).
    F32(Vec<f32>),
    /// 64-bit float samples (may hold NaN or ±Inf).
    F64(Vec<f64>),
}

/// Applies `$body` to the inner vector of every variant, bound as `$v`.
macro_rules! each_variant {
    ($samples:expr, $v:ident => $body:expr) => {
        match $samples {
            Samples::U8($v) => $body,
            Samples::I8($v) => $body,
            Samples::U16($v) => $body,
            Samples::I16($v) => $body,
            Samples::U32($v) => $body,
            Samples::I32($v) => $body,
            Samples::F32($v) => $body,
            Samples::F64($v) => $body,
        }
    };
}

impl Samples {
    /// The stored type.
    pub fn scalar_type(&self) -> ScalarType {
        match self {
            Self::U8(_) => ScalarType::U8,
            Self::I8(_) => ScalarType::I8,
            Self::U16(_) => ScalarType::U16,
            Self::I16(_) => ScalarType::I16,
            Self::U32(_) => ScalarType::U32,
            Self::I32(_) => ScalarType::I32,
            Self::F32(_) => ScalarType::F32,
            Self::F64(_) => ScalarType::F64,
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        each_variant!(self, v => v.len())
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The stored value at `index` as f64 (exact for every stored type but u64-range integers,
    /// which we do not store). Panics if `index` is out of bounds, like slice indexing.
    // The f64 variant casts to itself; the macro treats all variants alike.
    #[allow(clippy::unnecessary_cast)]
    pub fn get_f64(&self, index: usize) -> f64 {
        each_variant!(self, v => v[index] as f64)
    }

    /// Reverses the order of the samples inside every run of `row` consecutive ones: with `row`
    /// the x dimension, mirrors the volume along x in place. `row` of 0 changes nothing.
    pub(crate) fn reverse_rows(&mut self, row: usize) {
        if row > 0 {
            each_variant!(self, v => v.chunks_mut(row).for_each(<[_]>::reverse))
        }
    }

    /// `parts` (all of one type) one after the other; no samples where there are no parts.
    pub(crate) fn concat(parts: Vec<Self>) -> Self {
        let mut parts = parts.into_iter();
        let Some(mut all) = parts.next() else {
            return Self::U8(Vec::new());
        };
        for part in parts {
            match (&mut all, part) {
                (Self::U8(a), Self::U8(b)) => a.extend(b),
                (Self::I8(a), Self::I8(b)) => a.extend(b),
                (Self::U16(a), Self::U16(b)) => a.extend(b),
                (Self::I16(a), Self::I16(b)) => a.extend(b),
                (Self::U32(a), Self::U32(b)) => a.extend(b),
                (Self::I32(a), Self::I32(b)) => a.extend(b),
                (Self::F32(a), Self::F32(b)) => a.extend(b),
                (Self::F64(a), Self::F64(b)) => a.extend(b),
                // Parts of one volume share its type.
                _ => {}
            }
        }
        all
    }

    /// A copy of the samples in `range`.
    pub(crate) fn slice(&self, range: std::ops::Range<usize>) -> Self {
        match self {
            Self::U8(v) => Self::U8(v[range].to_vec()),
            Self::I8(v) => Self::I8(v[range].to_vec()),
            Self::U16(v) => Self::U16(v[range].to_vec()),
            Self::I16(v) => Self::I16(v[range].to_vec()),
            Self::U32(v) => Self::U32(v[range].to_vec()),
            Self::I32(v) => Self::I32(v[range].to_vec()),
            Self::F32(v) => Self::F32(v[range].to_vec()),
            Self::F64(v) => Self::F64(v[range].to_vec()),
        }
    }

    /// Every `step`-th sample from `start` (`start < step`): one channel of samples that
    /// interleave `step` channels.
    pub(crate) fn channel(&self, start: usize, step: usize) -> Self {
        match self {
            Self::U8(v) => Self::U8(v.iter().skip(start).step_by(step).copied().collect()),
            Self::I8(v) => Self::I8(v.iter().skip(start).step_by(step).copied().collect()),
            Self::U16(v) => Self::U16(v.iter().skip(start).step_by(step).copied().collect()),
            Self::I16(v) => Self::I16(v.iter().skip(start).step_by(step).copied().collect()),
            Self::U32(v) => Self::U32(v.iter().skip(start).step_by(step).copied().collect()),
            Self::I32(v) => Self::I32(v.iter().skip(start).step_by(step).copied().collect()),
            Self::F32(v) => Self::F32(v.iter().skip(start).step_by(step).copied().collect()),
            Self::F64(v) => Self::F64(v.iter().skip(start).step_by(step).copied().collect()),
        }
    }

    /// The samples at `indices`, in their order (each inside the samples).
    pub(crate) fn gather(&self, indices: &[usize]) -> Self {
        match self {
            Self::U8(v) => Self::U8(indices.iter().map(|&i| v[i]).collect()),
            Self::I8(v) => Self::I8(indices.iter().map(|&i| v[i]).collect()),
            Self::U16(v) => Self::U16(indices.iter().map(|&i| v[i]).collect()),
            Self::I16(v) => Self::I16(indices.iter().map(|&i| v[i]).collect()),
            Self::U32(v) => Self::U32(indices.iter().map(|&i| v[i]).collect()),
            Self::I32(v) => Self::I32(indices.iter().map(|&i| v[i]).collect()),
            Self::F32(v) => Self::F32(indices.iter().map(|&i| v[i]).collect()),
            Self::F64(v) => Self::F64(indices.iter().map(|&i| v[i]).collect()),
        }
    }

    /// Folds every stored value as f64 on the pool of threads, in chunks of [`FOLD_CHUNK`]
    /// each folded from `init()`, then joins the chunks' results in an order `join` must not
    /// depend on (a minimum, a sum of counts).
    #[allow(clippy::unnecessary_cast)]
    pub(crate) fn fold_f64<T: Send>(
        &self,
        init: impl Fn() -> T + Sync + Send,
        fold: impl Fn(&mut T, f64) + Sync + Send,
        join: impl Fn(T, T) -> T + Sync + Send,
    ) -> T {
        use rayon::prelude::*;
        each_variant!(self, v => v
            .par_chunks(FOLD_CHUNK)
            .map(|chunk| {
                let mut acc = init();
                for &x in chunk {
                    fold(&mut acc, x as f64);
                }
                acc
            })
            .reduce(&init, &join))
    }

    /// Calls `f` with every stored value as f64, in storage order.
    #[allow(clippy::unnecessary_cast)]
    pub fn for_each_f64(&self, mut f: impl FnMut(f64)) {
        each_variant!(self, v => v.iter().for_each(|&x| f(x as f64)))
    }
}

/// The affine map from stored sample values to data units: `data = stored * slope + intercept`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ValueMapping {
    /// Multiplier applied to stored values (NIfTI `scl_slope`); never zero or non-finite.
    pub slope: f64,
    /// Offset added after the multiplication (NIfTI `scl_inter`, DICOM rescale intercept).
    pub intercept: f64,
}

impl ValueMapping {
    /// The identity mapping: data units are the stored values.
    pub const IDENTITY: Self = Self {
        slope: 1.0,
        intercept: 0.0,
    };

    /// Maps a stored value to data units.
    pub fn apply(&self, stored: f64) -> f64 {
        stored * self.slope + self.intercept
    }
}

impl Default for ValueMapping {
    fn default() -> Self {
        Self::IDENTITY
    }
}
