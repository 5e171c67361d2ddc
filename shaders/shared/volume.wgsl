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
// Where a brick of level 0 finds its voxels (src/render/volume_texture/atlas.rs, gpu_page, four
// f32 as u32 bits, so that a read decodes nothing): the atlas texel of voxel 0 of the level its
// brick is held at, as if that brick's slot were the whole level (a voxel `i` of the level, or
// of the brick's apron, lies at texel origin + i), and 2^-level (level 0: the brick itself;
// k: its ancestor `b >> k`, whose voxels are 2^k of level 0's per axis).
// A brick that no ray can see (empty under the transfer function, its neighbours too) holds no
// slot: its entry is a constant, (value, 0, 0, 0).
struct Page {
    origin: vec3<f32>,
    scale: f32,
}

fn page(b: vec3<i32>) -> Page {
    let e = bitcast<vec4<f32>>(textureLoad(volume_pages, b, 0));
    return Page(e.xyz, e.w);
}

// Voxel `i` (clamped into the volume), from the level its brick is held at.
fn volume_load(i: vec3<i32>) -> vec4<f32> {
    let j = clamp(i, vec3<i32>(0), volume_dims() - vec3<i32>(1));
    let p = page(j / i32(volume_geometry.brick_vox));
    if p.scale == 0.0 {
        return vec4<f32>(p.origin.x, 0.0, 0.0, 1.0);
    }
    // j · 2^-level, floored: exact in f32 for any voxel index below 2^24.
    let at_level = vec3<i32>(floor(vec3<f32>(j) * p.scale));
    return textureLoad(volume_tex, vec3<i32>(p.origin) + at_level, 0);
}

// How the points of one level-0 brick find their values: the atlas coordinate of box position
// p is p · scale + offset (scale: the held level's voxels per box unit in atlas units; offset:
// where its slot puts voxel 0 of that level), or, for a brick no ray can see, a constant. The
// apron and the overhang past the volume repeat the nearest voxel, so no clamp is needed for
// points of the box: the filter blends equal texels there, as clamp to edge does.
struct BrickMap {
    scale: vec3<f32>,
    offset: vec3<f32>,
    constant: bool,
    value: f32,
}

// The level-0 brick holding box position p (p in the box; points a rounding past a face count
// to the brick inside).
fn brick_at(p: vec3<f32>) -> vec3<i32> {
    let b = vec3<u32>(max(p * volume_geometry.bricks_per_box, vec3<f32>(0.0)));
    return vec3<i32>(min(b, volume_geometry.last_brick));
}

fn brick_map(b: vec3<i32>) -> BrickMap {
    let p = page(b);
    if p.scale == 0.0 {
        return BrickMap(vec3<f32>(0.0), vec3<f32>(0.0), true, p.origin.x);
    }
    let scale = volume_geometry.atlas_per_box * p.scale;
    return BrickMap(scale, p.origin * volume_geometry.texel_size, false, 0.0);
}

// The last brick a read went through, and its map: consecutive reads mostly stay in one brick.
// Which brick a point reads through depends on the point alone (brick_at), never on the reads
// before it, so that a value does not depend on the path a ray took to it.
var<private> held_brick: vec3<i32> = vec3<i32>(-1);
var<private> held_map: BrickMap;

// The map of brick `b`, from the page table where it is not the last one read.
fn map_of(b: vec3<i32>) -> BrickMap {
    if any(b != held_brick) {
        held_brick = b;
        held_map = brick_map(b);
    }
    return held_map;
}

// The texture unit's trilinear sample at box position p inside brick `m`'s brick.
fn volume_filtered_in(m: BrickMap, linear: sampler, p: vec3<f32>) -> vec4<f32> {
    if m.constant {
        return vec4<f32>(m.value, 0.0, 0.0, 1.0);
    }
    return textureSampleLevel(volume_tex, linear, fma(p, m.scale, m.offset), 0.0);
}

// The texture unit's trilinear sample at box position p (clamp to edge): through the brick
// holding it, at the level that brick is held at.
fn volume_filtered(linear: sampler, p: vec3<f32>) -> vec4<f32> {
    let q = clamp(p, vec3<f32>(0.0), vec3<f32>(1.0));
    return volume_filtered_in(map_of(brick_at(q)), linear, q);
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
