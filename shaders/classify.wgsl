// Sampling the volume and post-classification through the transfer-function table.

#include "common.wgsl"

// Normalised values below this come from interpolation touching a non-finite voxel (stored as
// -65504, see src/render/volume_texture.rs): such samples are transparent.
const MISSING_BELOW: f32 = -0.5;

// The normalised value (0 = volume minimum, 1 = maximum) at box position p, trilinearly
// interpolated by the texture unit.
fn sample_value(p: vec3<f32>) -> f32 {
    return textureSampleLevel(volume_tex, linear_clamp, p, 0.0).r * frame.texel_scale + frame.texel_bias;
}

// Colour and step-corrected opacity for a normalised value.
fn classify(s: f32) -> vec4<f32> {
    if s < MISSING_BELOW {
        return vec4<f32>(0.0);
    }
    let n = frame.lut_size;
    let u = (clamp(s, 0.0, 1.0) * (n - 1.0) + 0.5) / n;
    return textureSampleLevel(lut_tex, linear_clamp, vec2<f32>(u, 0.5), 0.0);
}
