// Labels as surfaces (LABEL_SURFACES): the shown labels' boundary as a smooth lit surface,
// found in the ray loop without a mesh. The mask (build/label_surface.wgsl: the shown labels'
// indicator smoothed by a Gaussian) is sampled trilinearly; where it rises through one half
// between two samples the crossing is refined by false position, lit by the mask's gradient and
// coloured by the shown label around it at that label's opacity. Only entries are drawn (a ray
// leaving a label draws nothing), and a shown label at the box's face shows a cap facing the eye.
// Leaping skips only nodes with no shown label within the kernel's reach (the label flags'
// apron), where the mask stays below one half: a sample after a leap starts outside, as the
// sample before it in plain ray casting is. DVR composites each surface in front of the sample
// after it; the isosurface, MIP, MinIP and X-ray show the surfaces over their picture
// (SurfaceOver below). The f64 twin is src/reference/surfaces.rs.

#include "shared/labels.wgsl"
#include "shared/shade.wgsl"

@group(0) @binding(9) var label_mask: texture_3d<f32>;

// False-position steps refining a crossing.
const SURFACE_REFINE: u32 = 5u;

// The surface lies where the mask crosses this.
const SURFACE_LEVEL: f32 = 0.5;

fn mask_at(p: vec3<f32>) -> f32 {
    return textureSampleLevel(label_mask, linear_clamp, p, 0.0).r;
}

// The mask's gradient per millimetre at p, by central differences one voxel apart.
fn mask_gradient(p: vec3<f32>) -> vec3<f32> {
    let h = 1.0 / frame.volume_dims;
    var g = vec3<f32>(0.0);
    for (var a = 0u; a < 3u; a++) {
        var e = vec3<f32>(0.0);
        e[a] = h[a];
        g[a] = 0.5 * (mask_at(p + e) - mask_at(p - e));
    }
    return g / frame.spacing_mm;
}

// What a ray knows of the surfaces: the sample it expects next and whether the mask was at or
// above the level at the last one taken.
struct SurfaceTrack {
    next_k: u32,
    inside: bool,
}

fn surface_track() -> SurfaceTrack {
    return SurfaceTrack(0u, false);
}

// The colour and opacity of the shown label a surface at p bounds: of the eight voxels around p,
// the one weighing most in the trilinear filter that holds a shown label (the first in order on
// a tie); else the label of the voxel one step inwards (along the mask's rise `g`).
fn surface_label(p: vec3<f32>, g: vec3<f32>) -> vec4<f32> {
    let dims = vec3<i32>(textureDimensions(label_tex));
    let v = p * frame.volume_dims - 0.5;
    let base = floor(v);
    let f = v - base;
    var best = vec4<f32>(0.0);
    var best_w = -1.0;
    for (var c = 0u; c < 8u; c++) {
        let o = vec3<f32>(f32(c & 1u), f32((c >> 1u) & 1u), f32((c >> 2u) & 1u));
        let w3 = o * f + (1.0 - o) * (1.0 - f);
        let w = w3.x * w3.y * w3.z;
        let i = clamp(vec3<i32>(base + o), vec3<i32>(0), dims - vec3<i32>(1));
        let l = shown_label_of(i);
        if (l.a > 0.0) & (w > best_w) {
            best = l;
            best_w = w;
        }
    }
    if (best.a <= 0.0) & (length(g) > 0.0) {
        best = shown_label(p + normalize(g) * frame.spacing_mm / frame.extent_mm);
    }
    return best;
}

// A surface a ray enters: its colour, lit, and opacity (a = 0: none), and its distance (mm).
struct SurfaceHit {
    colour: vec4<f32>,
    t: f32,
}

// The surface the ray enters between the sample before k (or the entry point) and sample k at
// distance t (box position p).
fn surface_before(track: ptr<function, SurfaceTrack>, ray: Ray, k: u32, t: f32, p: vec3<f32>) -> SurfaceHit {
    let was_inside = (*track).inside & ((*track).next_k == k);
    let f = mask_at(p);
    (*track).inside = f >= SURFACE_LEVEL;
    (*track).next_k = k + 1u;
    if was_inside | (f < SURFACE_LEVEL) {
        return SurfaceHit(vec4<f32>(0.0), t);
    }
    var t0 = 0.0;
    if k > 0u {
        t0 = sample_distance(ray, k - 1u);
    }
    var d0 = mask_at(ray.entry + ray.box_per_mm * t0) - SURFACE_LEVEL;
    var th = t0;
    // A crossing at the entry point (a label at the box's face) is a cap facing the eye.
    var g = ray.dir_world;
    if d0 < 0.0 {
        var t1 = t;
        var d1 = f - SURFACE_LEVEL;
        for (var i = 0u; i < SURFACE_REFINE; i++) {
            let tm = t0 + (t1 - t0) * clamp(d0 / (d0 - d1), 0.0, 1.0);
            let dm = mask_at(ray.entry + ray.box_per_mm * tm) - SURFACE_LEVEL;
            if dm >= 0.0 {
                t1 = tm;
                d1 = dm;
            } else {
                t0 = tm;
                d0 = dm;
            }
        }
        th = t0 + (t1 - t0) * clamp(d0 / (d0 - d1), 0.0, 1.0);
        g = mask_gradient(ray.entry + ray.box_per_mm * th);
    }
    let hit = ray.entry + ray.box_per_mm * th;
    let c = surface_label(hit, g);
    if c.a <= 0.0 {
        return SurfaceHit(vec4<f32>(0.0), th);
    }
    return SurfaceHit(vec4<f32>(phong(c.rgb, g, ray.dir_world), c.a), th);
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
