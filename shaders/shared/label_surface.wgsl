// Labels as surfaces (LABEL_SURFACES): the shown labels' boundary as a smooth lit surface,
// found in the ray loop without a mesh. The mask (build/label_surface.wgsl: the shown labels'
// indicator smoothed by a Gaussian) is sampled trilinearly; where it rises through one half
// between two samples the crossing is refined by false position, lit by the mask's gradient and
// coloured by the shown label around it at that label's opacity. Only entries are drawn (a ray
// leaving a label draws nothing), and a shown label at the box's face shows a cap facing the eye.
// Inside the shown labels, where the label of the nearest voxel changes between two samples,
// the wall between the two labels is drawn as the later one's entry: where its indicator
// overtakes the earlier one's, both smoothed by the cubic B-spline (the first layer's labels).
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

// False-position steps refining a wall between two labels (each reads 64 voxels).
const WALL_REFINE: u32 = 3u;

// Steps a wall's bracket may move before or after the two samples it lies between.
const WALL_REACH: u32 = 3u;

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

// What a ray knows of the surfaces: the sample it expects next, whether the mask was at or
// above the level at the last one taken, and the shown label (value) the ray was last in there
// (0: none known).
struct SurfaceTrack {
    next_k: u32,
    inside: bool,
    label: u32,
}

fn surface_track() -> SurfaceTrack {
    return SurfaceTrack(0u, false, 0u);
}

// Cubic B-spline weights for a fraction f of a voxel: the four voxels from the one before to the
// one two after.
fn spline(f: f32) -> vec4<f32> {
    let g = 1.0 - f;
    return vec4<f32>(g * g * g, (3.0 * f - 6.0) * f * f + 4.0, ((-3.0 * f + 3.0) * f + 3.0) * f + 1.0, f * f * f) / 6.0;
}

// Label b's indicator less label a's, each smoothed by the cubic B-spline over the 4³ voxels
// around box position p: zero on a smooth wall where they meet.
fn wall_field(p: vec3<f32>, a: u32, b: u32) -> f32 {
    let dims = vec3<i32>(textureDimensions(label_tex));
    let v = p * frame.volume_dims - 0.5;
    let base = vec3<i32>(floor(v));
    let f = v - floor(v);
    let wx = spline(f.x);
    let wy = spline(f.y);
    let wz = spline(f.z);
    var field = 0.0;
    for (var z = 0; z < 4; z++) {
        for (var y = 0; y < 4; y++) {
            for (var x = 0; x < 4; x++) {
                let i = clamp(base + vec3<i32>(x - 1, y - 1, z - 1), vec3<i32>(0), dims - vec3<i32>(1));
                let here = labels_of(i);
                let s = f32(any(here == vec4<u32>(b))) - f32(any(here == vec4<u32>(a)));
                field += s * wx[x] * wy[y] * wz[z];
            }
        }
    }
    return field;
}

// The wall field's gradient per millimetre at p, by central differences one voxel apart (as the
// mask's: a staircase two voxels long, a wall at 26.6°, cancels out).
fn wall_gradient(p: vec3<f32>, a: u32, b: u32) -> vec3<f32> {
    let h = 1.0 / frame.volume_dims;
    var g = vec3<f32>(0.0);
    for (var axis = 0u; axis < 3u; axis++) {
        var e = vec3<f32>(0.0);
        e[axis] = h[axis];
        g[axis] = 0.5 * (wall_field(p + e, a, b) - wall_field(p - e, a, b));
    }
    return g / frame.spacing_mm;
}

// The wall a ray crosses from shown label a into shown label b between the sample before k and
// sample k at distance t: where b's smoothed indicator overtakes a's (the nearest voxels' labels
// change at the voxels' faces, the smooth wall may lie up to WALL_REACH steps before or after:
// the bracket moves there first), refined by false position, lit by their difference's
// gradient, in b's colour at b's opacity.
fn wall_before(ray: Ray, k: u32, t: f32, a: u32, b: u32) -> SurfaceHit {
    var t0 = t;
    if k > 0u {
        t0 = sample_distance(ray, k - 1u);
    }
    let step = max(t - t0, 1e-6);
    var t1 = t;
    var d0 = wall_field(ray.entry + ray.box_per_mm * t0, a, b);
    var d1 = wall_field(ray.entry + ray.box_per_mm * t1, a, b);
    for (var i = 0u; (i < WALL_REACH) & (d0 >= 0.0); i++) {
        t1 = t0;
        d1 = d0;
        t0 = max(t1 - step, 0.0);
        d0 = wall_field(ray.entry + ray.box_per_mm * t0, a, b);
    }
    for (var i = 0u; (i < WALL_REACH) & (d1 < 0.0); i++) {
        t0 = t1;
        d0 = d1;
        t1 = t0 + step;
        d1 = wall_field(ray.entry + ray.box_per_mm * t1, a, b);
    }
    var th = t;
    if (d0 < 0.0) & (d1 >= 0.0) {
        for (var i = 0u; i < WALL_REFINE; i++) {
            let tm = t0 + (t1 - t0) * clamp(d0 / (d0 - d1), 0.0, 1.0);
            let dm = wall_field(ray.entry + ray.box_per_mm * tm, a, b);
            if dm >= 0.0 {
                t1 = tm;
                d1 = dm;
            } else {
                t0 = tm;
                d0 = dm;
            }
        }
        th = t0 + (t1 - t0) * clamp(d0 / (d0 - d1), 0.0, 1.0);
    }
    var g = wall_gradient(ray.entry + ray.box_per_mm * th, a, b);
    if length(g) == 0.0 {
        g = ray.dir_world;
    }
    let c = label_colour(b);
    return SurfaceHit(vec4<f32>(phong(c.rgb, g, ray.dir_world), c.a), th);
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
// distance t (box position p): the shown labels' outer surface, or a wall between two shown
// labels (where the label of the sample's nearest voxel changes inside them).
fn surface_before(track: ptr<function, SurfaceTrack>, ray: Ray, k: u32, t: f32, p: vec3<f32>) -> SurfaceHit {
    let was_inside = (*track).inside & ((*track).next_k == k);
    let f = mask_at(p);
    (*track).inside = f >= SURFACE_LEVEL;
    (*track).next_k = k + 1u;
    if f < SURFACE_LEVEL {
        (*track).label = 0u;
        return SurfaceHit(vec4<f32>(0.0), t);
    }
    let here = shown_of(voxel_of(p)).value;
    if was_inside {
        let before = (*track).label;
        if here == 0u {
            return SurfaceHit(vec4<f32>(0.0), t);
        }
        (*track).label = here;
        if (before == 0u) | (here == before) {
            return SurfaceHit(vec4<f32>(0.0), t);
        }
        return wall_before(ray, k, t, before, here);
    }
    (*track).label = here;
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
