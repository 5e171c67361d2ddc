// The parameter blocks of the leaping structures' builders (src/render/gpu_data.rs has their
// Rust twins).

// `BuildParams` in src/render/gpu_data.rs.
struct BuildParams {
    // The level this pass builds.
    level: u32,
    // Normalised value = texel * texel_scale + texel_bias.
    texel_scale: f32,
    texel_bias: f32,
    // Partial builds (build/minmax.wgsl): nodes per axis of one listed brick's box at this level.
    box_edge: u32,
    // Edge of the listed (data) bricks in voxels.
    data_brick: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// `EmptinessParams` in src/render/gpu_data.rs.
struct EmptinessParams {
    // Entries in the lookup table.
    lut_size: u32,
    // Nodes of all pyramid levels.
    node_count: u32,
    // 0: empty where the transfer function is zero (the table); 1: empty where max <= threshold
    // (X-ray: nothing above the window's low end).
    rule: u32,
    threshold: f32,
}
