// A voxel's labels, wherever they are held: one texture of the volume's grid, or a label atlas
// slot for slot with a bricked volume's (src/render/volume_texture/label_atlas.rs), found
// through the page table the includer binds (shared/volume.wgsl). Included only by the
// variants that read labels (shared/labels.wgsl under LABELS, entry/slice.wgsl under DISPLAY).

#include "shared/volume.wgsl"

#ifdef BRICKED
// The labels of voxel `i` (clamped into the volume) from the label atlas `atlas`, at the level
// its brick is held at; 0 in a brick held as a constant (no ray sees one).
fn volume_labels(atlas: texture_3d<u32>, i: vec3<i32>) -> vec4<u32> {
    let j = clamp(i, vec3<i32>(0), volume_dims() - vec3<i32>(1));
    let e = volume_pages[page_index(j / i32(volume_geometry.brick_vox))];
    let at_level = vec3<i32>(floor(vec3<f32>(j) * e.w));
    let t = textureLoad(atlas, vec3<i32>(e.xyz) + at_level, 0);
    return select(vec4<u32>(0u), t, e.w != 0.0);
}

// The labels of voxel `i` in `labels`: one texture of the grid, or, `in_bricks`, the label
// atlas (volume_labels).
fn labels_texel(labels: texture_3d<u32>, i: vec3<i32>, in_bricks: bool) -> vec4<u32> {
    // Uniform across a pass: every lane takes the same side.
    if in_bricks {
        return volume_labels(labels, i);
    }
    return textureLoad(labels, i, 0);
}
#else
// The labels of voxel `i` in `labels`, one texture of the grid (labels travel in bricks only
// with a bricked volume).
fn labels_texel(labels: texture_3d<u32>, i: vec3<i32>, in_bricks: bool) -> vec4<u32> {
    return textureLoad(labels, i, 0);
}
#endif
