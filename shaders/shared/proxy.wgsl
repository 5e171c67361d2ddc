// The proxy geometry that generates rays (Liang et al.): the cropping box's faces in box
// coordinates (the bounding box [0,1]^3 when nothing is cropped), plus a full-screen triangle on the near plane for rays that start inside
// the box (the eye inside the volume, or the near plane cutting a corner).

#include "shared/common.wgsl"

// The cube's 12 triangles, counter-clockwise seen from outside. Corner c has box coordinates
// (c & 1, (c >> 1) & 1, (c >> 2) & 1).
var<private> CUBE: array<u32, 36> = array<u32, 36>(
    4u, 6u, 2u, 4u, 2u, 0u, 1u, 3u, 7u, 1u, 7u, 5u, 1u, 5u, 4u, 1u, 4u, 0u,
    2u, 6u, 7u, 2u, 7u, 3u, 2u, 3u, 1u, 2u, 1u, 0u, 4u, 5u, 7u, 4u, 7u, 6u,
);

// Clip depth of the near-plane cap: inside the clip volume, so it is never clipped itself.
const CAP_DEPTH: f32 = 1e-6;
// Cap points this far outside [0,1]^3 (rounding of the inverse projection) still count as inside.
const CAP_EPSILON: f32 = 1e-5;

struct ProxyOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) box_pos: vec3<f32>,
    @location(1) @interpolate(flat) is_cap: u32,
}

// Vertices 0..35 are the cube, 36..38 the near-plane cap.
@vertex
fn vs_proxy(@builtin(vertex_index) index: u32) -> ProxyOut {
    var out: ProxyOut;
    if index < 36u {
        let c = CUBE[index];
        let corner = vec3<f32>(f32(c & 1u), f32((c >> 1u) & 1u), f32((c >> 2u) & 1u));
        // Exactly crop_min or crop_max on each axis (select, not mix: no rounding).
        let p = select(frame.crop_min, frame.crop_max, corner > vec3<f32>(0.5));
        out.clip = frame.clip_from_box * vec4<f32>(p, 1.0);
        out.box_pos = p;
        out.is_cap = 0u;
    } else {
        let j = index - 36u;
        let xy = vec2<f32>(f32((j << 1u) & 2u), f32(j & 2u)) * 2.0 - 1.0;
        out.clip = vec4<f32>(xy, CAP_DEPTH, 1.0);
        out.box_pos = vec3<f32>(0.0);
        out.is_cap = 1u;
    }
    return out;
}

// The ray's entry point in box coordinates (w = 1), or w = 0 where this fragment starts no ray.
// A front-face fragment enters where it lies; a cap fragment enters on the near plane, if that
// point is inside the (cropping) box. The two never both start a ray at one pixel: where the near-plane
// point is inside the box, the front face lies before the near plane and was clipped.
fn ray_entry(in: ProxyOut) -> vec4<f32> {
    if in.is_cap == 0u {
        return vec4<f32>(in.box_pos, 1.0);
    }
    let ndc = vec2<f32>(
        2.0 * in.clip.x / frame.viewport.x - 1.0,
        1.0 - 2.0 * in.clip.y / frame.viewport.y,
    );
    let h = frame.box_from_clip * vec4<f32>(ndc, 0.0, 1.0);
    let p = h.xyz / h.w;
    let lo = frame.crop_min;
    let hi = frame.crop_max;
    if any(p < lo - vec3<f32>(CAP_EPSILON)) || any(p > hi + vec3<f32>(CAP_EPSILON)) {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(clamp(p, lo, hi), 1.0);
}
