//! PNG plots drawn with plotters: frame time per strategy per dataset (bars), the block-size
//! curve, and frame time against samples per pixel (scatter). Text uses a font compiled into the
//! binary (the GPU machine has no system fonts).

use std::path::{Path, PathBuf};

use leapview::bench::stats::{TABLE1_STRATEGIES, table2};
use leapview::bench::{BenchResults, Summary};
use plotters::prelude::*;

use crate::cli::plotting::{FONT, err, legend, register};

/// Plot width in pixels.
const WIDTH: u32 = 1600;
/// Height of one panel in pixels.
const PANEL: u32 = 520;

fn colour(strategy: &str) -> RGBColor {
    match strategy {
        "RC" => RGBColor(0x8c, 0x8c, 0x8c),
        "RC-t" => RGBColor(0x1f, 0x77, 0xb4),
        "RC-s" => RGBColor(0xd6, 0x27, 0x28),
        _ => RGBColor(0x2c, 0xa0, 0x2c),
    }
}

/// The mode the bar chart and scatter show: DVR (the paper's) when present.
fn main_mode(summary: &Summary) -> Option<String> {
    let modes: Vec<&str> = summary.table1.iter().map(|r| r.mode.as_str()).collect();
    modes
        .iter()
        .find(|m| **m == "dvr")
        .or(modes.first())
        .map(|m| m.to_string())
}

/// Draws every plot into `out` and returns the files written.
pub fn draw_all(
    out: &Path,
    summary: &Summary,
    results: &BenchResults,
) -> anyhow::Result<Vec<PathBuf>> {
    register();
    let mut files = Vec::new();
    if let Some(mode) = main_mode(summary) {
        let path = out.join("frame_time.png");
        frame_time(&path, summary, &mode)?;
        files.push(path);
        let path = out.join("time_vs_samples.png");
        time_vs_samples(&path, results, &mode)?;
        files.push(path);
    }
    if !table2(&summary.runs).is_empty() {
        let path = out.join("block_size.png");
        block_size(&path, summary)?;
        files.push(path);
    }
    Ok(files)
}

/// Bars of median frame time, one group per dataset, one bar per strategy; a panel per path and
/// image size.
fn frame_time(path: &Path, summary: &Summary, mode: &str) -> anyhow::Result<()> {
    let rows: Vec<_> = summary.table1.iter().filter(|r| r.mode == mode).collect();
    let mut panels: Vec<(&str, [u32; 2])> = Vec::new();
    for r in &rows {
        if !panels.contains(&(r.path.as_str(), r.size)) {
            panels.push((r.path.as_str(), r.size));
        }
    }
    let root = BitMapBackend::new(path, (WIDTH, PANEL * panels.len() as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    for (area, (p, size)) in root.split_evenly((panels.len(), 1)).iter().zip(&panels) {
        let group: Vec<_> = rows
            .iter()
            .filter(|r| r.path == *p && r.size == *size)
            .collect();
        let ms = |fps: Option<f64>| fps.map(|f| 1000.0 / f);
        let top = group
            .iter()
            .flat_map(|r| r.fps.iter().filter_map(|f| ms(*f)))
            .fold(0.0, f64::max)
            * 1.15;
        let names: Vec<String> = group.iter().map(|r| r.dataset.clone()).collect();
        let mut chart = ChartBuilder::on(area)
            .caption(
                format!(
                    "{mode}: median frame time, {p} path, {}×{}",
                    size[0], size[1]
                ),
                (FONT, 24),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..names.len() as f64, 0.0..top.max(1e-3))
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(names.len() * 2 + 1)
            .x_label_formatter(&|x| {
                let i = x.floor() as usize;
                let centred = (x - x.floor() - 0.5).abs() < 1e-6;
                names
                    .get(i)
                    .filter(|_| centred)
                    .cloned()
                    .unwrap_or_default()
            })
            .y_desc("ms per frame")
            .label_style((FONT, 15))
            .draw()
            .map_err(err)?;
        let bar = 0.8 / TABLE1_STRATEGIES.len() as f64;
        for (s, name) in TABLE1_STRATEGIES.iter().enumerate() {
            let bars = group.iter().enumerate().filter_map(|(i, r)| {
                let x0 = i as f64 + 0.1 + s as f64 * bar;
                ms(r.fps[s])
                    .map(|v| Rectangle::new([(x0, 0.0), (x0 + bar, v)], colour(name).filled()))
            });
            chart
                .draw_series(bars)
                .map_err(err)?
                .label(*name)
                .legend(move |(x, y)| {
                    Rectangle::new([(x, y - 6), (x + 14, y + 6)], colour(name).filled())
                });
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    }
    root.present().map_err(err)
}

/// Median frame time against block edge (log scale), one line per swept dataset, strategy and
/// path.
fn block_size(path: &Path, summary: &Summary) -> anyhow::Result<()> {
    let groups = table2(&summary.runs);
    let top = groups
        .iter()
        .flatten()
        .map(|s| s.median_ms)
        .fold(0.0, f64::max)
        * 1.15;
    let root = BitMapBackend::new(path, (WIDTH, 2 * PANEL)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let mut chart = ChartBuilder::on(&root)
        .caption("Block-size sweep: median frame time", (FONT, 26))
        .margin(16)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(1.8f64..7.2, 0.0..top.max(1e-3))
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_labels(6)
        .x_label_formatter(&|x| format!("{}³", 2f64.powf(*x).round()))
        .x_desc("block edge (voxels)")
        .y_desc("ms per frame")
        .label_style((FONT, 16))
        .draw()
        .map_err(err)?;
    for (i, g) in groups.iter().enumerate() {
        let k = &g[0].key;
        let style = Palette99::pick(i).stroke_width(3);
        let points: Vec<(f64, f64)> = g
            .iter()
            .map(|s| ((s.key.block_vox as f64).log2(), s.median_ms))
            .collect();
        chart
            .draw_series(LineSeries::new(points.clone(), style))
            .map_err(err)?
            .label(format!(
                "{} {} {} {}",
                k.dataset, k.mode, k.strategy, k.path
            ))
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], style));
        chart
            .draw_series(points.iter().map(|p| Circle::new(*p, 5, style.filled())))
            .map_err(err)?;
    }
    legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
    root.present().map_err(err)
}

/// Every frame's time against its samples per pixel, coloured by strategy; a panel per path.
fn time_vs_samples(path: &Path, results: &BenchResults, mode: &str) -> anyhow::Result<()> {
    let runs: Vec<_> = results
        .runs
        .iter()
        .filter(|r| !r.key.sweep && r.key.mode == mode)
        .collect();
    let mut paths: Vec<&str> = runs.iter().map(|r| r.key.path.as_str()).collect();
    paths.dedup();
    paths.sort_unstable();
    paths.dedup();
    let root =
        BitMapBackend::new(path, (WIDTH, PANEL * paths.len().max(1) as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    for (area, p) in root
        .split_evenly((paths.len().max(1), 1))
        .iter()
        .zip(&paths)
    {
        let points: Vec<(f64, f64, &str)> = runs
            .iter()
            .filter(|r| r.key.path == *p)
            .flat_map(|r| {
                let pixels = r.key.width as f64 * r.key.height as f64;
                r.frames
                    .iter()
                    .map(move |f| (f.samples as f64 / pixels, f.ms, r.key.strategy.as_str()))
            })
            .collect();
        let x_top = points.iter().map(|p| p.0).fold(0.0, f64::max) * 1.05;
        let y_top = points.iter().map(|p| p.1).fold(0.0, f64::max) * 1.05;
        let mut chart = ChartBuilder::on(area)
            .caption(format!("{mode}, {p} path: frame time against samples per pixel (every frame, all sizes)"), (FONT, 22))
            .margin(12)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..x_top.max(1e-3), 0.0..y_top.max(1e-3))
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("samples per pixel")
            .y_desc("ms per frame")
            .label_style((FONT, 15))
            .draw()
            .map_err(err)?;
        for name in TABLE1_STRATEGIES {
            let mine = points.iter().filter(|q| q.2 == name);
            chart
                .draw_series(mine.map(|q| Circle::new((q.0, q.1), 4, colour(name).filled())))
                .map_err(err)?
                .label(name)
                .legend(move |(x, y)| Circle::new((x + 7, y), 5, colour(name).filled()));
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
    }
    root.present().map_err(err)
}
