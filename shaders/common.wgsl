// Frame uniforms and the volume's resources, shared by every ray-casting shader.
// Keep `Frame` in sync with `FrameUniforms` in src/render/uniforms.rs.

struct Frame {
    clip_from_box: mat4x4<f32>,
    box_from_clip: mat4x4<f32>,
    extent_mm: vec4<f32>,
    background: vec4<f32>,
    viewport: vec2<f32>,
    step_mm: f32,
    sample_offset: f32,
    termination_alpha: f32,
    texel_scale: f32,
    texel_bias: f32,
    lut_size: f32,
    volume_dims: vec4<f32>,
    leaf_level: u32,
    level_count: u32,
    iso_refine: u32,
    _pad0: u32,
    // Voxel spacing in mm (w unused).
    spacing_mm: vec4<f32>,
    // Ka, Kd, Ks, shininess.
    phong: vec4<f32>,
    // Direction the light travels (world, unit); w = 1 for a headlight (along each ray).
    light: vec4<f32>,
    // Window lo, hi (normalised values), MIP saturation value, X-ray density per mm.
    window: vec4<f32>,
    // Iso value (normalised), 1 / step in voxels (undoes the LUT's opacity correction), 1 for
    // jittered ray starts, pre-integration's optical-depth units per mm.
    iso: vec4<f32>,
    // Compute-path rays (box coordinates): near-plane point and near-to-far vector of the ray
    // through NDC (0,0), then their changes per unit of NDC x and y.
    ray_near: array<vec4<f32>, 3>,
    ray_dir: array<vec4<f32>, 3>,
    // The cropping box in box coordinates (w unused): rays start and end on it.
    crop_min: vec4<f32>,
    crop_max: vec4<f32>,
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
}

// Bits returned by acc_sample.
const SAMPLE_STOP: u32 = 1u;
const SAMPLE_CONTRIBUTED: u32 = 2u;

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var volume_tex: texture_3d<f32>;
@group(0) @binding(2) var linear_clamp: sampler;
@group(0) @binding(3) var lut_tex: texture_2d<f32>;

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
    if frame.iso.z > 0.5 {
        return fract(pixel_jitter(px) + (frame.sample_offset - 0.5));
    }
    return frame.sample_offset;
}

