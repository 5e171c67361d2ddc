// Empty-space leaping (RC-s). Where the ray enters a leaf block, it asks its mode whether the
// block can matter (acc_skips, the mode's leap predicate: for DVR whether the transfer
// function is zero over the block's values, for MIP whether its maximum can raise the ray's
// maximum, and so on, see modes/). A block that cannot matter sends the ray to the first sample of
// its grid past the largest such region known around it: the coarsest such ancestor in the
// min/max octree (the paper's hierarchical leaping) or, with LEAP_DISTANCE, the cube of blocks
// the distance field proves empty; the mode decides where exactly it lands (acc_leap_target).
// The exit is the exact ray/box exit, so the samples taken are exactly the plain strategy's
// samples that can change the image. Two ways to walk: block runs (march/runs.wgsl, leap_region:
// one question per block, then its samples without any) and sample by sample
// (march/samplewise.wgsl, leap_from: asks again at the first sample past the region the last
// answer covered).

#include "leap/pyramid.wgsl"

@group(3) @binding(0) var<storage, read> levels: array<LevelInfo>;
@group(3) @binding(1) var<storage, read> node_empty: array<u32>;
#ifdef LEAP_DISTANCE
@group(3) @binding(2) var<storage, read> block_distance: array<u32>;
#endif
@group(3) @binding(3) var<storage, read> minmax: array<vec2<f32>>;
#ifdef LABEL_INSIDE
// 1 where a node holds a shown label (build/labels.wgsl).
@group(3) @binding(4) var<storage, read> node_shown: array<u32>;
#endif
#ifdef LABEL_SURFACES
// 1 where a shown label lies in or within a cell of a node (build/labels.wgsl's apron).
@group(3) @binding(4) var<storage, read> node_shown: array<u32>;
#endif

// Whether the view cuts node `node` away: it holds no shown label while the image is shown only
// inside them (LABEL_INSIDE); the modes that skip by min/max ask (DVR's flags already hold it).
fn cut_away(node: u32) -> bool {
#ifdef LABEL_INSIDE
    return node_shown[node] == 0u;
#else
    return false;
#endif
}

// Whether node `node` may hold a shown label's surface (LABEL_SURFACES), so that no mode skips
// it; the modes that skip by min/max ask (DVR's flags already hold it).
fn keeps_surface(node: u32) -> bool {
#ifdef LABEL_SURFACES
    return node_shown[node] != 0u;
#else
    return false;
#endif
}

#ifdef LEAP_DISTANCE
// acc_reach of the modes whose field is built from emptiness flags (DVR, X-ray): `to_matter`
// the distance to the nearest block that can matter (0: this one can), `to_empty` to the nearest
// that cannot.
fn reach_two_sided(to_matter: u32, to_empty: u32) -> vec2<u32> {
    return vec2<u32>(select(to_empty, to_matter, to_matter != 0u), u32(to_matter == 0u));
}
#endif

// Whether node range `m` (min, max) holds no finite voxel: every sample there is missing.
fn holds_no_finite_voxel(m: vec2<f32>) -> bool {
    return m.x > m.y;
}

struct LeapRay {
    // The entry in voxel units, and mm per voxel of travel along each axis (1 / direction;
    // 3e38 along axes the ray runs parallel to, which it never leaves through): a box exit is one
    // multiply-add per axis.
    entry_vox: vec3<f32>,
    mm_per_vox: vec3<f32>,
    // The ray's first-sample offset (Ray.offset).
    offset: f32,
    // Sample by sample: the first grid sample past the region that can matter where the last
    // lookup found one (the samples before it are taken without asking).
    until: u32,
}

fn leap_ray(entry: vec3<f32>, box_per_mm: vec3<f32>, offset: f32) -> LeapRay {
    let dims = frame.volume_dims;
    let d = box_per_mm * dims;
    let inv = select(1.0 / d, vec3<f32>(3.0e38), d == vec3<f32>(0.0));
    return LeapRay(entry * dims, inv, offset, 0u);
}

// Distance (mm from the entry) at which the ray leaves the box [lo, hi), given in voxel units
// (voxel-centre coordinate + 1/2, so the volume spans [0, dims]). Along a parallel axis the
// upper face counts and lies (all but) infinitely far.
fn exit_distance(ray: LeapRay, lo: vec3<f32>, hi: vec3<f32>) -> f32 {
    let bound = select(lo, hi, ray.mm_per_vox > vec3<f32>(0.0));
    let t = (bound - ray.entry_vox) * ray.mm_per_vox;
    return min(t.x, min(t.y, t.z));
}

// Index of the first grid sample beyond distance t (and at least one past k), for a ray whose
// first sample lies at `offset` steps.
fn first_sample_after(t: f32, k: u32, offset: f32) -> u32 {
    let after = floor(t / frame.step_mm - offset) + 1.0;
    return max(u32(clamp(after, 0.0, 4.0e9)), k + 1u);
}

// The leaf block holding box position p.
fn leaf_block(p: vec3<f32>) -> vec3<u32> {
    let leaf = levels[frame.leaf_level];
    let v = max(p * frame.volume_dims, vec3<f32>(0.0));
    return min(vec3<u32>(v / f32(leaf.brick_vox)), leaf.nodes - 1u);
}

// What a leaf block is to a ray holding `acc`: whether it can matter, and a box in voxel units:
// where it can, the block itself (with LEAP_DISTANCE the cube of blocks around it that all can),
// else the largest region known around it that cannot change the pixel.
struct Region {
    matters: bool,
    lo: vec3<f32>,
    hi: vec3<f32>,
}

fn region_of(block: vec3<u32>, acc: Acc) -> Region {
    let leaf = levels[frame.leaf_level];
    let dims = frame.volume_dims;
    let brick = f32(leaf.brick_vox);
#ifdef LEAP_DISTANCE
    // The field's two sides (build/distance.wgsl), read by the mode (acc_reach): the cube of
    // d − 1 blocks around this one is all of one kind, all mattering (then the ray takes every
    // sample up to the cube's exit without asking again) or all not.
    let v = block_distance[block.x + leaf.nodes.x * (block.y + leaf.nodes.y * block.z)];
    let answer = acc_reach(acc, v & ((1u << DISTANCE_FULL_SHIFT) - 1u), v >> DISTANCE_FULL_SHIFT);
    let reach = i32(max(answer.x, 1u) - 1u);
    let lo = vec3<f32>(max(vec3<i32>(block) - reach, vec3<i32>(0))) * brick;
    let hi = min(vec3<f32>(block + vec3<u32>(u32(reach) + 1u)) * brick, dims);
    return Region(answer.y != 0u, lo, hi);
#else
    if !acc_skips(acc, node_index(leaf, block)) {
        return Region(true, vec3<f32>(block) * brick, min(vec3<f32>(block + 1u) * brick, dims));
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
    let size = f32(levels[level].brick_vox);
    return Region(false, vec3<f32>(node) * size, min(vec3<f32>(node + 1u) * size, dims));
#endif
}

// Block runs: what the ray does at sample k (box position p), the first sample of a block run,
// holding `acc`. x: where it goes, k itself (the block can matter) or where its mode lands past
// the region that cannot change the pixel; y, where x = k: the first grid sample past the leaf
// block (with LEAP_DISTANCE, the cube), so that samples k .. y − 1 are taken without any lookup.
// Each call is one lookup (counted into `tally`).
fn leap_region(ray: LeapRay, p: vec3<f32>, k: u32, acc: Acc, tally: ptr<function, Tally>) -> vec2<u32> {
    tally_lookup(tally);
    let region = region_of(leaf_block(p), acc);
    let after = first_sample_after(exit_distance(ray, region.lo, region.hi), k, ray.offset);
    if region.matters {
        return vec2<u32>(k, after);
    }
    return vec2<u32>(acc_leap_target(k, after), after);
}

// Sample by sample: where the ray goes from sample k at box position p, holding `acc`: k itself
// (sample it), or where its mode lands past a region that cannot change the pixel. Asks only
// where the sample lies past the region the last question found can matter (its leaf block, or
// with LEAP_DISTANCE the cube of such blocks around it); each question is counted into `tally`.
fn leap_from(ray: ptr<function, LeapRay>, p: vec3<f32>, k: u32, acc: Acc, tally: ptr<function, Tally>) -> u32 {
    if k < (*ray).until {
        return k;
    }
    tally_lookup(tally);
    let region = region_of(leaf_block(p), acc);
    let after = first_sample_after(exit_distance(*ray, region.lo, region.hi), k, (*ray).offset);
    if region.matters {
        (*ray).until = after;
        return k;
    }
    return acc_leap_target(k, after);
}
