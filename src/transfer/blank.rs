//! Why a picture shows nothing: a constant volume, a transfer function transparent over every
//! value the volume holds, an iso value outside its values, a window above them. Said in words,
//! so that an empty image is never silent.

use super::TransferFunction;
use crate::settings::{Mode, RenderSettings};
use crate::text::number;
use crate::volume::{ValueRange, Volume};

/// One sentence saying why `settings` render `volume` with `tf` as an empty (or black) picture,
/// or `None` when something can show.
pub fn why_blank(
    volume: &Volume,
    tf: &TransferFunction,
    settings: &RenderSettings,
) -> Option<String> {
    why_blank_in(volume.value_range(), tf, settings)
}

/// [`why_blank`] for a volume whose finite values span `range` (`None`: no finite value).
pub(crate) fn why_blank_in(
    range: Option<ValueRange>,
    tf: &TransferFunction,
    settings: &RenderSettings,
) -> Option<String> {
    let Some(range) = range else {
        return Some("no voxel holds a finite value (all are NaN or infinite)".to_string());
    };
    let constant = (range.min == range.max).then(|| number(range.min));
    match settings.mode {
        Mode::Dvr if transparent_over(tf, ValueRange::normalization(Some(range)), range) => {
            Some(match constant {
                Some(v) => {
                    format!("all voxels are {v}; the transfer function maps {v} to opacity 0")
                }
                None => format!(
                    "the transfer function gives opacity 0 to every value this volume holds ({} … {})",
                    number(range.min),
                    number(range.max)
                ),
            })
        }
        Mode::Iso => {
            let iso = settings.iso.value.unwrap_or((range.min + range.max) / 2.0);
            match constant {
                Some(v) => Some(format!(
                    "all voxels are {v}: no surface crosses any iso value"
                )),
                None if iso <= range.min || iso > range.max => Some(format!(
                    "the iso value {} lies outside this volume's values ({} … {}): no surface \
                     crosses it",
                    number(iso),
                    number(range.min),
                    number(range.max)
                )),
                None => None,
            }
        }
        Mode::Mip | Mode::Xray | Mode::XrayAttenuation => match settings.window {
            Some([lo, _]) if lo >= range.max => Some(format!(
                "the window starts at {}, above every value of this volume (at most {}): the \
                 picture is black",
                number(lo),
                number(range.max)
            )),
            _ => None,
        },
        _ => None,
    }
}

/// Whether `tf` is transparent at every value of `values` (a piecewise-linear curve's largest
/// value on an interval is at its ends or at a point inside).
fn transparent_over(tf: &TransferFunction, normalization: ValueRange, values: ValueRange) -> bool {
    let inside = tf
        .opacity
        .iter()
        .map(|p| tf.to_data(p[0], normalization))
        .filter(|&v| v > values.min && v < values.max);
    std::iter::once(values.min)
        .chain(std::iter::once(values.max))
        .chain(inside)
        .all(|v| tf.opacity_at(v, normalization) <= 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::synthetic::analytic::{Axis, constant, ramp};

    fn tf(opacity: &[[f64; 2]]) -> TransferFunction {
        TransferFunction {
            opacity: opacity.to_vec(),
            color: vec![[0.0, 1.0, 1.0, 1.0]],
            space: crate::transfer::ValueSpace::Data,
        }
    }

    #[test]
    fn a_constant_volume_under_a_transparent_value_says_so() {
        let v = constant([4, 4, 4], [1.0; 3], 7.0).expect("volume");
        let hidden = tf(&[[0.0, 0.0], [100.0, 0.0], [200.0, 1.0]]);
        let why = why_blank(&v, &hidden, &RenderSettings::default()).expect("blank");
        assert_eq!(
            why,
            "all voxels are 7; the transfer function maps 7 to opacity 0"
        );
        let shown = tf(&[[0.0, 0.0], [7.0, 0.5]]);
        assert_eq!(why_blank(&v, &shown, &RenderSettings::default()), None);
    }

    #[test]
    fn a_narrow_opaque_spike_inside_the_range_is_not_blank() {
        let v = ramp([16, 2, 2], [1.0; 3], Axis::X).expect("volume");
        let range = v.value_range().expect("finite");
        let mid = (range.min + range.max) / 2.0;
        let spike = tf(&[[mid - 0.01, 0.0], [mid, 0.8], [mid + 0.01, 0.0]]);
        assert_eq!(why_blank(&v, &spike, &RenderSettings::default()), None);
        let above = tf(&[[range.max + 1.0, 0.0], [range.max + 2.0, 1.0]]);
        let why = why_blank(&v, &above, &RenderSettings::default()).expect("blank");
        assert!(why.contains("opacity 0 to every value"), "{why}");
    }

    #[test]
    fn iso_values_and_windows_outside_the_data_are_named() {
        let v = ramp([16, 2, 2], [1.0; 3], Axis::X).expect("volume");
        let range = v.value_range().expect("finite");
        let mut s = RenderSettings {
            mode: Mode::Iso,
            ..RenderSettings::default()
        };
        assert_eq!(why_blank(&v, &TransferFunction::grey_ramp(), &s), None);
        s.iso.value = Some(range.max + 10.0);
        let why = why_blank(&v, &TransferFunction::grey_ramp(), &s).expect("blank");
        assert!(why.contains("outside this volume's values"), "{why}");
        s.mode = Mode::Mip;
        s.window = Some([range.max + 1.0, range.max + 5.0]);
        let why = why_blank(&v, &TransferFunction::grey_ramp(), &s).expect("blank");
        assert!(why.contains("black"), "{why}");
    }
}
