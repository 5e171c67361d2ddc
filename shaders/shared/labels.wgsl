// A segmentation in the ray loop (LABELS): the label of the voxel nearest a sample (labels are
// never interpolated) in up to four layers, and what the variant does with it: LABEL_COLOUR, a
// sample takes its shown label's colour; LABEL_INSIDE, samples outside the shown labels are
// cut away. src/render/labels.rs uploads both textures; src/reference/modes.rs twins the rules.

#include "shared/common.wgsl"

#ifdef LABELS
#include "shared/label_texel.wgsl"

// The labels on the volume's grid, a layer per channel (or, with frame.label_bricks, the label
// atlas slot for slot with the volume's bricks: labels_texel), and each label value's colour at texel
// (value % 256, value / 256), its alpha 0 where the label is hidden or absent.
@group(0) @binding(7) var label_tex: texture_3d<u32>;
@group(0) @binding(8) var label_colours: texture_2d<f32>;

// The labels of the voxel nearest box position p, a layer per component (0 past the layers the
// texture holds: an R16Uint texel reads alpha 1).
fn labels_at(p: vec3<f32>) -> vec4<u32> {
    return labels_of(voxel_of(p));
}

// The voxel nearest box position p (clamped to the grid).
fn voxel_of(p: vec3<f32>) -> vec3<i32> {
    let dims = volume_dims();
    return clamp(vec3<i32>(floor(p * vec3<f32>(dims))), vec3<i32>(0), dims - vec3<i32>(1));
}

// The labels of voxel i (on the grid), a layer per component.
fn labels_of(i: vec3<i32>) -> vec4<u32> {
    let texel = labels_texel(label_tex, i, frame.label_bricks != 0u);
    return select(vec4<u32>(0u), texel, vec4<u32>(0u, 1u, 2u, 3u) < vec4<u32>(frame.label_layers));
}

// Label value l's colour (rgb) and its opacity (a; 0: hidden).
fn label_colour(l: u32) -> vec4<f32> {
    return textureLoad(label_colours, vec2<i32>(i32(l % 256u), i32(l / 256u)), 0);
}

// The first layer's shown label at p: its colour and opacity (a = 0 where none is shown). The
// colour table is read only for the layers the texture holds, and only where a label lies.
fn shown_label(p: vec3<f32>) -> vec4<f32> {
    return shown_label_of(voxel_of(p));
}

// The first layer's shown label of voxel i (a = 0 where none is shown).
fn shown_label_of(i: vec3<i32>) -> vec4<f32> {
    let here = labels_of(i);
    for (var layer = 0u; layer < min(frame.label_layers, 4u); layer++) {
        if here[layer] != 0u {
            let c = label_colour(here[layer]);
            if c.a > 0.0 {
                return c;
            }
        }
    }
    return vec4<f32>(0.0);
}

// Whether some layer's label at p is shown.
fn inside_labels(p: vec3<f32>) -> bool {
    return shown_label(p).a > 0.0;
}
#endif

// A sample's colour `rgb` at p as the variant shows it: with LABEL_COLOUR, mixed towards the
// colour of the first layer's shown label there by that label's opacity (the table's alpha; 0
// where none is shown leaves `rgb` as it is).
fn labelled_colour(rgb: vec3<f32>, p: vec3<f32>) -> vec3<f32> {
#ifdef LABEL_COLOUR
    let c = shown_label(p);
    return mix(rgb, c.rgb, c.a);
#else
    return rgb;
#endif
}

// A ray's sample value s at p as the variant sees it: with LABEL_INSIDE, missing (transparent,
// never an extreme, no density) outside the shown labels.
fn labelled_value(s: f32, p: vec3<f32>) -> f32 {
#ifdef LABEL_INSIDE
    if !inside_labels(p) {
        return MISSING_BELOW - 1.0;
    }
#endif
    return s;
}
