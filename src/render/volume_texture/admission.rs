//! The admission check a load makes before reading samples.

use crate::render::context::GpuContext;

use super::encoding::{bytes_per_texel, candidates};
use super::plan::plan;
use super::{Allocation, allocate, besides_texels};
use crate::settings::Bricking;

/// The check a load makes of the volume's shape before reading its samples
/// ([`crate::volume::LoadProgress::with_admission`]): a layout on this GPU (one texture, or
/// bricks where an axis is past its 3D texture limit), and a texture of that size and format allocated (and let go) without running
/// out of memory. What the texture upload would refuse after minutes of reading is refused
/// first.
pub fn admission(
    ctx: &GpuContext,
    gpu_budget: Option<u64>,
) -> Box<crate::volume::progress::Admission> {
    let ctx = ctx.clone();
    Box::new(move |shape: &crate::volume::progress::Shape| {
        let max = ctx.limits.max_texture_dimension_3d;
        // Integer formats as `choose_encoding` picks them; floats may hold NaN, which only
        // float formats keep, and are sized as the widest.
        let format = if shape.colour {
            wgpu::TextureFormat::Rgba8Unorm
        } else {
            candidates(shape.scalar_type, false)
                .iter()
                .copied()
                .find(|&f| ctx.is_filterable(f))
                .unwrap_or(wgpu::TextureFormat::R16Float)
        };
        let bpt = bytes_per_texel(format) as u64;
        // The default layout: one texture where the volume fits it, else bricks of the finest
        // level that fits.
        let budget = gpu_budget.or_else(|| ctx.default_gpu_budget());
        // The texels' share, as the upload lays them out: the test allocation stays inside the
        // budget too.
        let besides = besides_texels(&ctx, shape.dims, budget);
        let texels = budget.map(|b| b.saturating_sub(besides).max(1));
        let layout = match plan(shape.dims, Bricking::Auto, (max, texels), bpt) {
            // Laid out as the upload will lay it out where the driver pads it (`tiling::fit`):
            // the first box of a 1024³ atlas took 1.6 GB under a 1 GB budget on the H100.
            Ok(layout) => texels
                .and_then(|s| {
                    let replan =
                        |lower| plan(shape.dims, Bricking::Auto, (max, Some(lower)), bpt).ok();
                    super::tiling::fit(&ctx, layout, s, replan, format)
                })
                .unwrap_or(layout),
            Err(e) => {
                // Named against the budget given where that alone is too small, else against
                // the texels' share of it.
                let why = match (plan(shape.dims, Bricking::Auto, (max, budget), bpt), budget) {
                    (Err(whole), _) => whole.to_string(),
                    (Ok(_), Some(b)) => format!(
                        "{e} (the texels' share of a budget of {}: its leaping structures, page \
                         tables, upload staging and a frame's targets take {})",
                        crate::text::bytes(b),
                        crate::text::bytes(besides)
                    ),
                    (Ok(_), None) => e.to_string(),
                };
                return Err(format!(
                    "the volume is {} x {} x {} voxels and does not fit this GPU ({}): {why}",
                    shape.dims[0], shape.dims[1], shape.dims[2], ctx.adapter_info.name
                ));
            }
        };
        let megabytes = layout.bytes(bpt) as f64 / 1e6;
        match allocate(&ctx, layout.extent(), format) {
            Ok((texture, _)) => {
                texture.destroy();
                Ok(())
            }
            Err(Allocation::OutOfMemory) => Err(format!(
                "the GPU ({}) has not enough memory for a {megabytes:.0} MB volume texture",
                ctx.adapter_info.name
            )),
            Err(Allocation::Refused(e)) => Err(format!(
                "the GPU ({}) refused a volume texture of {megabytes:.0} MB: {}",
                ctx.adapter_info.name,
                e.lines().next().unwrap_or_default()
            )),
        }
    })
}
