// Shadows (SHADOWS, lit DVR and isosurfaces): the share of the light that reaches a lit sample
// through the transfer function's opacity between it and the light (an isosurface's hit: 0 where
// the isosurface lies between them, else 1). A directional light's by a secondary
// ray marched from the sample towards the light, at samples every `shadow_step_mm` (the first
// one step from the sample: its own opacity is in its colour) up to the crop box or
// `shadow_reach_mm`, summing the table's optical depth scaled from the primary step to the
// shadow step; with LEAP it leaps over the nodes the primary ray would (their samples add no
// depth: exactly the same sum); with EARLY_TERMINATION it ends where the light falls below one
// 8-bit level. A headlight's is the opacity the primary ray gathered in front of the sample
// (the same samples, towards the eye); nothing lies in front of an isosurface's first crossing.
// The f64 twin is `shadow_transmittance` in src/reference/modes.rs.

// Optical depth past which rays that stop early call the light gone: −ln(1/255).
const SHADOW_GONE_DEPTH: f32 = 5.541264;

// Distance (mm) from box position p along `box_per_mm` to the crop box's face it leaves by;
// along an axis it runs parallel to, no face.
fn crop_exit_mm(p: vec3<f32>, box_per_mm: vec3<f32>) -> f32 {
    let bound = select(frame.crop_min, frame.crop_max, box_per_mm > vec3<f32>(0.0));
    let parallel = box_per_mm == vec3<f32>(0.0);
    let t = select((bound - p) / box_per_mm, vec3<f32>(3.0e38), parallel);
    return max(min(t.x, min(t.y, t.z)), 0.0);
}

// The directional light's transmittance to box position p, for a ray holding `acc` (its leap
// predicate decides which nodes are empty).
fn light_transmittance(p: vec3<f32>, acc_in: Acc) -> f32 {
    var acc = acc_in;
#ifdef MODE_ISO
    // The shadow ray leaves the surface on its side below the iso value: a node wholly below
    // holds nothing that blocks the light.
    acc.side = -1.0;
#endif
    let box_per_mm = -frame.light_dir / frame.extent_mm;
    let length_mm = min(crop_exit_mm(p, box_per_mm), frame.shadow_reach_mm);
    let h = frame.shadow_step_mm;
    // The table holds the depth of one primary step.
    let per_step = h / frame.step_mm;
    var depth = 0.0;
#ifdef LEAP
    let leap = leap_ray(p, box_per_mm, 0.0);
    var until = 0u;
#endif
    var j = 1u;
    loop {
        let t = f32(j) * h;
        if t >= length_mm {
            break;
        }
        let q = p + box_per_mm * t;
#ifdef LEAP
        if j >= until {
            let region = region_of(leaf_block(q), acc);
            let exit = exit_distance(leap, region.lo, region.hi);
            let after = max(u32(clamp(floor(exit / h) + 1.0, 0.0, 4.0e9)), j + 1u);
            if !region.matters {
                j = after;
                continue;
            }
            until = after;
        }
#endif
        let s = labelled_value(sample_value(q), q);
#ifdef MODE_ISO
        if s >= frame.iso_threshold {
            return 0.0;
        }
#else
        depth += classify(s).a * per_step;
#endif
#ifdef EARLY_TERMINATION
        if depth > SHADOW_GONE_DEPTH {
            return 0.0;
        }
#endif
        j++;
    }
    return exp(-depth);
}
