//! What each mode does along one ray, in f64: DVR compositing, the isosurface's first crossing,
//! MIP/MinIP, and the X-ray integrals. Same conventions as the shaders' mode modules.

use glam::DVec3;

use crate::camera::Aabb;
use crate::labels::LabelMap;
use crate::sampling::{SampleGrid, corrected_opacity, pixel_light_point};
use crate::settings::effects::OCCLUSION_RAYS;
use crate::settings::{Light, MipColor, Mode, RenderSettings, Shading, Strategy};
use crate::transfer::{TransferFunction, preintegration};
use crate::volume::{ValueRange, Volume};

use super::shade::{FLAT_GRADIENT, gradient, phong_shadowed};
use super::surfaces::{Surface, SurfaceWalk};
use super::trilinear::{sample_colour, sample_trilinear};
use crate::counters::FrameCounters;

/// A segmentation over the volume: its labels on the volume's grid and each label value's
/// colour and visibility ([`LabelMap::colour_table`]), shown as the settings' `labels` say.
pub struct Labelled<'a> {
    /// The labels.
    pub map: &'a LabelMap,
    /// Each label value's sRGB colour, alpha 255 where shown.
    pub table: &'a [[u8; 4]],
}

impl Labelled<'_> {
    /// The shown labels of the voxel nearest world position `p` (mm; voxel i's centre at
    /// i · spacing), by layer (at most four, as the GPU reads): (value, colour).
    pub(super) fn shown_at(&self, volume: &Volume, p: DVec3) -> impl Iterator<Item = [u8; 4]> + '_ {
        self.shown_values_at(volume, p).map(|(_, c)| c)
    }

    /// [`Self::shown_at`] with each label's value.
    pub(super) fn shown_values_at(
        &self,
        volume: &Volume,
        p: DVec3,
    ) -> impl Iterator<Item = (u16, [u8; 4])> + '_ {
        let dims = volume.dims();
        let spacing = volume.spacing_mm();
        let i: [u32; 3] = std::array::from_fn(|a| {
            let v = (p[a] / spacing[a] + 0.5).floor();
            v.clamp(0.0, f64::from(dims[a] - 1)) as u32
        });
        let index = volume.index(i[0], i[1], i[2]);
        self.map
            .layers()
            .iter()
            .take(4)
            .map(move |layer| layer[index])
            .filter(|&l| l != 0)
            .map(|l| (l, self.table[usize::from(l)]))
            .filter(|(_, c)| c[3] > 0)
    }
}

/// One ray through the volume.
pub struct RayInput<'a> {
    /// The volume.
    pub volume: &'a Volume,
    /// The transfer function.
    pub tf: &'a TransferFunction,
    /// A segmentation over the volume, if any.
    pub labels: Option<&'a Labelled<'a>>,
    /// Where the settings draw the labels as surfaces, the shown labels' smoothed mask, a
    /// channel per class.
    pub surface_mask: Option<&'a super::surfaces::SurfaceMasks>,
    /// The settings.
    pub settings: &'a RenderSettings,
    /// The crop box in world millimetres: where rays, shadow rays too, end.
    pub bounds: Aabb,
    /// The pixel the ray is cast for (soft shadows take the pixel's point of the light).
    pub pixel: [u32; 2],
    /// Entry point, world millimetres.
    pub entry: DVec3,
    /// Unit direction, world.
    pub dir: DVec3,
    /// Path length inside the volume, mm.
    pub length_mm: f64,
    /// First sample at `(k + offset) · step` (the settings' offset, or the pixel's jitter).
    pub offset: f64,
}

impl RayInput<'_> {
    fn range(&self) -> ValueRange {
        self.volume.normalization_range()
    }

    fn grid(&self) -> SampleGrid {
        let step_mm = self.settings.step_vox * self.volume.min_spacing_mm();
        SampleGrid {
            length_mm: self.length_mm,
            step_mm,
            offset: self.offset,
        }
    }

    /// Normalised value at distance `t` from the entry, `None` where a non-finite voxel weighs in.
    fn value(&self, t: f64) -> Option<f64> {
        sample_trilinear(self.volume, self.entry + self.dir * t).map(|v| self.range().normalize(v))
    }

    /// Whether the image is shown at distance `t`: everywhere, or where the labels cut the rest
    /// away, only inside a shown label (shaders/shared/labels.wgsl).
    fn shown(&self, t: f64) -> bool {
        self.shown_at(self.entry + self.dir * t)
    }

    /// [`Self::shown`] at world position `p`.
    fn shown_at(&self, p: DVec3) -> bool {
        match self.labels {
            Some(l) if self.settings.labels.cuts() => l.shown_at(self.volume, p).next().is_some(),
            _ => true,
        }
    }

    /// [`Self::value`] as the variant sees it: `None` where the labels cut the image away.
    fn labelled_value(&self, t: f64) -> Option<f64> {
        self.value(t).filter(|_| self.shown(t))
    }

    /// A sample's colour at distance `t` as shown: `colour` mixed towards that of the first
    /// layer's shown label there by its opacity, where labels colour the image (not in X-ray).
    fn labelled_colour(&self, colour: DVec3, t: f64) -> DVec3 {
        let xray = matches!(self.settings.mode, Mode::Xray | Mode::XrayAttenuation);
        match self.labels {
            Some(l) if self.settings.labels.colours() && !xray => l
                .shown_at(self.volume, self.entry + self.dir * t)
                .next()
                .map_or(colour, |[r, g, b, a]| {
                    let label = DVec3::new(f64::from(r), f64::from(g), f64::from(b)) / 255.0;
                    colour.lerp(label, f64::from(a) / 255.0)
                }),
            _ => colour,
        }
    }

    /// `color` lit at distance `t` (where the settings light the mode), a share `light` of the
    /// light reaching it, its ambient light occluded where the settings say.
    fn lit_shadowed(&self, color: DVec3, t: f64, light: f64) -> DVec3 {
        let shading = self.settings.mode.can_shade() && self.settings.shading == Shading::Phong;
        if !shading {
            return color;
        }
        let p = self.entry + self.dir * t;
        let g = gradient(self.volume, p, self.settings.gradient);
        let ambient = if self.settings.occlusion.on {
            self.occlusion(p, g)
        } else {
            1.0
        };
        phong_shadowed(
            color,
            g,
            self.dir,
            (&self.settings.phong, &self.settings.light),
            [light, ambient],
        )
    }

    /// The share of the ambient light reaching world position `p` whose gradient is `g`
    /// (shaders/shared/occlusion.wgsl): the mean transmittance of [`OCCLUSION_RAYS`] rays at 45°
    /// from −g, evenly around it and turned by the ray's first-sample offset, sampling every
    /// smallest voxel spacing from one out to the occlusion radius or the crop box (for the
    /// isosurface: 0 for a ray that reaches the iso value); 1 where g is flat.
    fn occlusion(&self, p: DVec3, g: DVec3) -> f64 {
        let len = g.length();
        if len.is_nan() || len <= FLAT_GRADIENT {
            return 1.0;
        }
        let s = self.settings;
        let n = -g / len;
        let [t, b] = plane_across(n);
        let d0 = self.volume.min_spacing_mm();
        let radius = s.occlusion.radius_vox * d0;
        let per_step = d0 / (s.step_vox * d0);
        let rays = f64::from(OCCLUSION_RAYS);
        let mut open = 0.0;
        for k in 0..OCCLUSION_RAYS {
            let phi = std::f64::consts::TAU * (f64::from(k) + self.offset) / rays;
            let d = (n + phi.cos() * t + phi.sin() * b).normalize();
            let Some((_, exit)) = self.bounds.intersect(p, d) else {
                open += 1.0;
                continue;
            };
            let length_mm = exit.min(radius);
            let mut light = 1.0;
            for j in 1u64.. {
                let at = j as f64 * d0;
                if at > length_mm {
                    break;
                }
                light *= self.secondary_share(p + d * at, per_step);
                if light == 0.0 {
                    break;
                }
            }
            open += light;
        }
        open / rays
    }

    /// The share of light a secondary ray's sample at world position `q`, `per_step` primary
    /// steps long, lets through (shaders/shared/secondary.wgsl's `secondary_depth`): the
    /// transfer function's, corrected to its length; for the isosurface 0 where the sample
    /// reaches the iso value, else 1; 1 where the sample is missing or cut away.
    fn secondary_share(&self, q: DVec3, per_step: f64) -> f64 {
        let s = self.settings;
        let range = self.range();
        let Some(v) = sample_trilinear(self.volume, q).filter(|_| self.shown_at(q)) else {
            return 1.0;
        };
        if s.mode == Mode::Iso {
            return if range.normalize(v) >= s.iso.threshold(range) {
                0.0
            } else {
                1.0
            };
        }
        let a = self.tf.opacity_at(v, range);
        1.0 - corrected_opacity(a, s.opacity_step_vox(), per_step)
    }

    /// DVR's colour of a sample of opacity `a` behind opacity `front`: lit (shadowed where the
    /// settings say), or where its weight in the pixel `a · (1 − front)` is below the settings'
    /// lighting threshold as if it faced the light, without highlight or shadow (the GPU's rule).
    fn lit_if_seen(&self, color: DVec3, t: f64, front: f64, a: f64) -> DVec3 {
        let shading = self.settings.mode.can_shade() && self.settings.shading == Shading::Phong;
        if shading && (1.0 - front) * a < self.settings.light_min_weight {
            let p = &self.settings.phong;
            return color * (p.ambient + p.diffuse);
        }
        self.lit_shadowed(color, t, self.shadow_transmittance(t, front))
    }

    /// The share of the light reaching the sample at distance `t` behind opacity `front` where
    /// DVR or the isosurface is lit and shadowed (shaders/shared/shadow.wgsl): a headlight's
    /// `1 − front`; a directional light's through the transfer function's opacity at samples
    /// every shadow step from the sample towards the light (the first one step away) up to the
    /// crop box or the reach, each sample's opacity corrected to the shadow step (rays that stop
    /// early call it gone below 1/255); for the isosurface 0 where a sample reaches the iso
    /// value, else 1.
    fn shadow_transmittance(&self, t: f64, front: f64) -> f64 {
        let s = self.settings;
        if !(s.shadows.on && s.mode.can_shade() && s.shading == Shading::Phong) {
            return 1.0;
        }
        let to_light = match s.light {
            Light::Headlight => return 1.0 - front,
            Light::Direction(d) => -DVec3::from_array(d).normalize_or(DVec3::NEG_Z),
        };
        let [x, y] = self.pixel;
        let to_light = towards_light(
            to_light,
            s.shadows.softness_deg,
            pixel_light_point(x, y, s.shadows.sample),
        );
        let p = self.entry + self.dir * t;
        let Some((_, exit)) = self.bounds.intersect(p, to_light) else {
            return 1.0;
        };
        let whole = Aabb::of_volume(self.volume.dims(), self.volume.spacing_mm());
        let length_mm = exit.min(s.shadows.reach * whole.size().length());
        let d0 = self.volume.min_spacing_mm();
        let h = s.shadows.step_vox * d0;
        let per_step = h / (s.step_vox * d0);
        let mut light = 1.0;
        for j in 1u64.. {
            let t = j as f64 * h;
            if t >= length_mm {
                break;
            }
            light *= self.secondary_share(p + to_light * t, per_step);
            if light == 0.0 || stops_early(self) && light < SHADOW_GONE {
                return 0.0;
            }
        }
        light
    }

    fn tf_color(&self, normalized: f64) -> DVec3 {
        DVec3::from_array(
            self.tf
                .color_at(self.range().denormalize(normalized), self.range()),
        )
    }

    /// Window lo and hi as normalised values.
    fn window(&self) -> (f64, f64) {
        let r = self.range();
        let [lo, hi] = self.settings.window.unwrap_or([r.min, r.max]);
        (r.normalize(lo), r.normalize(hi))
    }
}

/// The pixel colour for a ray (composited over the background where the mode composites), or
/// `None` to show the background.
pub fn cast(ray: &RayInput, counts: &mut FrameCounters) -> Option<DVec3> {
    match ray.settings.mode {
        Mode::Dvr => Some(dvr(ray, counts)),
        Mode::Iso => iso(ray, counts),
        Mode::Mip | Mode::MinIp => extreme(ray, counts),
        Mode::Xray | Mode::XrayAttenuation => Some(xray(ray, counts)),
    }
}

/// The unit direction towards a light seen in direction `l` (unit) with angular radius
/// `softness_deg`, at point `u` of the unit square on its disc (uniform over the disc of
/// radius tan(angle) across `l`), as `towards_light` in shaders/shared/shadow.wgsl.
fn towards_light(l: DVec3, softness_deg: f64, u: [f64; 2]) -> DVec3 {
    let tan = softness_deg.to_radians().tan();
    if tan <= 0.0 {
        return l;
    }
    let [t, b] = plane_across(l);
    let r = tan * u[0].sqrt();
    let phi = std::f64::consts::TAU * u[1];
    (l + r * (phi.cos() * t + phi.sin() * b)).normalize()
}

/// Two unit vectors making an orthonormal basis with the unit `n`, as `plane_across` in
/// shaders/shared/secondary.wgsl builds them.
fn plane_across(n: DVec3) -> [DVec3; 2] {
    let helper = if n.x.abs() > 0.9 { DVec3::Y } else { DVec3::X };
    let t = n.cross(helper).normalize();
    [t, n.cross(t)]
}

/// Shadow rays that stop early call the light gone below this (one 8-bit level).
const SHADOW_GONE: f64 = 1.0 / 255.0;

fn stops_early(ray: &RayInput) -> bool {
    ray.settings.strategy != Strategy::Rc
}

fn dvr(ray: &RayInput, counts: &mut FrameCounters) -> DVec3 {
    if ray.settings.preintegrated {
        return dvr_preintegrated(ray, counts);
    }
    let range = ray.range();
    let (mut color, mut alpha) = (DVec3::ZERO, 0.0);
    let mut walk = SurfaceWalk::default();
    let mut before = 0.0;
    for s in ray.grid().samples() {
        counts.samples += 1;
        // A label's surface the ray enters before this sample lies in front of it.
        if let Some(Surface {
            colour: c,
            alpha: a,
            ..
        }) = walk.before(ray, std::mem::replace(&mut before, s.t_mm), s.t_mm)
        {
            color += (1.0 - alpha) * a * c;
            alpha += (1.0 - alpha) * a;
            if stops_early(ray) && alpha > ray.settings.termination_alpha {
                break;
            }
        }
        let Some(value) = sample_trilinear(ray.volume, ray.entry + ray.dir * s.t_mm)
            .filter(|_| ray.shown(s.t_mm))
        else {
            continue;
        };
        let a = corrected_opacity(
            ray.tf.opacity_at(value, range),
            ray.settings.opacity_step_vox(),
            s.weight,
        );
        if a <= 0.0 {
            continue;
        }
        counts.visible_samples += 1;
        let own = sample_colour(ray.volume, ray.entry + ray.dir * s.t_mm);
        let own = own.unwrap_or_else(|| DVec3::from_array(ray.tf.color_at(value, range)));
        let c = ray.lit_if_seen(ray.labelled_colour(own, s.t_mm), s.t_mm, alpha, a);
        color += (1.0 - alpha) * a * c;
        alpha += (1.0 - alpha) * a;
        if stops_early(ray) && alpha > ray.settings.termination_alpha {
            break;
        }
    }
    color + (1.0 - alpha) * DVec3::from_array(ray.settings.background)
}

/// DVR over the segments between consecutive samples (the first from the entry point), each
/// classified by [`preintegration::segment`].
fn dvr_preintegrated(ray: &RayInput, counts: &mut FrameCounters) -> DVec3 {
    let range = ray.range();
    let per_mm =
        ray.settings.opacity_step_vox() / (ray.settings.step_vox * ray.volume.min_spacing_mm());
    let (mut color, mut alpha) = (DVec3::ZERO, 0.0);
    let mut front = (0.0, ray.labelled_value(0.0));
    let mut walk = SurfaceWalk::default();
    for s in ray.grid().samples() {
        counts.samples += 1;
        if let Some(Surface {
            colour: c,
            alpha: a,
            ..
        }) = walk.before(ray, front.0, s.t_mm)
        {
            color += (1.0 - alpha) * a * c;
            alpha += (1.0 - alpha) * a;
            if stops_early(ray) && alpha > ray.settings.termination_alpha {
                return color + (1.0 - alpha) * DVec3::from_array(ray.settings.background);
            }
        }
        let back = (s.t_mm, ray.labelled_value(s.t_mm));
        let (t0, v0) = std::mem::replace(&mut front, back);
        let (Some(v0), Some(v1)) = (v0, back.1) else {
            continue;
        };
        let (c, a) = preintegration::segment(ray.tf, range, v0, v1, (s.t_mm - t0) * per_mm);
        if a <= 0.0 {
            continue;
        }
        // A colour volume: the segment's opacity pre-integrated over luminance, its colour the
        // sample's own (the shader's rule).
        let c = sample_colour(ray.volume, ray.entry + ray.dir * s.t_mm).unwrap_or(c);
        let c = ray.labelled_colour(c, s.t_mm);
        counts.visible_samples += 1;
        let c = ray.lit_if_seen(c, s.t_mm, alpha, a);
        color += (1.0 - alpha) * a * c;
        alpha += (1.0 - alpha) * a;
        if stops_early(ray) && alpha > ray.settings.termination_alpha {
            return color + (1.0 - alpha) * DVec3::from_array(ray.settings.background);
        }
    }
    // The last sample lies up to a step before the exit: the segment from it to the exit.
    let (t0, v0) = front;
    if let (Some(v0), Some(v1)) = (v0, ray.labelled_value(ray.length_mm)) {
        let (c, a) = preintegration::segment(ray.tf, range, v0, v1, (ray.length_mm - t0) * per_mm);
        let c = sample_colour(ray.volume, ray.entry + ray.dir * ray.length_mm).unwrap_or(c);
        let c = ray.labelled_colour(c, ray.length_mm);
        if a > 0.0 {
            color += (1.0 - alpha) * a * ray.lit_if_seen(c, ray.length_mm, alpha, a);
            alpha += (1.0 - alpha) * a;
        }
    }
    color + (1.0 - alpha) * DVec3::from_array(ray.settings.background)
}

fn iso(ray: &RayInput, counts: &mut FrameCounters) -> Option<DVec3> {
    let range = ray.range();
    let iso = ray.settings.iso.threshold(range);
    let mut prev: Option<(f64, f64)> = None;
    let mut walk = SurfaceWalk::default();
    let mut before = 0.0;
    let background = DVec3::from_array(ray.settings.background);
    for s in ray.grid().samples() {
        counts.samples += 1;
        // A label's surface entered before this sample: in front of the isosurface unless its
        // crossing in the same step lies nearer.
        let surface = walk.before(ray, std::mem::replace(&mut before, s.t_mm), s.t_mm);
        let crossing = iso_crossing(ray, counts, (iso, &mut prev), s.t_mm);
        if let Some(surface) = &surface
            && crossing.is_none_or(|(hit, _)| surface.t <= hit)
            && walk.add(ray, surface)
            && crossing.is_none()
        {
            return Some(walk.over(background));
        }
        if let Some((_, colour)) = crossing {
            return Some(walk.over(colour));
        }
    }
    SurfaceWalk::drawn(ray).then(|| walk.over(background))
}

/// The isosurface's crossing between the previous finite sample (`prev`: its distance and
/// value − iso) and the sample at `t`, if any: its distance and lit colour.
fn iso_crossing(
    ray: &RayInput,
    counts: &mut FrameCounters,
    (iso, prev): (f64, &mut Option<(f64, f64)>),
    t: f64,
) -> Option<(f64, DVec3)> {
    let d = ray.value(t)? - iso;
    let (t0, d0) = prev.replace((t, d))?;
    if (d >= 0.0) == (d0 >= 0.0) {
        return None;
    }
    let (mut t0, mut d0, mut t1, mut d1) = (t0, d0, t, d);
    let root =
        |t0: f64, d0: f64, t1: f64, d1: f64| t0 + (t1 - t0) * (d0 / (d0 - d1)).clamp(0.0, 1.0);
    for _ in 0..ray.settings.iso.refine_iterations {
        let tm = root(t0, d0, t1, d1);
        let dm = ray.value(tm).unwrap_or(d0 + iso) - iso;
        if (dm >= 0.0) == (d0 >= 0.0) {
            (t0, d0) = (tm, dm);
        } else {
            (t1, d1) = (tm, dm);
        }
    }
    let hit = root(t0, d0, t1, d1);
    // A crossing the labels cut away: the ray goes on, on its new side.
    if !ray.shown(hit) {
        return None;
    }
    counts.visible_samples += 1;
    let colour =
        sample_colour(ray.volume, ray.entry + ray.dir * hit).unwrap_or_else(|| ray.tf_color(iso));
    // Nothing lies in front of the first crossing: a headlight reaches it whole.
    let light = ray.shadow_transmittance(hit, 0.0);
    Some((
        hit,
        ray.lit_shadowed(ray.labelled_colour(colour, hit), hit, light),
    ))
}

fn extreme(ray: &RayInput, counts: &mut FrameCounters) -> Option<DVec3> {
    let minimum = ray.settings.mode == Mode::MinIp;
    let (lo, hi) = ray.window();
    let saturation = match (minimum, ray.settings.mip_color) {
        (true, MipColor::Window) => lo,
        (true, MipColor::Tf) => 0.0,
        (false, MipColor::Window) => hi,
        (false, MipColor::Tf) => 1.0,
    };
    let mut best: Option<(f64, f64)> = None;
    // Labels' surfaces over the projection of the whole ray (which they may hide).
    let mut walk = SurfaceWalk::default();
    let surfaces = SurfaceWalk::drawn(ray);
    let mut before = 0.0;
    for s in ray.grid().samples() {
        counts.samples += 1;
        if let Some(surface) = walk.before(ray, std::mem::replace(&mut before, s.t_mm), s.t_mm)
            && walk.add(ray, &surface)
        {
            break;
        }
        let Some(v) = ray.labelled_value(s.t_mm) else {
            continue;
        };
        let better = best.is_none_or(|(b, _)| if minimum { v < b } else { v > b });
        if better {
            counts.visible_samples += 1;
            best = Some((v, s.t_mm));
        }
        // A saturated projection ends the ray unless a surface may lie behind.
        if stops_early(ray)
            && !surfaces
            && (if minimum {
                v <= saturation
            } else {
                v >= saturation
            })
        {
            break;
        }
    }
    let background = DVec3::from_array(ray.settings.background);
    let projection = best.map(|(v, at)| extreme_colour(ray, (v, at), (lo, hi)));
    if surfaces {
        return Some(walk.over(projection.unwrap_or(background)));
    }
    projection
}

/// The colour of the extreme `v` taken at `at` through the window `(lo, hi)` or the function.
fn extreme_colour(ray: &RayInput, (v, at): (f64, f64), (lo, hi): (f64, f64)) -> DVec3 {
    match ray.settings.mip_color {
        // Grey, tinted by the label where the extreme was taken.
        MipColor::Window => {
            ((v - lo) / (hi - lo)).clamp(0.0, 1.0) * ray.labelled_colour(DVec3::ONE, at)
        }
        MipColor::Tf => {
            let r = ray.range();
            let a = ray.tf.opacity_at(r.denormalize(v), r);
            a * ray.labelled_colour(ray.tf_color(v), at)
                + (1.0 - a) * DVec3::from_array(ray.settings.background)
        }
    }
}

fn xray(ray: &RayInput, counts: &mut FrameCounters) -> DVec3 {
    let (lo, hi) = ray.window();
    let attenuation = ray.settings.mode == Mode::XrayAttenuation;
    let density = ray.settings.xray_density_per_mm;
    let grid = ray.grid();
    let mut integral = 0.0;
    // Labels' surfaces over the projection of the whole ray (which they may hide).
    let mut walk = SurfaceWalk::default();
    let surfaces = SurfaceWalk::drawn(ray);
    let mut before = 0.0;
    for (k, s) in grid.samples().enumerate() {
        counts.samples += 1;
        if let Some(surface) = walk.before(ray, std::mem::replace(&mut before, s.t_mm), s.t_mm)
            && walk.add(ray, &surface)
        {
            break;
        }
        let Some(v) = ray.labelled_value(s.t_mm) else {
            continue;
        };
        let f = ((v - lo) / (hi - lo)).clamp(0.0, 1.0);
        if f <= 0.0 {
            continue;
        }
        counts.visible_samples += 1;
        integral += f * grid.step_mm.min(grid.length_mm - k as f64 * grid.step_mm);
        if attenuation && stops_early(ray) && !surfaces && density * integral > 255f64.ln() {
            break;
        }
    }
    let grey = if attenuation {
        1.0 - (-density * integral).exp()
    } else {
        (integral / ray.length_mm).clamp(0.0, 1.0)
    };
    walk.over(DVec3::splat(grey))
}
