// Shadows (SHADOWS, lit DVR and isosurfaces): the share of the light that reaches a lit sample
// through the transfer function's opacity between it and the light (an isosurface's hit: 0 where
// the isosurface lies between them, else 1). A directional light's by a secondary
// ray marched from the sample towards the light, at samples every `shadow_step_mm` (the first
// one step from the sample: its own opacity is in its colour) up to the crop box or
// `shadow_reach_mm`, summing the table's optical depth scaled from the primary step to the
// shadow step; with LEAP it leaps over the nodes the primary ray would (their samples add no
// depth: exactly the same sum); with EARLY_TERMINATION it ends where the light falls below one
// 8-bit level. A headlight's is the opacity the primary ray gathered in front of the sample
// (the same samples, towards the eye); nothing lies in front of an isosurface's first crossing.
// The f64 twin is `shadow_transmittance` in src/reference/modes.rs.

// Optical depth past which rays that stop early call the light gone: −ln(1/255).
const SHADOW_GONE_DEPTH: f32 = 5.541264;

#include "shared/secondary.wgsl"

// The point of the unit square pixel px's shadow rays take on the light's disc: two hashes of
// the pixel rotated by the frame's sample, as `pixel_light_point` in src/sampling.rs.
fn light_point(px: vec2<u32>) -> vec2<f32> {
    let h = vec2<f32>(pixel_jitter(px), pixel_jitter(vec2<u32>(px.y + 1013u, px.x + 4099u)));
    return fract(h + (frame.shadow_sample - vec2<f32>(0.5)));
}

// The unit world direction towards the light from a pixel whose point on the light's disc is
// `u`: the light's own direction, or with a radius (softness) that point of the disc of radius
// tan(angle) in the plane across it (uniform over the disc's area).
fn towards_light(u: vec2<f32>) -> vec3<f32> {
    let l = -frame.light_dir;
    if frame.shadow_tan <= 0.0 {
        return l;
    }
    let across = plane_across(l);
    let r = frame.shadow_tan * sqrt(u.x);
    let phi = 6.283185307 * u.y;
    return normalize(l + r * (cos(phi) * across[0] + sin(phi) * across[1]));
}

// The directional light's transmittance to box position p on `ray`, for a ray holding `acc`
// (its leap predicate decides which nodes are empty).
fn light_transmittance(p: vec3<f32>, ray: Ray, acc_in: Acc) -> f32 {
    var acc = acc_in;
#ifdef MODE_ISO
    // The shadow ray leaves the surface on its side below the iso value: a node wholly below
    // holds nothing that blocks the light.
    acc.side = -1.0;
#endif
    let box_per_mm = ray.to_light;
    let length_mm = min(crop_exit_mm(p, box_per_mm), frame.shadow_reach_mm);
    let h = frame.shadow_step_mm;
    let per_step = h / frame.step_mm;
    var depth = 0.0;
#ifdef LEAP
    let leap = leap_ray(p, box_per_mm, 0.0);
    var until = 0u;
#endif
    var j = 1u;
    // Samples taken (counted with STATS only).
    var taken = 0u;
    loop {
        let t = f32(j) * h;
        if t >= length_mm {
            break;
        }
        let q = p + box_per_mm * t;
#ifdef LEAP
        if j >= until {
            let region = region_of(leaf_block(q), acc);
            let exit = exit_distance(leap, region.lo, region.hi);
            let after = max(u32(clamp(floor(exit / h) + 1.0, 0.0, 4.0e9)), j + 1u);
            if !region.matters {
                j = after;
                continue;
            }
            until = after;
        }
#endif
        depth += secondary_depth(q, per_step);
#ifdef STATS
        taken++;
#endif
        if depth >= BLOCKED_DEPTH {
            shadow_tally(taken);
            return 0.0;
        }
#ifdef EARLY_TERMINATION
        if depth > SHADOW_GONE_DEPTH {
            shadow_tally(taken);
            return 0.0;
        }
#endif
        j++;
    }
    shadow_tally(taken);
    return exp(-depth);
}

// A shadow ray ended having taken `taken` samples (STATS: the frame's counters; an atomic per
// shadow ray, the statistics variants only).
#ifdef STATS
fn shadow_tally(taken: u32) {
    count(COUNTER_SHADOW_RAYS, 1u);
    count(COUNTER_SHADOW_SAMPLES, taken);
}
#else
fn shadow_tally(taken: u32) {}
#endif
