// The volume as every shader reads it: one 3D texture of the volume, or (BRICKED) bricks in an
// atlas found through a page table (src/accel/bricks.rs). Each slot holds a brick and an apron
// of one voxel, so the texture unit's trilinear filter inside a slot reads exactly the voxels it
// would read in one texture: samples, gradients and the builders are exact across brick borders.
// The includer declares `volume_tex` (texture_3d<f32>), `volume_pages` (texture_3d<u32>) and
// `volume_geometry` (uniform VolumeGeometry) at bindings of its own.

#include "shared/volume_geometry.wgsl"

// Voxels per axis.
fn volume_dims() -> vec3<i32> {
    return vec3<i32>(volume_geometry.dims);
}

#ifdef BRICKED
// Atlas texel of voxel 0 of brick `b`, as if the brick's slot were the whole volume: a voxel
// `i` of the brick (or of its apron) lies at texel origin + i.
fn brick_origin(b: vec3<i32>) -> vec3<i32> {
    let e = textureLoad(volume_pages, b, 0).r;
    let slot = vec3<i32>(vec3<u32>(e & 1023u, (e >> 10u) & 1023u, (e >> 20u) & 1023u));
    return slot * i32(volume_geometry.slot_vox) + vec3<i32>(1) - b * i32(volume_geometry.brick_vox);
}

// Voxel `i` (clamped into the volume).
fn volume_load(i: vec3<i32>) -> vec4<f32> {
    let j = clamp(i, vec3<i32>(0), volume_dims() - vec3<i32>(1));
    return textureLoad(volume_tex, brick_origin(j / i32(volume_geometry.brick_vox)) + j, 0);
}

// The texture unit's trilinear sample at box position p (clamp to edge): the brick holding the
// clamped point, then the same continuous coordinate inside its slot.
fn volume_filtered(linear: sampler, p: vec3<f32>) -> vec4<f32> {
    let dims = vec3<f32>(volume_geometry.dims);
    let c = clamp(p * dims, vec3<f32>(0.5), dims - vec3<f32>(0.5));
    let b = vec3<i32>(c / f32(volume_geometry.brick_vox));
    let a = vec3<f32>(brick_origin(b)) + c;
    return textureSampleLevel(volume_tex, linear, a * volume_geometry.texel_size, 0.0);
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
#endif
