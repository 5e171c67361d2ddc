// The volume as every shader reads it: one 3D texture of the volume, or (BRICKED) bricks of one
// of its levels in an atlas found through a page table (src/accel/bricks.rs). Each slot holds a brick and an apron
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
// Where a brick of level 0 finds its voxels: the atlas texel of voxel 0 of the brick that holds
// them, as if that brick's slot were the whole level (a voxel `i` of the level, or of the
// brick's apron, lies at texel origin + i), and the level (0: the brick itself; k: its ancestor
// `b >> k`, whose voxels are 2^k of level 0's per axis).
// A brick that no ray can see (empty under the transfer function, its neighbours too) holds no
// slot: its entry is a constant (bit 31), one of its values, as unorm16 or (bit 30) f16 bits.
struct Page {
    origin: vec3<i32>,
    level: u32,
    constant: bool,
    value: f32,
}

fn page(b: vec3<i32>) -> Page {
    let e = textureLoad(volume_pages, b, 0).r;
    if (e & 0x80000000u) != 0u {
        let value = select(unpack2x16unorm(e).x, unpack2x16float(e).x, (e & 0x40000000u) != 0u);
        return Page(vec3<i32>(0), 0u, true, value);
    }
    let slot = vec3<i32>(vec3<u32>(e & 511u, (e >> 9u) & 511u, (e >> 18u) & 511u));
    let level = e >> 27u;
    let brick = i32(volume_geometry.brick_vox);
    let held = b >> vec3<u32>(level);
    return Page(slot * i32(volume_geometry.slot_vox) + vec3<i32>(1) - held * brick, level, false, 0.0);
}

// Voxels per axis of level `level`.
fn level_dims(level: u32) -> vec3<i32> {
    let scale = (1u << level) - 1u;
    return vec3<i32>((volume_geometry.dims + vec3<u32>(scale)) >> vec3<u32>(level));
}

// Voxel `i` (clamped into the volume), from the level its brick is held at.
fn volume_load(i: vec3<i32>) -> vec4<f32> {
    let j = clamp(i, vec3<i32>(0), volume_dims() - vec3<i32>(1));
    let p = page(j / i32(volume_geometry.brick_vox));
    if p.constant {
        return vec4<f32>(p.value, 0.0, 0.0, 1.0);
    }
    return textureLoad(volume_tex, p.origin + (j >> vec3<u32>(p.level)), 0);
}

// The texture unit's trilinear sample at box position p (clamp to edge): the brick holding the
// clamped point, then the same continuous coordinate inside its slot, at its level.
fn volume_filtered(linear: sampler, p: vec3<f32>) -> vec4<f32> {
    let dims = vec3<f32>(volume_geometry.dims);
    let c = clamp(p * dims, vec3<f32>(0.5), dims - vec3<f32>(0.5));
    let held = page(vec3<i32>(c / f32(volume_geometry.brick_vox)));
    if held.constant {
        return vec4<f32>(held.value, 0.0, 0.0, 1.0);
    }
    var a = c;
    if held.level > 0u {
        let top = vec3<f32>(level_dims(held.level)) - vec3<f32>(0.5);
        a = clamp(c / f32(1u << held.level), vec3<f32>(0.5), top);
    }
    a += vec3<f32>(held.origin);
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
