//! What the accuracy benchmark records per setting (GPU time and error against the reference),
//! how errors over several views combine, the Pareto front, and the tables it writes.

use serde::{Deserialize, Serialize};

use crate::imaging::ImageDiff;

use super::plan::{Knob, KnobGroup};

/// One setting measured on one dataset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Measurement {
    /// Dataset name.
    pub dataset: String,
    /// The knob swept.
    pub knob: Knob,
    /// The knob's value.
    pub value: String,
    /// Median frame time over every view and repetition, milliseconds.
    pub ms: f64,
    /// Error against the reference over all views.
    pub error: ErrorStats,
}

/// Error of a setting's images against the reference images, over all views.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ErrorStats {
    /// Root mean square error over every RGB channel of every view.
    pub rmse: f64,
    /// Largest absolute channel error of any view.
    pub max_abs: f64,
    /// PSNR of `rmse` in dB (peak 1); infinite for identical images.
    pub psnr_db: f64,
    /// Share of pixels (all views) with a channel off by more than 1/255.
    pub share_over_1_255: f64,
}

impl ErrorStats {
    /// Combines per-view differences of equally sized images.
    pub fn combine(views: &[ImageDiff]) -> Self {
        if views.is_empty() {
            return Self::default();
        }
        let n = views.len() as f64;
        let mse = views.iter().map(|d| d.rmse * d.rmse).sum::<f64>() / n;
        let rmse = mse.sqrt();
        Self {
            rmse,
            max_abs: views.iter().map(|d| d.max_abs).fold(0.0, f64::max),
            psnr_db: if rmse > 0.0 {
                -20.0 * rmse.log10()
            } else {
                f64::INFINITY
            },
            share_over_1_255: views.iter().map(|d| d.share_over_1_255).sum::<f64>() / n,
        }
    }
}

/// Indices of the points on the Pareto front of `(time, error)` pairs (nothing else is both
/// faster and more accurate), sorted by time.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| {
        points[a]
            .0
            .total_cmp(&points[b].0)
            .then(points[a].1.total_cmp(&points[b].1))
    });
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for i in order {
        if points[i].1 < best {
            best = points[i].1;
            front.push(i);
        }
    }
    front
}

/// The Markdown table of one dataset's measurements, Pareto-optimal rows (within their mode)
/// marked.
pub fn markdown_table(rows: &[&Measurement]) -> String {
    let mut out = String::from(
        "| knob | value | GPU ms | RMSE | max abs | PSNR dB | > 1/255 | Pareto |\n\
         |---|---|---:|---:|---:|---:|---:|:-:|\n",
    );
    let front = front_of(rows);
    for (i, m) in rows.iter().enumerate() {
        let e = &m.error;
        out.push_str(&format!(
            "| {} | {} | {:.3} | {:.5} | {:.4} | {} | {:.2} % | {} |\n",
            m.knob.label(),
            m.value,
            m.ms,
            e.rmse,
            e.max_abs,
            if e.psnr_db.is_finite() {
                format!("{:.1}", e.psnr_db)
            } else {
                "∞".to_string()
            },
            100.0 * e.share_over_1_255,
            if front.contains(&i) { "●" } else { "" }
        ));
    }
    out
}

/// Pareto-optimal rows within each group of knobs sharing a reference (DVR, isosurface,
/// shadowed DVR).
fn front_of(rows: &[&Measurement]) -> Vec<usize> {
    let mut front = Vec::new();
    for group in KnobGroup::ALL {
        let idx: Vec<usize> = (0..rows.len())
            .filter(|&i| rows[i].knob.group() == group)
            .collect();
        let points: Vec<(f64, f64)> = idx
            .iter()
            .map(|&i| (rows[i].ms, rows[i].error.rmse))
            .collect();
        front.extend(pareto_front(&points).into_iter().map(|j| idx[j]));
    }
    front
}

/// CSV of all measurements (one line each).
pub fn csv(rows: &[Measurement]) -> String {
    let mut out = String::from("dataset,knob,value,gpu_ms,rmse,max_abs,psnr_db,share_over_1_255\n");
    for m in rows {
        let e = &m.error;
        out.push_str(&format!(
            "{},{},{},{:.5},{:.6},{:.5},{:.3},{:.5}\n",
            m.dataset,
            m.knob.label().replace(',', ";"),
            m.value,
            m.ms,
            e.rmse,
            e.max_abs,
            e.psnr_db,
            e.share_over_1_255
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_front_keeps_only_points_nothing_beats_on_both() {
        let points = [
            (1.0, 0.5),
            (2.0, 0.2),
            (1.5, 0.6),
            (3.0, 0.2),
            (0.5, 0.9),
            (4.0, 0.1),
        ];
        let front = pareto_front(&points);
        assert_eq!(front, vec![4, 0, 1, 5]);
        // Brute force: a point is on the front iff no other point is at least as good on both
        // and better on one.
        for (i, p) in points.iter().enumerate() {
            let dominated = points
                .iter()
                .enumerate()
                .any(|(j, q)| j != i && q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1));
            assert_eq!(front.contains(&i), !dominated, "point {i}");
        }
    }

    #[test]
    fn combined_errors_weigh_views_equally() {
        let d = |rmse: f64, max_abs: f64, share: f64| ImageDiff {
            max_abs,
            rmse,
            share_over_1_255: share,
            psnr_db: 0.0,
        };
        let e = ErrorStats::combine(&[d(0.3, 0.5, 0.1), d(0.4, 0.9, 0.3)]);
        assert!((e.rmse - (0.125f64).sqrt()).abs() < 1e-12);
        assert_eq!(e.max_abs, 0.9);
        assert!((e.share_over_1_255 - 0.2).abs() < 1e-12);
        assert!((e.psnr_db - -20.0 * (0.125f64).sqrt().log10()).abs() < 1e-9);
        assert_eq!(
            ErrorStats::combine(&[d(0.0, 0.0, 0.0)]).psnr_db,
            f64::INFINITY
        );
    }
}
