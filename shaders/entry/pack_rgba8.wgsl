// Quantising the rendered image to 8-bit RGBA on the GPU before it is read back: a quarter of
// the bytes of f32 pixels, half of the f16 ones, and no conversion on the CPU. pack4x8unorm
// rounds as `ImageF32::to_rgba8` does (floor(0.5 + 255 · clamp(c, 0, 1))), so the bytes are those
// of the PNG the same image would be saved as.

#include "generated/constants.wgsl"

@group(0) @binding(0) var image: texture_2d<f32>;
// One u32 per pixel, rows packed without padding; byte order r, g, b, a.
@group(0) @binding(1) var<storage, read_write> packed: array<u32>;

@compute @workgroup_size(WORKGROUP, WORKGROUP, 1)
fn pack_rgba8(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(image);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    packed[id.y * size.x + id.x] = pack4x8unorm(textureLoad(image, vec2<i32>(id.xy), 0));
}
