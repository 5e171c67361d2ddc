// The plain loop (RC, and RC-t where the mode stops the ray): every grid sample from `first` to
// `end`, four texture reads at a time (batch.wgsl; docs/benchmarks/nvidia-h200-sample-batch).

#include "march/batch.wgsl"

// Takes grid samples `first` .. `end` − 1 of `ray` into `acc`: the whole ray, or with RAY_SPLIT
// one part of it. Returns the sample it stopped at.
fn march_samples(acc: ptr<function, Acc>, tally: ptr<function, Tally>, ray: Ray, first: u32, end: u32) -> u32 {
    var k = first;
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
    return k;
}
