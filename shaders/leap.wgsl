// Empty-space leaping (RC-s). When a sample enters a new leaf block, the block's emptiness under
// the current transfer function is looked up; an empty block sends the ray to the first sample of
// its grid past the largest empty region known around it: the coarsest empty ancestor in the
// min/max octree (the paper's hierarchical leaping), or, with LEAP_DISTANCE, the cube of blocks
// the distance field proves empty. The exit is the exact ray/box exit, so the samples taken are
// exactly RC-t's samples that can contribute.

#include "leap_common.wgsl"

@group(3) @binding(0) var<storage, read> levels: array<LevelInfo>;
@group(3) @binding(1) var<storage, read> node_empty: array<u32>;
#ifdef LEAP_DISTANCE
@group(3) @binding(2) var<storage, read> block_distance: array<u32>;
#endif

struct LeapRay {
    entry: vec3<f32>,
    box_per_mm: vec3<f32>,
    // The leaf block of the last sample that was looked up.
    block: vec3<u32>,
}

fn leap_ray(entry: vec3<f32>, box_per_mm: vec3<f32>) -> LeapRay {
    return LeapRay(entry, box_per_mm, vec3<u32>(0xffffffffu));
}

// Distance (mm from the entry) at which the ray leaves the box [lo, hi), given in voxel units
// (voxel-centre coordinate + 1/2, so the volume spans [0, dims]).
fn exit_distance(ray: LeapRay, lo: vec3<f32>, hi: vec3<f32>) -> f32 {
    let dims = frame.volume_dims.xyz;
    let d = ray.box_per_mm;
    let bound = select(lo, hi, d > vec3<f32>(0.0)) / dims;
    // Axis-parallel rays never leave through the faces they run along.
    let t = select((bound - ray.entry) / d, vec3<f32>(3.0e38), d == vec3<f32>(0.0));
    return min(t.x, min(t.y, t.z));
}

// Index of the first grid sample beyond distance t (and at least one past k).
fn first_sample_after(t: f32, k: u32) -> u32 {
    let after = floor(t / frame.step_mm - frame.sample_offset) + 1.0;
    return max(u32(clamp(after, 0.0, 4.0e9)), k + 1u);
}

// Where the ray should go from sample k at box position p: k itself (sample it), or the first
// sample past an empty region.
fn leap_from(ray: ptr<function, LeapRay>, p: vec3<f32>, k: u32) -> u32 {
    let leaf = levels[frame.leaf_level];
    let dims = frame.volume_dims.xyz;
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
    if node_empty[node_index(leaf, block)] == 0u {
        return k;
    }
    var level = frame.leaf_level;
    var node = block;
    loop {
        if level + 1u >= frame.level_count {
            break;
        }
        let up = node / 2u;
        if node_empty[node_index(levels[level + 1u], up)] == 0u {
            break;
        }
        level += 1u;
        node = up;
    }
    let brick = f32(levels[level].brick_vox);
    let lo = vec3<f32>(node) * brick;
    let hi = min(vec3<f32>(node + 1u) * brick, dims);
#endif
    return first_sample_after(exit_distance(*ray, lo, hi), k);
}
