// X-ray projection. The integrand is the windowed value f = clamp((s − lo)/(hi − lo), 0, 1),
// integrated over the path with each sample's segment length. The mean mode divides by the path
// length inside the volume (known analytically, so leaping over f = 0 changes nothing); the
// attenuation mode shows 1 − exp(−density · ∫f ds), like a radiograph.

#include "shared/classify.wgsl"
#ifdef LABEL_SURFACES
#include "shared/label_surface.wgsl"
#endif

struct Acc {
    integral_mm: f32,
#ifdef LABEL_SURFACES
    // The labels' surfaces over the projection.
    over: SurfaceOver,
#endif
}

fn acc_init() -> Acc {
    var acc: Acc;
    acc.integral_mm = 0.0;
#ifdef LABEL_SURFACES
    acc.over = surface_over();
#endif
    return acc;
}

#ifdef LEAP
// A node is skipped where no value lies above the window's low end: it adds nothing to the
// integral (and the mean divides by the analytic path length).
fn acc_skips(acc: Acc, node: u32) -> bool {
    let m = minmax[node];
    let skip = holds_no_finite_voxel(m) || m.y <= frame.window_lo || cut_away(node);
    return skip && !keeps_surface(node);
}

fn acc_leap_target(k: u32, after: u32) -> u32 {
    return after;
}

#ifdef LEAP_DISTANCE
// The field is built from the emptiness flags (what lies at or below the window's low end):
// two-sided.
fn acc_reach(acc: Acc, low: u32, high: u32) -> vec2<u32> {
    return reach_two_sided(low, high);
}
#endif
// Every region can be asked about from the ray's first sample on.
fn acc_needs_sample(acc: Acc) -> bool {
    return false;
}

// Leaps land past the region: never called.
fn acc_landing_waits(acc: Acc) -> bool {
    return false;
}

// Nothing to learn before the march.
fn acc_prime(acc: ptr<function, Acc>, ray: Ray, part: u32, parts: u32) -> vec2<u32> {
    return vec2<u32>(0u);
}
#endif

#ifdef RAY_SPLIT
// The integral over two parts of a ray.
fn acc_combine(front: Acc, back: Acc) -> Acc {
    var joined = front;
    joined.integral_mm += back.integral_mm;
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
    return integral_sample(acc, ray, k, p, s_in) | surfaced;
#else
    return integral_sample(acc, ray, k, p, s_in);
#endif
}

// Sample k's value s_in at p in the integral.
fn integral_sample(acc: ptr<function, Acc>, ray: Ray, k: u32, p: vec3<f32>, s_in: f32) -> u32 {
    let s = labelled_value(s_in, p);
    if s < MISSING_BELOW {
        return 0u;
    }
    let f = clamp((s - frame.window_lo) / (frame.window_hi - frame.window_lo), 0.0, 1.0);
    if f <= 0.0 {
        return 0u;
    }
    let segment = min(frame.step_mm, ray.length_mm - f32(k) * frame.step_mm);
    (*acc).integral_mm += f * segment;
#ifdef MODE_XRAY_ATTENUATION
#ifdef EARLY_TERMINATION
#ifndef LABEL_SURFACES
    // Past an optical depth of ln(255) the radiograph is within 1/255 of white (a label's
    // surface behind can still show).
    if frame.xray_density_per_mm * (*acc).integral_mm > 5.5413 {
        return SAMPLE_STOP | SAMPLE_CONTRIBUTED;
    }
#endif
#endif
#endif
    return SAMPLE_CONTRIBUTED;
}

fn acc_finish(acc: Acc, ray: Ray) -> vec4<f32> {
#ifdef LABEL_SURFACES
    return over_finish(acc.over, projection(acc, ray));
#else
    return projection(acc, ray);
#endif
}

// The projection's grey.
fn projection(acc: Acc, ray: Ray) -> vec4<f32> {
#ifdef MODE_XRAY_ATTENUATION
    let grey = 1.0 - exp(-frame.xray_density_per_mm * acc.integral_mm);
#else
    // A path of zero length (a ray that touches an edge or a corner, where the f32 entry and exit
    // coincide) has no mean, and 0/0 would be NaN: it shows the background, as a ray that misses.
    if !(ray.length_mm > 0.0) {
        return frame.background;
    }
    let grey = clamp(acc.integral_mm / ray.length_mm, 0.0, 1.0);
#endif
    return vec4<f32>(vec3<f32>(grey), 1.0);
}
