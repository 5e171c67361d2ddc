//! Per-frame uniforms, built by a pure function of the camera, the viewport, the volume's
//! geometry and the render settings.
//!
//! Ray positions in the shaders are *box* coordinates: `[0, 1]³` over the volume's bounding box,
//! which are also its texture coordinates. Lengths along rays are measured in millimetres
//! through `extent_mm`.

use glam::{DMat4, Mat4};

use crate::camera::{Aabb, Camera};

use super::effects::{Light, MipColor};
use super::settings::{Mode, RenderSettings};
use glam::DVec3;

/// The uniform block every ray-casting shader reads. Keep in sync with `Frame` in
/// `shaders/common.wgsl` (a test checks the size against the WGSL declaration).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameUniforms {
    /// Box coordinates → clip space.
    pub clip_from_box: [[f32; 4]; 4],
    /// Clip space → box coordinates (to put rays of the near-plane cap in the box).
    pub box_from_clip: [[f32; 4]; 4],
    /// Size of the bounding box in millimetres (w unused).
    pub extent_mm: [f32; 4],
    /// Background colour composited behind the volume (a = 1).
    pub background: [f32; 4],
    /// Viewport width and height in pixels.
    pub viewport: [f32; 2],
    /// Distance between samples, millimetres.
    pub step_mm: f32,
    /// First sample at `(k + sample_offset) * step`, k = 0, 1, …
    pub sample_offset: f32,
    /// RC-t stops once accumulated opacity exceeds this.
    pub termination_alpha: f32,
    /// Normalised value = texel * texel_scale + texel_bias.
    pub texel_scale: f32,
    /// See `texel_scale`.
    pub texel_bias: f32,
    /// Number of entries in the transfer-function lookup table.
    pub lut_size: f32,
    /// Volume dimensions in voxels (w unused): box coordinates × dims = voxel coordinate + ½.
    pub volume_dims: [f32; 4],
    /// Pyramid level of the leaping blocks.
    pub leaf_level: u32,
    /// Number of pyramid levels.
    pub level_count: u32,
    /// Isosurface refinement steps.
    pub iso_refine: u32,
    /// Padding.
    pub pad: u32,
    /// Voxel spacing in millimetres (w unused).
    pub spacing_mm: [f32; 4],
    /// Phong Ka, Kd, Ks, shininess.
    pub phong: [f32; 4],
    /// Direction the light travels (world, unit); w = 1 for a headlight.
    pub light: [f32; 4],
    /// Window lo and hi (normalised values), MIP/MinIP saturation value, X-ray density per mm.
    pub window: [f32; 4],
    /// Iso threshold (normalised, [`super::effects::IsoSettings::threshold`]), the reciprocal of
    /// the step in voxels, 1 for jittered ray starts; w unused.
    pub iso: [f32; 4],
    /// The pixel rays of the compute path (box coordinates, w unused): the near-plane point of
    /// the ray through NDC `(x, y)` is `near[0] + x·near[1] + y·near[2]`, and the ray runs to
    /// the far plane along `dir[0] + x·dir[1] + y·dir[2]` (both affine in x and y for either
    /// projection; computed in f64 so no f32 unprojection loses digits).
    pub ray_near: [[f32; 4]; 3],
    /// See `ray_near`.
    pub ray_dir: [[f32; 4]; 3],
    /// The cropping box's smallest corner in box coordinates (w unused): rays start and end on
    /// the cropping box ([`super::crop::CropBox`]).
    pub crop_min: [f32; 4],
    /// The cropping box's largest corner (w unused).
    pub crop_max: [f32; 4],
}

const _: () = assert!(std::mem::size_of::<FrameUniforms>() == 432);

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
    /// The volume's normalisation range (data units ↔ normalised values).
    pub range: crate::volume::ValueRange,
}

/// Builds the uniforms of one frame.
pub fn frame_uniforms(
    geometry: &FrameGeometry,
    size: [u32; 2],
    dims: [u32; 3],
    spacing_mm: [f64; 3],
    settings: &RenderSettings,
    decoding: SampleDecoding,
    leap: LeapLevels,
) -> FrameUniforms {
    let bounds = Aabb::of_volume(dims, spacing_mm);
    let extent = bounds.size();
    let d0 = spacing_mm.iter().copied().fold(f64::INFINITY, f64::min);
    let to_f32 =
        |m: DMat4| Mat4::from_cols_array(&m.to_cols_array().map(|x| x as f32)).to_cols_array_2d();
    let [r, g, b] = settings.background.map(|c| c as f32);
    FrameUniforms {
        clip_from_box: to_f32(geometry.clip_from_box),
        box_from_clip: to_f32(geometry.clip_from_box.inverse()),
        extent_mm: xyz0(extent.to_array()),
        background: [r, g, b, 1.0],
        viewport: [size[0] as f32, size[1] as f32],
        step_mm: (settings.step_vox * d0) as f32,
        sample_offset: settings.sample_offset as f32,
        termination_alpha: settings.termination_alpha as f32,
        texel_scale: decoding.texel_scale,
        texel_bias: decoding.texel_bias,
        lut_size: decoding.lut_size as f32,
        volume_dims: [dims[0] as f32, dims[1] as f32, dims[2] as f32, 0.0],
        leaf_level: leap.leaf_level,
        level_count: leap.level_count,
        ray_near: geometry.ray_near.map(|v| xyz0(v.to_array())),
        ray_dir: geometry.ray_dir.map(|v| xyz0(v.to_array())),
        iso_refine: settings.iso.refine_iterations,
        pad: 0,
        spacing_mm: xyz0(spacing_mm),
        phong: [
            settings.phong.ambient,
            settings.phong.diffuse,
            settings.phong.specular,
            settings.phong.shininess,
        ]
        .map(|c| c as f32),
        light: match settings.light {
            Light::Headlight => [0.0, 0.0, 0.0, 1.0],
            Light::Direction(d) => xyz0(DVec3::from_array(d).normalize_or(DVec3::NEG_Z).to_array()),
        },
        window: window_uniform(settings, decoding.range),
        iso: [
            settings.iso.threshold(decoding.range) as f32,
            // Undoes the LUT's opacity correction where MIP and MinIP colour by the TF.
            (1.0 / settings.opacity_step_vox()) as f32,
            f32::from(u8::from(settings.jitter)),
            // Pre-integration: optical-depth units (d₀, or steps without opacity correction)
            // per millimetre of segment.
            (settings.opacity_step_vox() / (settings.step_vox * d0)) as f32,
        ],
        crop_min: xyz0(settings.crop.min),
        crop_max: xyz0(settings.crop.max),
    }
}

/// A 3-vector as a uniform `vec4` with w = 0.
fn xyz0(v: [f64; 3]) -> [f32; 4] {
    [v[0] as f32, v[1] as f32, v[2] as f32, 0.0]
}

/// Window lo/hi as normalised values, the MIP/MinIP saturation value (where the image can no
/// longer change: the window's end for grey, the volume's extreme for colours) and the X-ray
/// density.
fn window_uniform(settings: &RenderSettings, range: crate::volume::ValueRange) -> [f32; 4] {
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
    [
        lo as f32,
        hi as f32,
        saturation as f32,
        settings.xray_density_per_mm as f32,
    ]
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
