// The same ray loop in a compute shader, one invocation per pixel (docs/benchmarks/README.md: far
// faster than fragments on data-centre GPUs). Each invocation intersects its pixel's ray with the box itself,
// so the path needs no rasterised entry and exit points: on GPUs whose graphics slice is small,
// those two full-screen passes cost more than the whole ray loop of a sparse volume.

#include "march/march.wgsl"

@group(1) @binding(0) var out_tex: texture_storage_2d<rgba16float, write>;

// Entry (xyz, w = 1 where the ray meets the box) and exit of the ray through pixel `px`, clipped
// to the near and far planes as the rasterised proxy geometry is: the part of the segment from
// the near-plane point to the far-plane point that lies inside the cropping box (slab test;
// [0,1]^3 when nothing is cropped).
fn box_segment(px: vec2<u32>) -> array<vec4<f32>, 2> {
    let ndc = vec2<f32>(
        2.0 * (f32(px.x) + 0.5) / frame.viewport.x - 1.0,
        1.0 - 2.0 * (f32(px.y) + 0.5) / frame.viewport.y,
    );
    // Affine in NDC (from f64 on the CPU): an f32 unprojection through box_from_clip would lose
    // most digits when the near plane is 1e-5 of the far one (the eye inside the volume).
    let near = frame.ray_near[0].xyz + ndc.x * frame.ray_near[1].xyz + ndc.y * frame.ray_near[2].xyz;
    let d = frame.ray_dir[0].xyz + ndc.x * frame.ray_dir[1].xyz + ndc.y * frame.ray_dir[2].xyz;
    let lo = frame.crop_min;
    let hi = frame.crop_max;
    var t0 = 0.0;
    var t1 = 1.0;
    for (var a = 0; a < 3; a += 1) {
        if abs(d[a]) < 1e-30 {
            // Parallel to this slab: inside it or never.
            if near[a] < lo[a] || near[a] > hi[a] {
                t1 = -1.0;
            }
        } else {
            let ta = (lo[a] - near[a]) / d[a];
            let tb = (hi[a] - near[a]) / d[a];
            t0 = max(t0, min(ta, tb));
            t1 = min(t1, max(ta, tb));
        }
    }
    let hit = f32(t1 > t0);
    let entry = clamp(near + d * t0, lo, hi);
    let exit = clamp(near + d * t1, lo, hi);
    return array<vec4<f32>, 2>(vec4<f32>(entry, hit), vec4<f32>(exit, hit));
}

// The pixel of invocation `id`, and whether it lies in the rows dispatched: the whole image, or
// one band of rows starting at `frame.row_offset` (a long frame is rendered in bands so that the
// window stays responsive).
fn pixel_of(id: vec3<u32>) -> vec3<u32> {
    let size = vec2<u32>(frame.viewport);
    let px = vec2<u32>(id.x, id.y + frame.row_offset);
    let inside = all(px < size) && px.y < frame.row_end;
    return vec3<u32>(px, u32(inside));
}

#ifdef RAY_SPLIT
// Each pixel's ray in RAY_PARTS parts, one invocation each (the workgroup's z), joined in
// order through workgroup memory: a ray's samples are taken by several invocations at once,
// so that a frame of few rays, or of rays of very different lengths, is not as long as its
// longest ray (src/render/raycast/variant.rs says which variants do this).
var<workgroup> parts: array<Acc, WORKGROUP * SPLIT_GROUP_ROWS * RAY_PARTS>;
#ifdef LOOP_RUNS
// Whether a part's share of the priming settled its pixel.
var<workgroup> settled_parts: array<u32, WORKGROUP * SPLIT_GROUP_ROWS * RAY_PARTS>;
#endif

// The parts of the pixel whose first part is in `slot`, joined in order.
fn joined_parts(slot: u32) -> Acc {
    var joined = parts[slot];
    for (var j = 1u; j < RAY_PARTS; j++) {
        joined = acc_combine(joined, parts[slot + j]);
    }
    return joined;
}

@compute @workgroup_size(WORKGROUP, SPLIT_GROUP_ROWS, RAY_PARTS)
fn cs_raycast(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_id) local: vec3<u32>) {
    let pixel = pixel_of(id);
    let px = pixel.xy;
    let pixel_slot = local.x + WORKGROUP * local.y;
    let slot = pixel_slot * RAY_PARTS;
    var ray: Ray;
    var hit = false;
    if pixel.z != 0u {
        let segment = box_segment(px);
        if segment[0].w > 0.0 {
            hit = true;
            ray = ray_between(segment[0].xyz, segment[1].xyz, px);
        }
    }
    var acc = acc_init();
    var primes = 0u;
    var settled = false;
#ifdef LOOP_RUNS
    // The parts share the ray's priming: each takes its share, then all start from the join.
    var primed = vec2<u32>(0u);
    if hit && ray.length_mm > 0.0 {
        primed = acc_prime(&acc, ray, local.z, RAY_PARTS);
    }
    primes = primed.x;
    parts[slot + local.z] = acc;
    settled_parts[slot + local.z] = primed.y;
    workgroupBarrier();
    if hit {
        acc = joined_parts(slot);
        for (var j = 0u; j < RAY_PARTS; j++) {
            settled = settled || settled_parts[slot + j] != 0u;
        }
    }
    workgroupBarrier();
#endif
    if hit {
        acc = march_part(ray, local.z, pixel_slot, acc, primes, settled);
    }
    parts[slot + local.z] = acc;
    workgroupBarrier();
    if pixel.z != 0u && local.z == 0u {
        var color = frame.background;
        if hit {
            color = acc_finish(joined_parts(slot), ray);
        }
        textureStore(out_tex, px, color);
    }
}
#else
// One invocation per pixel of the rows dispatched.
@compute @workgroup_size(WORKGROUP, WORKGROUP)
fn cs_raycast(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = pixel_of(id);
    if pixel.z == 0u {
        return;
    }
    let px = pixel.xy;
    let segment = box_segment(px);
    var color = frame.background;
    if segment[0].w > 0.0 {
        color = march(segment[0].xyz, segment[1].xyz, px);
    }
    textureStore(out_tex, px, color);
}
#endif
