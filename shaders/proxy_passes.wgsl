// The proxy passes that only rasterise positions: pass 1 (back faces -> exit points, both paths)
// and, for the compute path, the front faces and cap -> entry points.

#include "proxy.wgsl"

// Pass 1: the back faces, giving each pixel its ray's exit point.
@fragment
fn fs_exit(in: ProxyOut) -> @location(0) vec4<f32> {
    return vec4<f32>(in.box_pos, 1.0);
}

// Compute path only: the front faces (and cap), giving each pixel its ray's entry point.
@fragment
fn fs_entry(in: ProxyOut) -> @location(0) vec4<f32> {
    let entry = ray_entry(in);
    if entry.w == 0.0 {
        discard;
    }
    return entry;
}
