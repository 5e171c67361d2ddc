//! The parameters of the visual effects beyond plain compositing: Phong lighting from on-the-fly
//! gradients, the isosurface, the grey window of MIP and X-ray, the X-ray attenuation.

use serde::{Deserialize, Serialize};

use crate::volume::ValueRange;

/// Whether samples are lit.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum,
)]
pub enum Shading {
    /// Colours as the transfer function gives them.
    Off,
    /// Per-sample Phong lighting from the gradient (DVR and isosurface).
    #[default]
    #[value(name = "on")]
    Phong,
}

/// How gradients are estimated from the trilinearly filtered volume.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum,
)]
pub enum GradientScheme {
    /// Central differences one voxel apart: 6 extra reads, second-order accurate.
    #[default]
    Central,
    /// Fourth-order central differences (points at ±1 and ±2 voxels): 12 extra reads.
    FourthOrder,
}

/// `I = Ka·Ia + Kd·Il·cosθ + Ks·Il·cosⁿα` (Ia = Il = 1; the specular term is white).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Phong {
    /// Ambient coefficient Ka.
    pub ambient: f64,
    /// Diffuse coefficient Kd.
    pub diffuse: f64,
    /// Specular coefficient Ks.
    pub specular: f64,
    /// Specular exponent n.
    pub shininess: f64,
}

impl Default for Phong {
    fn default() -> Self {
        Self {
            ambient: 0.3,
            diffuse: 0.7,
            specular: 0.25,
            shininess: 24.0,
        }
    }
}

/// Where the light comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum Light {
    /// A light at the eye, shining along each ray.
    #[default]
    Headlight,
    /// A directional light shining along this world direction.
    Direction([f64; 3]),
}

/// Shadows: the light reaching a lit sample through the transfer function's opacity between it
/// and the light (DVR), by a secondary ray that leaps over empty space as the primary does.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Shadows {
    /// Whether lit samples are shadowed.
    pub on: bool,
    /// Distance between a shadow ray's samples, in units of the smallest voxel spacing `d0`
    /// (within [`SHADOW_STEP_RANGE`]).
    pub step_vox: f64,
    /// How far a shadow ray reaches, as a share of the bounding box's diagonal (0 < reach ≤ 1):
    /// 1 lets every voxel between a sample and the light shadow it, less keeps shadows local.
    pub reach: f64,
    /// The light's angular radius in degrees (0…[`MOST_SHADOW_SOFTNESS`]): 0 casts hard
    /// shadows; above, each pixel's shadow rays aim at their own point of the light's disc, so
    /// one frame shows soft shadows as noise that refinement averages away.
    pub softness_deg: f64,
    /// The point of the unit square this frame's shadow rays take on the light's disc, shifted
    /// per pixel: refinement moves it frame by frame ([`crate::sampling::light_sample`]).
    #[serde(skip)]
    pub sample: [f64; 2],
}

/// Ambient occlusion: the ambient light of each lit sample (DVR, an isosurface's hit) scaled by
/// how open its surroundings are: the mean transmittance of [`OCCLUSION_RAYS`] short rays over
/// the side its gradient points away from.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Occlusion {
    /// Whether the ambient light is occluded.
    pub on: bool,
    /// How far the rays reach, in units of the smallest voxel spacing (within
    /// [`OCCLUSION_RADIUS_RANGE`]); they sample every voxel.
    pub radius_vox: f64,
}

/// Rays an occluded sample casts (`OCCLUSION_RAYS` in shaders/shared/occlusion.wgsl): six at 45°
/// from the normal, turned per pixel by the ray's first-sample offset.
pub const OCCLUSION_RAYS: u32 = 6;

/// Shortest and longest occlusion rays accepted, voxels.
pub const OCCLUSION_RADIUS_RANGE: (f64, f64) = (1.0, 16.0);

impl Default for Occlusion {
    fn default() -> Self {
        Self {
            on: false,
            radius_vox: 4.0,
        }
    }
}

/// The largest angular radius of the light (degrees) accepted.
pub const MOST_SHADOW_SOFTNESS: f64 = 20.0;

/// Smallest and largest shadow step (voxels) accepted: ⅛ to 4, the range the shadows are tested
/// over.
pub const SHADOW_STEP_RANGE: (f64, f64) = (0.125, 4.0);

impl Default for Shadows {
    fn default() -> Self {
        Self {
            on: false,
            step_vox: 1.0,
            reach: 1.0,
            softness_deg: 0.0,
            sample: [0.5; 2],
        }
    }
}

/// How MIP and MinIP turn the extreme value into a colour.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum,
)]
pub enum MipColor {
    /// Grey through the window.
    #[default]
    Window,
    /// The transfer function's colour at the value.
    Tf,
}

/// How a segmentation loaded beside the volume shows in the 3D view (nothing without one).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum,
)]
pub enum LabelView {
    /// The image alone, as if no labels were loaded.
    Off,
    /// The image's transfer function, each sample coloured by its shown label (hidden labels
    /// keep the function's colour; MIP and MinIP tint their pixel by the label of the extreme;
    /// X-ray, a density integral, stays grey).
    #[default]
    Colour,
    /// The image only inside the shown labels: every other sample is cut away (DVR, MIP, MinIP,
    /// X-ray); an isosurface only where its crossing lies inside them.
    Inside,
    /// Both: only inside the shown labels, each sample in its label's colour.
    #[value(name = "colour-inside")]
    ColourInside,
    /// Each shown label's boundary drawn as a smooth lit surface in the label's colour, at its
    /// opacity: composited with the image in DVR, in front of the isosurface, over the MIP,
    /// MinIP or X-ray of the whole ray.
    Surfaces,
}

impl LabelView {
    /// Whether samples take their label's colour.
    pub fn colours(self) -> bool {
        matches!(self, Self::Colour | Self::ColourInside)
    }

    /// Whether the shown labels' boundaries are drawn as surfaces.
    pub fn surfaces(self) -> bool {
        self == Self::Surfaces
    }

    /// Whether everything outside the shown labels is cut away.
    pub fn cuts(self) -> bool {
        matches!(self, Self::Inside | Self::ColourInside)
    }
}

/// Isosurface parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct IsoSettings {
    /// Iso value in data units; `None` = the middle of the volume's value range.
    pub value: Option<f64>,
    /// Secant (false-position) refinement steps between the two samples around a hit.
    pub refine_iterations: u32,
}

/// Default isosurface refinement steps (each one fetch): four took the error below visibility
/// at ½- and 2-voxel steps, at a small cost in frame time (docs/accuracy/README.md).
pub const DEFAULT_ISO_REFINEMENT: u32 = 4;
/// Most refinement steps accepted.
pub const MAX_ISO_REFINEMENT: u32 = 16;

/// How far below the iso value, in normalised units (the volume's value range is 0..1), a sample
/// still counts as having reached it: 2⁻²⁰. The GPU decodes stored values in f32, a few 10⁻⁷
/// off, so without it a plateau at exactly the iso value (or at the data maximum) would fall on
/// either side by rounding alone, the surface landing on any sample inside the plateau, and
/// voxels at the data minimum could fall below an iso value set to the minimum. 2⁻²⁰ of the range
/// is a sixteenth of one level of 16-bit data: the surface moves by less than data resolve.
pub const ISO_TIE_TOLERANCE: f64 = 1.0 / 1_048_576.0;

impl IsoSettings {
    /// The normalised value samples are compared with: the iso value (the middle of `range` when
    /// unset) normalised over `range`, less [`ISO_TIE_TOLERANCE`]. The GPU and the reference
    /// both use it, for the crossings and for the colour.
    pub fn threshold(&self, range: ValueRange) -> f64 {
        range.normalize(self.value.unwrap_or(range.denormalize(0.5))) - ISO_TIE_TOLERANCE
    }
}

impl Default for IsoSettings {
    fn default() -> Self {
        Self {
            value: None,
            refine_iterations: DEFAULT_ISO_REFINEMENT,
        }
    }
}

/// Default X-ray attenuation per millimetre at the top of the window (1/mm): about water's
/// linear attenuation coefficient at 70 keV (0.019/mm), so a 20 cm head of window-top material
/// transmits e^(−3.8) ≈ 2 %.
pub const DEFAULT_XRAY_DENSITY_PER_MM: f64 = 0.019;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iso_threshold_sits_just_below_the_value_at_both_ends_of_the_range() {
        let range = ValueRange {
            min: 100.0,
            max: 4000.0,
        };
        let at = |value| IsoSettings {
            value,
            ..IsoSettings::default()
        };
        // Exact: the normalised ends are 0 and 1, and 2⁻²⁰ is a power of two.
        assert_eq!(at(Some(100.0)).threshold(range), -ISO_TIE_TOLERANCE);
        assert_eq!(at(Some(4000.0)).threshold(range), 1.0 - ISO_TIE_TOLERANCE);
        assert_eq!(at(None).threshold(range), 0.5 - ISO_TIE_TOLERANCE);
        // Below a sixteenth of one 16-bit level, and above f32's rounding of values near 1.
        const {
            assert!(ISO_TIE_TOLERANCE < 1.0 / 65535.0 / 16.0);
            assert!(ISO_TIE_TOLERANCE > 4.0 * f32::EPSILON as f64);
        }
    }
}
