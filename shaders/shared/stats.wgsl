// Per-ray tallies for the statistics variants, as helpers the ray loop always calls: with STATS
// they count, and rays add their totals to 64-bit sums (pairs of 32-bit atomics) once, at their
// end; without it they are empty and compile to nothing (no counters binding, no atomics).

#include "shared/common.wgsl"

struct Tally {
#ifdef STATS
    samples: u32,
    contributing: u32,
    leaps: u32,
    // Grid samples skipped by leaping (with the samples taken, what RC-t takes).
    leapt: u32,
    // Questions asked of the leaping structure.
    lookups: u32,
#else
    unused: u32,
#endif
}

#ifdef STATS
@group(2) @binding(0) var<storage, read_write> counters: array<atomic<u32>>;

fn count(counter: u32, amount: u32) {
    if amount == 0u {
        return;
    }
    let old = atomicAdd(&counters[2u * counter], amount);
    if old + amount < old {
        atomicAdd(&counters[2u * counter + 1u], 1u);
    }
}
#endif

fn tally_new() -> Tally {
    var t: Tally;
    return t;
}

// A sample was taken; `result` holds acc_sample's bits.
fn tally_sample(t: ptr<function, Tally>, result: u32) {
#ifdef STATS
    (*t).samples += 1u;
    (*t).contributing += u32((result & SAMPLE_CONTRIBUTED) != 0u);
#endif
}

// The ray leapt over `skipped` grid samples.
fn tally_leap(t: ptr<function, Tally>, skipped: u32) {
#ifdef STATS
    (*t).leaps += 1u;
    (*t).leapt += skipped;
#endif
}

// The ray asked its leaping structure about the block (or cube) it entered.
fn tally_lookup(t: ptr<function, Tally>) {
#ifdef STATS
    (*t).lookups += 1u;
#endif
}

// The ray (or, with RAY_SPLIT, one part of it) ended: add its tallies to the frame's counters;
// `counts_ray` for one part of each ray only.
fn tally_ray(t: Tally, counts_ray: bool) {
#ifdef STATS
    count(COUNTER_SAMPLES, t.samples);
    count(COUNTER_VISIBLE_SAMPLES, t.contributing);
    count(COUNTER_RAYS, u32(counts_ray));
    count(COUNTER_LEAPS, t.leaps);
    count(COUNTER_LEAPT_SAMPLES, t.leapt);
    count(COUNTER_LOOKUPS, t.lookups);
#endif
}
