// Leaping over hidden labels: one flag per pyramid node, 1 where the node holds a shown label
// (label surfaces: where one lies within the apron around it).
// Level 0 from the cells' label lists (src/accel/label_cells.rs: cells of CELL_VOX³ voxels, a
// level-0 node of B voxels covers (B / CELL_VOX)³ of them) and the visibility bits of
// src/render/labels.rs; every other level from its children, as the min/max pyramid is built. A
// node owns the samples whose nearest voxel is one of its own (src/accel/pyramid.rs), so a node
// without a shown label holds only samples a cut view takes away. Then, where the frame's flag
// rule reads node_empty (DVR; X-ray with the distance field), cut_flags marks those nodes empty.
// Surfaces instead clear the flag of every node near a shown label (keep_flags). Rebuilt when the
// shown labels change: src/render/raycast/leap.rs.

#include "leap/pyramid.wgsl"
#include "generated/constants.wgsl"

// `LabelParams` in src/render/gpu_data.rs.
struct LabelParams {
    // Cells per axis of the label lists.
    cells: vec3<u32>,
    // The level this pass builds.
    level: u32,
    // Cells around a level-0 node that count as its own (label surfaces: the smoothed mask
    // reaches that far past a shown voxel), 0 for views that cut to the shown labels.
    apron: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> params: LabelParams;
@group(0) @binding(1) var<storage, read> levels: array<LevelInfo>;
@group(0) @binding(2) var<storage, read_write> node_shown: array<u32>;
@group(0) @binding(3) var<storage, read> cell_offsets: array<u32>;
@group(0) @binding(4) var<storage, read> cell_labels: array<u32>;
@group(0) @binding(5) var<storage, read> shown_bits: array<u32>;
@group(0) @binding(6) var<storage, read_write> node_empty: array<u32>;

fn cells() -> vec3<u32> {
    return params.cells;
}

fn shown(label: u32) -> bool {
    return (shown_bits[label / 32u] & (1u << (label % 32u))) != 0u;
}

@compute @workgroup_size(BUILD_WORKGROUP, BUILD_WORKGROUP, BUILD_WORKGROUP)
fn shown_base(@builtin(global_invocation_id) id: vec3<u32>) {
    let level = levels[0];
    if any(id >= level.nodes) {
        return;
    }
    let per = level.brick_vox / CELL_VOX;
    let lo = max(id * per, vec3<u32>(params.apron)) - vec3<u32>(params.apron);
    let hi = min(id * per + vec3<u32>(per + params.apron), cells());
    let n = cells();
    var any_shown = 0u;
    for (var z = lo.z; z < hi.z; z++) {
        for (var y = lo.y; y < hi.y; y++) {
            for (var x = lo.x; x < hi.x; x++) {
                let c = x + n.x * (y + n.y * z);
                for (var i = cell_offsets[c]; i < cell_offsets[c + 1u]; i++) {
                    any_shown |= u32(shown(cell_labels[i]));
                }
            }
        }
    }
    node_shown[node_index(level, id)] = any_shown;
}

@compute @workgroup_size(BUILD_WORKGROUP, BUILD_WORKGROUP, BUILD_WORKGROUP)
fn shown_parent(@builtin(global_invocation_id) id: vec3<u32>) {
    let parent = levels[params.level];
    let child = levels[params.level - 1u];
    if any(id >= parent.nodes) {
        return;
    }
    var any_shown = 0u;
    for (var c = 0u; c < 8u; c++) {
        let k = 2u * id + vec3<u32>(c & 1u, (c >> 1u) & 1u, (c >> 2u) & 1u);
        if all(k < child.nodes) {
            any_shown |= node_shown[node_index(child, k)];
        }
    }
    node_shown[node_index(parent, id)] = any_shown;
}

// Every node of the level without a shown label is empty (after the flag pass): views cut to
// the shown labels.
@compute @workgroup_size(BUILD_WORKGROUP, BUILD_WORKGROUP, BUILD_WORKGROUP)
fn cut_flags(@builtin(global_invocation_id) id: vec3<u32>) {
    let level = levels[params.level];
    if any(id >= level.nodes) {
        return;
    }
    let i = node_index(level, id);
    node_empty[i] = node_empty[i] | (1u - node_shown[i]);
}

// Every node of the level near a shown label is not empty (after the flag pass, whatever side
// bits it held): label surfaces may lie in it.
@compute @workgroup_size(BUILD_WORKGROUP, BUILD_WORKGROUP, BUILD_WORKGROUP)
fn keep_flags(@builtin(global_invocation_id) id: vec3<u32>) {
    let level = levels[params.level];
    if any(id >= level.nodes) {
        return;
    }
    let i = node_index(level, id);
    node_empty[i] = select(node_empty[i], 0u, node_shown[i] != 0u);
}
