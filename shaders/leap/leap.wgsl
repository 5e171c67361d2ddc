// Empty-space leaping (RC-s). When a sample enters a new leaf block, the ray asks its mode
// whether the block can matter (acc_skips, the mode's leap predicate: for DVR whether the transfer
// function is zero over the block's values, for MIP whether its maximum can raise the ray's
// maximum, and so on, see modes/). A block that cannot matter sends the ray to the first sample of
// its grid past the largest such region known around it: the coarsest such ancestor in the
// min/max octree (the paper's hierarchical leaping) or, with LEAP_DISTANCE, the cube of blocks
// the distance field proves empty; the mode decides where exactly it lands (acc_leap_target).
// The exit is the exact ray/box exit, so the samples taken are exactly the plain strategy's
// samples that can change the image.

#include "leap/pyramid.wgsl"

@group(3) @binding(0) var<storage, read> levels: array<LevelInfo>;
@group(3) @binding(1) var<storage, read> node_empty: array<u32>;
#ifdef LEAP_DISTANCE
@group(3) @binding(2) var<storage, read> block_distance: array<u32>;
#endif
@group(3) @binding(3) var<storage, read> minmax: array<vec2<f32>>;

// Whether node range `m` (min, max) holds no finite voxel: every sample there is missing.
fn holds_no_finite_voxel(m: vec2<f32>) -> bool {
    return m.x > m.y;
}

struct LeapRay {
    entry: vec3<f32>,
    box_per_mm: vec3<f32>,
    // The leaf block of the last sample that was looked up.
    block: vec3<u32>,
    // The ray's first-sample offset (Ray.offset).
    offset: f32,
}

fn leap_ray(entry: vec3<f32>, box_per_mm: vec3<f32>, offset: f32) -> LeapRay {
    return LeapRay(entry, box_per_mm, vec3<u32>(0xffffffffu), offset);
}

// Distance (mm from the entry) at which the ray leaves the box [lo, hi), given in voxel units
// (voxel-centre coordinate + 1/2, so the volume spans [0, dims]).
fn exit_distance(ray: LeapRay, lo: vec3<f32>, hi: vec3<f32>) -> f32 {
    let dims = frame.volume_dims;
    let d = ray.box_per_mm;
    let bound = select(lo, hi, d > vec3<f32>(0.0)) / dims;
    // Axis-parallel rays never leave through the faces they run along.
    let t = select((bound - ray.entry) / d, vec3<f32>(3.0e38), d == vec3<f32>(0.0));
    return min(t.x, min(t.y, t.z));
}

// Index of the first grid sample beyond distance t (and at least one past k), for a ray whose
// first sample lies at `offset` steps.
fn first_sample_after(t: f32, k: u32, offset: f32) -> u32 {
    let after = floor(t / frame.step_mm - offset) + 1.0;
    return max(u32(clamp(after, 0.0, 4.0e9)), k + 1u);
}

// Where the ray should go from sample k at box position p, holding `acc`: k itself (sample it), or
// where its mode lands past a region that cannot change the pixel.
fn leap_from(ray: ptr<function, LeapRay>, p: vec3<f32>, k: u32, acc: Acc) -> u32 {
    let leaf = levels[frame.leaf_level];
    let dims = frame.volume_dims;
    let v = max(p * dims, vec3<f32>(0.0));
    let block = min(vec3<u32>(v / f32(leaf.brick_vox)), leaf.nodes - 1u);
    if all(block == (*ray).block) {
        return k;
    }
    (*ray).block = block;
#ifdef LEAP_DISTANCE
    let d = block_distance[block.x + leaf.nodes.x * (block.y + leaf.nodes.y * block.z)];
    if d == 0u {
        return k;
    }
    let brick = f32(leaf.brick_vox);
    let lo = vec3<f32>(max(vec3<i32>(block) - i32(d - 1u), vec3<i32>(0))) * brick;
    let hi = min(vec3<f32>(block + d) * brick, dims);
#else
    if !acc_skips(acc, node_index(leaf, block)) {
        return k;
    }
    var level = frame.leaf_level;
    var node = block;
    loop {
        if level + 1u >= frame.level_count {
            break;
        }
        let up = node / 2u;
        if !acc_skips(acc, node_index(levels[level + 1u], up)) {
            break;
        }
        level += 1u;
        node = up;
    }
    let brick = f32(levels[level].brick_vox);
    let lo = vec3<f32>(node) * brick;
    let hi = min(vec3<f32>(node + 1u) * brick, dims);
#endif
    let after = first_sample_after(exit_distance(*ray, lo, hi), k, (*ray).offset);
    return acc_leap_target(k, after);
}
