// The same ray loop in a compute shader: entry and exit points were rasterised into textures by
// the proxy passes; one invocation per pixel (GPU.md: far faster than fragments on data-centre
// GPUs).

#include "march.wgsl"

@group(1) @binding(0) var exit_tex: texture_2d<f32>;
@group(1) @binding(1) var entry_tex: texture_2d<f32>;
@group(1) @binding(2) var out_tex: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn cs_raycast(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(frame.viewport);
    if any(id.xy >= size) {
        return;
    }
    let entry = textureLoad(entry_tex, id.xy, 0);
    let exit = textureLoad(exit_tex, id.xy, 0);
    var color = frame.background;
    if entry.w > 0.0 && exit.w > 0.0 {
        color = march(entry.xyz, exit.xyz);
    }
    textureStore(out_tex, id.xy, color);
}
