//! Gradients and Phong lighting for the reference, in f64, with the GPU's conventions: gradients
//! of the normalised value per millimetre from trilinear reads one voxel apart (or ±1, ±2 voxels
//! for the fourth-order scheme), two-sided normals, `I = Ka + Kd·cosθ + Ks·cosⁿα` with a white
//! highlight; a flat or undefined gradient leaves the colour unlit.

use glam::DVec3;

use crate::settings::{GradientScheme, Light, Phong};
use crate::volume::Volume;

use super::trilinear::sample_trilinear;

/// Gradients shorter than this (normalised value per mm) are flat (as `FLAT_GRADIENT` in
/// shaders/shared/shade.wgsl).
pub(super) const FLAT_GRADIENT: f64 = 1e-7;

/// The gradient of the normalised value per mm at world position `p`; zero where a read touches
/// a non-finite voxel.
pub fn gradient(volume: &Volume, p: DVec3, scheme: GradientScheme) -> DVec3 {
    let range = volume.normalization_range();
    let spacing = volume.spacing_mm();
    let value = |q: DVec3| sample_trilinear(volume, q).map(|v| range.normalize(v));
    let mut g = DVec3::ZERO;
    for a in 0..3 {
        let mut e = DVec3::ZERO;
        e[a] = spacing[a];
        let reads = match scheme {
            GradientScheme::Central => [value(p + e), value(p - e), Some(0.0), Some(0.0)],
            GradientScheme::FourthOrder => [
                value(p + e),
                value(p - e),
                value(p + 2.0 * e),
                value(p - 2.0 * e),
            ],
        };
        let [Some(f1), Some(b1), Some(f2), Some(b2)] = reads else {
            return DVec3::ZERO;
        };
        let per_voxel = match scheme {
            GradientScheme::Central => 0.5 * (f1 - b1),
            GradientScheme::FourthOrder => (8.0 * (f1 - b1) - (f2 - b2)) / 12.0,
        };
        g[a] = per_voxel / spacing[a];
    }
    g
}

/// Lights `color` at a sample with gradient `g`, seen along the unit `view_dir`.
pub fn phong(color: DVec3, g: DVec3, view_dir: DVec3, phong: &Phong, light: &Light) -> DVec3 {
    phong_shadowed(color, g, view_dir, (phong, light), [1.0, 1.0])
}

/// [`phong`] where a share `[light, ambient]` (0…1 each) of the light and of the ambient
/// light reach the sample (shadows, ambient occlusion): the diffuse and specular terms scaled by
/// the first, the ambient by the second; a flat gradient's colour scaled from full by
/// (Ka·ambient + Kd·light) / (Ka + Kd), as shaders/shared/shade.wgsl does.
pub fn phong_shadowed(
    color: DVec3,
    g: DVec3,
    view_dir: DVec3,
    (phong, light): (&Phong, &Light),
    [reaching, ambient_share]: [f64; 2],
) -> DVec3 {
    let ambient = phong.ambient * ambient_share;
    let len = g.length();
    if len.is_nan() || len <= FLAT_GRADIENT {
        let lit = phong.ambient + phong.diffuse;
        if (reaching < 1.0 || ambient_share < 1.0) && lit > 0.0 {
            return color * (ambient + phong.diffuse * reaching) / lit;
        }
        return color;
    }
    let to_eye = -view_dir;
    let mut n = -g / len;
    if n.dot(to_eye) < 0.0 {
        n = -n;
    }
    let to_light = match light {
        Light::Headlight => to_eye,
        Light::Direction(d) => -DVec3::from_array(*d).normalize_or(DVec3::NEG_Z),
    };
    let diffuse = n.dot(to_light).max(0.0);
    let r = 2.0 * n.dot(to_light) * n - to_light;
    let specular = r.dot(to_eye).max(0.0).powf(phong.shininess);
    color * (ambient + phong.diffuse * diffuse * reaching)
        + DVec3::splat(phong.specular * specular * reaching)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::synthetic::{Axis, ramp};

    #[test]
    fn ramp_gradient_is_exact_for_both_schemes() {
        let v = ramp([16, 8, 8], [2.0, 1.0, 1.0], Axis::X).expect("ramp");
        // Values rise by 1/15 of the range per voxel, over 2 mm.
        for scheme in [GradientScheme::Central, GradientScheme::FourthOrder] {
            let g = gradient(&v, DVec3::new(15.0, 3.0, 3.0), scheme);
            assert!(
                (g.x - 1.0 / 30.0).abs() < 1e-9 && g.y.abs() < 1e-12 && g.z.abs() < 1e-12,
                "{scheme:?} {g}"
            );
        }
    }

    #[test]
    fn flat_gradient_is_unlit_and_lit_faces_follow_cosine() {
        let p = Phong {
            ambient: 0.2,
            diffuse: 0.8,
            specular: 0.0,
            shininess: 1.0,
        };
        let c = DVec3::splat(0.5);
        assert_eq!(phong(c, DVec3::ZERO, DVec3::Z, &p, &Light::Headlight), c);
        // Head-on headlight: full diffuse.
        let lit = phong(
            c,
            DVec3::new(0.0, 0.0, 3.0),
            DVec3::Z,
            &p,
            &Light::Headlight,
        );
        assert!((lit - c).length() < 1e-12);
        // Light at 60° to the normal: cos = 1/2.
        // The light travels towards +z (into the surface whose normal faces the eye, −z), 60° off.
        let light = Light::Direction([0.0, 3f64.sqrt() / 2.0, 0.5]);
        let lit = phong(c, DVec3::new(0.0, 0.0, 1.0), DVec3::Z, &p, &light);
        assert!((lit.x - 0.5 * (0.2 + 0.8 * 0.5)).abs() < 1e-12, "{lit}");
    }
}
