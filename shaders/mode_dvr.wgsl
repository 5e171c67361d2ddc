// DVR: front-to-back compositing with post-classification and opacity correction.

#include "classify.wgsl"
#ifdef SHADING
#include "shade.wgsl"
#endif

struct Acc {
    color: vec4<f32>,
}

fn acc_init() -> Acc {
    return Acc(vec4<f32>(0.0));
}

fn acc_leap_query(acc: Acc) -> f32 {
    return 0.0;
}

fn acc_sample(acc: ptr<function, Acc>, ray: Ray, k: u32, t: f32, p: vec3<f32>, s: f32) -> u32 {
    var c = classify(s);
    if c.a <= 0.0 {
        return 0u;
    }
    if k + 1u == ray.count {
        // The last segment may be shorter than a step: scale its optical depth.
        let w = clamp((ray.length_mm - f32(k) * frame.step_mm) / frame.step_mm, 0.0, 1.0);
        c.a = select(1.0 - pow(1.0 - c.a, w), 1.0, c.a >= 1.0);
    }
#ifdef SHADING
    c = vec4<f32>(phong(c.rgb, gradient(p), ray.dir_world), c.a);
#endif
    (*acc).color += (1.0 - (*acc).color.a) * vec4<f32>(c.rgb * c.a, c.a);
#ifdef EARLY_TERMINATION
    if (*acc).color.a > frame.termination_alpha {
        return SAMPLE_STOP | SAMPLE_CONTRIBUTED;
    }
#endif
    return SAMPLE_CONTRIBUTED;
}

fn acc_finish(acc: Acc, ray: Ray) -> vec4<f32> {
    return vec4<f32>(acc.color.rgb + (1.0 - acc.color.a) * frame.background.rgb, 1.0);
}
