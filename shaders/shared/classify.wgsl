// Sampling the volume and post-classification through the transfer-function table.

#include "shared/common.wgsl"

// Normalised values below MISSING_BELOW (generated/constants.wgsl) come from interpolation
// touching a non-finite voxel (stored far below 0, see src/render/volume_texture.rs): such samples
// are transparent.

// The normalised value (0 = volume minimum, 1 = maximum) at box position p, trilinearly
// interpolated by the texture unit.
fn sample_value(p: vec3<f32>) -> f32 {
    return textureSampleLevel(volume_tex, linear_clamp, p, 0.0).r * frame.texel_scale + frame.texel_bias;
}

// Colour and the optical depth of one step (src/transfer/lut.rs) for a normalised value.
fn classify(s: f32) -> vec4<f32> {
    if s < MISSING_BELOW {
        return vec4<f32>(0.0);
    }
    let n = frame.lut_size;
    let u = (clamp(s, 0.0, 1.0) * (n - 1.0) + 0.5) / n;
    let c = textureSampleLevel(lut_tex, linear_clamp, vec2<f32>(u, 0.5), 0.0);
    return vec4<f32>(c.rgb, c.a * frame.lut_depth_unit);
}

// Opacity 1 − exp(−d) of an optical depth d, accurate for small d too (1 − exp(−d) in f32 loses
// all digits below d ≈ 6e-8 and ~10 % of them at 5e-7): a Taylor series below 1e-3, whose
// next term is below 2e-13 relative.
fn opacity_of_depth(d: f32) -> f32 {
    if d < 1.0e-3 {
        return d * (1.0 - d * (0.5 - d * (1.0 / 6.0)));
    }
    return 1.0 - exp(-d);
}
