//! The editing model behind the transfer-function editor: adding, moving and deleting opacity
//! points and colour stops, loading presets, with undo and redo. No UI here; the egui panel
//! (issue 5) drives it, and the tests exercise it directly.
//!
//! Points stay sorted by value. Moving a point past a neighbour re-sorts and follows the point
//! (its new index is returned). Consecutive moves of the same point are one undo step (a drag),
//! until [`TfEditor::end_gesture`]. Every curve keeps at least one point.

use super::presets::preset;
use super::{TransferError, TransferFunction};

/// Which curve a point belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Curve {
    /// `(value, alpha)` points.
    Opacity,
    /// `(value, r, g, b)` stops.
    Color,
}

/// Why an edit was refused.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EditError {
    /// No point at that index.
    #[error("the {curve:?} curve has no point {index}")]
    NoPoint {
        /// The curve.
        curve: Curve,
        /// The index asked for.
        index: usize,
    },
    /// Deleting the last point of a curve.
    #[error("the {0:?} curve needs at least one point")]
    LastPoint(Curve),
    /// A value that is NaN or infinite.
    #[error("point values must be finite, got {0}")]
    NotFinite(f64),
}

/// Most undo steps kept.
pub const UNDO_LIMIT: usize = 200;

/// A transfer function being edited, with its history.
#[derive(Clone, Debug, PartialEq)]
pub struct TfEditor {
    tf: TransferFunction,
    undo: Vec<TransferFunction>,
    redo: Vec<TransferFunction>,
    /// The point the current drag moves, so its moves make one undo step.
    dragging: Option<(Curve, usize)>,
    /// Whether a whole-curve gesture (window/level drag) is under way: one undo step.
    remapping: bool,
}

impl Default for TfEditor {
    /// The grey ramp, no history.
    fn default() -> Self {
        Self::new(TransferFunction::grey_ramp())
    }
}

impl TfEditor {
    /// Starts editing `tf` with an empty history.
    pub fn new(tf: TransferFunction) -> Self {
        Self {
            tf,
            undo: Vec::new(),
            redo: Vec::new(),
            dragging: None,
            remapping: false,
        }
    }

    /// The transfer function as edited.
    pub fn tf(&self) -> &TransferFunction {
        &self.tf
    }

    /// Whether [`Self::undo`] would change anything.
    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    /// Whether [`Self::redo`] would change anything.
    pub(crate) fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    fn record(&mut self) {
        self.undo.push(self.tf.clone());
        if self.undo.len() > UNDO_LIMIT {
            self.undo.remove(0);
        }
        self.redo.clear();
    }

    /// Ends a drag: the next move starts a new undo step.
    pub(crate) fn end_gesture(&mut self) {
        self.dragging = None;
        self.remapping = false;
    }

    /// Moves every point of both curves to `f(value)` (a window/level drag: shift and scale);
    /// `f` must be increasing, so the order is kept. Calls until [`Self::end_gesture`] are one
    /// undo step. A non-finite result leaves the function unchanged.
    pub(crate) fn remap(&mut self, f: impl Fn(f64) -> f64) {
        let mut tf = self.tf.clone();
        tf.opacity.iter_mut().for_each(|p| p[0] = f(p[0]));
        tf.color.iter_mut().for_each(|p| p[0] = f(p[0]));
        let finite = tf.opacity.iter().all(|p| p[0].is_finite())
            && tf.color.iter().all(|p| p[0].is_finite());
        if !finite || tf == self.tf {
            return;
        }
        if !self.remapping {
            self.dragging = None;
            self.record();
            self.remapping = true;
        }
        // A rounding tie could swap equal neighbours; keep the curves sorted whatever `f` did.
        tf.opacity.sort_by(|a, b| a[0].total_cmp(&b[0]));
        tf.color.sort_by(|a, b| a[0].total_cmp(&b[0]));
        self.tf = tf;
    }

    /// Replaces the whole function (a preset, a loaded file) as one undo step.
    pub fn set(&mut self, tf: TransferFunction) {
        if tf != self.tf {
            self.end_gesture();
            self.record();
            self.tf = tf;
        }
    }

    /// Loads a named preset as one undo step.
    pub(crate) fn load_preset(&mut self, name: &str) -> Result<(), TransferError> {
        self.set(preset(name)?);
        Ok(())
    }

    /// Adds an opacity point (alpha clamped to 0..1); returns its index.
    pub(crate) fn add_opacity(&mut self, value: f64, alpha: f64) -> Result<usize, EditError> {
        finite(value)?;
        self.end_gesture();
        self.record();
        let i = self.tf.opacity.partition_point(|p| p[0] <= value);
        self.tf.opacity.insert(i, [value, clamp01(alpha)]);
        Ok(i)
    }

    /// Adds a colour stop (components clamped to 0..1); returns its index.
    pub(crate) fn add_color(&mut self, value: f64, rgb: [f64; 3]) -> Result<usize, EditError> {
        finite(value)?;
        self.end_gesture();
        self.record();
        let i = self.tf.color.partition_point(|p| p[0] <= value);
        let [r, g, b] = rgb.map(clamp01);
        self.tf.color.insert(i, [value, r, g, b]);
        Ok(i)
    }

    /// Moves opacity point `index` to `(value, alpha)`; returns its index after re-sorting.
    pub(crate) fn move_opacity(
        &mut self,
        index: usize,
        value: f64,
        alpha: f64,
    ) -> Result<usize, EditError> {
        finite(value)?;
        self.check(Curve::Opacity, index)?;
        self.begin_move(Curve::Opacity, index);
        self.tf.opacity.remove(index);
        let i = insert_sorted(&mut self.tf.opacity, [value, clamp01(alpha)]);
        self.dragging = Some((Curve::Opacity, i));
        Ok(i)
    }

    /// Moves colour stop `index` to `value`, keeping its colour; returns its new index.
    pub(crate) fn move_color(&mut self, index: usize, value: f64) -> Result<usize, EditError> {
        finite(value)?;
        self.check(Curve::Color, index)?;
        self.begin_move(Curve::Color, index);
        let mut p = self.tf.color.remove(index);
        p[0] = value;
        let i = insert_sorted(&mut self.tf.color, p);
        self.dragging = Some((Curve::Color, i));
        Ok(i)
    }

    /// Sets the colour of stop `index` (one undo step per call; the colour picker calls it
    /// once its dialog closes).
    pub(crate) fn set_color(&mut self, index: usize, rgb: [f64; 3]) -> Result<(), EditError> {
        self.check(Curve::Color, index)?;
        self.end_gesture();
        self.record();
        let [r, g, b] = rgb.map(clamp01);
        self.tf.color[index] = [self.tf.color[index][0], r, g, b];
        Ok(())
    }

    /// Deletes point `index` of `curve`; the last point of a curve stays.
    pub fn remove(&mut self, curve: Curve, index: usize) -> Result<(), EditError> {
        self.check(curve, index)?;
        let len = match curve {
            Curve::Opacity => self.tf.opacity.len(),
            Curve::Color => self.tf.color.len(),
        };
        if len <= 1 {
            return Err(EditError::LastPoint(curve));
        }
        self.end_gesture();
        self.record();
        match curve {
            Curve::Opacity => {
                self.tf.opacity.remove(index);
            }
            Curve::Color => {
                self.tf.color.remove(index);
            }
        }
        Ok(())
    }

    /// Undoes the last edit; false when there is none.
    pub fn undo(&mut self) -> bool {
        self.end_gesture();
        match self.undo.pop() {
            Some(previous) => {
                self.redo.push(std::mem::replace(&mut self.tf, previous));
                true
            }
            None => false,
        }
    }

    /// Redoes the last undone edit; false when there is none.
    pub fn redo(&mut self) -> bool {
        self.end_gesture();
        match self.redo.pop() {
            Some(next) => {
                self.undo.push(std::mem::replace(&mut self.tf, next));
                true
            }
            None => false,
        }
    }

    fn check(&self, curve: Curve, index: usize) -> Result<(), EditError> {
        let len = match curve {
            Curve::Opacity => self.tf.opacity.len(),
            Curve::Color => self.tf.color.len(),
        };
        if index < len {
            Ok(())
        } else {
            Err(EditError::NoPoint { curve, index })
        }
    }

    /// Records an undo step unless this move continues the current drag of the same point.
    fn begin_move(&mut self, curve: Curve, index: usize) {
        if self.dragging != Some((curve, index)) {
            self.record();
        }
    }
}

fn finite(value: f64) -> Result<(), EditError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(EditError::NotFinite(value))
    }
}

fn clamp01(x: f64) -> f64 {
    if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) }
}

/// Inserts `p` after every point with a value ≤ its own; returns its index.
fn insert_sorted<const N: usize>(points: &mut Vec<[f64; N]>, p: [f64; N]) -> usize {
    let i = points.partition_point(|q| q[0] <= p[0]);
    points.insert(i, p);
    i
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::ValueSpace;

    fn ramp() -> TransferFunction {
        TransferFunction {
            opacity: vec![[0.0, 0.0], [100.0, 0.5], [200.0, 1.0]],
            color: vec![[0.0, 1.0, 0.0, 0.0], [200.0, 0.0, 0.0, 1.0]],
            space: ValueSpace::Data,
        }
    }

    fn sorted(tf: &TransferFunction) -> bool {
        tf.opacity.windows(2).all(|w| w[0][0] <= w[1][0])
            && tf.color.windows(2).all(|w| w[0][0] <= w[1][0])
    }

    #[test]
    fn adding_keeps_points_sorted_and_clamps_alpha() {
        let mut e = TfEditor::new(ramp());
        assert_eq!(e.add_opacity(150.0, 2.0), Ok(2));
        assert_eq!(e.tf().opacity[2], [150.0, 1.0]);
        assert_eq!(e.add_opacity(-50.0, -1.0), Ok(0));
        assert_eq!(e.tf().opacity[0], [-50.0, 0.0]);
        assert_eq!(e.add_color(100.0, [0.5, 2.0, -1.0]), Ok(1));
        assert_eq!(e.tf().color[1], [100.0, 0.5, 1.0, 0.0]);
        assert!(sorted(e.tf()));
        assert!(matches!(
            e.add_opacity(f64::NAN, 0.5),
            Err(EditError::NotFinite(_))
        ));
        assert!(e.add_opacity(f64::INFINITY, 0.5).is_err());
    }

    #[test]
    fn moving_past_a_neighbour_resorts_and_follows_the_point() {
        let mut e = TfEditor::new(ramp());
        let i = e.move_opacity(0, 150.0, 0.2).expect("move");
        assert_eq!(i, 1);
        assert_eq!(
            e.tf().opacity,
            vec![[100.0, 0.5], [150.0, 0.2], [200.0, 1.0]]
        );
        let i = e.move_opacity(i, 250.0, 0.3).expect("move");
        assert_eq!(i, 2);
        assert!(sorted(e.tf()));
        let c = e.move_color(1, -10.0).expect("move");
        assert_eq!(c, 0);
        assert_eq!(e.tf().color[0], [-10.0, 0.0, 0.0, 1.0]);
        assert!(e.move_opacity(7, 0.0, 0.0).is_err());
    }

    #[test]
    fn a_drag_is_one_undo_step_and_redo_restores_it() {
        let original = ramp();
        let mut e = TfEditor::new(original.clone());
        let mut i = 1;
        for v in [110.0, 130.0, 170.0, 210.0] {
            i = e.move_opacity(i, v, 0.6).expect("move");
        }
        e.end_gesture();
        let dragged = e.tf().clone();
        assert!(e.undo());
        assert_eq!(*e.tf(), original, "one undo reverts the whole drag");
        assert!(!e.undo());
        assert!(e.redo());
        assert_eq!(*e.tf(), dragged);
        assert!(!e.redo());
    }

    #[test]
    fn deleting_keeps_one_point_and_a_new_edit_clears_redo() {
        let mut e = TfEditor::new(ramp());
        e.remove(Curve::Opacity, 0).expect("remove");
        e.remove(Curve::Opacity, 0).expect("remove");
        assert_eq!(
            e.remove(Curve::Opacity, 0),
            Err(EditError::LastPoint(Curve::Opacity))
        );
        assert_eq!(e.tf().opacity, vec![[200.0, 1.0]]);
        assert!(e.undo());
        assert!(e.can_redo());
        e.set_color(0, [0.2, 0.3, 0.4]).expect("colour");
        assert!(!e.can_redo(), "a new edit drops the redo branch");
        assert_eq!(e.tf().color[0], [0.0, 0.2, 0.3, 0.4]);
    }

    #[test]
    fn presets_load_as_one_step_and_survive_a_json_round_trip() {
        let mut e = TfEditor::new(ramp());
        for name in crate::transfer::presets::NAMES {
            e.load_preset(name).expect("preset");
            let json = e.tf().to_json_string();
            let back = TransferFunction::from_json_str(&json).expect("parse");
            assert_eq!(&back, e.tf(), "{name}");
        }
        assert!(e.load_preset("no-such-preset").is_err());
        let steps = crate::transfer::presets::NAMES.len();
        for _ in 0..steps {
            assert!(e.undo());
        }
        assert_eq!(*e.tf(), ramp());
    }

    #[test]
    fn a_window_drag_shifts_and_scales_both_curves_as_one_step() {
        let mut e = TfEditor::new(ramp());
        for k in 1..=5 {
            let shift = 10.0 * f64::from(k);
            e.remap(|x| 100.0 + shift + (x - 100.0) * 0.5);
            // Each call remaps the current function: the last one wins within a gesture.
        }
        e.end_gesture();
        assert!(sorted(e.tf()));
        assert!(e.undo());
        assert_eq!(*e.tf(), ramp(), "the whole drag is one undo step");
        assert!(!e.can_undo());
        e.remap(|x| x + 50.0);
        assert_eq!(e.tf().opacity[0][0], 50.0);
        assert_eq!(e.tf().color[1][0], 250.0);
        e.remap(|_| f64::NAN);
        assert_eq!(
            e.tf().opacity[0][0],
            50.0,
            "a non-finite result changes nothing"
        );
    }

    #[test]
    fn history_is_bounded() {
        let mut e = TfEditor::new(ramp());
        for k in 0..(UNDO_LIMIT + 50) {
            e.add_opacity(300.0 + k as f64, 0.1).expect("add");
        }
        let mut undone = 0;
        while e.undo() {
            undone += 1;
        }
        assert_eq!(undone, UNDO_LIMIT);
    }
}
