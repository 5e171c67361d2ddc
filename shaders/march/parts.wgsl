// Rays in parts (RAY_SPLIT, compute path only): each pixel's ray in RAY_PARTS parts, one
// invocation each, joined in order by the mode's acc_combine (shaders/entry/raycast_compute.wgsl
// joins them; src/render/raycast/variant.rs says which variants split, and why).

// The invocation's part of its pixel's ray (set by march_part), and its pixel's slot in the
// workgroup.
var<private> split_part: u32;
var<private> split_pixel: u32;
#ifdef EARLY_TERMINATION
// Per pixel of the workgroup, one bit per part of its ray that stopped (SAMPLE_STOP).
var<workgroup> stopped_parts: array<atomic<u32>, WORKGROUP * SPLIT_GROUP_ROWS>;
#endif

// Whether the samples this invocation takes can still change the pixel: with EARLY_TERMINATION,
// not once a part in front of its own has stopped (nothing behind a stopped part changes the
// pixel: acc_combine drops it).
fn part_matters() -> bool {
#ifdef EARLY_TERMINATION
    return (atomicLoad(&stopped_parts[split_pixel]) & ((1u << split_part) - 1u)) == 0u;
#else
    return true;
#endif
}

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
