//! What every plot of the command line shares: the font compiled into the binary (the GPU
//! machine has no system fonts), one legend style, and plotting errors as `anyhow` errors.

use std::sync::Once;

use anyhow::anyhow;
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};

/// The family name the embedded font is registered under.
pub const FONT: &str = "sans-serif";
/// Registers the embedded font under [`FONT`] (once per process).
pub fn register() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        if register_font(FONT, FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT).is_err() {
            log::warn!("the embedded plot font did not load; plots will have no text");
        }
    });
}

/// Draws the series legend of `chart` at `position` (one style for every plot).
pub fn legend<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> anyhow::Result<()>
where
    DB: DrawingBackend + 'a,
    CT: plotters::coord::CoordTranslate,
{
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font((FONT, 16))
        .position(position)
        .draw()
        .map_err(err)
}

/// A plotting library error as an `anyhow` error.
pub fn err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("drawing a plot: {e}")
}
