// Sampling the volume and post-classification through the transfer-function table.

#include "shared/common.wgsl"
#include "shared/labels.wgsl"

// Non-finite voxels are stored far below 0 (see src/render/volume_texture/encoding.rs): the texture
// unit's blend of any that take part falls below MISSING_BELOW (generated/constants.wgsl).
// Normalised values below MISSING_BELOW are missing samples: transparent.

// The normalised value (0 = volume minimum, 1 = maximum) at box position p, trilinearly
// interpolated by the texture unit (shared/volume.wgsl); in volumes with non-finite voxels (MISSING_VOXELS), where
// one takes part, from the finite ones alone (sample_finite).
fn sample_value(p: vec3<f32>) -> f32 {
    return value_of(volume_filtered(linear_clamp, p).r, p);
}

// sample_value at a position p inside the box (a ray's sample): bricks need no clamp there.
fn inner_value(p: vec3<f32>) -> f32 {
    return value_of(volume_inner(linear_clamp, p).r, p);
}

// The normalised value of texel `texel` read at p.
fn value_of(texel: f32, p: vec3<f32>) -> f32 {
    let s = texel * frame.texel_scale + frame.texel_bias;
#ifdef MISSING_VOXELS
    if s < MISSING_BELOW {
        return sample_finite(p);
    }
#endif
    return s;
}

// The value at p from the finite voxels of its eight: their trilinear weights renormalised, so
// that a non-finite voxel takes no finite neighbour with it; missing (MISSING_BELOW − 1) where
// they weigh less than half (p lies nearer non-finite voxels). src/reference/trilinear.rs twins it.
#ifdef MISSING_VOXELS
fn sample_finite(p: vec3<f32>) -> f32 {
    let dims = volume_dims();
    let v = clamp(p * vec3<f32>(dims) - vec3<f32>(0.5), vec3<f32>(0.0), vec3<f32>(dims - vec3<i32>(1)));
    let base = floor(v);
    let f = v - base;
    let lo = vec3<i32>(base);
    let hi = min(lo + vec3<i32>(1), dims - vec3<i32>(1));
    // The eight corners unrolled (x fastest), each value and its weight.
    var acc = vec2<f32>(0.0);
    acc += corner(vec3<i32>(lo.x, lo.y, lo.z), (1.0 - f.x) * (1.0 - f.y) * (1.0 - f.z));
    acc += corner(vec3<i32>(hi.x, lo.y, lo.z), f.x * (1.0 - f.y) * (1.0 - f.z));
    acc += corner(vec3<i32>(lo.x, hi.y, lo.z), (1.0 - f.x) * f.y * (1.0 - f.z));
    acc += corner(vec3<i32>(hi.x, hi.y, lo.z), f.x * f.y * (1.0 - f.z));
    acc += corner(vec3<i32>(lo.x, lo.y, hi.z), (1.0 - f.x) * (1.0 - f.y) * f.z);
    acc += corner(vec3<i32>(hi.x, lo.y, hi.z), f.x * (1.0 - f.y) * f.z);
    acc += corner(vec3<i32>(lo.x, hi.y, hi.z), (1.0 - f.x) * f.y * f.z);
    acc += corner(vec3<i32>(hi.x, hi.y, hi.z), f.x * f.y * f.z);
    return select(MISSING_BELOW - 1.0, acc.x / max(acc.y, 1.0e-6), acc.y >= 0.5);
}

// A corner's weighted value and weight, (0, 0) where its voxel is not finite.
fn corner(i: vec3<i32>, w: f32) -> vec2<f32> {
    let s = volume_load(i).r * frame.texel_scale + frame.texel_bias;
    return select(vec2<f32>(0.0), vec2<f32>(w * s, w), w > 0.0 && s >= MISSING_BELOW);
}
#endif

// A colour volume's own colour at p (its texels hold luminance, red, green, blue: the texture
// unit blends the colour as it blends the value).
fn sample_colour(p: vec3<f32>) -> vec3<f32> {
    return volume_filtered(linear_clamp, p).gba;
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
