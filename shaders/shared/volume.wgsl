// The volume as every shader reads it: one 3D texture of the volume, or (BRICKED) bricks of one
// of its levels in an atlas found through a page table (src/accel/bricks.rs). Each slot holds a brick and an apron
// of one voxel, so the texture unit's trilinear filter inside a slot reads exactly the voxels it
// would read in one texture: samples, gradients and the builders are exact across brick borders.
// The includer declares `volume_tex` (texture_3d<f32>), `volume_pages` (storage array<vec4<f32>>)
// and `volume_geometry` (uniform VolumeGeometry) at bindings of its own.

#include "shared/volume_geometry.wgsl"

// Voxels per axis.
fn volume_dims() -> vec3<i32> {
    return vec3<i32>(volume_geometry.dims);
}

#ifdef BRICKED
// Where a brick of level 0 finds its voxels (src/render/volume_texture/atlas.rs, gpu_page; a
// storage buffer, x fastest, of four f32 so that a read decodes nothing): the atlas texel of
// voxel 0 of the level its brick is held at, as if that brick's slot were the whole level (a
// voxel `i` of the level, or of the brick's apron, lies at texel origin + i), and 2^-level
// (level 0: the brick itself; k: its ancestor `b >> k`, whose voxels are 2^k of level 0's per
// axis). A brick that no ray can see (empty under the transfer function, its neighbours too)
// holds no slot: its entry is a constant, (value, 0, 0, 0).
//
// How the points of that brick find their values: the atlas coordinate of box position p is
// p · atlas_per_box · 2^-level + origin · texel_size, or, for a brick no ray can see, the
// constant. The apron and the overhang past the volume repeat the nearest voxel, so no clamp is
// needed for points of the box: the filter blends equal texels there, as clamp to edge does.
// Each read takes its brick's entry afresh and never behind a branch, so that a lane crossing
// into another brick does not make its warp read twice (keeping the last brick's entry measured
// no faster: docs/benchmarks/nvidia-h100-bricks-stream §7, §13).

// The level-0 brick holding box position p (p in the box; points a rounding past a face count
// to the brick inside).
fn brick_at(p: vec3<f32>) -> vec3<i32> {
    let b = vec3<u32>(max(p * volume_geometry.bricks_per_box, vec3<f32>(0.0)));
    return vec3<i32>(min(b, volume_geometry.last_brick));
}

// Brick b's place in the page table.
fn page_index(b: vec3<i32>) -> i32 {
    let n = vec3<i32>(volume_geometry.last_brick) + vec3<i32>(1);
    return b.x + n.x * (b.y + n.y * b.z);
}

// Voxel `i` (clamped into the volume), from the level its brick is held at.
fn volume_load(i: vec3<i32>) -> vec4<f32> {
    let j = clamp(i, vec3<i32>(0), volume_dims() - vec3<i32>(1));
    let e = volume_pages[page_index(j / i32(volume_geometry.brick_vox))];
    // j · 2^-level, floored: exact in f32 for any voxel index below 2^24. A constant's entry
    // reads texel (value, 0, 0), which the select drops: no branch.
    let at_level = vec3<i32>(floor(vec3<f32>(j) * e.w));
    let t = textureLoad(volume_tex, vec3<i32>(e.xyz) + at_level, 0);
    return select(t, vec4<f32>(e.x, 0.0, 0.0, 1.0), e.w == 0.0);
}

// The texture unit's trilinear sample at box position p inside the box, through the brick
// holding it, at the level that brick is held at.
fn volume_inner(linear: sampler, p: vec3<f32>) -> vec4<f32> {
    // (origin, 2^-level), or a constant's (value, 0, 0, 0): that scales by 0 and reads the atlas
    // at (value, 0, 0) · texel size, which the select drops.
    let e = volume_pages[page_index(brick_at(p))];
    let scale = volume_geometry.atlas_per_box * e.w;
    let offset = e.xyz * volume_geometry.texel_size;
    let t = textureSampleLevel(volume_tex, linear, fma(p, scale, offset), 0.0);
    return select(t, vec4<f32>(e.x, 0.0, 0.0, 1.0), e.w == 0.0);
}

// The texture unit's trilinear sample at box position p (clamp to edge).
fn volume_filtered(linear: sampler, p: vec3<f32>) -> vec4<f32> {
    return volume_inner(linear, clamp(p, vec3<f32>(0.0), vec3<f32>(1.0)));
}
#else
// Voxel `i` (inside the volume).
fn volume_load(i: vec3<i32>) -> vec4<f32> {
    return textureLoad(volume_tex, i, 0);
}

// The texture unit's trilinear sample at box position p (clamp to edge).
fn volume_filtered(linear: sampler, p: vec3<f32>) -> vec4<f32> {
    return textureSampleLevel(volume_tex, linear, p, 0.0);
}

// volume_filtered at a position p inside the box.
fn volume_inner(linear: sampler, p: vec3<f32>) -> vec4<f32> {
    return volume_filtered(linear, p);
}
#endif
