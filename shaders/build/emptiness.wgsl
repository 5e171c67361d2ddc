// Rebuilt whenever the transfer function changes: prefix counts of lookup-table entries with
// non-zero opacity, the paper's emptiness table indexed by (max bin, min bin), and from it one
// flag per pyramid node. Same rules as src/accel/emptiness.rs (conservative: one extra entry on
// each side of an interval for the table's linear filtering).

#include "leap/pyramid.wgsl"
#include "generated/constants.wgsl"
#include "build/params.wgsl"

// One workgroup scans the table.
const SCAN_THREADS: u32 = 256u;


@group(0) @binding(0) var<uniform> params: EmptinessParams;
@group(0) @binding(1) var lut_tex: texture_2d<f32>;
@group(0) @binding(2) var<storage, read_write> prefix: array<u32>;
@group(0) @binding(3) var<storage, read_write> table: array<u32>;
@group(0) @binding(4) var<storage, read> minmax: array<vec2<f32>>;
@group(0) @binding(5) var<storage, read_write> node_empty: array<u32>;

var<workgroup> partial: array<u32, SCAN_THREADS>;

// One workgroup: prefix[i] = number of entries in [0, i) with non-zero alpha.
@compute @workgroup_size(SCAN_THREADS)
fn scan_lut(@builtin(local_invocation_index) t: u32) {
    let chunk = (params.lut_size + SCAN_THREADS - 1u) / SCAN_THREADS;
    let first = t * chunk;
    let end = min(first + chunk, params.lut_size);
    var count = 0u;
    for (var i = first; i < end; i++) {
        count += u32(textureLoad(lut_tex, vec2<u32>(i, 0u), 0).a > 0.0);
    }
    partial[t] = count;
    workgroupBarrier();
    if t == 0u {
        var running = 0u;
        for (var i = 0u; i < SCAN_THREADS; i++) {
            let c = partial[i];
            partial[i] = running;
            running += c;
        }
        prefix[params.lut_size] = running;
    }
    workgroupBarrier();
    var running = partial[t];
    for (var i = first; i < end; i++) {
        prefix[i] = running;
        running += u32(textureLoad(lut_tex, vec2<u32>(i, 0u), 0).a > 0.0);
    }
}

// Whether every sample with normalised value in [lo, hi] is transparent.
fn interval_empty(lo: f32, hi: f32) -> bool {
    let last = f32(params.lut_size - 1u);
    let first = u32(max(floor(clamp(lo, 0.0, 1.0) * last) - 1.0, 0.0));
    let end = min(u32(ceil(clamp(hi, 0.0, 1.0) * last)) + 1u, params.lut_size - 1u);
    return prefix[end + 1u] == prefix[first];
}

@compute @workgroup_size(TABLE_WORKGROUP, TABLE_WORKGROUP)
fn build_table(@builtin(global_invocation_id) id: vec3<u32>) {
    let min_bin = id.x;
    let max_bin = id.y;
    if min_bin >= TABLE_SIZE || max_bin >= TABLE_SIZE {
        return;
    }
    var empty = 0u;
    if min_bin <= max_bin {
        let m = f32(TABLE_SIZE);
        empty = u32(interval_empty(f32(min_bin) / m, f32(max_bin + 1u) / m));
    }
    table[max_bin * TABLE_SIZE + min_bin] = empty;
}

fn bin(v: f32) -> u32 {
    return min(u32(clamp(v, 0.0, 1.0) * f32(TABLE_SIZE)), TABLE_SIZE - 1u);
}

@compute @workgroup_size(NODE_WORKGROUP)
fn flag_nodes(@builtin(global_invocation_id) id: vec3<u32>) {
    // Dispatches wider than MAX_WORKGROUPS_PER_DIMENSION groups wrap into y.
    let i = id.x + id.y * MAX_WORKGROUPS_PER_DIMENSION * NODE_WORKGROUP;
    if i >= params.node_count {
        return;
    }
    let m = minmax[i];
    if params.rule == RULE_ISO {
        // Bit 0: every value below the iso value; bit 1: every value at or above it (both where
        // the node holds no finite value).
        var sides = 3u;
        if m.x <= m.y {
            sides = u32(m.y < params.threshold) | (u32(m.x >= params.threshold) << 1u);
        }
        node_empty[i] = sides;
        return;
    }
    var empty = 1u;
    if m.x <= m.y {
        if params.rule == RULE_AT_MOST {
            empty = u32(m.y <= params.threshold);
        } else {
            empty = table[bin(m.y) * TABLE_SIZE + bin(m.x)];
        }
    }
    node_empty[i] = empty;
}
