//! The accuracy benchmark (`leapview accuracy`): what each quality knob costs in GPU time and
//! buys in error against a reference image, and the Pareto front the quality presets come from.

pub mod plan;
pub mod results;

pub use plan::{Knob, KnobGroup, Variant, plan, reference};
pub use results::{ErrorStats, Measurement, pareto_front};
