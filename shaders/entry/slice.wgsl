// A slice view: each pixel's value sampled from the volume texture at the voxel coordinates of
// its centre (trilinear from eight texel loads with exact f32 weights, clamp-to-edge inside the
// volume's box, or the nearest voxel), written as a value in data units (NaN where nothing is:
// outside the box or a missing sample) and as grey through the window. The f64 reference is
// src/reference/slice.rs; the pixel grid comes from src/mpr/view.rs (`VoxelGrid`).

#include "generated/constants.wgsl"

// `SliceParams` in src/render/gpu_data.rs.
struct SliceParams {
    // Voxel coordinates of pixel (0, 0)'s centre (w unused).
    first: vec4<f32>,
    // One pixel to the right, in voxel coordinates (w unused).
    step_x: vec4<f32>,
    // One pixel down (w unused).
    step_y: vec4<f32>,
    // Between two samples of a thick slab, along the normal (w unused).
    slab_step: vec4<f32>,
    width: u32,
    height: u32,
    // 1: nearest voxel; 0: trilinear.
    nearest: u32,
    // u32 words per row of `image` (rows padded for a copy into a texture).
    pitch: u32,
    // Largest integer of a unorm texture (255, 65535): u = round(texel * texel_max) recovers
    // its integer exactly; 0 for a float texture (u = texel, which holds the normalised value).
    texel_max: f32,
    // Data value = u * unit_scale + unit_bias.
    unit_scale: f32,
    unit_bias: f32,
    // The window (data units): grey 0 at window_lo, 255 at window_hi.
    window_lo: f32,
    window_hi: f32,
    // Samples across a thick slab, centred on the plane (1: a thin slice), and how they
    // combine (SLAB_MIP, SLAB_MINIP, SLAB_MEAN).
    slab_count: u32,
    slab_mode: u32,
    _pad0: u32,
}

@group(0) @binding(0) var volume: texture_3d<f32>;
@group(0) @binding(1) var<uniform> params: SliceParams;
@group(0) @binding(2) var<storage, read_write> values: array<f32>;
@group(0) @binding(3) var<storage, read_write> image: array<u32>;

// Texel `i` as u (see `texel_max`): exact integers for unorm textures; a float texture's
// MISSING marker stays far below MISSING_BELOW.
fn texel(i: vec3<i32>) -> f32 {
    let t = textureLoad(volume, i, 0).r;
    if params.texel_max > 0.0 {
        return round(t * params.texel_max);
    }
    return t;
}

// Whether u is the MISSING marker (only float textures hold it).
fn missing(u: f32) -> bool {
    return params.texel_max == 0.0 && u < MISSING_BELOW;
}

fn nan() -> f32 {
    let bits = 0x7fc00000u;
    return bitcast<f32>(bits);
}

// u at voxel coordinates `v` (inside the box), trilinear or nearest; a missing u where a
// missing texel takes part.
fn sample_units(v: vec3<f32>) -> f32 {
    let dims = vec3<i32>(textureDimensions(volume));
    let top = vec3<f32>(dims - vec3<i32>(1));
    if params.nearest == 1u {
        let i = clamp(vec3<i32>(floor(v + vec3<f32>(0.5))), vec3<i32>(0), dims - vec3<i32>(1));
        return texel(i);
    }
    let x = clamp(v, vec3<f32>(0.0), top);
    let base = floor(x);
    let f = x - base;
    let lo = vec3<i32>(base);
    let hi = min(lo + vec3<i32>(1), dims - vec3<i32>(1));
    var sum = 0.0;
    for (var c = 0u; c < 8u; c = c + 1u) {
        let pick = vec3<bool>((c & 1u) != 0u, (c & 2u) != 0u, (c & 4u) != 0u);
        let w3 = select(vec3<f32>(1.0) - f, f, pick);
        let w = w3.x * w3.y * w3.z;
        if w == 0.0 {
            continue;
        }
        let u = texel(select(lo, hi, pick));
        if missing(u) {
            return u;
        }
        sum = sum + w * u;
    }
    return sum;
}

fn grey(value: f32) -> f32 {
    if value != value {
        return 0.0;
    }
    if params.window_hi > params.window_lo {
        return clamp((value - params.window_lo) / (params.window_hi - params.window_lo), 0.0, 1.0);
    }
    return select(0.0, 1.0, value >= params.window_hi);
}

// The value (data units) at voxel coordinates `v`; NaN outside the box or where a missing
// sample takes part.
fn value_at(v: vec3<f32>) -> f32 {
    let dims = vec3<f32>(textureDimensions(volume));
    let inside = all(v >= vec3<f32>(-0.5)) && all(v <= dims - vec3<f32>(0.5));
    if inside {
        let u = sample_units(v);
        if !missing(u) {
            return u * params.unit_scale + params.unit_bias;
        }
    }
    return nan();
}

@compute @workgroup_size(WORKGROUP, WORKGROUP, 1)
fn slice(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let v = params.first.xyz + f32(id.x) * params.step_x.xyz + f32(id.y) * params.step_y.xyz;
    var value = nan();
    if params.slab_count <= 1u {
        value = value_at(v);
    } else {
        // Samples at (s − (count − 1) / 2) steps from the plane; those with no value are left out.
        let middle = f32(params.slab_count - 1u) * 0.5;
        var sum = 0.0;
        var n = 0u;
        for (var s = 0u; s < params.slab_count; s = s + 1u) {
            let x = value_at(v + (f32(s) - middle) * params.slab_step.xyz);
            if x != x {
                continue;
            }
            if n == 0u {
                value = x;
            } else if params.slab_mode == SLAB_MIP {
                value = max(value, x);
            } else if params.slab_mode == SLAB_MINIP {
                value = min(value, x);
            }
            sum = sum + x;
            n = n + 1u;
        }
        if params.slab_mode == SLAB_MEAN && n > 0u {
            value = sum / f32(n);
        }
    }
    values[id.y * params.width + id.x] = value;
    let g = grey(value);
    image[id.y * params.pitch + id.x] = pack4x8unorm(vec4<f32>(g, g, g, 1.0));
}
