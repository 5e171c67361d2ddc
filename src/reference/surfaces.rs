//! Labels as surfaces in f64 (the twin of shaders/shared/label_surface.wgsl): the smoothed mask
//! of the shown labels ([`crate::labels::surface::smoothed_mask`]) filtered trilinearly, a
//! surface where it rises through one half between two samples, refined by false position, lit
//! by the mask's gradient and coloured by the shown label around it.

use glam::DVec3;

use super::modes::RayInput;
use super::shade::phong;
use super::trilinear::corners;

/// Where the mask crosses the surface.
const LEVEL: f64 = 0.5;

/// False-position steps refining a crossing (the shader's `SURFACE_REFINE`).
const REFINE: usize = 5;

/// A ray's walk through the surfaces: whether its last sample was inside, and the surfaces it
/// entered composited front to back (premultiplied) for the modes that show them over their
/// picture (isosurface, MIP, MinIP, X-ray).
#[derive(Default)]
pub(super) struct SurfaceWalk {
    inside: bool,
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

    /// The surface the ray enters between `t0` (the previous sample, or 0 at the entry) and `t`
    /// (mm), if it enters one.
    pub(super) fn before(&mut self, ray: &RayInput, t0: f64, t: f64) -> Option<Surface> {
        let mask = ray.surface_mask?;
        let f = mask_at(ray, mask, t);
        let was_inside = std::mem::replace(&mut self.inside, f >= LEVEL);
        if was_inside || f < LEVEL {
            return None;
        }
        let (mut t0, mut d0) = (t0, mask_at(ray, mask, t0) - LEVEL);
        let (th, g) = if d0 >= 0.0 {
            // A label at the box's face: a cap facing the eye.
            (t0, ray.dir)
        } else {
            let (mut t1, mut d1) = (t, f - LEVEL);
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
        let [r, gr, b, a] = label_around(ray, ray.entry + ray.dir * th, g)?;
        let colour = DVec3::new(f64::from(r), f64::from(gr), f64::from(b)) / 255.0;
        let s = ray.settings;
        Some(Surface {
            colour: phong(colour, g, ray.dir, &s.phong, &s.light),
            alpha: f64::from(a) / 255.0,
            t: th,
        })
    }
}

fn mask_value(ray: &RayInput, mask: &[u8], p: DVec3) -> f64 {
    let v = ray.volume;
    corners(v, p, |i, j, k| {
        Some(DVec3::splat(f64::from(mask[v.index(i, j, k)]) / 255.0))
    })
    .0
    .x
}

fn mask_at(ray: &RayInput, mask: &[u8], t: f64) -> f64 {
    mask_value(ray, mask, ray.entry + ray.dir * t)
}

/// The mask's gradient per mm, by central differences one voxel apart.
fn gradient(ray: &RayInput, mask: &[u8], p: DVec3) -> DVec3 {
    let spacing = DVec3::from_array(ray.volume.spacing_mm());
    let mut g = DVec3::ZERO;
    for a in 0..3 {
        let mut e = DVec3::ZERO;
        e[a] = spacing[a];
        g[a] = 0.5 * (mask_value(ray, mask, p + e) - mask_value(ray, mask, p - e)) / spacing[a];
    }
    g
}

/// The shown label of the voxel around `p` weighing most in the trilinear filter (the first in
/// corner order on a tie), else that of the voxel one step along `g` (inwards).
fn label_around(ray: &RayInput, p: DVec3, g: DVec3) -> Option<[u8; 4]> {
    let labels = ray.labels?;
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
        if let Some(c) = labels.shown_at(v, centre).next()
            && best.is_none_or(|(_, bw)| w > bw)
        {
            best = Some((c, w));
        }
    }
    best.map(|(c, _)| c).or_else(|| {
        let inward = p + g.normalize_or_zero() * spacing;
        labels.shown_at(v, inward).next()
    })
}
