// Ambient occlusion (OCCLUSION, lit DVR and isosurfaces): the share of the ambient light that
// reaches a lit sample, the mean transmittance of OCCLUSION_RAYS short rays over the side its
// gradient points away from (the open side of a surface): at 45° from −∇, evenly around it,
// turned per pixel by the ray's first-sample offset (so jittered rays and refinement average
// the pattern away), each sampling the transfer function's opacity every occlusion step (the
// smallest voxel spacing) from one step out to `occlusion_radius_mm` or the crop box (for an
// isosurface: blocked where a sample reaches the iso value). A flat
// gradient has no open side: unoccluded. The f64 twin is `RayInput::occlusion` in
// src/reference/modes.rs.

#include "shared/shade.wgsl"
#include "shared/secondary.wgsl"

// `OCCLUSION_RAYS` in src/settings/effects.rs.
const OCCLUSION_RAYS: u32 = 6u;

// The share of the ambient light reaching box position p, whose gradient is g, on `ray`.
fn occlusion_at(p: vec3<f32>, g: vec3<f32>, ray: Ray) -> f32 {
    let len = length(g);
    if !(len > FLAT_GRADIENT) {
        return 1.0;
    }
    let n = -g / len;
    let across = plane_across(n);
    let h = frame.occlusion_step_mm;
    let per_step = h / frame.step_mm;
    var open = 0.0;
    for (var k = 0u; k < OCCLUSION_RAYS; k++) {
        let phi = 6.283185307 * (f32(k) + ray.offset) / f32(OCCLUSION_RAYS);
        let d = normalize(n + cos(phi) * across[0] + sin(phi) * across[1]);
        let box_per_mm = d / frame.extent_mm;
        let length_mm = min(crop_exit_mm(p, box_per_mm), frame.occlusion_radius_mm);
        var depth = 0.0;
        for (var j = 1u; f32(j) * h <= length_mm; j++) {
            depth += secondary_depth(p + box_per_mm * (f32(j) * h), per_step);
            if depth >= BLOCKED_DEPTH {
                break;
            }
        }
        open += exp(-depth);
    }
    return open / f32(OCCLUSION_RAYS);
}
