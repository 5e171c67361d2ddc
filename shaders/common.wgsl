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
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var volume_tex: texture_3d<f32>;
@group(0) @binding(2) var linear_clamp: sampler;
@group(0) @binding(3) var lut_tex: texture_2d<f32>;
