//! What lives as long as one transfer function: the function itself, its generation (the one
//! change signal the window and the leaping structures follow), the baked lookup table and the
//! pre-integration table, each rebuilt only when what it depends on changed.

use std::sync::Arc;

use crate::accel::emptiness::OpacityIndex;
use crate::render::context::GpuContext;
use crate::render::table_texture::TableTexture;
use crate::transfer::{TransferFunction, lut, preintegration};
use crate::volume::ValueRange;

/// The transfer function on the GPU.
pub struct TransferTables {
    function: TransferFunction,
    /// Bumped on every change of the function.
    generation: u64,
    lut: TableTexture,
    integrals: TableTexture,
    /// (generation, step bits) the lookup table was baked for; `None` = stale.
    lut_baked_for: Option<(u64, u64)>,
    /// Generation the integral table was built for; `None` = stale.
    integrals_built_for: Option<u64>,
    /// What the stored depths are multiplied by to give optical depths (the reciprocal of the
    /// table's [`lut::f16_depth_scale`]).
    depth_unit: f32,
    /// Which entries of the baked table are not transparent, with the generation it was baked
    /// for (the bricks' residency decides from it).
    opacity: Option<(u64, Arc<OpacityIndex>)>,
}

impl TransferTables {
    /// The tables, holding the grey ramp until a function is set (baked on first use).
    pub fn new(ctx: &GpuContext) -> Self {
        Self {
            function: TransferFunction::grey_ramp(),
            generation: 0,
            lut: TableTexture::lut(ctx, lut::LUT_SIZE as u32),
            integrals: TableTexture::integrals(ctx, lut::LUT_SIZE as u32),
            lut_baked_for: None,
            integrals_built_for: None,
            depth_unit: 1.0,
            opacity: None,
        }
    }

    /// Sets the function; returns whether it changed (and the generation with it).
    pub fn set(&mut self, function: &TransferFunction) -> bool {
        if *function == self.function {
            return false;
        }
        self.function = function.clone();
        self.generation += 1;
        true
    }

    /// The current function.
    pub fn function(&self) -> &TransferFunction {
        &self.function
    }

    /// The function's generation: changes exactly when the function does.
    pub(crate) fn generation(&self) -> u64 {
        self.generation
    }

    /// Which entries of the baked lookup table are not transparent, and the generation it
    /// was baked for (`None` before the first bake).
    pub(crate) fn opacity(&self) -> Option<&(u64, Arc<OpacityIndex>)> {
        self.opacity.as_ref()
    }

    /// Marks both tables stale (a new volume brings a new value range).
    pub(crate) fn invalidate(&mut self) {
        self.opacity = None;
        self.lut_baked_for = None;
        self.integrals_built_for = None;
    }

    /// Re-bakes the lookup table when the function or the step changed since it was baked for
    /// `range`; returns whether it did.
    pub(crate) fn refresh_lut(
        &mut self,
        ctx: &GpuContext,
        range: ValueRange,
        step_vox: f64,
    ) -> bool {
        let wanted = (self.generation, step_vox.to_bits());
        if self.lut_baked_for == Some(wanted) {
            return false;
        }
        let mut table = lut::bake(&self.function, range, step_vox);
        // The step changes opacities, never which are zero.
        if self
            .opacity
            .as_ref()
            .is_none_or(|(g, _)| *g != self.generation)
        {
            let index = OpacityIndex::from_lut(&table);
            self.opacity = Some((self.generation, Arc::new(index)));
        }
        let scale = lut::f16_depth_scale(&table);
        table.iter_mut().for_each(|e| e[3] *= scale);
        self.lut.write(&ctx.queue, &table);
        self.depth_unit = 1.0 / scale;
        self.lut_baked_for = Some(wanted);
        true
    }

    /// Rebuilds the pre-integration table when the function changed since it was built for
    /// `range` (it does not depend on the step); returns whether it did.
    pub(crate) fn refresh_integrals(&mut self, ctx: &GpuContext, range: ValueRange) -> bool {
        if self.integrals_built_for == Some(self.generation) {
            return false;
        }
        let rows = preintegration::integral_table(&self.function, range);
        self.integrals.write(&ctx.queue, &rows);
        self.integrals_built_for = Some(self.generation);
        true
    }

    /// The lookup table.
    pub fn lut(&self) -> &TableTexture {
        &self.lut
    }

    /// What the lookup table's stored depths are multiplied by to give optical depths.
    pub(crate) fn depth_unit(&self) -> f32 {
        self.depth_unit
    }

    /// The pre-integration table.
    pub fn integrals(&self) -> &TableTexture {
        &self.integrals
    }
}
