// Per-frame counters for the statistics variants only: 64-bit sums kept as (low, high) pairs of
// 32-bit atomics. Rays add their totals once, at their end.

const COUNTER_SAMPLES: u32 = 0u;
const COUNTER_VISIBLE_SAMPLES: u32 = 1u;
const COUNTER_RAYS: u32 = 2u;
const COUNTER_LEAPS: u32 = 3u;
// Grid samples skipped by leaping (with COUNTER_SAMPLES, what RC-t takes).
const COUNTER_LEAPT_SAMPLES: u32 = 4u;

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
