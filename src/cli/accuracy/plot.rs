//! The error-against-time plot of one dataset: RMSE (log) against GPU milliseconds for every
//! knob, the step series as lines, the Pareto front dashed; the shadowed DVR knobs and the
//! isosurface refinement in panels of their own (each has its own reference image).

use std::path::Path;

use leapview::accuracy::results::pareto_front;
use leapview::accuracy::{Knob, KnobGroup, Measurement};
use plotters::prelude::*;

use crate::cli::plotting::{FONT, err, legend, register};

fn colour(knob: Knob) -> RGBColor {
    match knob {
        Knob::Step => RGBColor(0x1f, 0x77, 0xb4),
        Knob::StepPreintegrated => RGBColor(0xd6, 0x27, 0x28),
        Knob::StepJittered => RGBColor(0x2c, 0xa0, 0x2c),
        Knob::StepUncorrected => RGBColor(0x8c, 0x8c, 0x8c),
        Knob::Termination => RGBColor(0x94, 0x67, 0xbd),
        Knob::Gradient => RGBColor(0xff, 0x7f, 0x0e),
        Knob::LightMinWeight => RGBColor(0xe3, 0x77, 0xc2),
        Knob::IsoRefinement => RGBColor(0x17, 0xbe, 0xcf),
        Knob::Precision => RGBColor(0x8c, 0x56, 0x4b),
        Knob::Preset => RGBColor(0x00, 0x00, 0x00),
        Knob::ShadowStep => RGBColor(0xbc, 0xbd, 0x22),
        Knob::ShadowLightMinWeight => RGBColor(0x7f, 0x7f, 0x7f),
    }
}

/// Smallest RMSE shown (the log axis cannot show 0).
const FLOOR: f64 = 1e-5;

/// Draws `rows` (one dataset) into `path`.
pub fn draw(path: &Path, dataset: &str, rows: &[&Measurement]) -> anyhow::Result<()> {
    register();
    let root = BitMapBackend::new(path, (2200, 640)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let (left, rest) = root.split_horizontally(1100);
    let (middle, right) = rest.split_horizontally(550);
    let of = |group: KnobGroup| -> Vec<&Measurement> {
        rows.iter()
            .copied()
            .filter(|m| m.knob.group() == group)
            .collect()
    };
    panel(
        &left,
        &format!("{dataset}: DVR, error against time"),
        &of(KnobGroup::Dvr),
    )?;
    panel(
        &middle,
        &format!("{dataset}: DVR with shadows"),
        &of(KnobGroup::Shadows),
    )?;
    panel(
        &right,
        &format!("{dataset}: isosurface refinement"),
        &of(KnobGroup::Iso),
    )?;
    root.present().map_err(err)
}

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    caption: &str,
    rows: &[&Measurement],
) -> anyhow::Result<()> {
    let y = |m: &Measurement| m.error.rmse.max(FLOOR);
    let (x_lo, x_hi) = rows.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), m| {
        (lo.min(m.ms), hi.max(m.ms))
    });
    let (y_lo, y_hi) = rows.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), m| {
        (lo.min(y(m)), hi.max(y(m)))
    });
    if rows.is_empty() {
        return Ok(());
    }
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FONT, 22))
        .margin(12)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(
            (x_lo * 0.8..x_hi * 1.25).log_scale(),
            (y_lo * 0.6..y_hi * 1.6).log_scale(),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("GPU ms per frame (median)")
        .y_desc("RMSE against the reference")
        .x_label_formatter(&|v| short(*v))
        .y_label_formatter(&|v| short(*v))
        .label_style((FONT, 15))
        .draw()
        .map_err(err)?;
    // The Pareto front first, under the points.
    let points: Vec<(f64, f64)> = rows.iter().map(|m| (m.ms, y(m))).collect();
    let front: Vec<(f64, f64)> = pareto_front(&points)
        .into_iter()
        .map(|i| points[i])
        .collect();
    chart
        .draw_series(DashedLineSeries::new(front, 6, 4, BLACK.stroke_width(1)))
        .map_err(err)?
        .label("Pareto front")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLACK));
    for knob in Knob::ALL {
        let mine: Vec<&Measurement> = rows.iter().copied().filter(|m| m.knob == knob).collect();
        if mine.is_empty() {
            continue;
        }
        let c = colour(knob);
        let line = matches!(
            knob,
            Knob::Step
                | Knob::StepPreintegrated
                | Knob::StepJittered
                | Knob::StepUncorrected
                | Knob::IsoRefinement
                | Knob::ShadowStep
        );
        if line {
            chart
                .draw_series(LineSeries::new(
                    mine.iter().map(|m| (m.ms, y(m))),
                    c.stroke_width(2),
                ))
                .map_err(err)?;
        }
        chart
            .draw_series(
                mine.iter()
                    .map(|m| Circle::new((m.ms, y(m)), 5, c.filled())),
            )
            .map_err(err)?
            .label(knob.label())
            .legend(move |(x, y)| Circle::new((x + 8, y), 5, c.filled()));
        // Values next to the points of the plain step series, the iso series and the others.
        if knob != Knob::StepJittered && knob != Knob::StepUncorrected {
            chart
                .draw_series(
                    mine.iter()
                        .map(|m| Text::new(m.value.clone(), (m.ms, y(m)), (FONT, 13).into_font())),
                )
                .map_err(err)?;
        }
    }
    legend(&mut chart, SeriesLabelPosition::UpperRight)
}

/// A tick label with two significant digits.
fn short(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (1 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}
