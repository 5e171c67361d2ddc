// Isosurface: the first sign change of (value − iso) between consecutive samples, refined by
// false position (secant steps that keep the bracket), coloured by the transfer function at the
// iso value and lit. Leaping hands over the side of the last sample so that no crossing is missed
// and the bracketing samples stay those of plain ray casting.

#include "shared/classify.wgsl"
#ifdef SHADING
#include "shared/shade.wgsl"
#ifdef SHADOWS
#include "shared/shadow.wgsl"
#endif
#ifdef OCCLUSION
#include "shared/occlusion.wgsl"
#endif
#endif
#ifdef LABEL_SURFACES
#include "shared/label_surface.wgsl"
#endif

struct Acc {
    // Side of the previous sample: -1 below the iso value, +1 at or above, 0 before the first.
    side: f32,
    prev_t: f32,
    prev_d: f32,
    hit: bool,
    hit_p: vec3<f32>,
#ifdef LABEL_SURFACES
    // The labels' surfaces in front of the isosurface.
    over: SurfaceOver,
#endif
}

fn acc_init() -> Acc {
    var acc: Acc;
#ifdef LABEL_SURFACES
    acc.over = surface_over();
#endif
    return acc;
}

#ifdef LEAP
// A node is skipped where it lies wholly on the side of the iso value the ray is already on, or
// holds no finite value. A ray without a side yet skips only the latter: a region wholly above,
// a gap of missing voxels and one wholly below hold a crossing that plain ray casting finds across
// the gap (and such a ray asks nothing anyway, acc_needs_sample).
fn acc_skips(acc: Acc, node: u32) -> bool {
    let m = minmax[node];
    let iso = frame.iso_threshold;
    let skip = holds_no_finite_voxel(m) || (m.y < iso && acc.side < 0.0)
        || (m.x >= iso && acc.side > 0.0);
    return skip && !keeps_surface(node);
}

// Land on the region's last sample, so the crossing after it is bracketed by the same two
// samples as without leaping; where that is sample k itself, do not leap.
fn acc_leap_target(k: u32, after: u32) -> u32 {
    return select(k, after - 1u, after - 1u > k);
}
#ifdef LEAP_DISTANCE
// The field's sides (RULE_ISO flags): `below` the distance to the nearest block not wholly below
// the iso value, `above` to the nearest not wholly at or above it. A ray below skips cubes of
// blocks wholly below, a ray above cubes wholly above; for a ray without a side (which asks
// nothing, acc_needs_sample) the block can matter.
fn acc_reach(acc: Acc, below: u32, above: u32) -> vec2<u32> {
    if acc.side == 0.0 {
        return vec2<u32>(1u, 1u);
    }
    let d = select(above, below, acc.side < 0.0);
    return vec2<u32>(d, u32(d == 0u));
}
#endif

// A ray without a side (no finite sample taken yet) takes its samples one by one rather than a
// block's run (it could skip only regions of missing voxels, acc_skips). Usually the ray's first
// sample gives the side.
fn acc_needs_sample(acc: Acc) -> bool {
    return acc.side == 0.0;
}

// The landing sample lies in a region the ray skips by its side (or holding no finite value), so
// taking it leaves the side, and so what the ray skips, as it is: it may wait, unless the volume
// has missing voxels: a sample that does not wait may be the last finite one before a crossing
// past missing samples, which plain ray casting brackets with it.
fn acc_landing_waits(acc: Acc) -> bool {
    return frame.all_finite != 0u;
}

// Nothing to learn before the march.
fn acc_prime(acc: ptr<function, Acc>, ray: Ray, part: u32, parts: u32) -> vec2<u32> {
    return vec2<u32>(0u);
}
#endif

#ifdef RAY_SPLIT
// The first crossing of two parts of a ray: the front part's where it has one.
fn acc_combine(front: Acc, back: Acc) -> Acc {
    if front.hit {
        return front;
    }
    return back;
}

// A part starting at sample `first` takes up what the whole ray's loop would hold there: the
// side of the last sample before it that is not missing (so that a crossing between the two
// parts is bracketed by the same two samples). Returns how many samples it read.
fn acc_enter(acc: ptr<function, Acc>, ray: Ray, first: u32) -> u32 {
    var k = first;
    loop {
        if k == 0u {
            break;
        }
        k -= 1u;
        let t = sample_distance(ray, k);
        let d = sample_value(ray.entry + ray.box_per_mm * t) - frame.iso_threshold;
        if d + frame.iso_threshold >= MISSING_BELOW {
            (*acc).side = select(-1.0, 1.0, d >= 0.0);
            (*acc).prev_t = t;
            (*acc).prev_d = d;
            break;
        }
    }
    return first - k;
}
#endif

fn acc_sample(acc: ptr<function, Acc>, ray: Ray, k: u32, t: f32, p: vec3<f32>, s: f32) -> u32 {
    if (*acc).hit {
        // Plain RC marches on without effect.
        return 0u;
    }
#ifdef LABEL_SURFACES
    // A label's surface entered before this sample: in front of the isosurface unless the
    // isosurface's crossing in the same step lies nearer (iso_sample adds it then).
    var track = (*acc).over.track;
    let surface = surface_before(&track, ray, k, t, p);
    (*acc).over.track = track;
    let r = iso_sample(acc, ray, t, s, surface);
    if !(*acc).hit && surface.colour.a > 0.0 {
        var added = (*acc).over;
        let stop = over_add(&added, surface.colour);
        (*acc).over = added;
        return stop | r;
    }
    return r;
#else
    return iso_sample(acc, ray, t, s, 0.0);
#endif
}

#ifndef LABEL_SURFACES
// No surfaces: a stand-in for their hit.
alias SurfaceHit = f32;
#endif

// Sample value s at distance t: the isosurface's crossing since the last sample, if any.
// `surface` (LABEL_SURFACES) is a label's surface entered in the same step: where the
// isosurface's crossing lies behind it, it is added first.
fn iso_sample(acc: ptr<function, Acc>, ray: Ray, t: f32, s: f32, surface: SurfaceHit) -> u32 {
    let d = s - frame.iso_threshold;
    let side = select(-1.0, 1.0, d >= 0.0);
    if (*acc).side != 0.0 && side != (*acc).side && s >= MISSING_BELOW {
        var t0 = (*acc).prev_t;
        var d0 = (*acc).prev_d;
        var t1 = t;
        var d1 = d;
        for (var i = 0u; i < frame.iso_refine; i++) {
            let tm = t0 + (t1 - t0) * clamp(d0 / (d0 - d1), 0.0, 1.0);
            let dm = sample_value(ray.entry + ray.box_per_mm * tm) - frame.iso_threshold;
            if (dm >= 0.0) == (d0 >= 0.0) {
                t0 = tm;
                d0 = dm;
            } else {
                t1 = tm;
                d1 = dm;
            }
        }
        let th = t0 + (t1 - t0) * clamp(d0 / (d0 - d1), 0.0, 1.0);
        let hit_p = ray.entry + ray.box_per_mm * th;
#ifdef LABEL_INSIDE
        // A crossing outside the shown labels is cut away: the ray goes on, on its new side.
        if !inside_labels(hit_p) {
            (*acc).side = side;
            (*acc).prev_t = t;
            (*acc).prev_d = d;
            return 0u;
        }
#endif
#ifdef LABEL_SURFACES
        if surface.colour.a > 0.0 && surface.t <= th {
            var added = (*acc).over;
            over_add(&added, surface.colour);
            (*acc).over = added;
        }
#endif
        (*acc).hit = true;
        (*acc).hit_p = hit_p;
#ifdef EARLY_TERMINATION
        return SAMPLE_STOP | SAMPLE_CONTRIBUTED;
#else
        return SAMPLE_CONTRIBUTED;
#endif
    }
    if s >= MISSING_BELOW {
        (*acc).side = side;
        (*acc).prev_t = t;
        (*acc).prev_d = d;
    }
    return 0u;
}

fn acc_finish(acc: Acc, ray: Ray) -> vec4<f32> {
#ifdef LABEL_SURFACES
    return over_finish(acc.over, isosurface(acc, ray));
#else
    return isosurface(acc, ray);
#endif
}

// The isosurface's colour where the ray hit it, else the background.
fn isosurface(acc: Acc, ray: Ray) -> vec4<f32> {
    if !acc.hit {
        return frame.background;
    }
    var color = classify(frame.iso_threshold).rgb;
    if frame.colour_volume != 0u {
        color = sample_colour(acc.hit_p);
    }
    color = labelled_colour(color, acc.hit_p);
#ifdef SHADING
    let g = gradient(acc.hit_p);
    // The shares of the light and of the ambient light that reach the hit.
    var reach = vec2<f32>(1.0);
#ifdef SHADOWS
    // Nothing lies in front of the first crossing: a headlight reaches it whole.
    if frame.headlight == 0u {
        reach.x = light_transmittance(acc.hit_p, ray, acc);
    }
#endif
#ifdef OCCLUSION
    reach.y = occlusion_at(acc.hit_p, g, ray);
#endif
    color = phong_shadowed(color, g, ray.dir_world, reach);
#endif
    return vec4<f32>(color, 1.0);
}
