// The ray loop, shared by the fragment and compute entry points. Samples lie on one grid per ray,
// t_k = min((k + offset) * step, L), with the last, partial segment's opacity weighted by its
// length (src/sampling.rs documents the rule; the CPU reference implements the same). Leaping
// variants skip grid samples but never move them.

#include "common.wgsl"
#include "classify.wgsl"
#ifdef STATS
#include "stats.wgsl"
#endif
#ifdef LEAP
#include "leap.wgsl"
#endif

// Composites the ray from `entry` to `exit` (box coordinates) front to back over the background.
fn march(entry: vec3<f32>, exit: vec3<f32>) -> vec4<f32> {
    let segment = exit - entry;
    let length_mm = length(segment * frame.extent_mm.xyz);
    var acc = vec4<f32>(0.0);
#ifdef STATS
    var samples = 0u;
    var visible = 0u;
    var leaps = 0u;
#endif
    if length_mm > 0.0 {
        let step = frame.step_mm;
        let count = u32(ceil(length_mm / step));
        let box_per_mm = segment / length_mm;
#ifdef LEAP
        var ray = leap_ray(entry, box_per_mm);
#endif
        var k = 0u;
        loop {
            if k >= count {
                break;
            }
            let t = min((f32(k) + frame.sample_offset) * step, length_mm);
            let p = entry + box_per_mm * t;
#ifdef LEAP
            let next = leap_from(&ray, p, k);
            if next != k {
                k = next;
#ifdef STATS
                leaps += 1u;
#endif
                continue;
            }
#endif
            var c = classify(sample_value(p));
#ifdef STATS
            samples += 1u;
            visible += u32(c.a > 0.0);
#endif
            if k + 1u == count {
                // The last segment may be shorter than a step: scale its optical depth.
                let w = clamp((length_mm - f32(k) * step) / step, 0.0, 1.0);
                c.a = select(1.0 - pow(1.0 - c.a, w), 1.0, c.a >= 1.0);
            }
            acc += (1.0 - acc.a) * vec4<f32>(c.rgb * c.a, c.a);
#ifdef EARLY_TERMINATION
            if acc.a > frame.termination_alpha {
                break;
            }
#endif
            k += 1u;
        }
    }
#ifdef STATS
    count(COUNTER_SAMPLES, samples);
    count(COUNTER_VISIBLE_SAMPLES, visible);
    count(COUNTER_RAYS, 1u);
    count(COUNTER_LEAPS, leaps);
#endif
    return vec4<f32>(acc.rgb + (1.0 - acc.a) * frame.background.rgb, 1.0);
}
