// Block runs (leaping isosurfaces, MIP, MinIP and X-ray): one question per block, then each block
// that can matter is one run of samples in a tight inner loop, four reads at a time (with the
// distance field, each cube of such blocks). Measured faster than sample by sample for these modes
// (docs/benchmarks/nvidia-h200-leap-walk, nvidia-h200-two-sided); never with PREINTEGRATED (DVR
// does not walk in runs). The caller has primed `acc` (acc_prime).

#include "march/batch.wgsl"

// No sample waits to be taken (march_samples).
const NO_LANDING: u32 = 0xffffffffu;

// Takes grid sample k of `ray`; whether it stops the ray.
fn take_sample(acc: ptr<function, Acc>, tally: ptr<function, Tally>, ray: Ray, k: u32) -> bool {
    let t = sample_distance(ray, k);
    let p = ray.entry + ray.box_per_mm * t;
    let r = acc_sample(acc, ray, k, t, p, inner_value(p));
    tally_sample(tally, r);
    return (r & SAMPLE_STOP) != 0u;
}

// Takes or leaps grid samples `first` .. `end` − 1 of `ray` into `acc`: the whole ray, or with
// RAY_SPLIT one part of it. Returns the sample it stopped at (past `end` where a leap overshot).
fn march_samples(acc: ptr<function, Acc>, tally: ptr<function, Tally>, ray: Ray, first: u32, end: u32) -> u32 {
    let entry = ray.entry;
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
            // below: that measured more registers and slower frames
            // (docs/benchmarks/nvidia-h200-iso-landing/review).
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
            // Landed inside the region, on its last sample. Asking about it again would cost a
            // lookup per leap; the lookup past the region decides whether it is needed
            // (docs/benchmarks/nvidia-h200-iso-landing), unless the mode must take it now, or
            // the part ends with the region (then it is taken as the part's last run).
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
        if stopped {
            break;
        }
    }
    return k;
}
