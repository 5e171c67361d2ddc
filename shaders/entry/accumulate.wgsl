// Progressive refinement: the running mean of frames rendered with different sample offsets.
// Each pass adds the latest frame to an f32 sum per pixel and writes sum / count, so a mean of n
// frames is exact to f32 whatever n (no re-weighting of an f16 mean).

#include "generated/constants.wgsl"

// `AccumulateParams` in src/render/gpu_data.rs.
struct AccumulateParams {
    // Frames in the mean after this pass (1 restarts it).
    count: u32,
    width: u32,
    height: u32,
    _pad0: u32,
}

@group(0) @binding(0) var<uniform> params: AccumulateParams;
@group(0) @binding(1) var latest: texture_2d<f32>;
@group(0) @binding(2) var<storage, read_write> sum: array<vec4<f32>>;
@group(0) @binding(3) var mean: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(WORKGROUP, WORKGROUP, 1)
fn accumulate(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let i = id.y * params.width + id.x;
    let c = textureLoad(latest, vec2<i32>(id.xy), 0);
    var s = c;
    if params.count > 1u {
        s = sum[i] + c;
    }
    sum[i] = s;
    textureStore(mean, vec2<i32>(id.xy), s / f32(params.count));
}
