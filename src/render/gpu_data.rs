//! Everything the Rust side shares with the shaders, in one place: the constants both use (the
//! WGSL side is generated from them, [`wgsl_constants`]) and every `#[repr(C)]` struct a buffer
//! hands to WGSL, each listed in [`layouts`] with its WGSL twin so that a test can check every
//! field's name, offset and type against naga's reflection of the shader.

use crate::accel::{
    distance::{FULL_SHIFT, MAX_DISTANCE},
    emptiness::TABLE_SIZE,
};

use super::volume_texture::MISSING_BELOW;

/// Compute workgroup edge of the ray loop and the accumulation pass (8 × 8 invocations).
pub const WORKGROUP: u32 = 8;
/// Parts each ray is split into, one invocation each, by the compute variants that split rays
/// (`PipelineKey::split`): the ray loop's workgroup is `WORKGROUP × SPLIT_GROUP_ROWS` pixels ×
/// `RAY_PARTS`.
pub const RAY_PARTS: u32 = 4;
/// Pixel rows per workgroup of a split ray loop: `WORKGROUP` pixels wide, 256 invocations in all.
pub const SPLIT_GROUP_ROWS: u32 = 256 / (WORKGROUP * RAY_PARTS);
/// Workgroup edge of the 3D builders (min/max pyramid, distance field): 4 × 4 × 4 nodes.
pub const BUILD_WORKGROUP: u32 = 4;
/// Longest row, in blocks, the distance field's tiled pass (`distance_rows`) takes: every volume
/// of up to 2032 voxels an axis at 4³ blocks; longer rows take the windowed pass. Also the stride
/// of the tile's rows in workgroup memory: 4 less than a multiple of 32, so that the 8 rows × 4
/// positions a subgroup copies at once fall in 32 different banks, and
/// `DISTANCE_TILE_ROWS × DISTANCE_ROW_MAX` u32 fit WebGPU's 16 KiB of workgroup memory.
pub const DISTANCE_ROW_MAX: u32 = 508;
/// Rows one workgroup of the distance field's tiled pass takes.
pub const DISTANCE_TILE_ROWS: u32 = 8;
/// Invocations per row of the distance field's tiled pass (a workgroup is
/// `DISTANCE_ROW_THREADS × DISTANCE_TILE_ROWS` = 256).
pub const DISTANCE_ROW_THREADS: u32 = 32;
const _: () = assert!(
    DISTANCE_ROW_MAX % 32 == 28 && DISTANCE_TILE_ROWS * DISTANCE_ROW_MAX * 4 <= 16384,
    "the tile's rows fit workgroup memory and spread over the banks"
);
const _: () = assert!(DISTANCE_TILE_ROWS * DISTANCE_ROW_THREADS == 256);
/// Workgroup edge of the emptiness-table build: 16 × 16 entries.
pub const TABLE_WORKGROUP: u32 = 16;
/// Workgroup size of the node-flag pass (one node per invocation).
pub const NODE_WORKGROUP: u32 = 256;
/// Most workgroups a dispatch has along one dimension (WebGPU's default limit); wider 1D
/// dispatches wrap into y.
pub const MAX_WORKGROUPS_PER_DIMENSION: u32 = 65535;

/// Number of 64-bit counters in the statistics buffer, in the order of
/// [`crate::counters::FrameCounters`]'s fields: samples, visible samples, rays, leaps, samples
/// leapt, lookups (the `COUNTER_*` indices in WGSL).
pub const COUNTERS: usize = 8;

/// The constants WGSL shares with Rust, as `(name, WGSL type, value)`.
fn shared_constants() -> Vec<(&'static str, &'static str, String)> {
    let u = |v: u32| format!("{v}u");
    let mut constants = vec![
        ("WORKGROUP", "u32", u(WORKGROUP)),
        ("RAY_PARTS", "u32", u(RAY_PARTS)),
        ("SPLIT_GROUP_ROWS", "u32", u(SPLIT_GROUP_ROWS)),
        ("BUILD_WORKGROUP", "u32", u(BUILD_WORKGROUP)),
        ("CELL_VOX", "u32", u(crate::accel::label_cells::CELL_VOX)),
        ("TABLE_WORKGROUP", "u32", u(TABLE_WORKGROUP)),
        ("NODE_WORKGROUP", "u32", u(NODE_WORKGROUP)),
        (
            "MAX_WORKGROUPS_PER_DIMENSION",
            "u32",
            u(MAX_WORKGROUPS_PER_DIMENSION),
        ),
        ("DISTANCE_ROW_MAX", "u32", u(DISTANCE_ROW_MAX)),
        ("DISTANCE_TILE_ROWS", "u32", u(DISTANCE_TILE_ROWS)),
        ("DISTANCE_ROW_THREADS", "u32", u(DISTANCE_ROW_THREADS)),
        ("TABLE_SIZE", "u32", u(TABLE_SIZE as u32)),
        ("MAX_DISTANCE", "u32", u(MAX_DISTANCE)),
        ("DISTANCE_FULL_SHIFT", "u32", u(FULL_SHIFT)),
        ("RULE_AT_MOST", "u32", u(RULE_AT_MOST)),
        ("RULE_ISO", "u32", u(RULE_ISO)),
        ("SIDES_ISO", "u32", u(SIDES_ISO)),
        ("MISSING_BELOW", "f32", format!("{MISSING_BELOW:?}")),
        ("SLAB_MIP", "u32", u(SLAB_MIP)),
        ("SLAB_MINIP", "u32", u(SLAB_MINIP)),
        ("SLAB_MEAN", "u32", u(SLAB_MEAN)),
        ("SLAB_BRICK", "u32", u(SLAB_BRICK)),
    ];
    let counters = [
        "COUNTER_SAMPLES",
        "COUNTER_VISIBLE_SAMPLES",
        "COUNTER_RAYS",
        "COUNTER_LEAPS",
        "COUNTER_LEAPT_SAMPLES",
        "COUNTER_LOOKUPS",
        "COUNTER_SHADOW_RAYS",
        "COUNTER_SHADOW_SAMPLES",
    ];
    const { assert!(COUNTERS == 8, "one name per counter") };
    for (index, name) in counters.into_iter().enumerate() {
        constants.push((name, "u32", u(index as u32)));
    }
    constants
}

/// The WGSL module `generated/constants.wgsl`: `shared_constants` as WGSL `const`s.
pub(crate) fn wgsl_constants() -> String {
    let mut out = String::from(
        "// Generated from src/render/gpu_data.rs at start-up; there is no file to edit.\n",
    );
    for (name, ty, value) in shared_constants() {
        out.push_str(&format!("const {name}: {ty} = {value};\n"));
    }
    out
}

/// A 4×4 column-major f32 matrix (WGSL `mat4x4<f32>`).
#[repr(transparent)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Mat4x4(pub [[f32; 4]; 4]);

/// The WGSL type a Rust field stands for, as naga would print it.
pub trait WgslType {
    /// E.g. `vec3<f32>`.
    fn wgsl() -> String;
}

macro_rules! wgsl_type {
    ($($rust:ty => $wgsl:literal),* $(,)?) => {
        $(impl WgslType for $rust {
            fn wgsl() -> String {
                $wgsl.to_string()
            }
        })*
    };
}

wgsl_type! {
    f32 => "f32",
    u32 => "u32",
    [f32; 2] => "vec2<f32>",
    [f32; 3] => "vec3<f32>",
    [f32; 4] => "vec4<f32>",
    [u32; 3] => "vec3<u32>",
    Mat4x4 => "mat4x4<f32>",
}

impl<const N: usize> WgslType for [[f32; 4]; N] {
    fn wgsl() -> String {
        format!("array<vec4<f32>, {N}>")
    }
}

/// One field of a GPU struct as Rust lays it out.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FieldLayout {
    /// Field name (the WGSL member must have the same).
    pub name: &'static str,
    /// Byte offset.
    pub offset: usize,
    /// The WGSL type it stands for.
    pub wgsl_type: String,
}

/// A GPU struct as Rust lays it out, and where its WGSL twin is declared.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StructLayout {
    /// The Rust type.
    pub rust_name: &'static str,
    /// The WGSL struct's name.
    pub wgsl_name: &'static str,
    /// The shader module (under `shaders/`) that declares it.
    pub module: &'static str,
    /// Size in bytes.
    pub size: usize,
    /// The fields, in declaration order.
    pub fields: Vec<FieldLayout>,
}

/// The WGSL type of the field `_field` selects (only its type is used).
fn field_type<S, T: WgslType>(_field: fn(&S) -> &T) -> String {
    T::wgsl()
}

/// `StructLayout` of a Rust struct from its field names, in order.
macro_rules! layout {
    ($rust:ident = $wgsl:literal in $module:literal { $($field:ident),* $(,)? }) => {
        StructLayout {
            rust_name: stringify!($rust),
            wgsl_name: $wgsl,
            module: $module,
            size: std::mem::size_of::<$rust>(),
            fields: vec![$(FieldLayout {
                name: stringify!($field),
                offset: std::mem::offset_of!($rust, $field),
                wgsl_type: field_type(|s: &$rust| &s.$field),
            }),*],
        }
    };
}

/// Every GPU struct with its WGSL twin.
pub fn layouts() -> Vec<StructLayout> {
    vec![
        layout!(FrameUniforms = "Frame" in "shared/common.wgsl" {
            clip_from_box, box_from_clip, ray_near, ray_dir, background, extent_mm, step_mm,
            volume_dims, texel_scale, spacing_mm, texel_bias, crop_min, lut_size, crop_max,
            sample_offset, light_dir, headlight, viewport, termination_alpha, jitter,
            phong_ambient, phong_diffuse, phong_specular, phong_shininess, window_lo, window_hi,
            saturation, xray_density_per_mm, iso_threshold, steps_per_d0, depth_units_per_mm,
            iso_refine, leaf_level, level_count, lut_depth_unit, light_min_weight, row_offset,
            row_end, all_finite, colour_volume, label_layers, surface_channels, label_bricks, _pad2,
            surface_scale, _pad3, shadow_step_mm, shadow_reach_mm, shadow_tan,
            occlusion_radius_mm, shadow_sample, occlusion_step_mm, _pad6,
        }),
        layout!(VolumeGeometry = "VolumeGeometry" in "shared/volume_geometry.wgsl" {
            dims, brick_vox, texel_size, _pad0, bricks_per_box, _pad1, last_brick, _pad2,
            atlas_per_box, _pad3,
        }),
        layout!(LevelInfo = "LevelInfo" in "leap/pyramid.wgsl" {
            nodes, offset, brick_vox, _pad0, _pad1, _pad2,
        }),
        layout!(BuildParams = "BuildParams" in "build/params.wgsl" {
            level, texel_scale, texel_bias, box_edge, data_brick, _pad0, _pad1, _pad2,
        }),
        layout!(EmptinessParams = "EmptinessParams" in "build/params.wgsl" {
            lut_size, node_count, rule, threshold,
        }),
        layout!(LabelParams = "LabelParams" in "build/labels.wgsl" {
            cells, level, apron, _pad0, _pad1, _pad2,
        }),
        layout!(SurfaceParams = "SurfaceParams" in "build/label_surface.wgsl" {
            dims, axis, origin, row_words, extent, radius, weights, layers, channels, _pad1, _pad2,
            read_origin, _pad3,
        }),
        layout!(DistanceParams = "DistanceParams" in "build/distance.wgsl" {
            leaf_level, axis, sides, _pad1,
        }),
        layout!(AccumulateParams = "AccumulateParams" in "entry/accumulate.wgsl" {
            count, width, height, _pad0,
        }),
        layout!(SliceParams = "SliceParams" in "entry/slice.wgsl" {
            first, step_x, step_y, slab_step, width, height, nearest, pitch, texel_max,
            unit_scale, unit_bias, window_lo, window_hi, slab_count, slab_mode, leap, colour,
            colour_lo, colour_hi, invert, volume_colour, labels, label_opacity, label_outline,
            label_bricks, _pad0, _pad1, _pad2,
        }),
    ]
}

/// The uniform block every ray-casting shader reads (`Frame`). Built each frame by the pure
/// [`crate::render::raycast::uniforms::frame_uniforms`]; shaders/shared/common.wgsl documents
/// each field beside its WGSL declaration.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameUniforms {
    /// Box coordinates → clip space.
    pub clip_from_box: Mat4x4,
    /// Clip space → box coordinates (rays of the near-plane cap).
    pub box_from_clip: Mat4x4,
    /// The compute path's rays (box coordinates, w unused): the near-plane point of the ray
    /// through NDC `(x, y)` is `ray_near[0] + x·ray_near[1] + y·ray_near[2]`, and the ray runs
    /// to the far plane along `ray_dir[0] + x·ray_dir[1] + y·ray_dir[2]` (both affine in x and y
    /// for either projection; computed in f64 so no f32 unprojection loses digits).
    pub ray_near: [[f32; 4]; 3],
    /// See `ray_near`.
    pub ray_dir: [[f32; 4]; 3],
    /// Background colour composited behind the volume (a = 1).
    pub background: [f32; 4],
    /// Size of the bounding box in millimetres.
    pub extent_mm: [f32; 3],
    /// Distance between samples, millimetres.
    pub step_mm: f32,
    /// Volume dimensions in voxels: box coordinates × dims = voxel coordinate + ½.
    pub volume_dims: [f32; 3],
    /// Normalised value = texel * texel_scale + texel_bias.
    pub texel_scale: f32,
    /// Voxel spacing in millimetres.
    pub spacing_mm: [f32; 3],
    /// See `texel_scale`.
    pub texel_bias: f32,
    /// The cropping box's smallest corner in box coordinates: rays start and end on the
    /// cropping box ([`crate::settings::CropBox`]).
    pub crop_min: [f32; 3],
    /// Number of entries in the transfer-function lookup table.
    pub lut_size: f32,
    /// The cropping box's largest corner.
    pub crop_max: [f32; 3],
    /// First sample at `(k + sample_offset) * step`, k = 0, 1, …
    pub sample_offset: f32,
    /// Direction a directional light travels (world, unit); unused with the headlight.
    pub light_dir: [f32; 3],
    /// 1 for a headlight (at the eye, shining along each ray), else 0.
    pub headlight: u32,
    /// Viewport width and height in pixels.
    pub viewport: [f32; 2],
    /// RC-t stops once accumulated opacity exceeds this.
    pub termination_alpha: f32,
    /// 1 for jittered ray starts, else 0.
    pub jitter: u32,
    /// Phong Ka.
    pub phong_ambient: f32,
    /// Phong Kd.
    pub phong_diffuse: f32,
    /// Phong Ks.
    pub phong_specular: f32,
    /// Phong exponent n.
    pub phong_shininess: f32,
    /// The window's low end (normalised value) of MIP, MinIP and X-ray.
    pub window_lo: f32,
    /// The window's high end.
    pub window_hi: f32,
    /// MIP/MinIP: the value past which the image can no longer change (the window's end for
    /// grey, the volume's extreme for colours).
    pub saturation: f32,
    /// X-ray attenuation per millimetre at the window's top.
    pub xray_density_per_mm: f32,
    /// The normalised iso value less the tie tolerance
    /// ([`crate::settings::IsoSettings::threshold`]).
    pub iso_threshold: f32,
    /// Lookup-table steps per d₀ (the reciprocal of the step in voxels): undoes the table's
    /// opacity correction where MIP and MinIP colour by the transfer function.
    pub steps_per_d0: f32,
    /// Pre-integration: optical-depth units (d₀, or steps without opacity correction) per
    /// millimetre of segment.
    pub depth_units_per_mm: f32,
    /// Isosurface refinement steps.
    pub iso_refine: u32,
    /// Pyramid level of the leaping blocks.
    pub leaf_level: u32,
    /// Number of pyramid levels.
    pub level_count: u32,
    /// What the lookup table's stored depths are multiplied by to give optical depths (they are
    /// stored scaled so that 16-bit floats hold faint ones).
    pub lut_depth_unit: f32,
    /// DVR: samples whose weight in the pixel is below this are composited unlit.
    pub light_min_weight: f32,
    /// The compute path's first image row: a frame rendered in bands of rows dispatches one
    /// band at a time (0 for a whole frame).
    pub row_offset: u32,
    /// The end of the compute path's rows (exclusive): the band's last row + 1, or the height.
    pub row_end: u32,
    /// 1 where every voxel of the volume is finite (no sample decodes as missing), else 0.
    pub all_finite: u32,
    /// 1 for a colour volume: DVR and isosurfaces take each sample's own colour.
    pub colour_volume: u32,
    /// Layers of labels bound beside the volume (0 without a segmentation).
    pub label_layers: u32,
    /// Channels of the label surfaces' mask the ray loop reads (1, 2 or 4; 0 without surfaces).
    pub surface_channels: u32,
    /// 1 where the labels travel in the volume's bricks (its label atlas, found through the
    /// page table), 0 where one texture of the grid holds them.
    pub label_bricks: u32,
    /// Padding.
    pub _pad2: u32,
    /// Box coordinates times this are the label surfaces' mask's: 1 but where the mask lies on
    /// the labels' grid reduced k-fold (it covers k·ceil(N / k) voxels of N).
    pub surface_scale: [f32; 3],
    /// Padding.
    pub _pad3: u32,
    /// Distance between a shadow ray's samples, mm (shaders/shared/shadow.wgsl).
    pub shadow_step_mm: f32,
    /// How far a shadow ray reaches, mm.
    pub shadow_reach_mm: f32,
    /// The tangent of the light's angular radius (0: hard shadows).
    pub shadow_tan: f32,
    /// How far ambient-occlusion rays reach, mm (shaders/shared/occlusion.wgsl).
    pub occlusion_radius_mm: f32,
    /// The frame's point of the unit square on the light's disc, rotated per pixel.
    pub shadow_sample: [f32; 2],
    /// The distance between an occlusion ray's samples (the smallest voxel spacing), mm.
    pub occlusion_step_mm: f32,
    /// Padding.
    pub _pad6: u32,
}

/// Where the shaders find a voxel of the volume (`VolumeGeometry`, shaders/shared/volume.wgsl):
/// in one texture of the volume's size, or in bricks of an atlas (`accel::bricks`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct VolumeGeometry {
    /// Volume voxels per axis.
    pub dims: [u32; 3],
    /// Brick edge in voxels (0: one texture).
    pub brick_vox: u32,
    /// 1 / the texture's texels per axis (the volume's, or the atlas's).
    pub texel_size: [f32; 3],
    /// Padding.
    pub _pad0: u32,
    /// Level-0 bricks per box unit along each axis (volume voxels / brick edge; 0: one texture).
    pub bricks_per_box: [f32; 3],
    /// Padding.
    pub _pad1: u32,
    /// The last level-0 brick's index per axis (0: one texture).
    pub last_brick: [u32; 3],
    /// Padding.
    pub _pad2: u32,
    /// Level-0 atlas units per box unit along each axis (volume voxels · texel size).
    pub atlas_per_box: [f32; 3],
    /// Padding.
    pub _pad3: u32,
}

/// One pyramid level as the shaders read it (`LevelInfo`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LevelInfo {
    /// Nodes per axis.
    pub nodes: [u32; 3],
    /// First node's index in the flat arrays.
    pub offset: u32,
    /// Brick edge in voxels.
    pub brick_vox: u32,
    /// Padding to 32 bytes.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
}

/// Parameters of one pass of the min/max pyramid build (`BuildParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BuildParams {
    /// The level this pass builds.
    pub level: u32,
    /// Normalised value = texel * texel_scale + texel_bias.
    pub texel_scale: f32,
    /// See `texel_scale`.
    pub texel_bias: f32,
    /// Partial builds: nodes per axis of one listed brick's box at this level.
    pub box_edge: u32,
    /// Edge of the listed (data) bricks in voxels.
    pub data_brick: u32,
    /// Padding to 32 bytes.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
}

/// What makes a node empty in the node-flag pass (`EmptinessParams.rule`).
pub const RULE_TRANSFER: u32 = 0;
/// X-ray: empty where no value lies above `threshold`.
pub const RULE_AT_MOST: u32 = 1;
/// Isosurfaces: two bits per node, 1 where every value lies below `threshold` (the iso value),
/// 2 where every value lies at or above it (3: no finite value).
pub const RULE_ISO: u32 = 2;

/// Parameters of the emptiness-table and node-flag passes (`EmptinessParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct EmptinessParams {
    /// Entries in the lookup table.
    pub lut_size: u32,
    /// Nodes of all pyramid levels.
    pub node_count: u32,
    /// [`RULE_TRANSFER`], [`RULE_AT_MOST`] or [`RULE_ISO`].
    pub rule: u32,
    /// The normalised value at or below which a node is empty under [`RULE_AT_MOST`]; the iso
    /// value under [`RULE_ISO`].
    pub threshold: f32,
}

/// Parameters of one level's pass of the label flags (`LabelParams`, build/labels.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LabelParams {
    /// Cells per axis of the label lists (`accel::label_cells`).
    pub cells: [u32; 3],
    /// The pyramid level this pass builds.
    pub level: u32,
    /// Cells around a level-0 node that count as its own (label surfaces), else 0.
    pub apron: u32,
    /// Padding to 16 bytes.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
}

/// Parameters of one pass of the label-surface mask over one slab (`SurfaceParams`,
/// build/label_surface.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SurfaceParams {
    /// The grid's dimensions.
    pub dims: [u32; 3],
    /// The axis the pass smooths along.
    pub axis: u32,
    /// The slab's first voxel.
    pub origin: [u32; 3],
    /// Words (four bytes: 4 / channels voxels) per row of the buffer.
    pub row_words: u32,
    /// The slab's extent in voxels.
    pub extent: [u32; 3],
    /// The kernel's radius in voxels.
    pub radius: u32,
    /// The kernel's weights for offsets 0…3.
    pub weights: [f32; 4],
    /// Layers of labels the label texture holds.
    pub layers: u32,
    /// The mask's channels (classes): 1, 2 or 4.
    pub channels: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
    /// The voxel the texture the pass reads (the mask so far) starts at: 0 for the whole
    /// mask, the region's first voxel for the scratch of a region's build.
    pub read_origin: [u32; 3],
    /// Padding.
    pub _pad3: u32,
}

/// Parameters of one axis pass of the distance field (`DistanceParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct DistanceParams {
    /// The pyramid level the field covers.
    pub leaf_level: u32,
    /// The axis this pass runs along (0, 1, 2).
    pub axis: u32,
    /// What the two sides of the field measure: [`SIDES_EMPTY_FULL`] or [`SIDES_ISO`].
    pub sides: u32,
    /// Padding to 16 bytes.
    pub _pad1: u32,
}

/// Distance field from 0/1 emptiness flags: low bits the distance to the nearest non-empty
/// block, high bits to the nearest empty one (`accel::distance::two_sided`).
pub const SIDES_EMPTY_FULL: u32 = 0;
/// Distance field from [`RULE_ISO`] flags: low bits the distance to the nearest block not wholly
/// below the iso value, high bits to the nearest not wholly at or above it.
pub const SIDES_ISO: u32 = 1;

/// Parameters of one accumulation pass of progressive refinement (`AccumulateParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct AccumulateParams {
    /// Frames in the mean after this pass (1 restarts it).
    pub count: u32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Padding to 16 bytes.
    pub _pad0: u32,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_layout_is_a_whole_number_of_16_byte_rows_without_gaps() {
        for layout in layouts() {
            assert_eq!(layout.size % 16, 0, "{}", layout.rust_name);
            // Fields follow each other with no hidden padding (Pod needs none; WGSL's rules
            // are what the naga test checks).
            let mut names: Vec<_> = layout.fields.iter().map(|f| f.name).collect();
            names.dedup();
            assert_eq!(names.len(), layout.fields.len(), "{}", layout.rust_name);
        }
    }

    #[test]
    fn the_generated_constants_hold_the_rust_values() {
        let wgsl = wgsl_constants();
        assert!(
            wgsl.contains(&format!("const WORKGROUP: u32 = {WORKGROUP}u;\n")),
            "{wgsl}"
        );
        // An f32 literal WGSL parses back to the same value (Rust's shortest round-trip form).
        let missing = format!("const MISSING_BELOW: f32 = {MISSING_BELOW:?};\n");
        assert!(wgsl.contains(&missing), "{wgsl}");
        assert!(
            wgsl.contains("const COUNTER_LEAPT_SAMPLES: u32 = 4u;\n"),
            "the fifth counter: {wgsl}"
        );
        assert_eq!(wgsl.matches("const COUNTER_").count(), COUNTERS);
    }
}

/// Parameters of a slice view's sampling pass (`SliceParams`, shaders/entry/slice.wgsl), built
/// by `render::slice::slice_params` from a `mpr::SliceView`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SliceParams {
    /// Voxel coordinates of pixel (0, 0)'s centre (w unused).
    pub first: [f32; 4],
    /// One pixel to the right, in voxel coordinates.
    pub step_x: [f32; 4],
    /// One pixel down, in voxel coordinates.
    pub step_y: [f32; 4],
    /// Between two samples of a thick slab, along the plane's normal (voxel coordinates).
    pub slab_step: [f32; 4],
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// 1: the nearest voxel; 0: trilinear.
    pub nearest: u32,
    /// u32 words per row of the grey image buffer.
    pub pitch: u32,
    /// Largest integer of a unorm texture (255 or 65535), whose texels are integers `u / max`
    /// (`u = round(texel × max)` recovers them exactly); 0 for a float texture (`u = texel`).
    pub texel_max: f32,
    /// Data value = u × unit_scale + unit_bias (exact for integer volumes: u is the stored
    /// value plus an offset).
    pub unit_scale: f32,
    /// See `unit_scale`.
    pub unit_bias: f32,
    /// Window low end (data units): grey 0.
    pub window_lo: f32,
    /// Window high end: grey 255.
    pub window_hi: f32,
    /// Samples across a thick slab, centred on the plane (1: a thin slice).
    pub slab_count: u32,
    /// How a slab's samples combine: `SLAB_MIP`, `SLAB_MINIP` or `SLAB_MEAN`.
    pub slab_mode: u32,
    /// 1: a slab skips the bricks that cannot change it; 0: it takes every sample.
    pub leap: u32,
    /// 1 (display variant): the transfer function's colour blended over the grey by its
    /// opacity; 0: grey.
    pub colour: u32,
    /// The data value at the colour table's first entry.
    pub colour_lo: f32,
    /// The data value at its last entry.
    pub colour_hi: f32,
    /// 1: grey runs from white at the window's low end to black at its high end (MONOCHROME1).
    pub invert: u32,
    /// 1 (display variant): a colour volume, whose thin slices show its own colour.
    pub volume_colour: u32,
    /// The layers of labels (`label_tex`'s channels, 0 … 4) the display variant fills over the
    /// image in their colours.
    pub labels: u32,
    /// How opaque a label's fill is, 0…1.
    pub label_opacity: f32,
    /// 1: each label's outline drawn opaque (where a neighbouring pixel's label differs).
    pub label_outline: u32,
    /// 1 where the labels travel in the volume's bricks (its label atlas), 0 where one texture
    /// of the grid holds them.
    pub label_bricks: u32,
    /// Padding.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
}

/// `SliceParams.slab_mode`: the largest sample.
pub const SLAB_MIP: u32 = 0;
/// `SliceParams.slab_mode`: the smallest sample.
pub const SLAB_MINIP: u32 = 1;
/// `SliceParams.slab_mode`: the mean of the samples.
pub const SLAB_MEAN: u32 = 2;
/// Edge in voxels of the bricks a thick slab leaps over (`render::slice::SliceBricks`).
pub const SLAB_BRICK: u32 = 8;
