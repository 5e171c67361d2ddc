//! Which value intervals the current transfer function makes fully transparent: the paper's 2D
//! emptiness table indexed by (block max, block min), built from the baked lookup table that the
//! shader actually samples.
//!
//! Conservative under quantisation: the shader reads the table at normalised value `s` by linear
//! filtering between entries `floor(s·(N−1))` and the next, so an interval is empty only if every
//! entry from one below its lowest reachable entry to one above its highest has zero opacity
//! (the extra entry on each side also absorbs the texture unit's rounding). Table cells cover
//! value bins of width 1/M; a cell is empty only if the whole span from its min bin's start to
//! its max bin's end is, so any node whose range falls in those bins is covered.

use super::pyramid::MinMax;

/// Bins per axis of the emptiness table.
pub const TABLE_SIZE: usize = 256;

/// Prefix counts of lookup-table entries with non-zero opacity.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OpacityIndex {
    /// `prefix[i]` = number of entries in `[0, i)` with non-zero alpha.
    prefix: Vec<u32>,
}

impl OpacityIndex {
    /// From a baked table (RGBA, alpha last).
    pub fn from_lut(lut: &[[f32; 4]]) -> Self {
        let mut prefix = Vec::with_capacity(lut.len() + 1);
        let mut count = 0u32;
        prefix.push(0);
        for e in lut {
            count += u32::from(e[3] > 0.0);
            prefix.push(count);
        }
        Self { prefix }
    }

    fn entries(&self) -> usize {
        self.prefix.len() - 1
    }

    /// Whether every sample whose normalised value lies in `[lo, hi]` is fully transparent.
    pub fn is_empty(&self, lo: f32, hi: f32) -> bool {
        if lo > hi {
            return true;
        }
        let n = self.entries();
        let last = (n - 1) as f32;
        let first = ((lo.clamp(0.0, 1.0) * last).floor() as usize).saturating_sub(1);
        let end = ((hi.clamp(0.0, 1.0) * last).ceil() as usize + 1).min(n - 1);
        self.prefix[end + 1] == self.prefix[first]
    }

    #[cfg(test)] // Only the tests ask.
    /// Whether a node with range `m` can be skipped.
    fn is_node_empty(&self, m: MinMax) -> bool {
        self.is_empty(m.min, m.max)
    }

    /// The paper's table: `table[max_bin * TABLE_SIZE + min_bin]` is 1 where empty, else 0.
    pub fn table(&self) -> Vec<u8> {
        let m = TABLE_SIZE as f32;
        let mut table = vec![0u8; TABLE_SIZE * TABLE_SIZE];
        for max_bin in 0..TABLE_SIZE {
            for min_bin in 0..=max_bin {
                let empty = self.is_empty(min_bin as f32 / m, (max_bin + 1) as f32 / m);
                table[max_bin * TABLE_SIZE + min_bin] = u8::from(empty);
            }
        }
        table
    }
}

/// The table bin of a normalised value.
pub fn bin(value: f32) -> usize {
    ((value.clamp(0.0, 1.0) * TABLE_SIZE as f32) as usize).min(TABLE_SIZE - 1)
}

/// Looks a node up in the table, as the GPU does.
pub fn table_says_empty(table: &[u8], m: MinMax) -> bool {
    m.min > m.max || table[bin(m.max) * TABLE_SIZE + bin(m.min)] == 1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::{TransferFunction, ValueSpace, lut};
    use crate::volume::ValueRange;

    fn index_of(opacity: Vec<[f64; 2]>) -> (OpacityIndex, Vec<[f32; 4]>) {
        let tf = TransferFunction {
            opacity,
            color: vec![[0.0, 1.0, 1.0, 1.0]],
            space: ValueSpace::Data,
        };
        let table = lut::bake(
            &tf,
            ValueRange {
                min: 0.0,
                max: 1000.0,
            },
            1.0,
        );
        (OpacityIndex::from_lut(&table), table)
    }

    /// Linear filtering between entries i and i+1, as the texture unit does.
    fn filtered_alpha(lut: &[[f32; 4]], s: f32) -> f32 {
        let x = s.clamp(0.0, 1.0) * (lut.len() - 1) as f32;
        let i = (x.floor() as usize).min(lut.len() - 2);
        let f = x - i as f32;
        lut[i][3] * (1.0 - f) + lut[i + 1][3] * f
    }

    #[test]
    fn never_empty_where_interpolation_can_reach_opacity() {
        // Opacity starts just above 400 (normalised 0.4): values right below still read a
        // non-zero entry through linear filtering.
        let (idx, table) = index_of(vec![[0.0, 0.0], [400.0, 0.0], [400.5, 0.5]]);
        for i in 0..2000 {
            let lo = i as f32 / 2000.0;
            for w in [0.0, 0.001, 0.01, 0.2] {
                let hi = (lo + w).min(1.0);
                if idx.is_empty(lo, hi) {
                    for k in 0..=20 {
                        let s = lo + (hi - lo) * k as f32 / 20.0;
                        assert_eq!(
                            filtered_alpha(&table, s),
                            0.0,
                            "[{lo}, {hi}] called empty but s = {s} is visible"
                        );
                    }
                }
            }
        }
        assert!(idx.is_empty(0.0, 0.39));
        assert!(!idx.is_empty(0.0, 0.41));
    }

    #[test]
    fn table_is_conservative_and_agrees_with_the_index_at_bin_edges() {
        let (idx, _) = index_of(vec![
            [0.0, 0.0],
            [300.0, 0.0],
            [310.0, 0.4],
            [600.0, 0.4],
            [620.0, 0.0],
        ]);
        let table = idx.table();
        for i in 0..500 {
            let lo = i as f32 / 500.0;
            for hi in [lo, lo + 0.003, lo + 0.05] {
                let m = MinMax {
                    min: lo,
                    max: hi.min(1.0),
                };
                if table_says_empty(&table, m) {
                    assert!(idx.is_node_empty(m), "{m:?}");
                }
            }
        }
        // Above the bump everything is transparent again.
        assert!(table_says_empty(&table, MinMax { min: 0.7, max: 0.9 }));
        assert!(!table_says_empty(&table, MinMax { min: 0.2, max: 0.9 }));
        assert!(table_says_empty(&table, MinMax::NONE));
    }
}
