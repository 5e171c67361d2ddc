// Pre-integrated classification (src/transfer/preintegration.rs documents the model): a segment
// whose value runs linearly from s_front to s_back gets opacity 1 − exp(−depth · mean τ) and the
// extinction-weighted mean colour, from differences of running integrals stored as hi + lo f32
// plus each cell's increment, read with textureLoad.

#include "shared/classify.wgsl"

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

// One end of a segment: its value (clamped to the table) and the running integrals there, so
// that a sample's integrals, read once, serve both segments it bounds.
struct SegmentEnd {
    s: f32,
    missing: bool,
    integral: RunningIntegral,
}

fn segment_end(s: f32) -> SegmentEnd {
    let c = clamp(s, 0.0, 1.0);
    return SegmentEnd(c, s < MISSING_BELOW, running_integral(c));
}

// (T, K.rgb) from a to b; exactly the negation of b to a, so the ratios below do not depend on
// which end is larger.
fn integral_between(a: RunningIntegral, b: RunningIntegral) -> vec4<f32> {
    return ((b.hi - a.hi) + (b.lo - a.lo)) + (b.part - a.part);
}

// Straight colour and opacity of a segment `length_mm` long from `front` to `back`.
fn preintegrated(front: SegmentEnd, back: SegmentEnd, length_mm: f32) -> vec4<f32> {
    if front.missing || back.missing || length_mm <= 0.0 {
        return vec4<f32>(0.0);
    }
    let cell = 1.0 / (frame.lut_size - 1.0);
    var width = back.s - front.s;
    var d: vec4<f32>;
    if abs(width) < cell {
        // Closer than one table cell: the mean over the cell around the midpoint.
        let mid = clamp(0.5 * (front.s + back.s), 0.5 * cell, 1.0 - 0.5 * cell);
        let lo = mid - 0.5 * cell;
        let hi = mid + 0.5 * cell;
        d = integral_between(running_integral(lo), running_integral(hi));
        width = hi - lo;
    } else {
        d = integral_between(front.integral, back.integral);
    }
    // Mean extinction over the segment's values (d and width share their sign).
    let tau = d.x / width;
    if !(tau > 0.0) {
        return vec4<f32>(0.0);
    }
    let depth = length_mm * frame.depth_units_per_mm * tau;
    return vec4<f32>(clamp(d.yzw / d.x, vec3<f32>(0.0), vec3<f32>(1.0)), opacity_of_depth(depth));
}
