//! A volume texture as the driver lays it out: a 3D texture may take more memory than its
//! texels (tiles padded on each axis), and the budget holds what it takes.

use ash::vk;

use super::plan::{Atlas, Plan};
use crate::render::context::GpuContext;

/// Rounds of laying the texture out again smaller before the last is kept.
const ROUNDS: usize = 4;

/// A shrunk layout aims this much below the share, as the padding of its new shape is not known
/// before it is asked for.
const MARGIN: f64 = 0.99;

/// `plan` laid out, before anything is allocated, so that its texture takes no more than
/// `share` as the driver lays it out: the order of a bricked atlas's axes (or one row) that the
/// driver pads least, and where that is still more than `share`, `replan`'s layout for a share
/// lowered by the ratio of taken to texels, a few rounds. Asked of Vulkan
/// ([`required_bytes`]: what lavapipe's allocations then took, to their 48-byte alignment);
/// `None` elsewhere (GL reports no sizes: its texture is counted as its texels).
pub(super) fn fit(
    ctx: &GpuContext,
    plan: Plan,
    share: u64,
    replan: impl Fn(u64) -> Option<Plan>,
    format: wgpu::TextureFormat,
) -> Option<Plan> {
    let mut best = least_required(ctx, plan, format)?;
    for _ in 0..ROUNDS {
        let texels = texels_of(&best.0, format);
        if best.1 <= share {
            break;
        }
        let lower = (share.min(texels) as f64 * texels as f64 / best.1 as f64 * MARGIN) as u64;
        let Some(smaller) = replan(lower).filter(|p| texels_of(p, format) < texels) else {
            break;
        };
        match least_required(ctx, smaller, format) {
            Some(next) => best = next,
            None => break,
        }
    }
    Some(best.0)
}

/// Of `plan`'s box of slots in each order of the axes (and in one row where the limit allows),
/// the one the driver takes least for, with those bytes; `None` off Vulkan.
fn least_required(
    ctx: &GpuContext,
    plan: Plan,
    format: wgpu::TextureFormat,
) -> Option<(Plan, u64)> {
    let first = (plan, required_bytes(ctx, plan.extent(), format)?);
    let Plan::Bricked(atlas) = plan else {
        return Some(first);
    };
    let best = boxes_of(ctx, atlas)
        .into_iter()
        .filter_map(|slots| {
            let candidate = Plan::Bricked(Atlas { slots, ..atlas });
            Some((candidate, required_bytes(ctx, candidate.extent(), format)?))
        })
        .fold(first, |best, c| if c.1 < best.1 { c } else { best });
    Some(best)
}

/// The other boxes holding an atlas's slots: each order of its axes, and one row where the
/// adapter's limit allows.
fn boxes_of(ctx: &GpuContext, atlas: Atlas) -> Vec<[u32; 3]> {
    let [x, y, z] = atlas.slots;
    let count = x * y * z;
    let per_axis = (ctx.limits.max_texture_dimension_3d / atlas.slot_vox())
        .min(crate::accel::bricks::MAX_SLOTS_PER_AXIS);
    let mut boxes = vec![[x, z, y], [y, x, z], [y, z, x], [z, x, y], [z, y, x]];
    if count <= per_axis {
        boxes.extend([[count, 1, 1], [1, count, 1], [1, 1, count]]);
    }
    boxes.sort_unstable();
    boxes.dedup();
    boxes.retain(|&b| b != atlas.slots);
    boxes
}

/// Bytes the driver will take for a 3D texture of `extent` in `format` as the volume's texture
/// is made (sampled, copied to), asked of Vulkan before anything is allocated
/// (`vkGetImageMemoryRequirements` of an image made and let go at once): `None` off Vulkan or
/// for a format it does not name here.
fn required_bytes(ctx: &GpuContext, extent: [u32; 3], format: wgpu::TextureFormat) -> Option<u64> {
    let format = match format {
        wgpu::TextureFormat::R8Unorm => vk::Format::R8_UNORM,
        wgpu::TextureFormat::R16Unorm => vk::Format::R16_UNORM,
        wgpu::TextureFormat::R16Float => vk::Format::R16_SFLOAT,
        wgpu::TextureFormat::R32Float => vk::Format::R32_SFLOAT,
        wgpu::TextureFormat::Rgba8Unorm => vk::Format::R8G8B8A8_UNORM,
        _ => return None,
    };
    // SAFETY: the raw device is only used to make an image, read its requirements and destroy
    // it again; nothing of wgpu's is touched and the guard outlives every call.
    let hal = unsafe { ctx.device.as_hal::<wgpu::hal::api::Vulkan>() }?;
    let device = hal.raw_device();
    let info = vk::ImageCreateInfo::default()
        .image_type(vk::ImageType::TYPE_3D)
        .format(format)
        .extent(vk::Extent3D {
            width: extent[0],
            height: extent[1],
            depth: extent[2],
        })
        .mip_levels(1)
        .array_layers(1)
        .samples(vk::SampleCountFlags::TYPE_1)
        .tiling(vk::ImageTiling::OPTIMAL)
        .usage(vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST)
        .sharing_mode(vk::SharingMode::EXCLUSIVE)
        .initial_layout(vk::ImageLayout::UNDEFINED);
    // SAFETY: `info` is a valid 3D image description within the adapter's limits (the plan
    // keeps every axis under them); the image is destroyed before return and never bound.
    let image = unsafe { device.create_image(&info, None) }.ok()?;
    let required = unsafe { device.get_image_memory_requirements(image) };
    unsafe { device.destroy_image(image, None) };
    Some(required.size)
}

/// Bytes of `plan`'s texels.
fn texels_of(plan: &Plan, format: wgpu::TextureFormat) -> u64 {
    plan.bytes(super::encoding::bytes_per_texel(format) as u64)
}

/// What wgpu's memory allocator has handed out (bytes), where the backend reports it (Vulkan
/// and DX12): a driver lays a 3D texture out in tiles, so it may take more than its texels
/// (lavapipe: 1.14× for 170³ of uint8, 1.99× for 34³): the count of the texture made.
pub(super) fn allocated_bytes(ctx: &GpuContext) -> Option<u64> {
    ctx.device
        .generate_allocator_report()
        .map(|r| r.total_allocated_bytes)
}
