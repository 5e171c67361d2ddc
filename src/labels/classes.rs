//! Classes for drawing the walls between touching labels as surfaces. Labels whose smoothed
//! indicators would run together are neighbours; the shown labels are coloured so that
//! neighbours differ wherever [`MOST_CLASSES`] classes allow (DSatur, the fewest clashes
//! otherwise); each class becomes a channel of the surfaces' mask, so that where one class's
//! channel rises through one half is every boundary of its labels, walls against the labels of
//! other classes included.

use rayon::prelude::*;
use rustc_hash::FxHashSet;

use super::LabelMap;

/// Edge (voxels) of the cells neighbours are found between: labels in one cell or in two cells
/// that touch (at a face, an edge or a corner) are neighbours, which holds every pair within
/// two voxels of each other along each axis (the smoothing's reach) and some up to three apart.
const CELL: u32 = 2;

/// Most classes: the channels of an RGBA8 mask.
pub const MOST_CLASSES: usize = 4;

/// Most shown labels coloured by DSatur (each pick scans those left); more by degree alone.
const MOST_DSATUR: usize = 1024;

/// The cells after a cell in the same slab of cells (fixed z) that it touches, as (dx, dy).
const SAME_SLAB: [(i64, i64); 4] = [(1, 0), (-1, 1), (0, 1), (1, 1)];

/// The distinct non-zero labels of every cell of slab `cz` (cells x fastest), as a CSR pair.
fn slab_lists(map: &LabelMap, cells: [u32; 3], cz: u32) -> (Vec<u32>, Vec<u16>) {
    let dims = map.dims();
    let layers = map.layers();
    let span = |c: u32, a: usize| c * CELL..((c + 1) * CELL).min(dims[a]);
    let mut offsets = Vec::with_capacity((cells[0] * cells[1]) as usize + 1);
    let mut labels = Vec::new();
    offsets.push(0);
    for cy in 0..cells[1] {
        for cx in 0..cells[0] {
            let start = labels.len();
            for z in span(cz, 2) {
                for y in span(cy, 1) {
                    for x in span(cx, 0) {
                        let i = x as usize
                            + dims[0] as usize * (y as usize + dims[1] as usize * z as usize);
                        for layer in layers {
                            let l = layer[i];
                            if l != 0 && !labels[start..].contains(&l) {
                                labels.push(l);
                            }
                        }
                    }
                }
            }
            offsets.push(labels.len() as u32);
        }
    }
    (offsets, labels)
}

/// The labels of cell (x, y) of a slab's lists (none past the grid).
fn cell_labels(lists: &(Vec<u32>, Vec<u16>), cells: [u32; 3], x: i64, y: i64) -> &[u16] {
    let (offsets, labels) = lists;
    if x < 0 || y < 0 || x >= i64::from(cells[0]) || y >= i64::from(cells[1]) {
        return &[];
    }
    let c = (x + i64::from(cells[0]) * y) as usize;
    &labels[offsets[c] as usize..offsets[c + 1] as usize]
}

/// Every pair of labels (a < b) that are neighbours in `map`, sorted.
pub fn neighbours(map: &LabelMap) -> Vec<(u16, u16)> {
    let cells = map.dims().map(|d| d.div_ceil(CELL).max(1));
    // Runs of slabs, each slab's lists made once within a run (and once more as the next of
    // the run before).
    let runs = cells[2].div_ceil(SLABS_A_RUN);
    let pairs = (0..runs)
        .into_par_iter()
        .fold(FxHashSet::default, |mut pairs, run| {
            let first = run * SLABS_A_RUN;
            let last = (first + SLABS_A_RUN).min(cells[2]);
            let mut next = Some(slab_lists(map, cells, first));
            for cz in first..last {
                let Some(here) = next.take() else { break };
                next = (cz + 1 < cells[2]).then(|| slab_lists(map, cells, cz + 1));
                pairs_between(&here, next.as_ref(), cells, &mut pairs);
            }
            pairs
        })
        .reduce(FxHashSet::default, |mut a, b| {
            a.extend(b);
            a
        });
    let mut pairs: Vec<(u16, u16)> = pairs.into_iter().collect();
    pairs.sort_unstable();
    pairs
}

/// Slabs of cells one task of [`neighbours`] walks.
const SLABS_A_RUN: u32 = 8;

/// The pairs of neighbours in slab `here` and between it and the slab after it (`next`).
fn pairs_between(
    here: &(Vec<u32>, Vec<u16>),
    next: Option<&(Vec<u32>, Vec<u16>)>,
    cells: [u32; 3],
    pairs: &mut FxHashSet<(u16, u16)>,
) {
    let list = |lists, x, y| cell_labels(lists, cells, x, y);
    let mut add = |a: &[u16], b: &[u16]| {
        // Most cells hold one label, and most neighbours the same one.
        if a.len() == 1 && a == b {
            return;
        }
        for &p in a {
            for &q in b {
                if p != q {
                    pairs.insert((p.min(q), p.max(q)));
                }
            }
        }
    };
    for cy in 0..i64::from(cells[1]) {
        for cx in 0..i64::from(cells[0]) {
            let own = list(here, cx, cy);
            if own.is_empty() {
                continue;
            }
            add(own, own);
            for (dx, dy) in SAME_SLAB {
                add(own, list(here, cx + dx, cy + dy));
            }
            if let Some(next) = next {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        add(own, list(next, cx + dx, cy + dy));
                    }
                }
            }
        }
    }
}

/// The shown labels' classes: each shown label value's class (`None` for the rest), and the
/// neighbouring pairs that share one (their wall is not drawn).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Classes {
    /// By label value: the class, where the label is shown.
    pub class: Vec<Option<u8>>,
    /// Neighbouring shown labels in one class.
    pub clashes: Vec<(u16, u16)>,
    /// How many classes are used (the mask's channels).
    pub used: usize,
    /// By label value: the class it last had, shown or not (a label shown again takes it back
    /// where no shown neighbour holds it).
    pub last: Vec<Option<u8>>,
}

/// Colours the shown labels (`shown[value]`) of the neighbour graph `pairs` with at most
/// [`MOST_CLASSES`] classes: DSatur (the label whose neighbours hold the most distinct classes
/// first, then the one with the most shown neighbours, then the smallest; past
/// `MOST_DSATUR` shown labels, by most neighbours alone), each taking the lowest class none of
/// its neighbours holds, else the one fewest of them hold.
pub fn classes(shown: &[bool], pairs: &[(u16, u16)]) -> Classes {
    let adjacent = adjacency(shown, pairs);
    let mut class: Vec<Option<u8>> = vec![None; shown.len()];
    let mut left: Vec<u16> = (0..shown.len())
        .filter(|&l| l != 0 && shown[l])
        .map(|l| l as u16)
        .collect();
    // DSatur's pick scans every label left: past MOST_DSATUR labels, the order of degree alone
    // (Welsh-Powell), whose picks cost nothing.
    let dsatur = left.len() <= MOST_DSATUR;
    if !dsatur {
        left.sort_unstable_by_key(|&l| (adjacent[usize::from(l)].len(), std::cmp::Reverse(l)));
    }
    while !left.is_empty() {
        let l = if dsatur {
            let saturation = |l: u16| {
                let mut seen = [false; MOST_CLASSES];
                for &n in &adjacent[usize::from(l)] {
                    if let Some(c) = class[usize::from(n)] {
                        seen[usize::from(c)] = true;
                    }
                }
                seen.iter().filter(|&&s| s).count()
            };
            let pick = left
                .iter()
                .enumerate()
                .max_by_key(|&(_, &l)| {
                    (
                        saturation(l),
                        adjacent[usize::from(l)].len(),
                        std::cmp::Reverse(l),
                    )
                })
                .map_or(0, |(i, _)| i);
            left.swap_remove(pick)
        } else {
            match left.pop() {
                Some(l) => l,
                None => break,
            }
        };
        let holding = held_by(&class, &adjacent[usize::from(l)]);
        class[usize::from(l)] = Some(least_held(&holding));
    }
    if dsatur {
        mend(&mut class, &adjacent);
    }
    finish(class, shown, pairs)
}

/// The shown labels' classes after the shown labels changed from those `previous` coloured:
/// every label still shown keeps its class (hiding a label adds no clash, and no wall elsewhere
/// comes or goes), each newly shown label takes back the class it last had where no shown
/// neighbour holds it, else the class fewest of them hold (the lowest of those). Where that
/// leaves more neighbours sharing a class than colouring afresh ([`classes`]) does, the fresh
/// colouring is taken instead.
pub fn classes_after(previous: &Classes, shown: &[bool], pairs: &[(u16, u16)]) -> Classes {
    let fresh = classes(shown, pairs);
    let mut class: Vec<Option<u8>> = (0..shown.len())
        .map(|l| {
            let kept = previous.class.get(l).copied().flatten();
            kept.filter(|_| shown[l] && l != 0)
        })
        .collect();
    let adjacent = adjacency(shown, pairs);
    for l in 1..shown.len() {
        if !shown[l] || class[l].is_some() {
            continue;
        }
        let holding = held_by(&class, &adjacent[l]);
        let before = previous.last.get(l).copied().flatten();
        let best = before.filter(|&c| holding[usize::from(c)] == 0);
        class[l] = Some(best.unwrap_or_else(|| least_held(&holding)));
    }
    let remember = |mut made: Classes| {
        for (last, before) in made.last.iter_mut().zip(&previous.last) {
            *last = last.or(*before);
        }
        made
    };
    let kept = finish(class, shown, pairs);
    if kept.clashes.len() <= fresh.clashes.len() {
        remember(kept)
    } else {
        remember(fresh)
    }
}

/// By label value, its shown neighbours in the graph `pairs`.
fn adjacency(shown: &[bool], pairs: &[(u16, u16)]) -> Vec<Vec<u16>> {
    let is_shown = |l: u16| shown.get(usize::from(l)).copied().unwrap_or(false);
    let mut adjacent: Vec<Vec<u16>> = vec![Vec::new(); shown.len().max(1)];
    for &(a, b) in pairs.iter().filter(|&&(a, b)| is_shown(a) && is_shown(b)) {
        adjacent[usize::from(a)].push(b);
        adjacent[usize::from(b)].push(a);
    }
    adjacent
}

/// How many of `neighbours` hold each class.
fn held_by(class: &[Option<u8>], neighbours: &[u16]) -> [usize; MOST_CLASSES] {
    let mut holding = [0usize; MOST_CLASSES];
    for &n in neighbours {
        if let Some(c) = class[usize::from(n)] {
            holding[usize::from(c)] += 1;
        }
    }
    holding
}

/// The class fewest neighbours hold (the lowest of those).
fn least_held(holding: &[usize; MOST_CLASSES]) -> u8 {
    (0..MOST_CLASSES)
        .min_by_key(|&c| (holding[c], c))
        .unwrap_or(0) as u8
}

/// The classes `class` gives the shown labels, with the neighbours sharing one and the classes
/// used.
fn finish(class: Vec<Option<u8>>, shown: &[bool], pairs: &[(u16, u16)]) -> Classes {
    let is_shown = |l: u16| shown.get(usize::from(l)).copied().unwrap_or(false);
    let clashes = pairs
        .iter()
        .copied()
        .filter(|&(a, b)| {
            is_shown(a) && is_shown(b) && class[usize::from(a)] == class[usize::from(b)]
        })
        .collect();
    let used = class
        .iter()
        .flatten()
        .map(|&c| usize::from(c) + 1)
        .max()
        .unwrap_or(0);
    Classes {
        last: class.clone(),
        class,
        clashes,
        used,
    }
}

/// Moves a local search makes after DSatur, at most.
const MOST_MOVES: usize = 500;

/// Labels a move leaves where they are for a while (tabu), so the search does not undo it.
const TABU_MOVES: usize = 7;

/// Lessens the neighbours sharing a class: a tabu search that moves a label in a clash to the
/// class fewest of its neighbours hold (sideways too, where no class is better), keeping the
/// best colouring seen. On the MR's 120 parcels (396 pairs) DSatur leaves 18 sharing a class,
/// the search 16, in 1.6 ms (the ignored `measure` test; more moves found no fewer).
fn mend(class: &mut [Option<u8>], adjacent: &[Vec<u16>]) {
    let clashes_of = |class: &[Option<u8>], l: usize| {
        let c = class[l];
        adjacent[l]
            .iter()
            .filter(|&&n| class[usize::from(n)] == c)
            .count()
    };
    // The shown labels: a move scans them, not every value.
    let shown: Vec<usize> = (0..class.len()).filter(|&l| class[l].is_some()).collect();
    let total =
        |class: &[Option<u8>]| -> usize { shown.iter().map(|&l| clashes_of(class, l)).sum() };
    let mut now = total(class);
    let mut best = (now, class.to_vec());
    let mut moved_at: Vec<usize> = vec![0; class.len()];
    for step in 1..=MOST_MOVES {
        if now == 0 {
            break;
        }
        // The best move of any label in a clash, tabu labels aside (unless it beats the best).
        let mut pick: Option<(isize, usize, u8)> = None;
        for &l in &shown {
            let Some(c) = class[l] else { continue };
            let here = clashes_of(class, l);
            if here == 0 {
                continue;
            }
            let holding = held_by(class, &adjacent[l]);
            for k in 0..MOST_CLASSES as u8 {
                if k == c {
                    continue;
                }
                let gain = here as isize - holding[usize::from(k)] as isize;
                let tabu = moved_at[l] + TABU_MOVES > step && moved_at[l] != 0;
                let aspires = (now as isize - 2 * gain) < best.0 as isize;
                if (!tabu || aspires) && pick.is_none_or(|(g, _, _)| gain > g) {
                    pick = Some((gain, l, k));
                }
            }
        }
        let Some((gain, l, k)) = pick else { break };
        class[l] = Some(k);
        moved_at[l] = step;
        // Each clash counts at both its labels.
        now = (now as isize - 2 * gain) as usize;
        if now < best.0 {
            best = (now, class.to_vec());
        }
    }
    class.copy_from_slice(&best.1);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Labels of `dims` from `f(x, y, z)`, one layer.
    fn map(dims: [u32; 3], f: impl Fn(u32, u32, u32) -> u16) -> LabelMap {
        let mut layer = Vec::new();
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    layer.push(f(x, y, z));
                }
            }
        }
        LabelMap::bare(dims, vec![layer])
    }

    /// Every pair of labels within `reach` voxels of each other along each axis, by brute force.
    fn brute_force(map: &LabelMap, reach: i64) -> Vec<(u16, u16)> {
        let [nx, ny, nz] = map.dims().map(i64::from);
        let layer = &map.layers()[0];
        let at = |x: i64, y: i64, z: i64| layer[(x + nx * (y + ny * z)) as usize];
        let mut pairs = FxHashSet::default();
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let a = at(x, y, z);
                    if a == 0 {
                        continue;
                    }
                    for dz in -reach..=reach {
                        for dy in -reach..=reach {
                            for dx in -reach..=reach {
                                let (u, v, w) = (x + dx, y + dy, z + dz);
                                if u < 0 || v < 0 || w < 0 || u >= nx || v >= ny || w >= nz {
                                    continue;
                                }
                                let b = at(u, v, w);
                                if b != 0 && b != a {
                                    pairs.insert((a.min(b), a.max(b)));
                                }
                            }
                        }
                    }
                }
            }
        }
        let mut pairs: Vec<_> = pairs.into_iter().collect();
        pairs.sort_unstable();
        pairs
    }

    #[test]
    fn neighbours_hold_every_pair_within_two_voxels() {
        // Irregular blobs of 9 labels in 23 × 17 × 13 voxels (odd sizes: partial cells).
        let m = map([23, 17, 13], |x, y, z| {
            let h = (x * 7 + y * 13 + z * 29) / 9 + (x * y + z) % 3;
            if (x + 2 * y + 3 * z) % 11 == 0 {
                0
            } else {
                (h % 9 + 1) as u16
            }
        });
        let found = neighbours(&m);
        let near = brute_force(&m, 2);
        for pair in &near {
            assert!(
                found.contains(pair),
                "{pair:?} within two voxels, not found"
            );
        }
        // And none farther than two cells reach (three voxels).
        let far = brute_force(&m, 3);
        for pair in &found {
            assert!(
                far.contains(pair),
                "{pair:?} found but more than three voxels apart"
            );
        }
    }

    #[test]
    fn the_search_parts_neighbours_that_one_class_held() {
        // A 12 × 12 grid graph (two classes suffice), every label in class 0: 264 clashes.
        let id = |x: u16, y: u16| 1 + x + 12 * y;
        let mut adjacent: Vec<Vec<u16>> = vec![Vec::new(); 145];
        for y in 0..12u16 {
            for x in 0..12u16 {
                for (u, v) in [(x + 1, y), (x, y + 1)] {
                    if u < 12 && v < 12 {
                        adjacent[usize::from(id(x, y))].push(id(u, v));
                        adjacent[usize::from(id(u, v))].push(id(x, y));
                    }
                }
            }
        }
        let mut class: Vec<Option<u8>> = (0..145).map(|l| (l > 0).then_some(0)).collect();
        mend(&mut class, &adjacent);
        let left: usize = (1..145)
            .map(|l| {
                (adjacent[l].iter())
                    .filter(|&&n| class[usize::from(n)] == class[l])
                    .count()
            })
            .sum();
        assert_eq!(left, 0);
        assert!(class[0].is_none() && class[1..].iter().all(Option::is_some));
    }

    /// A toggle keeps every other shown label's class (no wall elsewhere comes or goes) and
    /// never leaves more neighbours in one class than colouring afresh.
    #[test]
    fn a_toggle_keeps_the_other_labels_classes() {
        // An 8 × 8 king's-move grid graph (each label touches up to 8: four classes suffice).
        let id = |x: u16, y: u16| 1 + x + 8 * y;
        let mut pairs = Vec::new();
        for y in 0..8u16 {
            for x in 0..8u16 {
                for (u, v) in [(x + 1, y), (x, y + 1), (x + 1, y + 1)] {
                    if u < 8 && v < 8 {
                        pairs.push((id(x, y), id(u, v)));
                    }
                }
                if x > 0 && y + 1 < 8 {
                    pairs.push((id(x, y), id(x - 1, y + 1)));
                }
            }
        }
        let all = vec![true; 65];
        let first = classes(&all, &pairs);
        assert!(first.clashes.is_empty(), "{first:?}");
        let mut shown = all.clone();
        let mut now = first.clone();
        // Hide labels one by one (each hide keeps every other class: a fresh colouring moved
        // some other label's class for 55 of the 64 single hides), then show them again in
        // the reverse order.
        let order: Vec<usize> = (1..65).map(|i| (i * 23) % 64 + 1).collect();
        let mut kept_shows = 0;
        for (step, &l) in order.iter().chain(order.iter().rev()).enumerate() {
            let hiding = step < order.len();
            shown[l] = !hiding;
            let next = classes_after(&now, &shown, &pairs);
            let fresh = classes(&shown, &pairs);
            assert!(next.clashes.len() <= fresh.clashes.len(), "step {step}");
            let kept = (1..65)
                .filter(|&k| k != l && shown[k])
                .all(|k| next.class[k] == now.class[k]);
            assert!(
                kept || !hiding,
                "step {step}: a hide moved another label's class"
            );
            kept_shows += usize::from(kept && !hiding);
            assert!((1..65).all(|k| next.class[k].is_some() == shown[k]));
            now = next;
        }
        // Shown again in reverse, each label takes back its old class: where it all began.
        assert_eq!(kept_shows, 64);
        assert_eq!(now.class, first.class);
        // A hidden label's neighbours keep their classes exactly.
        let mut hidden = all.clone();
        hidden[id(3, 3) as usize] = false;
        let after = classes_after(&first, &hidden, &pairs);
        for k in (1..65).filter(|&k| k != id(3, 3) as usize) {
            assert_eq!(after.class[k], first.class[k]);
        }
    }

    #[test]
    fn neighbours_get_different_classes_where_four_allow() {
        // A row of slabs 1 | 2 | 3 | 1 | 2 … along x, three voxels each: a path graph.
        let m = map([30, 4, 4], |x, _, _| (x / 3 % 6 + 1) as u16);
        let pairs = neighbours(&m);
        let shown = vec![true; 7];
        let c = classes(&shown, &pairs);
        assert!(c.clashes.is_empty(), "{c:?}");
        assert!(c.used <= 3, "{c:?}");
        // Five labels all touching each other (a clique) need five: one clash left.
        let pairs: Vec<(u16, u16)> = (1..=5u16)
            .flat_map(|a| (a + 1..=5).map(move |b| (a, b)))
            .collect();
        let c = classes(&[true; 6], &pairs);
        assert_eq!(c.clashes.len(), 1, "{c:?}");
        assert_eq!(c.used, MOST_CLASSES);
        // Hidden labels take no class and clash with none.
        let mut shown = vec![true; 6];
        shown[5] = false;
        let c = classes(&shown, &pairs);
        assert!(c.clashes.is_empty() && c.class[5].is_none(), "{c:?}");
        // Past DSatur's reach (a path of 3000 labels): by degree, still no clash.
        let pairs: Vec<(u16, u16)> = (1..3000u16).map(|a| (a, a + 1)).collect();
        let c = classes(&vec![true; 3001], &pairs);
        assert!(c.clashes.is_empty() && c.used <= 3, "{:?}", c.clashes);
        assert!(c.class[1..].iter().all(Option::is_some));
    }
}
#[cfg(test)]
mod measure {
    #[test]
    #[ignore]
    fn mr_parcels() {
        let data = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data"));
        let image = crate::volume::load_volume(
            &data.join("originals/VolumeRenderingData_seg3D_MR.nii.gz"),
            &crate::volume::LoadOptions::default(),
        )
        .unwrap();
        let map = crate::labels::load_labels(
            &data.join("labels/mr_head_t1_seg3d_parcels.nii.gz"),
            &image,
            &Default::default(),
        )
        .unwrap();
        let t = std::time::Instant::now();
        let pairs = super::neighbours(&map);
        let took = t.elapsed();
        let t = std::time::Instant::now();
        let shown: Vec<bool> = (0..1usize << 16).map(|v| v <= 120).collect();
        let c = super::classes(&shown, &pairs);
        eprintln!("classes in {:?}", t.elapsed());
        eprintln!(
            "pairs {} in {took:?}; classes used {}, clashes {}",
            pairs.len(),
            c.used,
            c.clashes.len()
        );
    }
}
