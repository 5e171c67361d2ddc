// The two-sided distance field over the leaf blocks: one 1D pass per axis of the separable
// L-infinity distance transform (src/accel/distance.rs, `two_sided`), capped at MAX_DISTANCE
// blocks (generated/constants.wgsl). Each entry holds two distances, one in its low bits and one
// from bit DISTANCE_FULL_SHIFT on, one pass carrying both: from emptiness flags, to the nearest
// non-empty block (0: the block is not empty) and to the nearest empty one (0: it is empty);
// for isosurfaces, to the nearest block not wholly below the iso value and to the nearest not
// wholly at or above it (`DistanceParams.sides`).
//
// Two entry points compute the same pass. `distance_rows` (rows of up to DISTANCE_ROW_MAX
// blocks: every volume of up to 2048 voxels an axis at 4³ blocks) sweeps each row in linear
// time, one invocation per row. `distance_pass` (any row) has one invocation per block read its
// whole window, 2 · MAX_DISTANCE + 1 entries. src/render/raycast/leap.rs chooses per pass.

#include "leap/pyramid.wgsl"
#include "generated/constants.wgsl"

// `DistanceParams` in src/render/gpu_data.rs.
struct DistanceParams {
    // The pyramid level the field covers.
    leaf_level: u32,
    // The axis this pass runs along (0, 1, 2).
    axis: u32,
    // What the sides measure: 0 (SIDES_EMPTY_FULL) the distance to the nearest non-empty block
    // and to the nearest empty one, from 0/1 flags; SIDES_ISO the distance to the nearest block
    // not wholly below the iso value and to the nearest not wholly at or above it, from the two
    // bits of RULE_ISO.
    sides: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> params: DistanceParams;
@group(0) @binding(1) var<storage, read> levels: array<LevelInfo>;
@group(0) @binding(2) var<storage, read> node_empty: array<u32>;
@group(0) @binding(3) var<storage, read> src_distance: array<u32>;
@group(0) @binding(4) var<storage, read_write> dst_distance: array<u32>;

fn local_index(nodes: vec3<u32>, n: vec3<u32>) -> u32 {
    return n.x + nodes.x * (n.y + nodes.y * n.z);
}

// What the pass reads for block n: on the first pass (along x) the cap on each side where the
// block belongs to that side's kind (non-empty blocks (0, the cap), empty ones (the cap, 0);
// with SIDES_ISO by bit), on the others the previous pass's distances.
fn pass_input(level: LevelInfo, n: vec3<u32>) -> u32 {
    if params.axis == 0u {
        let f = node_empty[node_index(level, n)];
        let iso = params.sides == SIDES_ISO;
        let low = select(f != 0u, (f & 1u) != 0u, iso);
        let high = select(f == 0u, (f & 2u) != 0u, iso);
        return select(0u, MAX_DISTANCE, low) | (select(0u, MAX_DISTANCE, high) << DISTANCE_FULL_SHIFT);
    }
    return src_distance[local_index(level.nodes, n)];
}

// One block's window in the buffer (rows of any length).
@compute @workgroup_size(BUILD_WORKGROUP, BUILD_WORKGROUP, BUILD_WORKGROUP)
fn distance_pass(@builtin(global_invocation_id) id: vec3<u32>) {
    let level = levels[params.leaf_level];
    if any(id >= level.nodes) {
        return;
    }
    let len = level.nodes[params.axis];
    let c = id[params.axis];
    let first = select(0u, c - MAX_DISTANCE, c > MAX_DISTANCE);
    let last = min(c + MAX_DISTANCE, len - 1u);
    var best_full = MAX_DISTANCE;
    var best_empty = MAX_DISTANCE;
    for (var k = first; k <= last; k++) {
        var n = id;
        n[params.axis] = k;
        let d = pass_input(level, n);
        let away = select(c - k, k - c, k > c);
        best_full = min(best_full, max(away, d & ((1u << DISTANCE_FULL_SHIFT) - 1u)));
        best_empty = min(best_empty, max(away, d >> DISTANCE_FULL_SHIFT));
    }
    dst_distance[local_index(level.nodes, id)] = best_full | (best_empty << DISTANCE_FULL_SHIFT);
}

const LOW_BITS: u32 = (1u << DISTANCE_FULL_SHIFT) - 1u;

// Entries of the rows pass's stack: a block's index along the row (bits 0–9), the first index
// from which its cone is the lowest seen so far (bits 10–19), and its input distance on the side
// being computed (bits 20 on).
const STACK_INDEX_BITS: u32 = 10u;
const STACK_INDEX_MASK: u32 = (1u << STACK_INDEX_BITS) - 1u;
const STACK_FROM_SHIFT: u32 = STACK_INDEX_BITS;
const STACK_INPUT_SHIFT: u32 = 2u * STACK_INDEX_BITS;

// One side of a packed entry: 0 the low bits, 1 the high ones.
fn side_of(v: u32, side: u32) -> u32 {
    return select(v & LOW_BITS, v >> DISTANCE_FULL_SHIFT, side == 1u);
}

// Block i's cone at index x of the row: max(|x − i|, g), g its input distance.
fn cone(x: u32, i: u32, g: u32) -> u32 {
    return max(select(i - x, x - i, x >= i), g);
}

// The other two axes of a pass along `axis`: x, the one consecutive invocations' rows lie side
// by side along (x for the passes along y and z, so that their reads and writes are neighbours
// in memory; y for the pass along x), and y.
fn across_axes(axis: u32) -> vec2<u32> {
    if axis == 0u {
        return vec2<u32>(1u, 2u);
    }
    if axis == 1u {
        return vec2<u32>(0u, 2u);
    }
    return vec2<u32>(0u, 1u);
}

// One invocation per row along `params.axis` (at most DISTANCE_ROW_MAX blocks), each side in
// linear time: the lower envelope of the blocks' cones (Meijster, Roerdink and Hesselink, "A
// general algorithm for computing distance transforms in linear time", 2000, with its L∞
// functions f(x, i) = max(|x − i|, g(i)) and Sep), kept on a stack by a sweep forward, read off by
// a sweep back. Equal to the windowed pass: a block further than the cap cannot be the nearest,
// as every block's own input is at most the cap. Rows are numbered along the first axis of
// `across_axes`, then the second; workgroups past 65535 wrap into y.
@compute @workgroup_size(DISTANCE_ROW_GROUP)
fn distance_rows(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let level = levels[params.leaf_level];
    let axis = params.axis;
    let other = across_axes(axis);
    let row = id.x + id.y * groups.x * DISTANCE_ROW_GROUP;
    let across = level.nodes[other.x];
    if row >= across * level.nodes[other.y] {
        return;
    }
    let m = min(level.nodes[axis], DISTANCE_ROW_MAX);
    var n = vec3<u32>(0u);
    n[other.x] = row % across;
    n[other.y] = row / across;
    var stack: array<u32, DISTANCE_ROW_MAX>;
    for (var side = 0u; side < 2u; side++) {
        // Forward: the stack holds the blocks whose cones make the envelope of the row so far,
        // each with the index it starts from.
        n[axis] = 0u;
        stack[0] = side_of(pass_input(level, n), side) << STACK_INPUT_SHIFT;
        var top = 0i;
        for (var u = 1u; u < m; u++) {
            n[axis] = u;
            let g = side_of(pass_input(level, n), side);
            loop {
                if top < 0 {
                    break;
                }
                let e = stack[top];
                let start = (e >> STACK_FROM_SHIFT) & STACK_INDEX_MASK;
                if cone(start, e & STACK_INDEX_MASK, e >> STACK_INPUT_SHIFT) <= cone(start, u, g) {
                    break;
                }
                top -= 1;
            }
            if top < 0 {
                top = 0;
                stack[0] = u | (g << STACK_INPUT_SHIFT);
            } else {
                // Sep(s, u): the last index where block s's cone is below u's; u's starts after.
                let e = stack[top];
                let s = e & STACK_INDEX_MASK;
                let gs = e >> STACK_INPUT_SHIFT;
                let middle = i32((s + u) / 2u);
                let sep = select(min(i32(u) - i32(gs), middle), max(i32(s + g), middle), gs <= g);
                let start = sep + 1;
                if start >= 0 && u32(start) < m {
                    top += 1;
                    stack[top] = u | (u32(start) << STACK_FROM_SHIFT) | (g << STACK_INPUT_SHIFT);
                }
            }
        }
        // Back: each index takes the cone of the block on top whose range it is in.
        for (var i = m; i > 0u; i--) {
            let u = i - 1u;
            let e = stack[top];
            let d = cone(u, e & STACK_INDEX_MASK, e >> STACK_INPUT_SHIFT);
            n[axis] = u;
            let at = local_index(level.nodes, n);
            if side == 0u {
                dst_distance[at] = d;
            } else {
                dst_distance[at] = dst_distance[at] | (d << DISTANCE_FULL_SHIFT);
            }
            if u == ((e >> STACK_FROM_SHIFT) & STACK_INDEX_MASK) {
                top -= 1;
            }
        }
    }
}
