// Where the shaders find a voxel of the volume (shared/volume.wgsl).

// `VolumeGeometry` in src/render/gpu_data.rs.
struct VolumeGeometry {
    // Volume voxels per axis.
    dims: vec3<u32>,
    // Brick edge in voxels (0: one texture).
    brick_vox: u32,
    // 1 / the texture's texels per axis.
    texel_size: vec3<f32>,
    // Edge of an atlas slot: the brick and its apron.
    slot_vox: u32,
}
