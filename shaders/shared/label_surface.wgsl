// Labels as surfaces (LABEL_SURFACES): the shown labels' boundary as a smooth lit surface,
// found in the ray loop without a mesh. The mask (build/label_surface.wgsl: per class of shown
// labels, their indicator smoothed by a Gaussian, a channel each) is sampled trilinearly; where
// a channel rises through one half between two samples the crossing is refined by false
// position, lit by that channel's gradient and coloured by the shown label of that class around
// it at that label's opacity. Touching labels of two classes meet at a wall, where the second's
// channel rises as the first's falls; touching labels that share a class have none between them
// (src/labels/classes.rs keeps that rare). Only entries are drawn (a ray leaving a label draws
// nothing), and a shown label at the box's face shows a cap facing the eye.
// Leaping skips only nodes with no shown label within the kernel's reach (the label flags'
// apron), where the mask stays below one half: a sample after a leap starts outside, as the
// sample before it in plain ray casting is. DVR composites each surface in front of the sample
// after it; the isosurface, MIP, MinIP and X-ray show the surfaces over their picture
// (SurfaceOver below). The f64 twin is src/reference/surfaces.rs.

#include "shared/labels.wgsl"
#include "shared/shade.wgsl"

@group(0) @binding(9) var label_mask: texture_3d<f32>;
// Each label value's class (its channel of the mask) at texel (value % 256, value / 256).
@group(0) @binding(10) var label_classes: texture_2d<u32>;

// False-position steps refining a crossing.
const SURFACE_REFINE: u32 = 5u;

// The surface lies where the mask crosses this.
const SURFACE_LEVEL: f32 = 0.5;

// The mask at box position p, a class per channel (those past the mask's channels 0: an R8
// texel reads alpha 1). Labels in bricks past one texture have theirs on a grid reduced k-fold,
// which covers a little more than the box (frame.surface_scale).
fn mask_at(p: vec3<f32>) -> vec4<f32> {
    let m = textureSampleLevel(label_mask, linear_clamp, p * frame.surface_scale, 0.0);
    return select(vec4<f32>(0.0), m, vec4<u32>(0u, 1u, 2u, 3u) < vec4<u32>(frame.surface_channels));
}

// Class c's channel of the mask at p.
fn mask_channel(p: vec3<f32>, c: u32) -> f32 {
    return mask_at(p)[c];
}

// Class c's channel's gradient per millimetre at p, by central differences one voxel of the
// mask's grid apart (box units h: a voxel of the image's, or k of them on a reduced grid).
fn mask_gradient(p: vec3<f32>, c: u32) -> vec3<f32> {
    let h = 1.0 / (vec3<f32>(textureDimensions(label_mask)) * frame.surface_scale);
    var g = vec3<f32>(0.0);
    for (var a = 0u; a < 3u; a++) {
        var e = vec3<f32>(0.0);
        e[a] = h[a];
        g[a] = 0.5 * (mask_channel(p + e, c) - mask_channel(p - e, c));
    }
    return g / (h * frame.extent_mm);
}

// The channels at or above the level in mask value m, as bits.
fn channels_above(m: vec4<f32>) -> u32 {
    let above = select(vec4<u32>(0u), vec4<u32>(1u, 2u, 4u, 8u), m >= vec4<f32>(SURFACE_LEVEL));
    return above.x | above.y | above.z | above.w;
}

// What a ray knows of the surfaces: the sample it expects next and the channels at or above the
// level at the last one taken (bits).
struct SurfaceTrack {
    next_k: u32,
    inside: u32,
}

fn surface_track() -> SurfaceTrack {
    return SurfaceTrack(0u, 0u);
}

// Label value l's class.
fn class_of(l: u32) -> u32 {
    return textureLoad(label_classes, vec2<i32>(i32(l % 256u), i32(l / 256u)), 0).r;
}

// The first layer's shown label of class c at voxel i (a = 0 where none is shown).
fn shown_label_in(i: vec3<i32>, c: u32) -> vec4<f32> {
    let here = labels_of(i);
    for (var layer = 0u; layer < min(frame.label_layers, 4u); layer++) {
        let l = here[layer];
        if l != 0u {
            let colour = label_colour(l);
            if colour.a > 0.0 && class_of(l) == c {
                return colour;
            }
        }
    }
    return vec4<f32>(0.0);
}

// The colour and opacity of the shown label of class c a surface at p bounds: of the eight
// voxels around p, the one weighing most in the trilinear filter that holds a shown label of
// that class (the first in order on a tie); else that of the voxel a step of the mask's grid
// inwards (along the channel's rise `g`). The labels lie on the image's grid (in one texture or
// in its bricks).
fn surface_label(p: vec3<f32>, g: vec3<f32>, c: u32) -> vec4<f32> {
    let dims = vec3<i32>(frame.volume_dims);
    let v = p * frame.volume_dims - 0.5;
    let base = floor(v);
    let f = v - base;
    var best = vec4<f32>(0.0);
    var best_w = -1.0;
    for (var corner = 0u; corner < 8u; corner++) {
        let o = vec3<f32>(f32(corner & 1u), f32((corner >> 1u) & 1u), f32((corner >> 2u) & 1u));
        let w3 = o * f + (1.0 - o) * (1.0 - f);
        let w = w3.x * w3.y * w3.z;
        let i = clamp(vec3<i32>(base + o), vec3<i32>(0), dims - vec3<i32>(1));
        let l = shown_label_in(i, c);
        if (l.a > 0.0) & (w > best_w) {
            best = l;
            best_w = w;
        }
    }
    if (best.a <= 0.0) & (length(g) > 0.0) {
        let step_box = 1.0 / (vec3<f32>(textureDimensions(label_mask)) * frame.surface_scale);
        best = shown_label_in(voxel_of(p + normalize(g) * step_box), c);
    }
    return best;
}

// A surface a ray enters: its colour, lit, and opacity (a = 0: none), and its distance (mm).
struct SurfaceHit {
    colour: vec4<f32>,
    t: f32,
}

// Where class c's channel rises through the level between t0 (d0: its value less the level
// there, below 0) and t1 (d1, at or above 0), by false position.
fn refine_crossing(ray: Ray, c: u32, t0_in: f32, d0_in: f32, t1_in: f32, d1_in: f32) -> f32 {
    var t0 = t0_in;
    var d0 = d0_in;
    var t1 = t1_in;
    var d1 = d1_in;
    for (var i = 0u; i < SURFACE_REFINE; i++) {
        let tm = t0 + (t1 - t0) * clamp(d0 / (d0 - d1), 0.0, 1.0);
        let dm = mask_channel(ray.entry + ray.box_per_mm * tm, c) - SURFACE_LEVEL;
        if dm >= 0.0 {
            t1 = tm;
            d1 = dm;
        } else {
            t0 = tm;
            d0 = dm;
        }
    }
    return t0 + (t1 - t0) * clamp(d0 / (d0 - d1), 0.0, 1.0);
}

// The surface of class c the ray enters between t0 (mask m0 there) and t (mask m): where its
// channel rises through the level, lit (a = 0 where no shown label of that class lies there).
fn surface_entered(ray: Ray, c: u32, t0: f32, m0: vec4<f32>, t: f32, m: vec4<f32>) -> SurfaceHit {
    let d0 = m0[c] - SURFACE_LEVEL;
    var th = t0;
    // A crossing at the entry point (a label at the box's face) is a cap facing the eye.
    var g = ray.dir_world;
    if d0 < 0.0 {
        th = refine_crossing(ray, c, t0, d0, t, m[c] - SURFACE_LEVEL);
        g = mask_gradient(ray.entry + ray.box_per_mm * th, c);
    }
    let l = surface_label(ray.entry + ray.box_per_mm * th, g, c);
    if l.a <= 0.0 {
        return SurfaceHit(vec4<f32>(0.0), th);
    }
    return SurfaceHit(vec4<f32>(phong(l.rgb, g, ray.dir_world), l.a), th);
}

// Several classes' surfaces entered in one step (`risen`, bits): composited front to back by
// distance (ties: the lower class first) into one, its distance the nearest's.
fn surfaces_entered(ray: Ray, risen: u32, t0: f32, m0: vec4<f32>, t: f32, m: vec4<f32>) -> SurfaceHit {
    var hits = array<SurfaceHit, 4>();
    for (var c = 0u; c < 4u; c++) {
        if ((risen >> c) & 1u) != 0u {
            hits[c] = surface_entered(ray, c, t0, m0, t, m);
        }
    }
    var sum = vec4<f32>(0.0);
    var nearest = t;
    var left = risen;
    while left != 0u {
        var pick = 0u;
        var best = 3.4e38;
        for (var c = 0u; c < 4u; c++) {
            if ((left >> c) & 1u) != 0u && hits[c].t < best {
                best = hits[c].t;
                pick = c;
            }
        }
        left &= ~(1u << pick);
        nearest = min(nearest, best);
        let s = hits[pick].colour;
        sum += (1.0 - sum.a) * vec4<f32>(s.rgb * s.a, s.a);
    }
    if sum.a <= 0.0 {
        return SurfaceHit(vec4<f32>(0.0), nearest);
    }
    return SurfaceHit(vec4<f32>(sum.rgb / sum.a, sum.a), nearest);
}

// The surfaces the ray enters between the sample before k (or the entry point) and sample k at
// distance t (box position p): where a class's channel rises through the level (a wall between
// labels of two classes is where the second's rises). Several in one step are composited in
// order of distance into one (its distance the nearest's).
fn surface_before(track: ptr<function, SurfaceTrack>, ray: Ray, k: u32, t: f32, p: vec3<f32>) -> SurfaceHit {
    let before = select(0u, (*track).inside, (*track).next_k == k);
    let m = mask_at(p);
    let now = channels_above(m);
    (*track).inside = now;
    (*track).next_k = k + 1u;
    let risen = now & ~before;
    if risen == 0u {
        return SurfaceHit(vec4<f32>(0.0), t);
    }
    var t0 = 0.0;
    if k > 0u {
        t0 = sample_distance(ray, k - 1u);
    }
    let m0 = mask_at(ray.entry + ray.box_per_mm * t0);
    // One class (nearly always): no list to sort.
    if (risen & (risen - 1u)) == 0u {
        return surface_entered(ray, firstTrailingBit(risen), t0, m0, t, m);
    }
    return surfaces_entered(ray, risen, t0, m0, t, m);
}

// The surfaces a ray has entered, composited front to back over the picture of a mode that does
// not composite (isosurface, MIP, MinIP, X-ray), and where it stands among them.
struct SurfaceOver {
    track: SurfaceTrack,
    // Premultiplied colour and opacity.
    colour: vec4<f32>,
}

fn surface_over() -> SurfaceOver {
    return SurfaceOver(surface_track(), vec4<f32>(0.0));
}

// Adds a surface behind those gathered; SAMPLE_STOP (with early termination) once they hide
// everything behind.
fn over_add(over: ptr<function, SurfaceOver>, c: vec4<f32>) -> u32 {
    (*over).colour += (1.0 - (*over).colour.a) * vec4<f32>(c.rgb * c.a, c.a);
#ifdef EARLY_TERMINATION
    if (*over).colour.a > frame.termination_alpha {
        return SAMPLE_STOP | SAMPLE_CONTRIBUTED;
    }
#endif
    return SAMPLE_CONTRIBUTED;
}

// The surface entered before sample k, added (see over_add; 0 where there is none).
fn over_sample(over: ptr<function, SurfaceOver>, ray: Ray, k: u32, t: f32, p: vec3<f32>) -> u32 {
    var track = (*over).track;
    let hit = surface_before(&track, ray, k, t, p);
    (*over).track = track;
    if hit.colour.a > 0.0 {
        return over_add(over, hit.colour);
    }
    return 0u;
}

// The surfaces over the mode's picture `under` (opaque).
fn over_finish(over: SurfaceOver, under: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(over.colour.rgb + (1.0 - over.colour.a) * under.rgb, 1.0);
}
