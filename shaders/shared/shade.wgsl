// Per-sample Phong lighting from on-the-fly gradients (DVR and isosurface variants only):
// I = Ka·Ia + Kd·Il·cosθ + Ks·Il·cosⁿα with Ia = Il = 1, two-sided normals, white highlights.

#include "shared/classify.wgsl"

// Gradient of the normalised value per millimetre at box position p, by differences of
// trilinearly filtered reads one voxel apart (or ±1 and ±2 voxels for the fourth-order scheme).
// Returns zero where any read touches a non-finite voxel.
fn gradient(p: vec3<f32>) -> vec3<f32> {
#ifdef BRICKED
    // Where every read's filter footprint lies in p's brick and its apron, the reads go through
    // p's map, found once (a read anywhere else finds its own brick, as sample_value does).
    let b = brick_at(p);
    let m = map_of(b);
    let local = p * frame.volume_dims - vec3<f32>(b) * f32(volume_geometry.brick_vox);
    let margin = GRADIENT_REACH - 0.5;
    let through_m = m.entry.w != 0.0 && all(local >= vec3<f32>(margin))
        && all(local < vec3<f32>(f32(volume_geometry.brick_vox) - margin));
#endif
    let h = 1.0 / frame.volume_dims;
    var g = vec3<f32>(0.0);
    var lowest = 0.0;
    for (var a = 0u; a < 3u; a++) {
        var e = vec3<f32>(0.0);
        e[a] = h[a];
#ifdef BRICKED
        let f1 = gradient_read(through_m, m, p + e);
        let b1 = gradient_read(through_m, m, p - e);
#else
        let f1 = sample_value(p + e);
        let b1 = sample_value(p - e);
#endif
#ifdef GRADIENT_FOURTH_ORDER
#ifdef BRICKED
        let f2 = gradient_read(through_m, m, p + 2.0 * e);
        let b2 = gradient_read(through_m, m, p - 2.0 * e);
#else
        let f2 = sample_value(p + 2.0 * e);
        let b2 = sample_value(p - 2.0 * e);
#endif
        g[a] = (8.0 * (f1 - b1) - (f2 - b2)) / 12.0;
        lowest = min(lowest, min(min(f1, b1), min(f2, b2)));
#else
        g[a] = 0.5 * (f1 - b1);
        lowest = min(lowest, min(f1, b1));
#endif
    }
    return select(g / frame.spacing_mm, vec3<f32>(0.0), lowest < MISSING_BELOW);
}

#ifdef BRICKED
// How far (voxels of level 0) the gradient's reads lie from the sample.
#ifdef GRADIENT_FOURTH_ORDER
const GRADIENT_REACH: f32 = 2.0;
#else
const GRADIENT_REACH: f32 = 1.0;
#endif

// A gradient read at q: through map m where its footprint lies in m's slot (the apron holds the
// neighbours' voxels, so the value is sample_value's), else through q's own brick.
fn gradient_read(through_m: bool, m: BrickMap, q: vec3<f32>) -> f32 {
    if through_m {
        return sample_value_in(m, q);
    }
    return sample_value(q);
}
#endif

// Gradients shorter than this (normalised value per mm) give no direction: the sample is unlit.
const FLAT_GRADIENT: f32 = 1e-7;

// Lights `color` at a sample with gradient `g`, seen along `view_dir` (unit, world).
fn phong(color: vec3<f32>, g: vec3<f32>, view_dir: vec3<f32>) -> vec3<f32> {
    let len = length(g);
    if !(len > FLAT_GRADIENT) {
        return color;
    }
    let to_eye = -view_dir;
    var n = -g / len;
    n = select(n, -n, dot(n, to_eye) < 0.0);
    let to_light = select(-frame.light_dir, to_eye, frame.headlight != 0u);
    let diffuse = max(dot(n, to_light), 0.0);
    let r = reflect(-to_light, n);
    let specular = pow(max(dot(r, to_eye), 0.0), frame.phong_shininess);
    return color * (frame.phong_ambient + frame.phong_diffuse * diffuse) + vec3<f32>(frame.phong_specular * specular);
}
