//! Labels as surfaces in f64 (the twin of shaders/shared/label_surface.wgsl): per class of shown
//! labels the smoothed mask of that class's labels ([`crate::labels::surface::smoothed_mask`])
//! filtered trilinearly, a surface where a class's mask rises through one half between two
//! samples (walls between touching labels of two classes included), refined by false position,
//! lit by that mask's gradient and coloured by the shown label of that class around it.

use glam::DVec3;

use super::modes::{Labelled, RayInput};
use super::shade::phong;
use super::trilinear::corners;
use crate::labels::classes::{self, Classes};
use crate::labels::surface::{occupancy, smoothed_mask, smoothed_occupancy};

/// Where the mask crosses the surface.
const LEVEL: f64 = 0.5;

/// False-position steps refining a crossing (the shader's `SURFACE_REFINE`).
const REFINE: usize = 5;

/// The surfaces' mask as the GPU builds it: the shown labels' classes
/// ([`crate::labels::classes`], from the same neighbour graph) and per class the smoothed
/// indicator of its shown labels ([`smoothed_mask`]).
pub struct SurfaceMasks {
    classes: Classes,
    channels: Vec<Vec<u8>>,
    /// The labels' grid reduced this many times on each axis to the masks' (1: the same grid).
    factor: u32,
    /// The masks' grid.
    dims: [u32; 3],
}

impl SurfaceMasks {
    /// The masks of `labels` as shown by their table, smoothed by `sigma` voxels, on the
    /// labels' grid (`factor` 1) or, as the GPU makes them for labels in bricks past one
    /// texture, on it reduced `factor`-fold from each class's occupancy.
    pub(super) fn new(labels: &Labelled<'_>, sigma: f32, factor: u32) -> Self {
        let shown: Vec<bool> = labels.table.iter().map(|c| c[3] > 0).collect();
        let classes = classes::classes(&shown, &classes::neighbours(labels.map));
        let full = labels.map.dims();
        let used = classes.used.max(1);
        if factor > 1 {
            let dims = full.map(|d| d.div_ceil(factor));
            let codes: Vec<u8> = (classes.class.iter())
                .map(|c| c.map_or(0, |c| c + 1))
                .collect();
            let all = occupancy(labels.map, &codes, (factor, used as u32), ([0; 3], dims));
            let channels = (0..used)
                .map(|c| {
                    let one: Vec<u8> = all.iter().skip(c).step_by(used).copied().collect();
                    smoothed_occupancy(dims, &one, sigma)
                })
                .collect();
            return Self {
                classes,
                channels,
                factor,
                dims,
            };
        }
        let bits = labels.map.shown_classes(labels.table, &classes.class);
        let channels = (0..used)
            .map(|c| {
                let inside: Vec<bool> = bits.iter().map(|b| b >> c & 1 == 1).collect();
                smoothed_mask(full, &inside, sigma)
            })
            .collect();
        Self {
            classes,
            channels,
            factor: 1,
            dims: full,
        }
    }

    fn class_of(&self, value: u16) -> Option<u8> {
        self.classes
            .class
            .get(usize::from(value))
            .copied()
            .flatten()
    }
}

/// A ray's walk through the surfaces: the channels its last sample was inside (bits), and the
/// surfaces it entered composited front to back (premultiplied) for the modes that show them
/// over their picture (isosurface, MIP, MinIP, X-ray).
#[derive(Default)]
pub(super) struct SurfaceWalk {
    inside: u8,
    colour: DVec3,
    alpha: f64,
}

/// A surface a ray enters: its lit colour, opacity and distance (mm).
pub(super) struct Surface {
    pub colour: DVec3,
    pub alpha: f64,
    pub t: f64,
}

impl SurfaceWalk {
    /// Adds `s` behind the surfaces gathered; whether they now hide what lies behind (the
    /// ray may stop, where it stops early).
    pub(super) fn add(&mut self, ray: &RayInput, s: &Surface) -> bool {
        self.colour += (1.0 - self.alpha) * s.alpha * s.colour;
        self.alpha += (1.0 - self.alpha) * s.alpha;
        ray.settings.strategy != crate::settings::Strategy::Rc
            && self.alpha > ray.settings.termination_alpha
    }

    /// The surfaces gathered over `under`.
    pub(super) fn over(&self, under: DVec3) -> DVec3 {
        self.colour + (1.0 - self.alpha) * under
    }

    /// Whether the ray draws surfaces.
    pub(super) fn drawn(ray: &RayInput) -> bool {
        ray.surface_mask.is_some()
    }

    /// The surfaces the ray enters between `t0` (the previous sample, or 0 at the entry) and
    /// `t` (mm), where a class's channel rises through the level, composited in order of
    /// distance into one (its distance the nearest's), if it enters any.
    pub(super) fn before(&mut self, ray: &RayInput, t0: f64, t: f64) -> Option<Surface> {
        let masks = ray.surface_mask?;
        let now = above(ray, masks, t);
        let risen = now & !std::mem::replace(&mut self.inside, now);
        if risen == 0 {
            return None;
        }
        let mut hits: Vec<(f64, usize, Option<Surface>)> = Vec::new();
        for (c, mask) in masks.channels.iter().enumerate() {
            if risen >> c & 1 == 0 {
                continue;
            }
            let (th, surface) = enter(ray, masks, c, mask, (t0, t));
            hits.push((th, c, surface));
        }
        // Front to back by distance (ties: the lower class first).
        hits.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let nearest = hits.first().map_or(t, |h| h.0.min(t));
        let (mut colour, mut alpha) = (DVec3::ZERO, 0.0);
        for s in hits.iter().filter_map(|h| h.2.as_ref()) {
            colour += (1.0 - alpha) * s.alpha * s.colour;
            alpha += (1.0 - alpha) * s.alpha;
        }
        (alpha > 0.0).then(|| Surface {
            colour: colour / alpha,
            alpha,
            t: nearest,
        })
    }
}

/// The channels at or above the level at distance `t`, as bits.
fn above(ray: &RayInput, masks: &SurfaceMasks, t: f64) -> u8 {
    (masks.channels.iter().enumerate())
        .filter(|(_, mask)| mask_at(ray, mask, t) >= LEVEL)
        .fold(0, |bits, (c, _)| bits | 1 << c)
}

/// Where channel `c` (`mask`) rises through the level between `t0` and `t1` (mm) and the
/// surface there, lit (none where no shown label of that class lies around it).
fn enter(
    ray: &RayInput,
    masks: &SurfaceMasks,
    c: usize,
    mask: &[u8],
    (t0, t1): (f64, f64),
) -> (f64, Option<Surface>) {
    let (mut t0, mut d0) = (t0, mask_at(ray, mask, t0) - LEVEL);
    let (th, g) = if d0 >= 0.0 {
        // A label at the box's face: a cap facing the eye.
        (t0, ray.dir)
    } else {
        let (mut t1, mut d1) = (t1, mask_at(ray, mask, t1) - LEVEL);
        for _ in 0..REFINE {
            let tm = t0 + (t1 - t0) * (d0 / (d0 - d1)).clamp(0.0, 1.0);
            let dm = mask_at(ray, mask, tm) - LEVEL;
            if dm >= 0.0 {
                (t1, d1) = (tm, dm);
            } else {
                (t0, d0) = (tm, dm);
            }
        }
        let th = t0 + (t1 - t0) * (d0 / (d0 - d1)).clamp(0.0, 1.0);
        (th, gradient(ray, mask, ray.entry + ray.dir * th))
    };
    let surface = label_around(ray, masks, c, ray.entry + ray.dir * th, g).map(|[r, gr, b, a]| {
        let colour = DVec3::new(f64::from(r), f64::from(gr), f64::from(b)) / 255.0;
        let s = ray.settings;
        Surface {
            colour: phong(colour, g, ray.dir, &s.phong, &s.light),
            alpha: f64::from(a) / 255.0,
            t: th,
        }
    });
    (th, surface)
}

fn mask_value(ray: &RayInput, masks: &SurfaceMasks, mask: &[u8], p: DVec3) -> f64 {
    let v = ray.volume;
    if masks.factor == 1 {
        return corners(v, p, |i, j, k| {
            Some(DVec3::splat(f64::from(mask[v.index(i, j, k)]) / 255.0))
        })
        .0
        .x;
    }
    // On the reduced grid: reduced voxel j's centre lies at fine voxel k·j + (k − 1) / 2, the
    // texture clamped to its edge voxels.
    let (k, dims, spacing) = (f64::from(masks.factor), masks.dims, v.spacing_mm());
    let (mut lo, mut hi, mut frac) = ([0usize; 3], [0usize; 3], [0.0; 3]);
    for a in 0..3 {
        let u = ((p[a] / spacing[a] + 0.5) / k - 0.5).clamp(0.0, f64::from(dims[a] - 1));
        let base = u.floor();
        lo[a] = base as usize;
        hi[a] = (lo[a] + 1).min(dims[a] as usize - 1);
        frac[a] = u - base;
    }
    let mut sum = 0.0;
    for corner in 0..8u32 {
        let mut w = 1.0;
        let mut i = [0usize; 3];
        for a in 0..3 {
            let pick = corner >> a & 1 == 1;
            w *= if pick { frac[a] } else { 1.0 - frac[a] };
            i[a] = if pick { hi[a] } else { lo[a] };
        }
        let at = i[0] + dims[0] as usize * (i[1] + dims[1] as usize * i[2]);
        sum += w * f64::from(mask[at]) / 255.0;
    }
    sum
}

fn mask_at(ray: &RayInput, mask: &[u8], t: f64) -> f64 {
    let masks = ray
        .surface_mask
        .expect("a ray through surfaces has their masks");
    mask_value(ray, masks, mask, ray.entry + ray.dir * t)
}

/// The mask's gradient per mm, by central differences one voxel of the masks' grid apart.
fn gradient(ray: &RayInput, mask: &[u8], p: DVec3) -> DVec3 {
    let masks = ray
        .surface_mask
        .expect("a ray through surfaces has their masks");
    let step = DVec3::from_array(ray.volume.spacing_mm()) * f64::from(masks.factor);
    let mut g = DVec3::ZERO;
    for a in 0..3 {
        let mut e = DVec3::ZERO;
        e[a] = step[a];
        let (f, b) = (
            mask_value(ray, masks, mask, p + e),
            mask_value(ray, masks, mask, p - e),
        );
        g[a] = 0.5 * (f - b) / step[a];
    }
    g
}

/// The shown label of class `c` of the voxel around `p` weighing most in the trilinear filter
/// (the first in corner order on a tie), else that of the voxel one step along `g` (inwards).
fn label_around(
    ray: &RayInput,
    masks: &SurfaceMasks,
    c: usize,
    p: DVec3,
    g: DVec3,
) -> Option<[u8; 4]> {
    let labels = ray.labels?;
    let in_class = |q: DVec3| {
        labels
            .shown_values_at(ray.volume, q)
            .find(|&(l, _)| masks.class_of(l).map(usize::from) == Some(c))
            .map(|(_, colour)| colour)
    };
    let v = ray.volume;
    let spacing = DVec3::from_array(v.spacing_mm());
    let dims = v.dims();
    let mut best: Option<([u8; 4], f64)> = None;
    for corner in 0..8u32 {
        let mut w = 1.0;
        let mut i = [0u32; 3];
        for a in 0..3 {
            let x = p[a] / spacing[a];
            let base = x.floor();
            let f = x - base;
            let pick = corner >> a & 1 == 1;
            w *= if pick { f } else { 1.0 - f };
            let idx = base + f64::from(u8::from(pick));
            i[a] = idx.clamp(0.0, f64::from(dims[a] - 1)) as u32;
        }
        let centre = DVec3::new(f64::from(i[0]), f64::from(i[1]), f64::from(i[2])) * spacing;
        if let Some(colour) = in_class(centre)
            && best.is_none_or(|(_, bw)| w > bw)
        {
            best = Some((colour, w));
        }
    }
    // A step of the masks' grid inwards.
    let step = spacing * f64::from(masks.factor);
    best.map(|(c, _)| c)
        .or_else(|| in_class(p + g.normalize_or_zero() * step))
}
