// The min/max pyramid's layout, shared by the builders and the leaping ray loop.

// One pyramid level: `LevelInfo` in src/render/gpu_data.rs (src/accel/pyramid.rs documents the
// layout).
struct LevelInfo {
    // Nodes per axis.
    nodes: vec3<u32>,
    // First node's index in the flat arrays.
    offset: u32,
    // Brick edge in voxels.
    brick_vox: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// Flat index of node n of a level.
fn node_index(level: LevelInfo, n: vec3<u32>) -> u32 {
    return level.offset + n.x + level.nodes.x * (n.y + level.nodes.y * n.z);
}
