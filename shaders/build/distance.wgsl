// The two-sided distance field over the leaf blocks: one 1D pass per axis of the separable
// L-infinity distance transform (src/accel/distance.rs, `two_sided`), capped at MAX_DISTANCE
// blocks (generated/constants.wgsl). Each entry holds two distances, one in its low bits and one
// from bit DISTANCE_FULL_SHIFT on, one pass carrying both: from emptiness flags, to the nearest
// non-empty block (0: the block is not empty) and to the nearest empty one (0: it is empty);
// for isosurfaces, to the nearest block not wholly below the iso value and to the nearest not
// wholly at or above it (`DistanceParams.sides`).
//
// Two entry points compute the same pass. `distance_rows` (rows of up to DISTANCE_ROW_MAX
// blocks: every volume of up to 2032 voxels an axis at 4³ blocks): a workgroup copies
// DISTANCE_TILE_ROWS neighbouring rows along the pass's axis into workgroup memory, each block
// looks outward from itself only as far as can still lower its distances, and the rows go back
// out. `distance_pass` (any row) has one invocation per block read its whole window,
// 2 · MAX_DISTANCE + 1 entries, from the buffer. src/render/raycast/leap.rs chooses per pass.
// (A linear-time sweep per row, one invocation each, measured slower but at 1024³:
// docs/benchmarks/nvidia-h200-distance-rows.)

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

// The tiled pass's rows: DISTANCE_TILE_ROWS rows DISTANCE_ROW_MAX entries apart. The stride is
// 4 less than a multiple of 32, so that the 8 rows × 4 positions one subgroup of 32 copies in or
// out along y or z lie in 32 different banks.
var<workgroup> tile: array<u32, DISTANCE_TILE_ROWS * DISTANCE_ROW_MAX>;

const LOW_BITS: u32 = (1u << DISTANCE_FULL_SHIFT) - 1u;

// Entry c of tile row `row` (of `len` entries) after the pass: the minimum over the row's
// entries k of max(|c − k|, entry k) on each side. Looks outward from c and stops at the first
// distance a no entry can improve on (max(a, ·) ≥ a ≥ both minima), so a block near its own
// kind reads a few entries, not the 2 · MAX_DISTANCE + 1 of the window. No block further than
// the cap can be the nearest: every block's own entry is at most the cap.
fn row_distance(row: u32, c: u32, len: u32) -> u32 {
    let base = row * DISTANCE_ROW_MAX;
    let own = tile[base + c];
    var full = min(own & LOW_BITS, MAX_DISTANCE);
    var empty = min(own >> DISTANCE_FULL_SHIFT, MAX_DISTANCE);
    for (var a = 1u; a < max(full, empty); a++) {
        if a <= c {
            let d = tile[base + c - a];
            full = min(full, max(a, d & LOW_BITS));
            empty = min(empty, max(a, d >> DISTANCE_FULL_SHIFT));
        }
        if c + a < len {
            let d = tile[base + c + a];
            full = min(full, max(a, d & LOW_BITS));
            empty = min(empty, max(a, d >> DISTANCE_FULL_SHIFT));
        }
    }
    return full | (empty << DISTANCE_FULL_SHIFT);
}

// The other two axes of a pass along `axis`: x, the one the tile's rows lie side by side along
// (x for the passes along y and z, so that a subgroup copies neighbours in memory; y for the
// pass along x), and y, the one the workgroups' second index runs along.
fn across_axes(axis: u32) -> vec2<u32> {
    if axis == 0u {
        return vec2<u32>(1u, 2u);
    }
    if axis == 1u {
        return vec2<u32>(0u, 2u);
    }
    return vec2<u32>(0u, 1u);
}

// DISTANCE_TILE_ROWS rows of at most DISTANCE_ROW_MAX blocks along `params.axis`: workgroup
// (i, j) takes rows i · DISTANCE_TILE_ROWS … along the first axis of `across_axes`, at index j
// of the second.
@compute @workgroup_size(DISTANCE_ROW_THREADS, DISTANCE_TILE_ROWS, 1)
fn distance_rows(@builtin(local_invocation_index) li: u32, @builtin(workgroup_id) group: vec3<u32>) {
    let level = levels[params.leaf_level];
    let axis = params.axis;
    let other = across_axes(axis);
    let len = min(level.nodes[axis], DISTANCE_ROW_MAX);
    let first_row = group.x * DISTANCE_TILE_ROWS;
    var origin = vec3<u32>(0u);
    origin[other.y] = group.y;
    // Copying in and out: along x, a subgroup takes 32 neighbours of one row; along y and z,
    // 4 positions of the 8 rows (neighbours in memory). The rows are then worked out with a
    // subgroup along each, 32 neighbours at a time.
    let along = axis == 0u;
    let copy_row = select(li % DISTANCE_TILE_ROWS, li / DISTANCE_ROW_THREADS, along);
    let copy_first = select(li / DISTANCE_TILE_ROWS, li % DISTANCE_ROW_THREADS, along);
    let copy_in_volume = first_row + copy_row < level.nodes[other.x];
    var n = origin;
    n[other.x] = first_row + copy_row;
    for (var i = copy_first; i < len; i += DISTANCE_ROW_THREADS) {
        if copy_in_volume {
            n[axis] = i;
            tile[copy_row * DISTANCE_ROW_MAX + i] = pass_input(level, n);
        }
    }
    workgroupBarrier();
    let row = li / DISTANCE_ROW_THREADS;
    let lane = li % DISTANCE_ROW_THREADS;
    var out: array<u32, DISTANCE_ROW_MAX / DISTANCE_ROW_THREADS + 1u>;
    for (var j = 0u; j <= DISTANCE_ROW_MAX / DISTANCE_ROW_THREADS; j++) {
        let c = lane + j * DISTANCE_ROW_THREADS;
        if c < len {
            out[j] = row_distance(row, c, len);
        }
    }
    workgroupBarrier();
    for (var j = 0u; j <= DISTANCE_ROW_MAX / DISTANCE_ROW_THREADS; j++) {
        let c = lane + j * DISTANCE_ROW_THREADS;
        if c < len {
            tile[row * DISTANCE_ROW_MAX + c] = out[j];
        }
    }
    workgroupBarrier();
    for (var i = copy_first; i < len; i += DISTANCE_ROW_THREADS) {
        if copy_in_volume {
            n[axis] = i;
            dst_distance[local_index(level.nodes, n)] = tile[copy_row * DISTANCE_ROW_MAX + i];
        }
    }
}
