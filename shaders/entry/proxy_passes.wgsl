// The proxy pass that only rasterises positions: pass 1 of the fragment path (back faces -> exit
// points). The compute path intersects each ray with the box itself.

#include "shared/proxy.wgsl"

// Pass 1: the back faces, giving each pixel its ray's exit point.
@fragment
fn fs_exit(in: ProxyOut) -> @location(0) vec4<f32> {
    return vec4<f32>(in.box_pos, 1.0);
}
