// The distance field over the leaf blocks: one 1D pass per axis of the separable L-infinity
// distance transform (src/accel/distance.rs), capped at MAX_DISTANCE blocks
// (generated/constants.wgsl).

#include "leap/pyramid.wgsl"
#include "generated/constants.wgsl"

// `DistanceParams` in src/render/gpu_data.rs.
struct DistanceParams {
    // The pyramid level the field covers.
    leaf_level: u32,
    // The axis this pass runs along (0, 1, 2).
    axis: u32,
    _pad0: u32,
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
    var best = MAX_DISTANCE;
    for (var k = first; k <= last; k++) {
        var n = id;
        n[params.axis] = k;
        var d: u32;
        if params.axis == 0u {
            // First pass: 0 for non-empty blocks, the cap for empty ones.
            d = select(0u, MAX_DISTANCE, node_empty[node_index(level, n)] != 0u);
        } else {
            d = src_distance[local_index(level.nodes, n)];
        }
        best = min(best, max(select(c - k, k - c, k > c), d));
    }
    dst_distance[local_index(level.nodes, id)] = best;
}
