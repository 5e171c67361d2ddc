// Labels as surfaces: the mask the ray loop finds their surfaces in (shared/label_surface.wgsl).
// A channel per class of shown labels (src/labels/classes.rs): the indicator of the shown labels
// of that class (1 where some layer's label has a colour of alpha above 0 and that class)
// smoothed by a separable Gaussian, one axis per pass, each pass written as bytes into a buffer
// laid out as the mask texture's rows (1, 2 or 4 bytes a voxel, 256-byte aligned) and copied into
// the texture, which the next pass reads. A pass covers a slab of the grid (z slabs for x and y,
// y slabs for z, so a pass never reads what it replaces). Voxels past the grid count as 0. After
// a toggle only the toggled labels' region is made again: the x and y passes over it widened by
// the kernel's reach into a scratch texture (read from read_origin), the z pass into the mask.
// The CPU twin is src/labels/surface.rs; the builder src/render/label_surface.rs.

// `SurfaceParams` in src/render/gpu_data.rs.
struct SurfaceParams {
    dims: vec3<u32>,
    // The axis this pass smooths along (0, 1, 2).
    axis: u32,
    // The slab's first voxel and its extent; the buffer holds the slab.
    origin: vec3<u32>,
    // Words (four bytes: 4 / channels voxels) per row of the buffer.
    row_words: u32,
    extent: vec3<u32>,
    // The kernel's radius (voxels) and its weights for offsets 0, 1, 2, 3.
    radius: u32,
    weights: vec4<f32>,
    // Layers of labels the label texture holds.
    layers: u32,
    // The mask's channels: 1, 2 or 4.
    channels: u32,
    _pad1: u32,
    _pad2: u32,
    // The voxel mask_in starts at: 0 for the whole mask, the region's first voxel for the
    // scratch of a region's build.
    read_origin: vec3<u32>,
    _pad3: u32,
}

@group(0) @binding(0) var<uniform> params: SurfaceParams;
@group(0) @binding(1) var label_tex: texture_3d<u32>;
@group(0) @binding(2) var label_colours: texture_2d<f32>;
@group(0) @binding(3) var mask_in: texture_3d<f32>;
@group(0) @binding(4) var<storage, read_write> mask_out: array<u32>;
// Each label value's class (its channel) at texel (value % 256, value / 256).
@group(0) @binding(5) var label_classes: texture_2d<u32>;

fn outside(i: vec3<i32>) -> bool {
    return any(i < vec3<i32>(0)) || any(i >= vec3<i32>(params.dims));
}

// Per channel, 1 where voxel i's label in some layer is shown and of that channel's class.
fn shown_voxel(i: vec3<i32>) -> vec4<f32> {
    var v = vec4<f32>(0.0);
    if outside(i) {
        return v;
    }
    let texel = textureLoad(label_tex, i, 0);
    for (var layer = 0u; layer < min(params.layers, 4u); layer++) {
        let l = texel[layer];
        let at = vec2<i32>(i32(l % 256u), i32(l / 256u));
        if l != 0u && textureLoad(label_colours, at, 0).a > 0.0 {
            v[min(textureLoad(label_classes, at, 0).r, 3u)] = 1.0;
        }
    }
    return v;
}

fn mask_voxel(i: vec3<i32>) -> vec4<f32> {
    if outside(i) {
        return vec4<f32>(0.0);
    }
    return textureLoad(mask_in, i - vec3<i32>(params.read_origin), 0);
}

fn quantise(v: f32) -> u32 {
    return u32(clamp(v, 0.0, 1.0) * 255.0 + 0.5);
}

// The pass's axis as a step.
fn axis_step() -> vec3<i32> {
    var e = vec3<i32>(0);
    e[params.axis] = 1;
    return e;
}

// The shown labels' indicators at voxel i smoothed along the pass's axis (the first pass).
fn smoothed_labels(i: vec3<i32>) -> vec4<f32> {
    let r = i32(params.radius);
    var sum = vec4<f32>(0.0);
    for (var o = -r; o <= r; o++) {
        sum += params.weights[abs(o)] * shown_voxel(i + o * axis_step());
    }
    return sum;
}

// The mask so far at voxel i smoothed along the pass's axis (later passes).
fn smoothed_mask(i: vec3<i32>) -> vec4<f32> {
    let r = i32(params.radius);
    var sum = vec4<f32>(0.0);
    for (var o = -r; o <= r; o++) {
        sum += params.weights[abs(o)] * mask_voxel(i + o * axis_step());
    }
    return sum;
}

// Voxels per word of the buffer.
fn per_word() -> u32 {
    return 4u / params.channels;
}

// Whether invocation id (word, row, slice within the slab) has voxels of the slab.
fn in_slab(id: vec3<u32>) -> bool {
    let words = (params.extent.x * params.channels + 3u) / 4u;
    return id.x < words && id.y < params.extent.y && id.z < params.extent.z;
}

// Voxel b of invocation id's word, and whether it lies in the slab.
fn voxel_of_word(id: vec3<u32>, b: u32) -> vec4<i32> {
    let x = id.x * per_word() + b;
    let i = vec3<i32>(params.origin + vec3<u32>(x, id.y, id.z));
    return vec4<i32>(i, i32(x < params.extent.x));
}

// Voxel b of a word's channels as bytes at their place in the word.
fn packed(v: vec4<f32>, b: u32) -> u32 {
    var word = 0u;
    for (var c = 0u; c < params.channels; c++) {
        word |= quantise(v[c]) << (8u * (b * params.channels + c));
    }
    return word;
}

fn store(id: vec3<u32>, word: u32) {
    mask_out[id.x + params.row_words * (id.y + params.extent.y * id.z)] = word;
}

// The first pass: the indicators of the shown labels, smoothed along the axis (each entry
// point reads only its own textures: its layout is derived from what it uses).
@compute @workgroup_size(8, 8, 4)
fn smooth_labels(@builtin(global_invocation_id) id: vec3<u32>) {
    if !in_slab(id) {
        return;
    }
    var word = 0u;
    for (var b = 0u; b < per_word(); b++) {
        let v = voxel_of_word(id, b);
        if v.w != 0 {
            word |= packed(smoothed_labels(v.xyz), b);
        }
    }
    store(id, word);
}

// Later passes: the mask so far, smoothed along the axis.
@compute @workgroup_size(8, 8, 4)
fn smooth_mask(@builtin(global_invocation_id) id: vec3<u32>) {
    if !in_slab(id) {
        return;
    }
    var word = 0u;
    for (var b = 0u; b < per_word(); b++) {
        let v = voxel_of_word(id, b);
        if v.w != 0 {
            word |= packed(smoothed_mask(v.xyz), b);
        }
    }
    store(id, word);
}
