//! Per-frame uniforms, built by a pure function of the camera, the viewport, the volume's
//! geometry and the render settings.
//!
//! Ray positions in the shaders are *box* coordinates: `[0, 1]³` over the volume's bounding box,
//! which are also its texture coordinates. Lengths along rays are measured in millimetres
//! through `extent_mm`.

use glam::{DMat4, DVec3, Mat4};

use crate::camera::{Aabb, Camera};
use crate::render::gpu_data::{FrameUniforms, Mat4x4};
use crate::settings::{Light, MipColor, Mode, RenderSettings};

/// The camera-dependent geometry of a frame, in f64.
#[derive(Clone, Copy, Debug)]
pub struct FrameGeometry {
    /// Box coordinates → clip space.
    pub clip_from_box: DMat4,
    /// Whether the near plane cuts the box, so some rays start on it rather than on a front face.
    pub needs_near_cap: bool,
    /// Near-plane point of the ray through NDC (0,0), and its change per unit of x and y.
    pub ray_near: [DVec3; 3],
    /// Near-to-far-plane vector of the ray through NDC (0,0), and its change per unit of x, y.
    pub ray_dir: [DVec3; 3],
}

impl FrameGeometry {
    /// Geometry for `camera` looking at a volume of `dims` voxels and `spacing_mm`, rendered at
    /// `size` pixels.
    pub fn new(camera: &Camera, size: [u32; 2], dims: [u32; 3], spacing_mm: [f64; 3]) -> Self {
        let bounds = Aabb::of_volume(dims, spacing_mm);
        let clip_from_box = camera.clip_from_world(size, &bounds) * bounds.world_from_box();
        let (near, _) = camera.near_far(&bounds);
        let view = camera.view_from_world();
        let nearest = bounds
            .corners()
            .iter()
            .map(|&c| -view.transform_point3(c).z)
            .fold(f64::INFINITY, f64::min);
        let box_from_clip = clip_from_box.inverse();
        let at = |x: f64, y: f64, z: f64| box_from_clip.project_point3(DVec3::new(x, y, z));
        let near_at = |x, y| at(x, y, 0.0);
        let dir_at = |x, y| at(x, y, 1.0) - at(x, y, 0.0);
        let (n0, d0) = (near_at(0.0, 0.0), dir_at(0.0, 0.0));
        Self {
            clip_from_box,
            needs_near_cap: nearest <= near,
            ray_near: [n0, near_at(1.0, 0.0) - n0, near_at(0.0, 1.0) - n0],
            ray_dir: [d0, dir_at(1.0, 0.0) - d0, dir_at(0.0, 1.0) - d0],
        }
    }
}

/// The leaping pyramid's levels as the ray loop needs them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LeapLevels {
    /// Level of the leaping blocks.
    pub leaf_level: u32,
    /// Number of levels.
    pub level_count: u32,
}

/// Texel decoding and lookup-table size, fixed per volume and table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleDecoding {
    /// Normalised value = texel * scale + bias.
    pub texel_scale: f32,
    /// See `texel_scale`.
    pub texel_bias: f32,
    /// Entries in the lookup table.
    pub lut_size: u32,
    /// What the table's stored depths are multiplied by to give optical depths.
    pub lut_depth_unit: f32,
    /// The volume's normalisation range (data units ↔ normalised values).
    pub range: crate::volume::ValueRange,
    /// Whether every voxel is finite, so that no sample decodes as missing.
    pub all_finite: bool,
    /// Whether the volume is a colour one (texels: luminance, red, green, blue).
    pub colour: bool,
}

/// Builds the uniforms of one frame.
pub(crate) fn frame_uniforms(
    geometry: &FrameGeometry,
    size: [u32; 2],
    dims: [u32; 3],
    spacing_mm: [f64; 3],
    settings: &RenderSettings,
    decoding: SampleDecoding,
    leap: LeapLevels,
) -> FrameUniforms {
    let bounds = Aabb::of_volume(dims, spacing_mm);
    let d0 = spacing_mm.iter().copied().fold(f64::INFINITY, f64::min);
    let to_f32 = |m: DMat4| {
        Mat4x4(Mat4::from_cols_array(&m.to_cols_array().map(|x| x as f32)).to_cols_array_2d())
    };
    let [r, g, b] = settings.background.map(|c| c as f32);
    let window = Window::of(settings, decoding.range);
    let (light_dir, headlight) = match settings.light {
        Light::Headlight => ([0.0; 3], 1),
        Light::Direction(d) => (
            xyz(DVec3::from_array(d).normalize_or(DVec3::NEG_Z).to_array()),
            0,
        ),
    };
    FrameUniforms {
        clip_from_box: to_f32(geometry.clip_from_box),
        box_from_clip: to_f32(geometry.clip_from_box.inverse()),
        ray_near: geometry.ray_near.map(|v| xyz0(v.to_array())),
        ray_dir: geometry.ray_dir.map(|v| xyz0(v.to_array())),
        background: [r, g, b, 1.0],
        extent_mm: xyz(bounds.size().to_array()),
        step_mm: (settings.step_vox * d0) as f32,
        volume_dims: dims.map(|d| d as f32),
        texel_scale: decoding.texel_scale,
        spacing_mm: xyz(spacing_mm),
        texel_bias: decoding.texel_bias,
        crop_min: xyz(settings.crop.min),
        lut_size: decoding.lut_size as f32,
        crop_max: xyz(settings.crop.max),
        sample_offset: settings.sample_offset as f32,
        light_dir,
        headlight,
        viewport: [size[0] as f32, size[1] as f32],
        termination_alpha: settings.termination_alpha as f32,
        jitter: u32::from(settings.jitter),
        phong_ambient: settings.phong.ambient as f32,
        phong_diffuse: settings.phong.diffuse as f32,
        phong_specular: settings.phong.specular as f32,
        phong_shininess: settings.phong.shininess as f32,
        window_lo: window.lo,
        window_hi: window.hi,
        saturation: window.saturation,
        xray_density_per_mm: settings.xray_density_per_mm as f32,
        iso_threshold: settings.iso.threshold(decoding.range) as f32,
        steps_per_d0: (1.0 / settings.opacity_step_vox()) as f32,
        depth_units_per_mm: (settings.opacity_step_vox() / (settings.step_vox * d0)) as f32,
        iso_refine: settings.iso.refine_iterations,
        leaf_level: leap.leaf_level,
        level_count: leap.level_count,
        lut_depth_unit: decoding.lut_depth_unit,
        light_min_weight: settings.light_min_weight as f32,
        row_offset: 0,
        row_end: size[1],
        all_finite: u32::from(decoding.all_finite),
        colour_volume: u32::from(decoding.colour),
        label_layers: 0,
        surface_channels: 0,
        label_bricks: 0,
        _pad2: 0,
        surface_scale: [1.0; 3],
        _pad3: 0,
        shadow_step_mm: (settings.shadows.step_vox * d0) as f32,
        shadow_reach_mm: (settings.shadows.reach * bounds.size().length()) as f32,
        shadow_tan: settings.shadows.softness_deg.to_radians().tan() as f32,
        occlusion_radius_mm: (settings.occlusion.radius_vox * d0) as f32,
        shadow_sample: settings.shadows.sample.map(|u| u as f32),
        occlusion_step_mm: d0 as f32,
        _pad6: 0,
    }
}

/// A 3-vector in f32.
fn xyz(v: [f64; 3]) -> [f32; 3] {
    v.map(|c| c as f32)
}

/// A 3-vector as a uniform `vec4` with w = 0.
fn xyz0(v: [f64; 3]) -> [f32; 4] {
    [v[0] as f32, v[1] as f32, v[2] as f32, 0.0]
}

/// The window of MIP, MinIP and X-ray in normalised values, and the MIP/MinIP saturation value
/// (where the image can no longer change: the window's end for grey, the volume's extreme for
/// colours).
struct Window {
    lo: f32,
    hi: f32,
    saturation: f32,
}

impl Window {
    fn of(settings: &RenderSettings, range: crate::volume::ValueRange) -> Self {
        let [lo, hi] = settings
            .window
            .unwrap_or([range.min, range.max])
            .map(|v| range.normalize(v));
        let saturation = match (settings.mode, settings.mip_color) {
            (Mode::MinIp, MipColor::Window) => lo,
            (Mode::MinIp, MipColor::Tf) => 0.0,
            (_, MipColor::Window) => hi,
            (_, MipColor::Tf) => 1.0,
        };
        Self {
            lo: lo as f32,
            hi: hi as f32,
            saturation: saturation as f32,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{ProjectionKind, ViewPreset};
    use glam::DVec3;

    #[test]
    fn near_cap_only_when_the_eye_is_inside_or_touching() {
        let dims = [16, 16, 16];
        let spacing = [1.0; 3];
        let bounds = Aabb::of_volume(dims, spacing);
        let (dir, up) = ViewPreset::PlusZ.direction_and_up();
        let mut cam = Camera::framing(&bounds, dir, up, ProjectionKind::Perspective);
        assert!(!FrameGeometry::new(&cam, [8, 8], dims, spacing).needs_near_cap);
        cam.eye = bounds.center() + DVec3::new(0.0, 0.0, -2.0);
        assert!(FrameGeometry::new(&cam, [8, 8], dims, spacing).needs_near_cap);
    }
}
