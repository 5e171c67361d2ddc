// DVR: front-to-back compositing with post-classification and opacity correction, or with
// PREINTEGRATED, of the segments between consecutive samples (sample k closes the segment from
// the previous sample, or from the entry point for k = 0).

#include "shared/classify.wgsl"
#ifdef PREINTEGRATED
#include "shared/preintegrate.wgsl"
#endif
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
    color: vec4<f32>,
#ifdef PREINTEGRATED
    // The segment's front end (the previous sample) and its distance.
    front: SegmentEnd,
    front_t: f32,
#endif
#ifdef LABEL_SURFACES
    track: SurfaceTrack,
#endif
}

fn acc_init() -> Acc {
    var acc: Acc;
    acc.color = vec4<f32>(0.0);
#ifdef LABEL_SURFACES
    acc.track = surface_track();
#endif
    return acc;
}

#ifdef PREINTEGRATED
// The ray's entry value starts the first segment.
fn acc_start(acc: ptr<function, Acc>, ray: Ray) {
    (*acc).front = segment_end(labelled_value(sample_value(ray.entry), ray.entry));
    (*acc).front_t = 0.0;
}

// After a leap: the sample at t (box position p, value s) starts the next segment; the segment
// ending at it lies inside the empty region and adds nothing.
fn acc_resume(acc: ptr<function, Acc>, t: f32, p: vec3<f32>, s: f32) {
    (*acc).front = segment_end(labelled_value(s, p));
    (*acc).front_t = t;
}
#endif

#ifdef LEAP
// A node is skipped where the transfer function is zero over its values (its emptiness flag).
fn acc_skips(acc: Acc, node: u32) -> bool {
    return node_empty[node] != 0u;
}

fn acc_leap_target(k: u32, after: u32) -> u32 {
    return after;
}

#ifdef LEAP_DISTANCE
// The field is built from the emptiness flags: two-sided.
fn acc_reach(acc: Acc, low: u32, high: u32) -> vec2<u32> {
    return reach_two_sided(low, high);
}
#endif
#endif

#ifdef RAY_SPLIT
// Two parts of a ray composited front to back (never with PREINTEGRATED). Where the front part
// is opaque enough to have ended the whole ray's loop, the back part is dropped, as that loop
// never took it.
fn acc_combine(front: Acc, back: Acc) -> Acc {
#ifdef EARLY_TERMINATION
    if front.color.a > frame.termination_alpha {
        return front;
    }
#endif
    var joined = front;
    joined.color = front.color + (1.0 - front.color.a) * back.color;
    return joined;
}

// A part of a ray needs nothing from before it.
fn acc_enter(acc: ptr<function, Acc>, ray: Ray, first: u32) -> u32 {
    return 0u;
}
#endif

fn acc_sample(acc: ptr<function, Acc>, ray: Ray, k: u32, t: f32, p: vec3<f32>, s_in: f32) -> u32 {
#ifdef LABEL_SURFACES
    // A label's surface the ray enters before this sample lies in front of it.
    // Through a local: naga's SPIR-V writer cannot pass a pointer into a pointer's pointee.
    var track = (*acc).track;
    let surface = surface_before(&track, ray, k, t, p).colour;
    (*acc).track = track;
    if surface.a > 0.0 {
        let added = add_lit(acc, surface);
        if (added & SAMPLE_STOP) != 0u {
            return added;
        }
    }
#endif
    let s = labelled_value(s_in, p);
#ifdef PREINTEGRATED
    let back = segment_end(s);
    var c = preintegrated((*acc).front, back, t - (*acc).front_t);
    (*acc).front = back;
    (*acc).front_t = t;
    if c.a <= 0.0 {
        return 0u;
    }
    if frame.colour_volume != 0u {
        // The segment's opacity pre-integrated over luminance, its colour the sample's own.
        c = vec4<f32>(sample_colour(p), c.a);
    }
    c = vec4<f32>(labelled_colour(c.rgb, p), c.a);
#else
    // The table holds the optical depth of a full step (src/transfer/lut.rs).
    var c = classify(s);
    if c.a <= 0.0 {
        return 0u;
    }
    var w = 1.0;
    if k + 1u == ray.count {
        // The last segment may be shorter than a step: scale its optical depth.
        w = clamp((ray.length_mm - f32(k) * frame.step_mm) / frame.step_mm, 0.0, 1.0);
    }
    c.a = opacity_of_depth(c.a * w);
    if frame.colour_volume != 0u {
        c = vec4<f32>(sample_colour(p), c.a);
    }
    c = vec4<f32>(labelled_colour(c.rgb, p), c.a);
#endif
    return composite(acc, ray, p, c);
}

// Adds colour c (straight) lit at p behind what the ray has gathered.
fn composite(acc: ptr<function, Acc>, ray: Ray, p: vec3<f32>, c_in: vec4<f32>) -> u32 {
    var c = c_in;
#ifdef SHADING
    // Only where it shows: a faint sample, or one behind nearly opaque ones, is composited as if
    // it faced the light, without its six or twelve gradient reads.
    if c.a * (1.0 - (*acc).color.a) >= frame.light_min_weight {
        let g = gradient(p);
        // The shares of the light and of the ambient light that reach the sample.
        var reach = vec2<f32>(1.0);
#ifdef SHADOWS
        // A headlight's shadow is what the ray gathered in front of the sample.
        reach.x = 1.0 - (*acc).color.a;
        if frame.headlight == 0u {
            reach.x = light_transmittance(p, ray, *acc);
        }
#endif
#ifdef OCCLUSION
        reach.y = occlusion_at(p, g, ray);
#endif
        c = vec4<f32>(phong_shadowed(c.rgb, g, ray.dir_world, reach), c.a);
    } else {
        c = vec4<f32>(c.rgb * (frame.phong_ambient + frame.phong_diffuse), c.a);
    }
#endif
    return add_lit(acc, c);
}

// Adds colour c (straight, already lit) behind what the ray has gathered.
fn add_lit(acc: ptr<function, Acc>, c: vec4<f32>) -> u32 {
    (*acc).color += (1.0 - (*acc).color.a) * vec4<f32>(c.rgb * c.a, c.a);
#ifdef EARLY_TERMINATION
    if (*acc).color.a > frame.termination_alpha {
        return SAMPLE_STOP | SAMPLE_CONTRIBUTED;
    }
#endif
    return SAMPLE_CONTRIBUTED;
}

#ifdef PREINTEGRATED
// After the last sample: the segment from it to the exit point (the last sample lies up to a
// step before the exit).
fn acc_tail(acc: ptr<function, Acc>, ray: Ray) {
    let exit = ray.entry + ray.box_per_mm * ray.length_mm;
    let back = segment_end(labelled_value(sample_value(exit), exit));
    var c = preintegrated((*acc).front, back, ray.length_mm - (*acc).front_t);
    if frame.colour_volume != 0u {
        c = vec4<f32>(sample_colour(exit), c.a);
    }
    c = vec4<f32>(labelled_colour(c.rgb, exit), c.a);
    if c.a > 0.0 {
        composite(acc, ray, exit, c);
    }
}
#endif

fn acc_finish(acc: Acc, ray: Ray) -> vec4<f32> {
    return vec4<f32>(acc.color.rgb + (1.0 - acc.color.a) * frame.background.rgb, 1.0);
}
