// The ray loop, shared by the fragment and compute entry points and by every mode. Samples lie on
// one grid per ray, t_k = min((k + offset) * step, L) (src/sampling.rs documents the rule; the CPU
// reference implements the same). The mode module included below decides what a sample does
// (acc_sample), when a ray may stop, and the final colour; leaping variants skip grid samples but
// never move them.

#include "common.wgsl"
#include "classify.wgsl"
#ifdef MODE_DVR
#include "mode_dvr.wgsl"
#endif
#ifdef MODE_ISO
#include "mode_iso.wgsl"
#endif
#ifdef MODE_MIP
#include "mode_mip.wgsl"
#endif
#ifdef MODE_MINIP
#include "mode_mip.wgsl"
#endif
#ifdef MODE_XRAY
#include "mode_xray.wgsl"
#endif
#ifdef MODE_XRAY_ATTENUATION
#include "mode_xray.wgsl"
#endif
#ifdef STATS
#include "stats.wgsl"
#endif
#ifdef LEAP
#include "leap.wgsl"
#endif

// Casts the ray from `entry` to `exit` (box coordinates); returns the pixel colour.
fn march(entry: vec3<f32>, exit: vec3<f32>, px: vec2<u32>) -> vec4<f32> {
    let segment = exit - entry;
    let segment_mm = segment * frame.extent_mm.xyz;
    var ray: Ray;
    ray.entry = entry;
    ray.offset = sample_offset_of(px);
    ray.length_mm = length(segment_mm);
    var acc = acc_init();
#ifdef STATS
    var samples = 0u;
    var contributing = 0u;
    var leaps = 0u;
    var leapt = 0u;
#endif
    if ray.length_mm > 0.0 {
        let step = frame.step_mm;
        ray.box_per_mm = segment / ray.length_mm;
        ray.dir_world = segment_mm / ray.length_mm;
        ray.count = u32(ceil(ray.length_mm / step));
#ifdef PREINTEGRATED
        acc_start(&acc, ray);
#endif
#ifdef LEAP
        var leap = leap_ray(entry, ray.box_per_mm, ray.offset);
#endif
        var k = 0u;
        loop {
            if k >= ray.count {
                break;
            }
            let t = min((f32(k) + ray.offset) * step, ray.length_mm);
            let p = entry + ray.box_per_mm * t;
#ifdef LEAP
            let next = leap_from(&leap, p, k, acc_leap_query(acc));
#ifndef PREINTEGRATED
            if next != k {
#ifdef STATS
                leaps += 1u;
                leapt += min(next, ray.count) - k;
#endif
                k = next;
                continue;
            }
#endif
#endif
            let result = acc_sample(&acc, ray, k, t, p, sample_value(p));
#ifdef STATS
            samples += 1u;
            contributing += u32((result & SAMPLE_CONTRIBUTED) != 0u);
#endif
            if (result & SAMPLE_STOP) != 0u {
                break;
            }
#ifdef LEAP
#ifdef PREINTEGRATED
            if next != k {
                // Sample k closed the segment into the empty region; the segments inside it add
                // nothing, and the region's last sample starts the segment out of it.
                let last = min(next, ray.count) - 1u;
                if last > k {
                    let t_last = min((f32(last) + ray.offset) * step, ray.length_mm);
                    acc_resume(&acc, t_last, sample_value(entry + ray.box_per_mm * t_last));
                }
#ifdef STATS
                leaps += 1u;
                // Samples k + 1 .. next − 1 (sample k was taken; the resumed one is not counted
                // as a sample, as it is only read, not classified).
                leapt += min(next, ray.count) - k - 1u;
#endif
                k = next;
                continue;
            }
#endif
#endif
            k += 1u;
        }
#ifdef PREINTEGRATED
        if k >= ray.count {
            acc_tail(&acc, ray);
        }
#endif
    }
#ifdef STATS
    count(COUNTER_SAMPLES, samples);
    count(COUNTER_VISIBLE_SAMPLES, contributing);
    count(COUNTER_RAYS, 1u);
    count(COUNTER_LEAPS, leaps);
    count(COUNTER_LEAPT_SAMPLES, leapt);
#endif
    return acc_finish(acc, ray);
}
