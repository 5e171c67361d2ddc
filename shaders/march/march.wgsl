// The ray loop, shared by the fragment and compute entry points and by every mode. Samples lie on
// one grid per ray, t_k = min((k + offset) * step, L) (`sample_distance`, shared/common.wgsl;
// src/sampling.rs documents the rule and the CPU reference implements the same). Leaping loops
// skip grid samples but never move them.
//
// THE LOOPS. The variant's key picks one loop file, as it picks one mode file (`Loop` in
// src/render/raycast/variant.rs lists them with the measurements that chose each):
//   march/plain.wgsl       LOOP_PLAIN       RC and RC-t: every sample, four reads at a time
//   march/samplewise.wgsl  LOOP_SAMPLEWISE  leaping DVR: a lookup where a sample passes the region
//                                           the last one found
//   march/runs.wgsl        LOOP_RUNS        leaping isosurface, MIP, MinIP and X-ray: one question
//                                           per block, then its samples four reads at a time
// Each defines march_samples(acc, tally, ray, first, end) -> u32. With RAY_SPLIT (compute path,
// small images) march/parts.wgsl marches each ray in parts, each part through the same loop.
//
// THE MODE CONTRACT. Exactly one module of modes/ is included (by the MODE_* symbol of the
// variant, src/render/raycast/variant.rs); it decides what a sample does and defines:
//   struct Acc                                   what a ray gathers
//   fn acc_init() -> Acc
//   fn acc_sample(acc: ptr<function, Acc>, ray: Ray, k: u32, t: f32, p: vec3<f32>, s: f32) -> u32
//       sample k at distance t (mm), box position p, normalised value s; returns SAMPLE_STOP
//       (the ray may end: nothing behind can change the pixel) | SAMPLE_CONTRIBUTED (counted)
//   fn acc_finish(acc: Acc, ray: Ray) -> vec4<f32>      the pixel's colour
// and, for leaping variants (LEAP), its leap predicate and landing rule:
//   fn acc_skips(acc: Acc, node: u32) -> bool
//       whether nothing in pyramid node `node` can change the pixel, given what the ray holds
//       (reads `node_empty` or `minmax` of leap/leap.wgsl)
//   fn acc_leap_target(k: u32, after: u32) -> u32
//       where a leap from sample k lands, given the first sample `after` past the region
//   fn acc_reach(acc: Acc, low: u32, high: u32) -> vec2<u32>
//       (LEAP_DISTANCE) what the block's two field distances (build/distance.wgsl) mean to the
//       ray: x the distance d (the cube of d − 1 blocks around it is all of one kind), y 1
//       where that kind can matter
//   fn acc_prime(acc: ptr<function, Acc>, ray: Ray, part: u32, parts: u32) -> vec2<u32>
//       (modes that walk in block runs, LOOP_RUNS: all but DVR) before the march: samples of
//       the ray's grid that sharpen the leap predicate from the first block on (MIP's lower
//       bound); returns how many, and 1 where the pixel is settled; (0, 0) for most modes.
//       With RAY_SPLIT, part `part` of `parts` takes its share of them and every part starts
//       from the join of all shares (so only a mode whose acc_combine is idempotent, a maximum
//       or a minimum, may prime); otherwise (0, 1)
//   fn acc_needs_sample(acc: Acc) -> bool
//       (LOOP_RUNS) whether the ray must take its next sample before it may ask about any region
//       (isosurfaces: until a finite sample has given it its side); false in most modes
//   fn acc_landing_waits(acc: Acc) -> bool
//       (LOOP_RUNS) where a leap lands on a sample inside the region it leapt (acc_leap_target
//       before the region's end: isosurfaces), whether that sample may wait until the lookup
//       past the region says what follows can matter: true only where leaving it out changes
//       neither what the ray skips nor the samples that bracket a crossing (isosurfaces: in
//       volumes without missing voxels); false in modes that land past the region
// and, for variants that split each ray into parts marched by several invocations (RAY_SPLIT,
// compute path only), how two consecutive parts' gatherings join:
//   fn acc_combine(front: Acc, back: Acc) -> Acc
//   fn acc_enter(acc: ptr<function, Acc>, ray: Ray, first: u32) -> u32
//       a part starting at grid sample `first` takes up what the whole ray would hold there
//       (isosurfaces: the side of the sample before); returns the samples it read
// and, for pre-integrated DVR only (PREINTEGRATED), the segment hooks:
//   fn acc_start(acc, ray)           the entry value starts the first segment
//   fn acc_resume(acc, t, p, s)      after a leap, the sample at t (at p) starts the next segment
//   fn acc_tail(acc, ray)            the segment from the last sample to the exit
// A new mode is a new modes/*.wgsl implementing this, one include line below, and its key in
// variant.rs; nothing in march/ or leap/ changes.

#include "shared/common.wgsl"
#include "shared/classify.wgsl"
#include "shared/stats.wgsl"
#ifdef MODE_DVR
#include "modes/dvr.wgsl"
#endif
#ifdef MODE_ISO
#include "modes/iso.wgsl"
#endif
#ifdef MODE_MIP
#include "modes/mip.wgsl"
#endif
#ifdef MODE_MINIP
#include "modes/mip.wgsl"
#endif
#ifdef MODE_XRAY
#include "modes/xray.wgsl"
#endif
#ifdef MODE_XRAY_ATTENUATION
#include "modes/xray.wgsl"
#endif
#ifdef LEAP
#include "leap/leap.wgsl"
#endif

// The ray of pixel `px` from `entry` to `exit` (box coordinates); its direction and count are
// left at zero when it has no length.
fn ray_between(entry: vec3<f32>, exit: vec3<f32>, px: vec2<u32>) -> Ray {
    let segment = exit - entry;
    let segment_mm = segment * frame.extent_mm;
    var ray: Ray;
    ray.entry = entry;
    ray.offset = sample_offset_of(px);
#ifdef SHADOWS
    ray.to_light = towards_light(light_point(px)) / frame.extent_mm;
#endif
    ray.length_mm = length(segment_mm);
    if ray.length_mm > 0.0 {
        ray.box_per_mm = segment / ray.length_mm;
        ray.dir_world = segment_mm / ray.length_mm;
        ray.count = u32(ceil(ray.length_mm / frame.step_mm));
    }
    return ray;
}

#ifdef RAY_SPLIT
#include "march/parts.wgsl"
#else
// Every sample a whole ray takes can change the pixel (parts.wgsl: not those behind a stopped part).
fn part_matters() -> bool {
    return true;
}
#endif

#ifdef LOOP_PLAIN
#include "march/plain.wgsl"
#endif
#ifdef LOOP_SAMPLEWISE
#include "march/samplewise.wgsl"
#endif
#ifdef LOOP_RUNS
#include "march/runs.wgsl"
#endif

// Casts the ray from `entry` to `exit` (box coordinates); returns the pixel colour.
fn march(entry: vec3<f32>, exit: vec3<f32>, px: vec2<u32>) -> vec4<f32> {
    let ray = ray_between(entry, exit, px);
    var acc = acc_init();
    var tally = tally_new();
    if ray.length_mm > 0.0 {
#ifdef PREINTEGRATED
        acc_start(&acc, ray);
#endif
        var first = 0u;
#ifdef LOOP_RUNS
        // A pixel the priming settles takes no more samples.
        let primed = acc_prime(&acc, ray, 0u, 1u);
        for (var j = 0u; j < primed.x; j++) {
            tally_sample(&tally, 0u);
        }
        first = select(0u, ray.count, primed.y != 0u);
#endif
        let k = march_samples(&acc, &tally, ray, first, ray.count);
#ifdef PREINTEGRATED
        if k >= ray.count {
            acc_tail(&acc, ray);
        }
#endif
    }
    tally_ray(tally, true);
    return acc_finish(acc, ray);
}
