// Per-sample Phong lighting from on-the-fly gradients (DVR and isosurface variants only):
// I = Ka·Ia + Kd·Il·cosθ + Ks·Il·cosⁿα with Ia = Il = 1, two-sided normals, white highlights.

#include "shared/classify.wgsl"

// Gradient of the normalised value per millimetre at box position p, by differences of
// trilinearly filtered reads one voxel apart (or ±1 and ±2 voxels for the fourth-order scheme).
// Returns zero where any read touches a non-finite voxel.
fn gradient(p: vec3<f32>) -> vec3<f32> {
    let h = 1.0 / frame.volume_dims;
    var g = vec3<f32>(0.0);
    var lowest = 0.0;
    for (var a = 0u; a < 3u; a++) {
        var e = vec3<f32>(0.0);
        e[a] = h[a];
        let f1 = sample_value(p + e);
        let b1 = sample_value(p - e);
#ifdef GRADIENT_FOURTH_ORDER
        let f2 = sample_value(p + 2.0 * e);
        let b2 = sample_value(p - 2.0 * e);
        g[a] = (8.0 * (f1 - b1) - (f2 - b2)) / 12.0;
        lowest = min(lowest, min(min(f1, b1), min(f2, b2)));
#else
        g[a] = 0.5 * (f1 - b1);
        lowest = min(lowest, min(f1, b1));
#endif
    }
    return select(g / frame.spacing_mm, vec3<f32>(0.0), lowest < MISSING_BELOW);
}

// Gradients shorter than this (normalised value per mm) give no direction: the sample is unlit.
const FLAT_GRADIENT: f32 = 1e-7;

// Lights `color` at a sample with gradient `g`, seen along `view_dir` (unit, world).
fn phong(color: vec3<f32>, g: vec3<f32>, view_dir: vec3<f32>) -> vec3<f32> {
    return phong_shadowed(color, g, view_dir, vec2<f32>(1.0));
}

// `phong` where a share `reach.x` (0…1) of the light and a share `reach.y` of the ambient light
// reach the sample (shadows, ambient occlusion): the diffuse and specular terms scaled by the
// first, the ambient by the second; a flat gradient's colour scaled from full (both 1) by
// (Ka·reach.y + Kd·reach.x) / (Ka + Kd).
fn phong_shadowed(color: vec3<f32>, g: vec3<f32>, view_dir: vec3<f32>, reach: vec2<f32>) -> vec3<f32> {
    let light = reach.x;
    let ambient = frame.phong_ambient * reach.y;
    let len = length(g);
    if !(len > FLAT_GRADIENT) {
        let lit = frame.phong_ambient + frame.phong_diffuse;
        let dimmed = any(reach < vec2<f32>(1.0)) && lit > 0.0;
        return select(color, color * (ambient + frame.phong_diffuse * light) / lit, dimmed);
    }
    let to_eye = -view_dir;
    var n = -g / len;
    n = select(n, -n, dot(n, to_eye) < 0.0);
    let to_light = select(-frame.light_dir, to_eye, frame.headlight != 0u);
    let diffuse = max(dot(n, to_light), 0.0);
    let r = reflect(-to_light, n);
    let specular = pow(max(dot(r, to_eye), 0.0), frame.phong_shininess);
    return color * (ambient + frame.phong_diffuse * diffuse * light) + vec3<f32>(frame.phong_specular * specular * light);
}
