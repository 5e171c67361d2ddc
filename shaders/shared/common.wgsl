// Frame uniforms and the volume's resources, shared by every ray-casting shader.
// `Frame` is `FrameUniforms` in src/render/gpu_data.rs; a test checks every field's name, offset
// and type against naga's reflection of this declaration.
//
// Coordinate spaces: ray positions are *box* coordinates, [0, 1]^3 over the volume's bounding
// box, which are also its texture coordinates; lengths along rays are millimetres (through
// `extent_mm`); voxel coordinates are box coordinates × `volume_dims` (voxel-centre + ½).

#include "generated/constants.wgsl"
#include "shared/volume.wgsl"

struct Frame {
    // Box coordinates -> clip space, and back (for rays of the near-plane cap).
    clip_from_box: mat4x4<f32>,
    box_from_clip: mat4x4<f32>,
    // Compute-path rays (box coordinates, w unused): near-plane point and near-to-far vector of
    // the ray through NDC (0,0), then their changes per unit of NDC x and y.
    ray_near: array<vec4<f32>, 3>,
    ray_dir: array<vec4<f32>, 3>,
    // Composited behind the volume (a = 1).
    background: vec4<f32>,
    // Size of the bounding box in millimetres.
    extent_mm: vec3<f32>,
    // Distance between samples, millimetres.
    step_mm: f32,
    // Volume dimensions in voxels.
    volume_dims: vec3<f32>,
    // Normalised value = texel * texel_scale + texel_bias.
    texel_scale: f32,
    // Voxel spacing in millimetres.
    spacing_mm: vec3<f32>,
    texel_bias: f32,
    // The cropping box in box coordinates: rays start and end on it.
    crop_min: vec3<f32>,
    // Entries in the transfer-function lookup table.
    lut_size: f32,
    crop_max: vec3<f32>,
    // First sample at (k + sample_offset) * step, k = 0, 1, ...
    sample_offset: f32,
    // Direction a directional light travels (world, unit); unused with the headlight.
    light_dir: vec3<f32>,
    // 1: the light is at the eye, shining along each ray.
    headlight: u32,
    // Viewport width and height in pixels.
    viewport: vec2<f32>,
    // RC-t stops once accumulated opacity exceeds this.
    termination_alpha: f32,
    // 1: each pixel's first sample at its own jittered offset.
    jitter: u32,
    // Phong Ka, Kd, Ks and exponent n.
    phong_ambient: f32,
    phong_diffuse: f32,
    phong_specular: f32,
    phong_shininess: f32,
    // The window (normalised values) MIP, MinIP and X-ray map to black..white.
    window_lo: f32,
    window_hi: f32,
    // MIP/MinIP: the value past which the image can no longer change.
    saturation: f32,
    // X-ray attenuation per mm at the window's top.
    xray_density_per_mm: f32,
    // Normalised iso value, less the tie tolerance.
    iso_threshold: f32,
    // Lookup-table steps per d0 (1 / step in voxels): undoes the table's opacity correction where
    // MIP and MinIP colour by the transfer function.
    steps_per_d0: f32,
    // Pre-integration: optical-depth units (d0, or steps without opacity correction) per mm.
    depth_units_per_mm: f32,
    // Isosurface refinement steps.
    iso_refine: u32,
    // Pyramid level of the leaping blocks, and the number of levels.
    leaf_level: u32,
    level_count: u32,
    // What the lookup table's stored depths are multiplied by (they are stored scaled so that
    // its 16-bit floats hold faint ones).
    lut_depth_unit: f32,
    // DVR: samples whose weight in the pixel, alpha * (1 - A), is below this are composited unlit.
    light_min_weight: f32,
    // The compute path's rows [row_offset, row_end): one band of a frame rendered in bands of
    // rows, or the whole image.
    row_offset: u32,
    row_end: u32,
    // 1 where every voxel is finite (no sample decodes as missing), else 0.
    all_finite: u32,
    // 1 for a colour volume: DVR and isosurfaces take each sample's own colour (sample_colour),
    // the transfer function its opacity.
    colour_volume: u32,
    // Layers of labels in label_tex (shared/labels.wgsl), 0 without a segmentation.
    label_layers: u32,
    // Channels of the label surfaces' mask (1, 2 or 4; 0 without surfaces).
    surface_channels: u32,
    // 1 where the labels travel in the volume's bricks (shared/labels.wgsl), else 0.
    label_bricks: u32,
    _pad2: u32,
    // Box coordinates times this are the surfaces' mask's (1 but where it lies on the labels'
    // grid reduced k-fold, covering k·ceil(N / k) voxels of N).
    surface_scale: vec3<f32>,
    _pad3: u32,
    // Distance between a shadow ray's samples, and how far it reaches (mm; shared/shadow.wgsl).
    shadow_step_mm: f32,
    shadow_reach_mm: f32,
    // The tangent of the light's angular radius (0: hard shadows), and the frame's point of the
    // unit square on its disc, rotated per pixel (shared/shadow.wgsl's light_point).
    shadow_tan: f32,
    // How far ambient-occlusion rays reach, and the distance between their samples (mm;
    // shared/occlusion.wgsl).
    occlusion_radius_mm: f32,
    shadow_sample: vec2<f32>,
    occlusion_step_mm: f32,
    _pad6: u32,
}

// One ray inside the volume: entry (box coordinates), direction in box units per mm and in
// world space, length in mm, number of grid samples.
struct Ray {
    entry: vec3<f32>,
    // First sample at (k + offset) * step.
    offset: f32,
    box_per_mm: vec3<f32>,
    dir_world: vec3<f32>,
    length_mm: f32,
    count: u32,
#ifdef SHADOWS
    // Towards the light, box units per mm, from this pixel's point of the light's disc
    // (shared/shadow.wgsl): the same for every sample of the ray.
    to_light: vec3<f32>,
#endif
}

// Distance (mm from the entry) of grid sample k of `ray`: t_k = min((k + offset) · step, L), the
// rule of src/sampling.rs. Every sample any loop takes or leaps to lies on it.
fn sample_distance(ray: Ray, k: u32) -> f32 {
    return min((f32(k) + ray.offset) * frame.step_mm, ray.length_mm);
}

// Bits returned by acc_sample.
const SAMPLE_STOP: u32 = 1u;
const SAMPLE_CONTRIBUTED: u32 = 2u;

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var volume_tex: texture_3d<f32>;
@group(0) @binding(2) var linear_clamp: sampler;
@group(0) @binding(3) var lut_tex: texture_2d<f32>;
// The page table and geometry of shared/volume.wgsl (binding 4 is the pre-integration table).
@group(0) @binding(5) var<storage, read> volume_pages: array<vec4<f32>>;
@group(0) @binding(6) var<uniform> volume_geometry: VolumeGeometry;

// The jittered first-sample offset of a pixel in [0, 1): the same hash as `pixel_jitter` in
// src/sampling.rs, bit for bit (u32 arithmetic wraps in both).
fn pixel_jitter(px: vec2<u32>) -> f32 {
    var h = px.x * 1973u + px.y * 9277u + 26699u;
    h = (h ^ (h >> 16u)) * 0x7feb352du;
    h = (h ^ (h >> 15u)) * 0x846ca68bu;
    h = h ^ (h >> 16u);
    return f32(h >> 8u) / 16777216.0;
}

// Where the first sample of pixel `px`'s ray lies within its first step: the frame's offset,
// or with jitter the pixel's hash rotated by the frame's offset minus ½ (exactly the hash at the
// default ½; progressive refinement rotates it), as `jittered_offset` in src/sampling.rs.
fn sample_offset_of(px: vec2<u32>) -> f32 {
    if frame.jitter != 0u {
        return fract(pixel_jitter(px) + (frame.sample_offset - 0.5));
    }
    return frame.sample_offset;
}
