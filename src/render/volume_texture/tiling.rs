//! A volume texture as the driver lays it out: a 3D texture may take more memory than its
//! texels (tiles padded on each axis), and the budget holds what it takes.

use super::plan::{Atlas, Plan};
use super::{Allocation, allocate};
use crate::render::context::GpuContext;

/// A layout, its texture and the bytes that texture took.
pub(super) type Placed = (Plan, wgpu::Texture, u64);

/// Rounds of laying the texture out again smaller before the last is kept.
const ROUNDS: usize = 4;

/// Textures up to this size try every order of their axes (each a trial allocation); larger
/// ones only shrink: allocations of 700-870 MB took 50-90 ms each on the H100 machine, and a
/// search of them held 2.6-3.2 GB at its peak under a budget of 1 GB (`nvidia-smi`,
/// docs/benchmarks/nvidia-h100-bricks-stream §11).
const SEARCH_MOST: u64 = 64 << 20;

/// A shrunk layout aims this much below the share, as the padding of its new shape is not known
/// before it is allocated.
const MARGIN: f64 = 0.99;

/// `first` within `share` bytes as allocated: a bricked atlas takes the order of its axes that
/// takes least; where that is still more than `share`, `replan` lays the volume out for a share
/// lowered by the ratio of taken to texels, a few rounds. Where no smaller layout exists (the
/// coarsest level's one slot, or one texture forced) the last one is kept, past the share by
/// the driver's padding alone.
pub(super) fn within(
    ctx: &GpuContext,
    first: Placed,
    share: u64,
    replan: impl Fn(u64) -> Option<Plan>,
    format: wgpu::TextureFormat,
) -> Result<Placed, Allocation> {
    let mut placed = least_taking(ctx, first, format);
    for _ in 0..ROUNDS {
        let (plan, texture, taken) = &placed;
        if *taken <= share {
            break;
        }
        let texels = texels_of(plan, format);
        let lower = (share.min(texels) as f64 * texels as f64 / *taken as f64 * MARGIN) as u64;
        log::debug!(
            "a volume texture of {} takes {}, more than the texels' share of {}",
            crate::text::bytes(texels),
            crate::text::bytes(*taken),
            crate::text::bytes(share)
        );
        let Some(smaller) = replan(lower).filter(|p| texels_of(p, format) < texels) else {
            break;
        };
        texture.destroy();
        let (texture, taken) = allocate(ctx, smaller.extent(), format)?;
        let taken = taken.unwrap_or(texels_of(&smaller, format));
        placed = least_taking(ctx, (smaller, texture, taken), format);
    }
    Ok(placed)
}

/// Bytes of `plan`'s texels.
fn texels_of(plan: &Plan, format: wgpu::TextureFormat) -> u64 {
    let bpt = super::encoding::bytes_per_texel(format) as u64;
    plan.extent().iter().map(|&e| u64::from(e)).product::<u64>() * bpt
}

/// Of the boxes of an atlas's slots in each order of the axes, and in one row where the limit
/// allows, the texture that takes the least memory as allocated (`first`: the one its own box
/// took): drivers pad each axis to tiles of their own (lavapipe: x to 64 texels, y to 4), so the
/// same slots take more or less by how they lie. One texture, and an atlas past
/// [`SEARCH_MOST`], is kept as it is.
fn least_taking(ctx: &GpuContext, first: Placed, format: wgpu::TextureFormat) -> Placed {
    let Plan::Bricked(atlas) = first.0 else {
        return first;
    };
    if texels_of(&first.0, format) > SEARCH_MOST {
        return first;
    }
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
    let mut best = first;
    for slots in boxes.into_iter().filter(|&b| b != atlas.slots) {
        let candidate = Plan::Bricked(Atlas { slots, ..atlas });
        let Ok((texture, Some(taken))) = allocate(ctx, candidate.extent(), format) else {
            continue;
        };
        if taken < best.2 {
            best.1.destroy();
            best = (candidate, texture, taken);
        } else {
            texture.destroy();
        }
    }
    best
}

/// What wgpu's memory allocator has handed out (bytes), where the backend reports it (Vulkan
/// and DX12): a driver lays a 3D texture out in tiles, so it may take more than its texels
/// (lavapipe: 1.14× for 170³ of uint8, 1.99× for 34³).
pub(super) fn allocated_bytes(ctx: &GpuContext) -> Option<u64> {
    ctx.device
        .generate_allocator_report()
        .map(|r| r.total_allocated_bytes)
}
