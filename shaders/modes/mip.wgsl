// Maximum (or, with MINIP, minimum) intensity projection: the extreme normalised value along the
// ray, as grey through the window or as the transfer function's colour.

#include "shared/classify.wgsl"
#ifdef LABEL_SURFACES
#include "shared/label_surface.wgsl"
#endif

// Samples taken before the march for a lower bound (leaping only).
const MIP_PRIME_SAMPLES: u32 = 4u;

struct Acc {
    extreme: f32,
    seen: bool,
    // Where the extreme was taken (LABEL_COLOUR: its label tints the pixel).
    at: vec3<f32>,
#ifdef LABEL_SURFACES
    // The labels' surfaces over the projection.
    over: SurfaceOver,
#endif
}

fn acc_init() -> Acc {
    var acc: Acc;
#ifdef MODE_MINIP
    acc.extreme = 3.0e38;
#else
    acc.extreme = -3.0e38;
#endif
#ifdef LABEL_SURFACES
    acc.over = surface_over();
#endif
    return acc;
}

#ifdef LEAP
// A node is skipped where its maximum cannot raise the ray's maximum (MinIP: its minimum cannot
// lower the minimum).
fn acc_skips(acc: Acc, node: u32) -> bool {
    let m = minmax[node];
#ifdef MODE_MINIP
    let skip = holds_no_finite_voxel(m) || m.x >= acc.extreme || cut_away(node);
#else
    let skip = holds_no_finite_voxel(m) || m.y <= acc.extreme || cut_away(node);
#endif
    return skip && !keeps_surface(node);
}

fn acc_leap_target(k: u32, after: u32) -> u32 {
    return after;
}

// Every region can be asked about from the ray's first sample on.
fn acc_needs_sample(acc: Acc) -> bool {
    return false;
}

// Leaps land past the region: never called.
fn acc_landing_waits(acc: Acc) -> bool {
    return false;
}

// A lower bound before the march: the ray's first sample, then MIP_PRIME_SAMPLES samples of its
// grid spread along it. Blocks whose maximum (MinIP: minimum) cannot beat them are skipped from
// the ray's first block on, where otherwise the running maximum starts from nothing. They are
// samples of the ray's own grid, so the result stays exactly the plain strategy's. Returns how
// many were taken and whether the pixel is already settled (the first sample saturates: the
// common MinIP case, where a ray entering through air ends at once). With RAY_SPLIT the parts
// of a ray share the priming: part `part` of `parts` takes every parts-th of those samples.
fn acc_prime(acc: ptr<function, Acc>, ray: Ray, part: u32, parts: u32) -> vec2<u32> {
    let n = min(MIP_PRIME_SAMPLES, ray.count);
    var taken = 0u;
    for (var j = part; j <= n; j += parts) {
        var k = 0u;
        if j > 0u {
            k = ((2u * j - 1u) * ray.count) / (2u * n);
        }
        let t = sample_distance(ray, k);
        let p = ray.entry + ray.box_per_mm * t;
        taken += 1u;
        // The projection's samples only (the surfaces are gathered in order by the march); a
        // saturated projection settles nothing where surfaces may lie behind (extreme_sample).
        if (extreme_sample(acc, p, sample_value(p)) & SAMPLE_STOP) != 0u {
            return vec2<u32>(taken, 1u);
        }
    }
    return vec2<u32>(taken, 0u);
}
#endif

#ifdef RAY_SPLIT
// The extreme of two parts of a ray: the front part's where they tie, as one loop keeps the
// first sample of a tie.
fn acc_combine(front: Acc, back: Acc) -> Acc {
#ifdef MODE_MINIP
    let back_wins = back.extreme < front.extreme;
#else
    let back_wins = back.extreme > front.extreme;
#endif
    var joined = front;
    if back_wins {
        joined = back;
    }
    joined.seen = front.seen || back.seen;
    return joined;
}

// A part of a ray needs nothing from before it.
fn acc_enter(acc: ptr<function, Acc>, ray: Ray, first: u32) -> u32 {
    return 0u;
}
#endif

fn acc_sample(acc: ptr<function, Acc>, ray: Ray, k: u32, t: f32, p: vec3<f32>, s_in: f32) -> u32 {
#ifdef LABEL_SURFACES
    var over = (*acc).over;
    let surfaced = over_sample(&over, ray, k, t, p);
    (*acc).over = over;
    if (surfaced & SAMPLE_STOP) != 0u {
        return surfaced;
    }
    return extreme_sample(acc, p, s_in) | surfaced;
#else
    return extreme_sample(acc, p, s_in);
#endif
}

// Sample value s_in at p in the projection.
fn extreme_sample(acc: ptr<function, Acc>, p: vec3<f32>, s_in: f32) -> u32 {
    let s = labelled_value(s_in, p);
    if s < MISSING_BELOW {
        return 0u;
    }
    (*acc).seen = true;
#ifdef MODE_MINIP
    let better = s < (*acc).extreme;
    (*acc).extreme = min((*acc).extreme, s);
    (*acc).at = select((*acc).at, p, better);
#ifdef EARLY_TERMINATION
#ifndef LABEL_SURFACES
    if (*acc).extreme <= frame.saturation {
        return SAMPLE_STOP | SAMPLE_CONTRIBUTED;
    }
#endif
#endif
#else
    let better = s > (*acc).extreme;
    (*acc).extreme = max((*acc).extreme, s);
    (*acc).at = select((*acc).at, p, better);
#ifdef EARLY_TERMINATION
#ifndef LABEL_SURFACES
    // Nothing can change the image once the value reaches the saturation point (but a label's
    // surface behind it can).
    if (*acc).extreme >= frame.saturation {
        return SAMPLE_STOP | SAMPLE_CONTRIBUTED;
    }
#endif
#endif
#endif
    return select(0u, SAMPLE_CONTRIBUTED, better);
}

fn acc_finish(acc: Acc, ray: Ray) -> vec4<f32> {
#ifdef LABEL_SURFACES
    return over_finish(acc.over, projection(acc));
#else
    return projection(acc);
#endif
}

// The projection's colour.
fn projection(acc: Acc) -> vec4<f32> {
    if !acc.seen {
        return frame.background;
    }
#ifdef MIP_TF_COLOR
    // The TF's colour weighted by its own (uncorrected) opacity over the background, so values
    // the TF hides show the background.
    let c = classify(acc.extreme);
    // The table holds the optical depth of a step; iso.y turns it into that of one d0.
    let a = opacity_of_depth(c.a * frame.steps_per_d0);
    return vec4<f32>(labelled_colour(c.rgb, acc.at) * a + (1.0 - a) * frame.background.rgb, 1.0);
#else
    let grey = clamp((acc.extreme - frame.window_lo) / (frame.window_hi - frame.window_lo), 0.0, 1.0);
    // Grey, or tinted by the label where the extreme was taken.
    return vec4<f32>(grey * labelled_colour(vec3<f32>(1.0), acc.at), 1.0);
#endif
}
