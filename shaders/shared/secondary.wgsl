// What the secondary rays of shadows and ambient occlusion share (shared/shadow.wgsl,
// shared/occlusion.wgsl).

#include "shared/common.wgsl"

// Distance (mm) from box position p along `box_per_mm` to the crop box's face it leaves by;
// along an axis it runs parallel to, no face.
fn crop_exit_mm(p: vec3<f32>, box_per_mm: vec3<f32>) -> f32 {
    let bound = select(frame.crop_min, frame.crop_max, box_per_mm > vec3<f32>(0.0));
    let parallel = box_per_mm == vec3<f32>(0.0);
    let t = select((bound - p) / box_per_mm, vec3<f32>(3.0e38), parallel);
    return max(min(t.x, min(t.y, t.z)), 0.0);
}
