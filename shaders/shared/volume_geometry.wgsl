// Where the shaders find a voxel of the volume (shared/volume.wgsl).

// `VolumeGeometry` in src/render/gpu_data.rs.
struct VolumeGeometry {
    // Volume voxels per axis.
    dims: vec3<u32>,
    // Brick edge in voxels (0: one texture).
    brick_vox: u32,
    // 1 / the texture's texels per axis.
    texel_size: vec3<f32>,
    _pad0: u32,
    // Level-0 bricks per box unit along each axis.
    bricks_per_box: vec3<f32>,
    _pad1: u32,
    // The last level-0 brick's index per axis.
    last_brick: vec3<u32>,
    _pad2: u32,
    // Level-0 atlas units per box unit along each axis.
    atlas_per_box: vec3<f32>,
    _pad3: u32,
}
