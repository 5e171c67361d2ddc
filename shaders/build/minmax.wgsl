// Builds the min/max pyramid: level 0 from the volume's texels (each 4³ brick extended by one
// voxel on every side, see src/accel/pyramid.rs), every other level from its children.
// Values are normalised as the ray loop decodes them; non-finite voxels are left out.

#include "leap/pyramid.wgsl"
#include "generated/constants.wgsl"
#include "build/params.wgsl"
#include "shared/volume.wgsl"

@group(0) @binding(0) var<uniform> params: BuildParams;
@group(0) @binding(1) var<storage, read> levels: array<LevelInfo>;
@group(0) @binding(2) var<storage, read_write> minmax: array<vec2<f32>>;
@group(0) @binding(3) var volume_tex: texture_3d<f32>;
@group(0) @binding(4) var<storage, read> volume_pages: array<vec4<f32>>;
@group(0) @binding(5) var<uniform> volume_geometry: VolumeGeometry;

// Texels of non-finite voxels decode below MISSING_BELOW (generated/constants.wgsl), as in
// shared/classify.wgsl.
const NONE: vec2<f32> = vec2<f32>(3.0e38, -3.0e38);

@compute @workgroup_size(BUILD_WORKGROUP, BUILD_WORKGROUP, BUILD_WORKGROUP)
fn build_base(@builtin(global_invocation_id) id: vec3<u32>) {
    base_node(id);
}

@compute @workgroup_size(BUILD_WORKGROUP, BUILD_WORKGROUP, BUILD_WORKGROUP)
fn build_parent(@builtin(global_invocation_id) id: vec3<u32>) {
    parent_node(id);
}

// Level 0's node `id` from the volume's voxels.
fn base_node(id: vec3<u32>) {
    let level = levels[0];
    if any(id >= level.nodes) {
        return;
    }
    let dims = volume_dims();
    let b = i32(level.brick_vox);
    let lo = max(vec3<i32>(id) * b - 1, vec3<i32>(0));
    let hi = min((vec3<i32>(id) + 1) * b, dims - 1);
#ifdef BRICKED
    minmax[node_index(level, id)] = bricked_span(lo, hi);
#else
    var m = NONE;
    for (var z = lo.z; z <= hi.z; z++) {
        for (var y = lo.y; y <= hi.y; y++) {
            for (var x = lo.x; x <= hi.x; x++) {
                m = take_texel(m, volume_load(vec3<i32>(x, y, z)).r);
            }
        }
    }
    minmax[node_index(level, id)] = m;
#endif
}

#ifdef BRICKED
// The span of voxels lo ..= hi (in the volume) as volume_load reads them, brick by brick: a
// constant's entry once, a data brick's texels each once (voxel j of a brick held at level k
// reads texel ⌊j·2^-k⌋, so a run of voxels reads a run of texels: a node's 10 voxels per axis
// are 3-4 texels at level 2), with no page read per voxel.
fn bricked_span(lo: vec3<i32>, hi: vec3<i32>) -> vec2<f32> {
    let b = i32(volume_geometry.brick_vox);
    let first = lo / b;
    let last = hi / b;
    var m = NONE;
    for (var bz = first.z; bz <= last.z; bz++) {
        for (var by = first.y; by <= last.y; by++) {
            for (var bx = first.x; bx <= last.x; bx++) {
                let brick = vec3<i32>(bx, by, bz);
                let e = volume_pages[page_index(brick)];
                if e.w == 0.0 {
                    m = take_texel(m, e.x);
                    continue;
                }
                let origin = vec3<i32>(e.xyz);
                let t_lo = vec3<i32>(floor(vec3<f32>(max(lo, brick * b)) * e.w));
                let t_hi = vec3<i32>(floor(vec3<f32>(min(hi, brick * b + b - 1)) * e.w));
                for (var z = t_lo.z; z <= t_hi.z; z++) {
                    for (var y = t_lo.y; y <= t_hi.y; y++) {
                        for (var x = t_lo.x; x <= t_hi.x; x++) {
                            let t = textureLoad(volume_tex, origin + vec3<i32>(x, y, z), 0);
                            m = take_texel(m, t.r);
                        }
                    }
                }
            }
        }
    }
    return m;
}
#endif

// Span m with texel value t taken in (decoded; left out where it marks a non-finite voxel).
fn take_texel(m: vec2<f32>, t: f32) -> vec2<f32> {
    let s = t * params.texel_scale + params.texel_bias;
    return select(m, vec2<f32>(min(m.x, s), max(m.y, s)), s >= MISSING_BELOW);
}

// Level params.level's node `id` from its children.
fn parent_node(id: vec3<u32>) {
    let parent = levels[params.level];
    let child = levels[params.level - 1u];
    if any(id >= parent.nodes) {
        return;
    }
    var m = NONE;
    for (var c = 0u; c < 8u; c++) {
        let k = 2u * id + vec3<u32>(c & 1u, (c >> 1u) & 1u, (c >> 2u) & 1u);
        if all(k < child.nodes) {
            let v = minmax[node_index(child, k)];
            m = vec2<f32>(min(m.x, v.x), max(m.y, v.y));
        }
    }
    minmax[node_index(parent, id)] = m;
}

// Builds after bricks arrived: only the nodes that read a voxel of a listed brick. `changed`
// holds their count (x of entry 0), then the bricks (level-0 bricks of params.data_brick
// voxels). Node n of a level of B-voxel blocks reads voxels n·B − 1 ..= (n + 1)·B, so brick b
// touches nodes ⌈b·D/B⌉ − 1 ..= ⌊(b + 1)·D/B⌋: params.box_edge of them per axis at most.
@group(0) @binding(6) var<storage, read> changed: array<vec4<u32>>;

// The node of invocation `i` (brick i / box_edge³, node i mod box_edge³ of its box); false past
// the list or the level.
fn listed_node(i: u32, level: LevelInfo) -> vec4<u32> {
    let e = params.box_edge;
    let per = e * e * e;
    let n = i / per;
    if n >= changed[0].x {
        return vec4<u32>(0u);
    }
    let b = changed[n + 1u].xyz;
    let d = params.data_brick;
    let first = (b * d + level.brick_vox - 1u) / level.brick_vox;
    let lo = max(first, vec3<u32>(1u)) - 1u;
    let j = i % per;
    let node = lo + vec3<u32>(j % e, (j / e) % e, j / (e * e));
    return vec4<u32>(node, u32(all(node < level.nodes)));
}

@compute @workgroup_size(64)
fn build_base_listed(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = listed_node(id.x, levels[0]);
    if n.w != 0u {
        base_node(n.xyz);
    }
}

@compute @workgroup_size(64)
fn build_parent_listed(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = listed_node(id.x, levels[params.level]);
    if n.w != 0u {
        parent_node(n.xyz);
    }
}
