// The two-sided distance field over the leaf blocks: one 1D pass per axis of the separable
// L-infinity distance transform (src/accel/distance.rs, `two_sided`), capped at MAX_DISTANCE
// blocks (generated/constants.wgsl). Each entry holds two distances, one in its low bits and one
// from bit DISTANCE_FULL_SHIFT on, one pass carrying both: from emptiness flags, to the nearest
// non-empty block (0: the block is not empty) and to the nearest empty one (0: it is empty);
// for isosurfaces, to the nearest block not wholly below the iso value and to the nearest not
// wholly at or above it (`DistanceParams.sides`).

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
        var d: u32;
        if params.axis == 0u {
            // First pass: the cap on each side where the block belongs to that side's kind
            // (non-empty blocks (0, the cap), empty ones (the cap, 0); with SIDES_ISO by bit).
            let f = node_empty[node_index(level, n)];
            let iso = params.sides == SIDES_ISO;
            let low = select(f != 0u, (f & 1u) != 0u, iso);
            let high = select(f == 0u, (f & 2u) != 0u, iso);
            d = select(0u, MAX_DISTANCE, low) | (select(0u, MAX_DISTANCE, high) << DISTANCE_FULL_SHIFT);
        } else {
            d = src_distance[local_index(level.nodes, n)];
        }
        let away = select(c - k, k - c, k > c);
        best_full = min(best_full, max(away, d & ((1u << DISTANCE_FULL_SHIFT) - 1u)));
        best_empty = min(best_empty, max(away, d >> DISTANCE_FULL_SHIFT));
    }
    dst_distance[local_index(level.nodes, id)] = best_full | (best_empty << DISTANCE_FULL_SHIFT);
}
