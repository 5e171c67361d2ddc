// The ray loop, shared by the fragment and compute entry points and by every mode. Samples lie on
// one grid per ray, t_k = min((k + offset) * step, L) (`sample_distance`, shared/common.wgsl;
// src/sampling.rs documents the rule and the CPU reference implements the same). Leaping variants skip grid samples but never move them.
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
//       (modes that walk in block runs, LEAP_RUNS: all but DVR) before the march: samples of
//       the ray's grid that sharpen the leap predicate from the first block on (MIP's lower
//       bound); returns how many, and 1 where the pixel is settled; (0, 0) for most modes.
//       With RAY_SPLIT, part `part` of `parts` takes its share of them and every part starts
//       from the join of all shares (so only a mode whose acc_combine is idempotent, a maximum
//       or a minimum, may prime); otherwise (0, 1)
//   fn acc_needs_sample(acc: Acc) -> bool
//       (LEAP_RUNS) whether the ray must take its next sample before it may ask about any region
//       (isosurfaces: until a finite sample has given it its side); false in most modes
//   fn acc_landing_waits(acc: Acc) -> bool
//       (LEAP_RUNS) where a leap lands on a sample inside the region it leapt (acc_leap_target
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
//   fn acc_resume(acc, t, s)         after a leap, the sample at t starts the next segment
//   fn acc_tail(acc, ray)            the segment from the last sample to the exit
// A new mode is a new modes/*.wgsl implementing this, one include line below, and its key in
// variant.rs; nothing else in the loop or in leap/ changes.

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

#ifdef LEAP_RUNS
// No sample waits to be taken (march_samples).
const NO_LANDING: u32 = 0xffffffffu;

// Takes grid sample k of `ray`; whether it stops the ray.
fn take_sample(acc: ptr<function, Acc>, tally: ptr<function, Tally>, ray: Ray, k: u32) -> bool {
    let t = sample_distance(ray, k);
    let p = ray.entry + ray.box_per_mm * t;
    let r = acc_sample(acc, ray, k, t, p, sample_value(p));
    tally_sample(tally, r);
    return (r & SAMPLE_STOP) != 0u;
}
#endif

#ifdef SAMPLE_BATCH
// Sample k of the batch (value s already read); whether it stops the ray.
fn take_one(acc: ptr<function, Acc>, tally: ptr<function, Tally>, ray: Ray, k: u32, t: f32, p: vec3<f32>, s: f32) -> bool {
    let r = acc_sample(acc, ray, k, t, p, s);
    tally_sample(tally, r);
    return (r & SAMPLE_STOP) != 0u;
}

// Takes grid samples k .. min(k + 4, end) − 1 of `ray` in order, their four texture reads issued
// before the first is used, so that they overlap (src/render/raycast/variant.rs says where this
// is chosen). Samples past `end` are read (their positions clamp to the exit, `sample_distance`)
// but never used. Returns the next sample, and 1 where a sample returned SAMPLE_STOP (then the
// next sample is the stopping one's, as the one-by-one loop leaves it).
fn take_batch(acc: ptr<function, Acc>, tally: ptr<function, Tally>, ray: Ray, k: u32, end: u32) -> vec2<u32> {
    let t0 = sample_distance(ray, k);
    let t1 = sample_distance(ray, k + 1u);
    let t2 = sample_distance(ray, k + 2u);
    let t3 = sample_distance(ray, k + 3u);
    let p0 = ray.entry + ray.box_per_mm * t0;
    let p1 = ray.entry + ray.box_per_mm * t1;
    let p2 = ray.entry + ray.box_per_mm * t2;
    let p3 = ray.entry + ray.box_per_mm * t3;
    let s0 = sample_value(p0);
    let s1 = sample_value(p1);
    let s2 = sample_value(p2);
    let s3 = sample_value(p3);
    // Then each in order, up to `end` (written out, not as a loop over arrays, so that no
    // driver's compiler can put the values in memory or move a read after a use).
    if take_one(acc, tally, ray, k, t0, p0, s0) {
        return vec2<u32>(k, 1u);
    }
    if k + 1u >= end {
        return vec2<u32>(k + 1u, 0u);
    }
    if take_one(acc, tally, ray, k + 1u, t1, p1, s1) {
        return vec2<u32>(k + 1u, 1u);
    }
    if k + 2u >= end {
        return vec2<u32>(k + 2u, 0u);
    }
    if take_one(acc, tally, ray, k + 2u, t2, p2, s2) {
        return vec2<u32>(k + 2u, 1u);
    }
    if k + 3u >= end {
        return vec2<u32>(k + 3u, 0u);
    }
    if take_one(acc, tally, ray, k + 3u, t3, p3, s3) {
        return vec2<u32>(k + 3u, 1u);
    }
    return vec2<u32>(k + 4u, 0u);
}
#endif

// The ray of pixel `px` from `entry` to `exit` (box coordinates); its direction and count are
// left at zero when it has no length.
fn ray_between(entry: vec3<f32>, exit: vec3<f32>, px: vec2<u32>) -> Ray {
    let segment = exit - entry;
    let segment_mm = segment * frame.extent_mm;
    var ray: Ray;
    ray.entry = entry;
    ray.offset = sample_offset_of(px);
    ray.length_mm = length(segment_mm);
    if ray.length_mm > 0.0 {
        ray.box_per_mm = segment / ray.length_mm;
        ray.dir_world = segment_mm / ray.length_mm;
        ray.count = u32(ceil(ray.length_mm / frame.step_mm));
    }
    return ray;
}

#ifdef RAY_SPLIT
// The invocation's part of its pixel's ray (set by the compute entry point), and its pixel's
// slot in the workgroup.
var<private> split_part: u32;
var<private> split_pixel: u32;
#ifdef EARLY_TERMINATION
// Per pixel of the workgroup, one bit per part of its ray that stopped (SAMPLE_STOP).
var<workgroup> stopped_parts: array<atomic<u32>, WORKGROUP * SPLIT_GROUP_ROWS>;
#endif
#endif

// Whether the samples this invocation takes can still change the pixel: with RAY_SPLIT and
// EARLY_TERMINATION, not once a part in front of its own has stopped (nothing behind a stopped
// part changes the pixel: acc_combine drops it); otherwise always.
fn part_matters() -> bool {
#ifdef RAY_SPLIT
#ifdef EARLY_TERMINATION
    return (atomicLoad(&stopped_parts[split_pixel]) & ((1u << split_part) - 1u)) == 0u;
#else
    return true;
#endif
#else
    return true;
#endif
}

// Takes or leaps grid samples `first` .. `end` − 1 of `ray` into `acc`: the whole ray, or with
// RAY_SPLIT one part of it. Returns the sample it stopped at (past `end` where a leap overshot).
fn march_samples(acc: ptr<function, Acc>, tally: ptr<function, Tally>, ray: Ray, first: u32, end: u32) -> u32 {
    let entry = ray.entry;
    // Leaping walks in one of two ways, chosen per variant by measurement
    // (src/render/raycast/variant.rs): block runs with LEAP_RUNS (set only with LEAP), else
    // sample by sample.
#ifdef LEAP_RUNS
    // Block runs: each block that can matter is one run of samples in a tight inner loop
    // (with the distance field, each cube of such blocks; never with PREINTEGRATED: DVR does
    // not set LEAP_RUNS).
    // (The caller has primed `acc`, acc_prime.)
    let leap = leap_ray(entry, ray.box_per_mm, ray.offset);
    var k = first;
    // A sample the ray leapt to but has not taken (NO_LANDING: none): the last of a region that
    // cannot change the pixel, which isosurfaces land on (it brackets a crossing just past the
    // region). It is the sample before k, and is taken first in k's run where k's region can
    // matter; where that region cannot either, the ray leaps on without it.
    var landing = NO_LANDING;
    loop {
        if k >= end || !part_matters() {
            break;
        }
        if acc_needs_sample(*acc) {
            // Where the mode may not ask yet, one sample without a question (no sample waits
            // then: one waits only once the mode may ask). Not a run of one through the batch
            // below: on the H200 that took a 512² isosurface invocation from 48 registers to 60
            // and its frames to 1.03× as long (docs/benchmarks/nvidia-h200-iso-landing/review).
            if take_sample(acc, tally, ray, k) {
                break;
            }
            k += 1u;
            continue;
        }
        let t_k = sample_distance(ray, k);
        let region = leap_region(leap, entry + ray.box_per_mm * t_k, k, *acc, tally);
        let next = region.x;
        let run_end = min(region.y, end);
        if next != k {
            let leapt_from = select(k, landing, landing != NO_LANDING);
            tally_leap(tally, min(next, end) - leapt_from);
            landing = NO_LANDING;
            k = next;
            if k >= run_end {
                continue;
            }
            // Landed inside the region, on its last sample. Asking about it again (as before
            // e9c2c1e) cost a lookup per leap; the lookup past the region decides whether it is
            // needed (docs/benchmarks/nvidia-h200-iso-landing), unless the mode must take it
            // now, or the part ends with the region (then it is taken as the part's last run).
            if run_end < end && acc_landing_waits(*acc) {
                landing = k;
                k = run_end;
                continue;
            }
        } else if landing != NO_LANDING {
            // k's region can matter: the run starts at the sample before it.
            k = landing;
            landing = NO_LANDING;
        }
        var stopped = false;
#ifdef SAMPLE_BATCH
        loop {
            let taken = take_batch(acc, tally, ray, k, run_end);
            k = taken.x;
            if taken.y != 0u {
                stopped = true;
                break;
            }
            if k >= run_end {
                break;
            }
        }
#else
        loop {
            if take_sample(acc, tally, ray, k) {
                stopped = true;
                break;
            }
            k += 1u;
            if k >= run_end {
                break;
            }
        }
#endif
        if stopped {
            break;
        }
    }
#else
    // Sample by sample (DVR, whose rays end early at different samples): a lookup where the
    // sample passes the region the last one found can matter (a leaf block; with the distance
    // field, the cube of such blocks around it). Block runs measured slower for DVR
    // (docs/benchmarks/nvidia-h200-leap-walk, nvidia-h200-two-sided). RC and RC-t take this
    // loop without the leaping.
#ifdef LEAP
    var leap = leap_ray(entry, ray.box_per_mm, ray.offset);
#endif
    var k = first;
#ifdef SAMPLE_BATCH
    // Without leaping only (variant.rs): the plain loop four samples at a time.
    loop {
        if k >= end || !part_matters() {
            break;
        }
        let taken = take_batch(acc, tally, ray, k, end);
        k = taken.x;
        if taken.y != 0u {
            break;
        }
    }
#else
    loop {
        if k >= end || !part_matters() {
            break;
        }
        let t = sample_distance(ray, k);
        let p = entry + ray.box_per_mm * t;
#ifdef LEAP
        let next = leap_from(&leap, p, k, *acc, tally);
#ifndef PREINTEGRATED
        if next != k {
            tally_leap(tally, min(next, end) - k);
            k = next;
            continue;
        }
#endif
#endif
        let result = acc_sample(acc, ray, k, t, p, sample_value(p));
        tally_sample(tally, result);
        if (result & SAMPLE_STOP) != 0u {
            break;
        }
#ifdef LEAP
#ifdef PREINTEGRATED
        if next != k {
            // Sample k closed the segment into the empty region; the segments inside it add
            // nothing, and the region's last sample starts the segment out of it.
            let last = min(next, end) - 1u;
            if last > k {
                let t_last = sample_distance(ray, last);
                acc_resume(acc, t_last, sample_value(entry + ray.box_per_mm * t_last));
            }
            // Samples k + 1 .. next − 1 (sample k was taken; the resumed one is not counted
            // as a sample, as it is only read, not classified).
            tally_leap(tally, min(next, end) - k - 1u);
            k = next;
            continue;
        }
#endif
#endif
        k += 1u;
    }
#endif
#endif
    return k;
}

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
#ifdef LEAP_RUNS
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

#ifdef RAY_SPLIT
// Part `part` (of RAY_PARTS) of `ray`, the pixel in workgroup slot `pixel`: its grid samples
// count·part/RAY_PARTS .. count·(part + 1)/RAY_PARTS − 1, gathered from `primed` (what the
// ray's priming found, `primes` samples of it taken by this invocation; nothing more to take
// where it `settled` the pixel); the parts are joined in order by the mode's acc_combine
// (src/render/raycast/variant.rs says which variants split). Part 0 counts the ray.
fn march_part(ray: Ray, part: u32, pixel: u32, primed: Acc, primes: u32, settled: bool) -> Acc {
    split_part = part;
    split_pixel = pixel;
    var acc = primed;
    var tally = tally_new();
    for (var j = 0u; j < primes; j++) {
        tally_sample(&tally, 0u);
    }
    if ray.length_mm > 0.0 && !settled {
        let first = ray.count * part / RAY_PARTS;
        let end = ray.count * (part + 1u) / RAY_PARTS;
        let entered = acc_enter(&acc, ray, first);
        for (var j = 0u; j < entered; j++) {
            tally_sample(&tally, 0u);
        }
        let k = march_samples(&acc, &tally, ray, first, end);
#ifdef EARLY_TERMINATION
        if k < end {
            // Stopped (or gave up behind a stopped part): the parts behind need not go on.
            atomicOr(&stopped_parts[pixel], 1u << part);
        }
#endif
    }
    tally_ray(tally, part == 0u);
    return acc;
}
#endif
