// Pre-integrated classification (src/transfer/preintegration.rs documents the model): a segment
// whose value runs linearly from s_front to s_back gets opacity 1 − exp(−depth · mean τ) and the
// extinction-weighted mean colour, from differences of running integrals stored as hi + lo f32
// plus each cell's increment, read with textureLoad.

#include "classify.wgsl"

@group(0) @binding(4) var integral_tex: texture_2d<f32>;

// Running integrals at normalised value s: (T, K.rgb), as parts that subtract without
// cancellation: whole-entry hi and lo, and the partial cell.
struct RunningIntegral {
    hi: vec4<f32>,
    lo: vec4<f32>,
    part: vec4<f32>,
}

fn running_integral(s: f32) -> RunningIntegral {
    let n = u32(frame.lut_size);
    let x = clamp(s, 0.0, 1.0) * f32(n - 1u);
    let i = min(u32(floor(x)), n - 2u);
    let f = x - f32(i);
    let t = textureLoad(integral_tex, vec2<u32>(i, 0u), 0);
    let k_hi = textureLoad(integral_tex, vec2<u32>(i, 1u), 0);
    let k_lo = textureLoad(integral_tex, vec2<u32>(i, 2u), 0);
    let dk = textureLoad(integral_tex, vec2<u32>(i, 3u), 0);
    return RunningIntegral(
        vec4<f32>(t.x, k_hi.rgb),
        vec4<f32>(t.y, k_lo.rgb),
        vec4<f32>(t.z, dk.rgb) * f,
    );
}

// Straight colour and opacity of a segment `length_mm` long from s_front to s_back.
fn preintegrated(s_front: f32, s_back: f32, length_mm: f32) -> vec4<f32> {
    if min(s_front, s_back) < MISSING_BELOW || length_mm <= 0.0 {
        return vec4<f32>(0.0);
    }
    let cell = 1.0 / (frame.lut_size - 1.0);
    var lo = clamp(min(s_front, s_back), 0.0, 1.0);
    var hi = clamp(max(s_front, s_back), 0.0, 1.0);
    if hi - lo < cell {
        // Closer than one table cell: the mean over the cell around the midpoint.
        let mid = clamp(0.5 * (lo + hi), 0.5 * cell, 1.0 - 0.5 * cell);
        lo = mid - 0.5 * cell;
        hi = mid + 0.5 * cell;
    }
    let a = running_integral(lo);
    let b = running_integral(hi);
    let d = ((b.hi - a.hi) + (b.lo - a.lo)) + (b.part - a.part);
    if d.x <= 0.0 {
        return vec4<f32>(0.0);
    }
    let depth = length_mm * frame.iso.w * d.x / (hi - lo);
    return vec4<f32>(clamp(d.yzw / d.x, vec3<f32>(0.0), vec3<f32>(1.0)), opacity_of_depth(depth));
}
