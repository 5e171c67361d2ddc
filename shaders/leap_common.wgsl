// The min/max pyramid's layout, shared by the builders and the leaping ray loop. Keep
// `LevelInfo` in sync with src/render/leap.rs.

struct LevelInfo {
    nodes: vec3<u32>,
    offset: u32,
    brick_vox: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// Flat index of node n of a level.
fn node_index(level: LevelInfo, n: vec3<u32>) -> u32 {
    return level.offset + n.x + level.nodes.x * (n.y + level.nodes.y * n.z);
}
