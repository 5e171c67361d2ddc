// The paper's single pass: the front faces (and near-plane cap) run the ray loop per fragment,
// reading the exit point that pass 1 rendered from the back faces.

#include "shared/proxy.wgsl"
#include "march/march.wgsl"

@group(1) @binding(0) var exit_tex: texture_2d<f32>;

@fragment
fn fs_raycast(in: ProxyOut) -> @location(0) vec4<f32> {
    let entry = ray_entry(in);
    if entry.w == 0.0 {
        discard;
    }
    let exit = textureLoad(exit_tex, vec2<u32>(in.clip.xy), 0);
    if exit.w == 0.0 {
        return frame.background;
    }
    return march(entry.xyz, exit.xyz, vec2<u32>(in.clip.xy));
}
