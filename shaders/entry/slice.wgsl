// A slice view: each pixel's value sampled from the volume (shared/volume.wgsl) at the voxel coordinates of
// its centre, clamp-to-edge inside the volume's box, and shown as grey through the window.
// Two variants:
// - exact (default): trilinear from eight texel loads with exact f32 weights, or the nearest
//   voxel; writes the value in data units (NaN where nothing is: outside the box or a missing
//   sample) and the grey image to buffers. The f64 reference is src/reference/slice.rs.
// - DISPLAY (what the window shows and `leapview slice` writes): the texture unit's trilinear
//   filter (one fetch, as the ray caster samples), or the nearest voxel; writes only the RGBA8
//   grey (or the transfer function's colour blended over it by its opacity), straight into the
//   texture on screen.
// A thick slab walks its samples along the normal through the min/max bricks of
// build/minmax.wgsl (SLAB_BRICK³ voxels, extended by one so no trilinear value escapes a brick's range)
// and, for MIP and MinIP, skips the bricks that cannot change the running maximum (minimum);
// the mean skips constant bricks, adding their value for each sample. The pixel grid comes from
// src/mpr/view.rs (`VoxelGrid`).

#include "generated/constants.wgsl"
#include "shared/volume.wgsl"

// `SliceParams` in src/render/gpu_data.rs.
struct SliceParams {
    // Voxel coordinates of pixel (0, 0)'s centre (w unused).
    first: vec4<f32>,
    // One pixel to the right, in voxel coordinates (w unused).
    step_x: vec4<f32>,
    // One pixel down (w unused).
    step_y: vec4<f32>,
    // Between two samples of a thick slab, along the normal (w unused).
    slab_step: vec4<f32>,
    width: u32,
    height: u32,
    // 1: nearest voxel; 0: trilinear.
    nearest: u32,
    // u32 words per row of `image` (rows padded for a copy into a texture).
    pitch: u32,
    // Largest integer of a unorm texture (255, 65535): u = round(texel * texel_max) recovers
    // its integer exactly; 0 for a float texture (u = texel, which holds the normalised value).
    texel_max: f32,
    // Data value = u * unit_scale + unit_bias.
    unit_scale: f32,
    unit_bias: f32,
    // The window (data units): grey 0 at window_lo, 255 at window_hi.
    window_lo: f32,
    window_hi: f32,
    // Samples across a thick slab, centred on the plane (1: a thin slice), and how they
    // combine (SLAB_MIP, SLAB_MINIP, SLAB_MEAN).
    slab_count: u32,
    slab_mode: u32,
    // 1: a slab skips the bricks that cannot change it (`bricks`); 0: it takes every sample.
    leap: u32,
    // 1 (display variant): the transfer function's colour blended over the grey by its
    // opacity (`colours`); 0: grey.
    colour: u32,
    // The data values at the first and last entries of `colours`.
    colour_lo: f32,
    colour_hi: f32,
    // 1: grey runs from white at window_lo to black at window_hi (MONOCHROME1).
    invert: u32,
    // 1 (display variant): a colour volume, whose thin slices show its own colour.
    volume_colour: u32,
    // The display variant fills this many layers of labels (label_tex's channels, 0 … 4) over
    // the image in their colours (label_colours, alpha 0 where hidden), label_opacity opaque;
    // with label_outline 1 each label's outline (a pixel whose neighbour's label differs) opaque.
    labels: u32,
    label_opacity: f32,
    label_outline: u32,
    // 1 where the labels travel in the volume's bricks (labels_texel), else 0.
    label_bricks: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}


@group(0) @binding(0) var volume_tex: texture_3d<f32>;
@group(0) @binding(6) var<storage, read> volume_pages: array<vec4<f32>>;
@group(0) @binding(7) var<uniform> volume_geometry: VolumeGeometry;
@group(0) @binding(1) var<uniform> params: SliceParams;
#ifdef DISPLAY
@group(0) @binding(2) var linear: sampler;
@group(0) @binding(3) var screen: texture_storage_2d<rgba8unorm, write>;
// The transfer function's straight colour and opacity per value (transfer::lut::slice_colours).
@group(0) @binding(5) var colours: texture_2d<f32>;
// The labels on the volume's grid, a layer per channel (render/slice/labels.rs), and each label
// value's colour at texel (value % 256, value / 256), its alpha 0 where the label is hidden.
@group(0) @binding(8) var label_tex: texture_3d<u32>;
@group(0) @binding(9) var label_colours: texture_2d<f32>;
#else
@group(0) @binding(2) var<storage, read_write> values: array<f32>;
@group(0) @binding(3) var<storage, read_write> image: array<u32>;
#endif
// (min, max) of u over each SLAB_BRICK³ brick extended by one voxel (build/minmax.wgsl's level 0, with
// texel_scale = texel_max (1 for a float texture) and texel_bias = 0), x fastest.
@group(0) @binding(4) var<storage, read> bricks: array<vec2<f32>>;

// Edge of a brick in voxels.
const BRICK: f32 = f32(SLAB_BRICK);

// Texel `i` as u (see `texel_max`): exact integers for unorm textures; a float texture's
// MISSING marker stays far below MISSING_BELOW.
fn texel(i: vec3<i32>) -> f32 {
    let t = volume_load(i).r;
    if params.texel_max > 0.0 {
        return round(t * params.texel_max);
    }
    return t;
}

// Whether u is the MISSING marker (only float textures hold it).
fn missing(u: f32) -> bool {
    return params.texel_max == 0.0 && u < MISSING_BELOW;
}

fn nan() -> f32 {
    let bits = 0x7fc00000u;
    return bitcast<f32>(bits);
}

// u at voxel coordinates `v` (clamped into the box) from eight texel loads with exact f32
// weights. Where missing texels take part, the others' weights are renormalised (a missing voxel
// takes no finite neighbour with it), and u is missing where they weigh less than half: the ray
// caster's `sample_finite` and src/reference/trilinear.rs.
fn trilinear_units(v: vec3<f32>) -> f32 {
    let dims = volume_dims();
    let top = vec3<f32>(dims - vec3<i32>(1));
    let x = clamp(v, vec3<f32>(0.0), top);
    let base = floor(x);
    let f = x - base;
    let lo = vec3<i32>(base);
    let hi = min(lo + vec3<i32>(1), dims - vec3<i32>(1));
    var sum = 0.0;
    var weight = 0.0;
    var lost = 0.0;
    for (var c = 0u; c < 8u; c = c + 1u) {
        let pick = vec3<bool>((c & 1u) != 0u, (c & 2u) != 0u, (c & 4u) != 0u);
        let w3 = select(vec3<f32>(1.0) - f, f, pick);
        let w = w3.x * w3.y * w3.z;
        if w == 0.0 {
            continue;
        }
        let u = texel(select(lo, hi, pick));
        if missing(u) {
            lost = lost + w;
        } else {
            sum = sum + w * u;
            weight = weight + w;
        }
    }
    if lost == 0.0 {
        return sum;
    }
    return select(MISSING_BELOW - 1.0, sum / weight, weight >= 0.5);
}

// u at voxel coordinates `v` (inside the box), trilinear or nearest; missing where missing
// texels outweigh the others (`trilinear_units`).
fn sample_units(v: vec3<f32>) -> f32 {
    let dims = volume_dims();
    if params.nearest == 1u {
        let i = clamp(vec3<i32>(floor(v + vec3<f32>(0.5))), vec3<i32>(0), dims - vec3<i32>(1));
        return texel(i);
    }
#ifdef DISPLAY
    // Clamp-to-edge at texture coordinate (v + ½) / dims is the exact path's clamp of v into
    // [0, dims − 1]; a missing texel's marker drags the blend far below MISSING_BELOW, and then
    // the exact path decides.
    let t = volume_filtered(linear, (v + vec3<f32>(0.5)) / vec3<f32>(dims)).r;
    let u = select(t, t * params.texel_max, params.texel_max > 0.0);
    if missing(u) {
        return trilinear_units(v);
    }
    return u;
#else
    return trilinear_units(v);
#endif
}

// Grey through the window (inverted where the image asks its lowest value to be white); black
// where nothing is.
fn grey(value: f32) -> f32 {
    if value != value {
        return 0.0;
    }
    var g = select(0.0, 1.0, value >= params.window_hi);
    if params.window_hi > params.window_lo {
        g = clamp((value - params.window_lo) / (params.window_hi - params.window_lo), 0.0, 1.0);
    }
    return select(g, 1.0 - g, params.invert == 1u);
}

// The value (data units) at voxel coordinates `v`; NaN outside the box or where a missing
// sample takes part.
fn value_at(v: vec3<f32>) -> f32 {
    let dims = vec3<f32>(volume_dims());
    let inside = all(v >= vec3<f32>(-0.5)) && all(v <= dims - vec3<f32>(0.5));
    if inside {
        let u = sample_units(v);
        if !missing(u) {
            return u * params.unit_scale + params.unit_bias;
        }
    }
    return nan();
}

// Sample `s` of the slab through `v`: (s − middle) steps along the normal.
fn slab_point(v: vec3<f32>, s: u32, middle: f32) -> vec3<f32> {
    return v + (f32(s) - middle) * params.slab_step.xyz;
}

// The samples of the slab through `v` that can lie inside the box: [first, last] (one more on
// each side than the exact intersection, whose rounding `value_at` settles); first > last when
// none can.
fn slab_span(v: vec3<f32>, middle: f32) -> vec2<u32> {
    let d = params.slab_step.xyz;
    let dims = vec3<f32>(volume_dims());
    var lo = 0.0;
    var hi = f32(params.slab_count - 1u);
    for (var a = 0; a < 3; a = a + 1) {
        if d[a] == 0.0 {
            if v[a] < -0.5 || v[a] > dims[a] - 0.5 {
                return vec2<u32>(1u, 0u);
            }
        } else {
            let t1 = (-0.5 - v[a]) / d[a] + middle;
            let t2 = (dims[a] - 0.5 - v[a]) / d[a] + middle;
            lo = max(lo, min(t1, t2));
            hi = min(hi, max(t1, t2));
        }
    }
    if lo > hi + 1.0 {
        return vec2<u32>(1u, 0u);
    }
    let first = u32(max(ceil(lo) - 1.0, 0.0));
    let last = u32(clamp(floor(hi) + 1.0, 0.0, f32(params.slab_count - 1u)));
    return vec2<u32>(first, last);
}

// The brick holding the sample at `p` (clamped into the grid), and how many samples from it on,
// at most `left`, stay in that brick's region [b·4 − ½, (b + 1)·4 − ½) (at least one).
struct Run {
    brick: u32,
    count: u32,
}

fn brick_run(p: vec3<f32>, left: u32) -> Run {
    let dims = volume_dims();
    let nodes = (dims + vec3<i32>(i32(SLAB_BRICK) - 1)) / i32(SLAB_BRICK);
    let b = clamp(vec3<i32>(floor((p + vec3<f32>(0.5)) / BRICK)), vec3<i32>(0), nodes - vec3<i32>(1));
    let d = params.slab_step.xyz;
    var n = f32(left);
    for (var a = 0; a < 3; a = a + 1) {
        if d[a] != 0.0 {
            let wall = select(f32(b[a]) * BRICK - 0.5, f32(b[a] + 1) * BRICK - 0.5, d[a] > 0.0);
            n = min(n, floor((wall - p[a]) / d[a]) + 1.0);
        }
    }
    let index = u32(b.x + nodes.x * (b.y + nodes.y * b.z));
    return Run(index, u32(max(n, 1.0)));
}

// A brick's (min, max) in data units, widened by a few ulps: a unorm texel decodes to
// u = texel × texel_max within rounding of the integer the exact path rounds it to.
fn brick_range(index: u32) -> vec2<f32> {
    let b = bricks[index];
    let pad = 1.0e-5 * max(abs(b.x), abs(b.y));
    let r = vec2<f32>(b.x - pad, b.y + pad) * params.unit_scale + vec2<f32>(params.unit_bias);
    let slack = 1.0e-6 * max(abs(r.x), abs(r.y));
    return vec2<f32>(min(r.x, r.y) - slack, max(r.x, r.y) + slack);
}

// Whether every sample of a run of `n` from `p` lies inside the box (the box is convex).
fn run_inside(p: vec3<f32>, n: u32) -> bool {
    let dims = vec3<f32>(volume_dims());
    let q = p + f32(n - 1u) * params.slab_step.xyz;
    return all(min(p, q) >= vec3<f32>(-0.5)) && all(max(p, q) <= dims - vec3<f32>(0.5));
}

// A thick slab's value at `v`: MIP, MinIP or mean of its samples that have a value, NaN when
// none has.
fn slab_value(v: vec3<f32>) -> f32 {
    let middle = f32(params.slab_count - 1u) * 0.5;
    let span = slab_span(v, middle);
    let mip = params.slab_mode == SLAB_MIP;
    let mean = params.slab_mode == SLAB_MEAN;
    var value = nan();
    // Where the slab has a sample on the plane, it bounds the maximum (minimum) from the start.
    if params.leap == 1u && !mean && params.slab_count % 2u == 1u {
        value = value_at(v);
    }
    var sum = 0.0;
    var n = 0.0;
    var s = span.x;
    while s <= span.y {
        let p = slab_point(v, s, middle);
        var run = Run(0u, span.y + 1u - s);
        if params.leap == 1u {
            run = brick_run(p, span.y + 1u - s);
            if mean {
                // A constant brick (no missing texel: unorm textures hold none) adds its value
                // for each of its samples.
                let b = bricks[run.brick];
                if b.x == b.y && params.texel_max > 0.0 && run_inside(p, run.count) {
                    let x = round(b.x) * params.unit_scale + params.unit_bias;
                    sum = sum + x * f32(run.count);
                    n = n + f32(run.count);
                    s = s + run.count;
                    continue;
                }
            } else if value == value {
                let r = brick_range(run.brick);
                if (mip && r.y <= value) || (!mip && r.x >= value) {
                    s = s + run.count;
                    continue;
                }
            }
        }
        for (var k = 0u; k < run.count; k = k + 1u) {
            let x = value_at(slab_point(v, s + k, middle));
            if x == x {
                if value != value {
                    value = x;
                } else if mip {
                    value = max(value, x);
                } else {
                    value = min(value, x);
                }
                sum = sum + x;
                n = n + 1.0;
            }
        }
        s = s + run.count;
    }
    if mean {
        return select(nan(), sum / n, n > 0.0);
    }
    return value;
}

#ifdef DISPLAY
#include "shared/label_texel.wgsl"

// The labels of the voxel nearest voxel coordinates `v`, a layer per component (0 past the
// layers there are: an R or RG texture's missing channels read 0, 1); 0 outside the volume.
fn labels_at(v: vec3<f32>) -> vec4<u32> {
    let dims = volume_dims();
    let i = vec3<i32>(floor(v + vec3<f32>(0.5)));
    if any(i < vec3<i32>(0)) || any(i >= dims) {
        return vec4<u32>(0u);
    }
    let texel = labels_texel(label_tex, i, params.label_bricks != 0u);
    return select(vec4<u32>(0u), texel, vec4<u32>(0u, 1u, 2u, 3u) < vec4<u32>(params.labels));
}

// `rgb` with the labels at `v` filled over it layer by layer (and their outlines, where on);
// as is where the pixel has no shown label.
fn with_labels(rgb: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    let here = labels_at(v);
    if all(here == vec4<u32>(0u)) {
        return rgb;
    }
    var edge = vec4<bool>(false);
    if params.label_outline == 1u {
        let dx = params.step_x.xyz;
        let dy = params.step_y.xyz;
        edge = labels_at(v + dx) != here | labels_at(v - dx) != here | labels_at(v + dy) != here
            | labels_at(v - dy) != here;
    }
    var out = rgb;
    for (var layer = 0u; layer < min(params.labels, 4u); layer = layer + 1u) {
        let l = here[layer];
        if l == 0u {
            continue;
        }
        let c = textureLoad(label_colours, vec2<i32>(i32(l % 256u), i32(l / 256u)), 0);
        // The fill at the panel's opacity times the label's own (the table's alpha; 0: hidden),
        // its outline opaque.
        if c.a > 0.0 {
            out = mix(out, c.rgb, select(params.label_opacity * c.a, 1.0, edge[layer]));
        }
    }
    return out;
}
#endif

// Pixel `id`'s value, grey, written.
fn shade(id: vec2<u32>) {
    let v = params.first.xyz + f32(id.x) * params.step_x.xyz + f32(id.y) * params.step_y.xyz;
    var value = nan();
    if params.slab_count <= 1u {
        value = value_at(v);
    } else {
        value = slab_value(v);
    }
    let g = grey(value);
#ifdef DISPLAY
    var rgb = vec3<f32>(g);
    if params.volume_colour == 1u && params.slab_count <= 1u && value == value {
        // A colour volume's own colour (its texels: luminance, red, green, blue), sampled as
        // the value is.
        let dims = volume_dims();
        if params.nearest == 1u {
            let i = clamp(vec3<i32>(floor(v + vec3<f32>(0.5))), vec3<i32>(0), dims - vec3<i32>(1));
            rgb = volume_load(i).gba;
        } else {
            rgb = volume_filtered(linear, (v + vec3<f32>(0.5)) / vec3<f32>(dims)).gba;
        }
    } else if params.colour == 1u && value == value {
        let n = f32(textureDimensions(colours).x);
        let s = clamp((value - params.colour_lo) / (params.colour_hi - params.colour_lo), 0.0, 1.0);
        let c = textureSampleLevel(colours, linear, vec2<f32>((s * (n - 1.0) + 0.5) / n, 0.5), 0.0);
        rgb = mix(rgb, c.rgb, clamp(c.a, 0.0, 1.0));
    }
    if params.labels > 0u {
        rgb = with_labels(rgb, v);
    }
    textureStore(screen, vec2<i32>(id), vec4<f32>(rgb, 1.0));
#else
    values[id.y * params.width + id.x] = value;
    image[id.y * params.pitch + id.x] = pack4x8unorm(vec4<f32>(g, g, g, 1.0));
#endif
}

// One invocation per column and band of rows: it shades rows id.y, id.y + stride, ... where
// the dispatch covers height / rows of them (`render::slice::dispatch`: thin slices several rows
// per invocation, measured faster; slabs one, their samples keep the invocations busy;
// docs/benchmarks/README.md, "Figures moved from code comments").
@compute @workgroup_size(WORKGROUP, WORKGROUP, 1)
fn slice(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    if id.x >= params.width {
        return;
    }
    let stride = groups.y * WORKGROUP;
    for (var y = id.y; y < params.height; y = y + stride) {
        shade(vec2<u32>(id.x, y));
    }
}
