// Four samples at a time: the reads of the plain loop and of block runs.

// Sample k of the batch (value s already read); whether it stops the ray.
fn take_one(acc: ptr<function, Acc>, tally: ptr<function, Tally>, ray: Ray, k: u32, t: f32, p: vec3<f32>, s: f32) -> bool {
    let r = acc_sample(acc, ray, k, t, p, s);
    tally_sample(tally, r);
    return (r & SAMPLE_STOP) != 0u;
}

// Takes grid samples k .. min(k + 4, end) − 1 of `ray` in order, their four texture reads issued
// before the first is used, so that they overlap (the loops that take runs of samples with no
// leaping test between them: plain.wgsl, runs.wgsl). Samples past `end` are read (their positions clamp to the exit, `sample_distance`)
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
    // Bricked, each through its own brick with no branch: a batch where one lane crosses
    // into another brick costs its warp one round of reads, not two
    // (docs/benchmarks/nvidia-h100-bricks-stream §13).
    let s0 = inner_value(p0);
    let s1 = inner_value(p1);
    let s2 = inner_value(p2);
    let s3 = inner_value(p3);
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
