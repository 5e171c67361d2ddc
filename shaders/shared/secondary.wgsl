// What the secondary rays of shadows and ambient occlusion share (shared/shadow.wgsl,
// shared/occlusion.wgsl).

#include "shared/classify.wgsl"

// Optical depth past which a secondary ray is blocked: the isosurface's samples at or above
// the iso value add it.
const BLOCKED_DEPTH: f32 = 3.0e38;

// Two unit vectors that with the unit vector n make an orthonormal basis (any, but the same
// for the same n: the f64 reference builds them alike, `plane_across` in
// src/reference/modes.rs).
fn plane_across(n: vec3<f32>) -> array<vec3<f32>, 2> {
    let helper = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(n.x) > 0.9);
    let t = normalize(cross(n, helper));
    return array<vec3<f32>, 2>(t, cross(n, t));
}

// The optical depth a secondary ray's sample at box position q adds, `per_step` primary steps
// long: the transfer function's (the table holds one primary step's); for the isosurface
// BLOCKED_DEPTH where the sample reaches the iso value, else none.
fn secondary_depth(q: vec3<f32>, per_step: f32) -> f32 {
    let s = labelled_value(sample_value(q), q);
#ifdef MODE_ISO
    return select(0.0, BLOCKED_DEPTH, s >= frame.iso_threshold);
#else
    return classify(s).a * per_step;
#endif
}

// Distance (mm) from box position p along `box_per_mm` to the crop box's face it leaves by;
// along an axis it runs parallel to, no face.
fn crop_exit_mm(p: vec3<f32>, box_per_mm: vec3<f32>) -> f32 {
    let bound = select(frame.crop_min, frame.crop_max, box_per_mm > vec3<f32>(0.0));
    let parallel = box_per_mm == vec3<f32>(0.0);
    let t = select((bound - p) / box_per_mm, vec3<f32>(3.0e38), parallel);
    return max(min(t.x, min(t.y, t.z)), 0.0);
}
