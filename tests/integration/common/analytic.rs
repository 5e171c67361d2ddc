//! Analytic answers for the hard-case tests: the path length of each pixel's ray through the
//! volume's box, the colour a uniform (constant-valued) volume gives in every mode, and an image
//! check that allows pixels whose footprint straddles a silhouette any value between the answers
//! seen within that footprint.

use leapview::camera::{Aabb, Camera};
use leapview::imaging::ImageF32;
use leapview::settings::{Mode, RenderPath, RenderSettings};
use leapview::transfer::{TransferFunction, ValueSpace};

/// Both ray-loop entry points.
pub const PATHS: [RenderPath; 2] = [RenderPath::Fragment, RenderPath::Compute];

/// The bound for analytic answers: one 8-bit level. The output is f16 (2^-11 relative)
/// and the ray loop f32; opacity.rs measured at most 2.4e-4 against `1 − (1 − α)^L`.
pub const ANALYTIC_TOLERANCE: f64 = 1.0 / 255.0;

/// Path length in millimetres inside `bounds` of the ray through pixel position `(px, py)`
/// (pixel indices; the ray passes through `(px + ½, py + ½)`), from the near plane on, as the
/// renderer clips it; `None` where the ray misses the box or only touches it.
pub fn path_length_mm(
    camera: &Camera,
    bounds: &Aabb,
    size: [u32; 2],
    px: f64,
    py: f64,
) -> Option<f64> {
    let (origin, dir) = camera.pixel_ray(px, py, size, bounds);
    let (t0, t1) = bounds.intersect(origin, dir)?;
    let t0 = t0.max(0.0);
    (t1 > t0).then_some(t1 - t0)
}

/// A transfer function with opacity `alpha` (per smallest spacing) and colour `rgb` at every
/// value.
pub fn uniform_tf(alpha: f64, rgb: [f64; 3]) -> TransferFunction {
    TransferFunction {
        opacity: vec![[0.0, alpha]],
        color: vec![[0.0, rgb[0], rgb[1], rgb[2]]],
        space: ValueSpace::Data,
    }
}

/// What a volume of one constant value shows in each mode.
#[derive(Clone, Copy, Debug)]
pub struct Uniform {
    /// Transfer-function opacity per `d0`.
    pub alpha: f64,
    /// Transfer-function colour.
    pub rgb: [f64; 3],
    /// The smallest voxel spacing, mm.
    pub d0_mm: f64,
    /// The constant value through the window (MIP, MinIP, X-ray), in 0..1.
    pub windowed: f64,
}

impl Uniform {
    /// The pixel colour for a ray of path length `length_mm` inside the volume (`None`: it
    /// misses). Gradients of a constant volume are zero, so lighting changes nothing; an
    /// isosurface never crosses; the extremes and the X-ray mean are the constant itself; the
    /// attenuation and DVR follow the Beer–Lambert law over the path.
    pub fn pixel(&self, settings: &RenderSettings, length_mm: Option<f64>) -> [f64; 3] {
        let bg = settings.background;
        let Some(l) = length_mm else { return bg };
        match settings.mode {
            Mode::Dvr => {
                let a = 1.0 - (1.0 - self.alpha).powf(l / self.d0_mm);
                std::array::from_fn(|c| self.rgb[c] * a + (1.0 - a) * bg[c])
            }
            Mode::Iso => bg,
            Mode::Mip | Mode::MinIp | Mode::Xray => [self.windowed; 3],
            Mode::XrayAttenuation => {
                [1.0 - (-settings.xray_density_per_mm * self.windowed * l).exp(); 3]
            }
        }
    }
}

/// The 3×3 points `(px + i·reach, py + j·reach)`, i, j ∈ {−1, 0, 1}, centre first.
pub fn footprint(px: u32, py: u32, reach: f64) -> [(f64, f64); 9] {
    let offsets = [
        (0, 0),
        (-1, -1),
        (0, -1),
        (1, -1),
        (-1, 0),
        (1, 0),
        (-1, 1),
        (0, 1),
        (1, 1),
    ];
    offsets.map(|(i, j)| {
        (
            px as f64 + f64::from(i) * reach,
            py as f64 + f64::from(j) * reach,
        )
    })
}

/// [`path_length_mm`] at every pixel's [`footprint`], row by row.
pub fn footprint_lengths(
    camera: &Camera,
    bounds: &Aabb,
    size: [u32; 2],
    reach: f64,
) -> Vec<[Option<f64>; 9]> {
    (0..size[1])
        .flat_map(|py| (0..size[0]).map(move |px| (px, py)))
        .map(|(px, py)| {
            footprint(px, py, reach).map(|(x, y)| path_length_mm(camera, bounds, size, x, y))
        })
        .collect()
}

/// Checks that no channel of `image` is NaN or infinite.
pub fn assert_all_finite(name: &str, image: &ImageF32) {
    if let Some(i) = image
        .pixels
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        let w = image.width as usize;
        panic!(
            "{name}: pixel ({}, {}) is {:?}",
            i % w,
            i / w,
            image.pixels[i]
        );
    }
}

/// Checks every pixel of `image` against `answers(px, py)`, the expected colours at the points
/// of the pixel's [`footprint`] (centre first): it must lie within `tol` of the interval they
/// span (one value where the answer is smooth; both sides' answers where a silhouette or a face
/// passes within the footprint, so that a ray rounding to the other side of a face passes). Also
/// checks that no pixel is NaN or infinite. Saves actual and expected (the centre answers) on
/// failure; returns the number of pixels whose answers spanned more than `tol` and the largest
/// distance of a channel from its interval.
pub fn assert_within_footprint(
    name: &str,
    image: &ImageF32,
    tol: f64,
    answers: impl Fn(u32, u32) -> [[f64; 3]; 9],
) -> (usize, f64) {
    assert_all_finite(name, image);
    let mut centre = ImageF32::filled(image.width, image.height, [0.0, 0.0, 0.0, 1.0]);
    let mut straddling = 0;
    let mut worst = 0.0f64;
    let mut failure = None;
    for py in 0..image.height {
        for px in 0..image.width {
            let answers = answers(px, py);
            let i = (py * image.width + px) as usize;
            let [r, g, b] = answers[0].map(|c| c as f32);
            centre.pixels[i] = [r, g, b, 1.0];
            let got = image.pixels[i];
            for c in 0..3 {
                let lo = answers.iter().map(|a| a[c]).fold(f64::INFINITY, f64::min);
                let hi = answers
                    .iter()
                    .map(|a| a[c])
                    .fold(f64::NEG_INFINITY, f64::max);
                straddling += usize::from(c == 0 && hi - lo > tol);
                let v = f64::from(got[c]);
                worst = worst.max(lo - v).max(v - hi);
                if (v < lo - tol || v > hi + tol) && failure.is_none() {
                    failure = Some(format!(
                        "pixel ({px}, {py}) channel {c}: {v} outside [{lo}, {hi}] ± {tol}"
                    ));
                }
            }
        }
    }
    if let Some(f) = failure {
        let dir = super::save_comparison(name, image, &centre);
        panic!("{name}: {f}; images in {}", dir.display());
    }
    (straddling, worst)
}
