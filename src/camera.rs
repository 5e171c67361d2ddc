//! Camera maths in world millimetres (f64): look-at cameras, perspective and orthographic
//! projections, the standard views, orbit/pan/zoom, and the per-pixel rays that both the GPU
//! uniforms and the CPU reference ray caster are built from.
//!
//! Frames: *world* is millimetres with voxel centre `(i, j, k)` at `(i*sx, j*sy, k*sz)`; *view* is
//! right-handed with the eye at the origin looking down −z; *clip* is wgpu's (depth 0..1). Pixel
//! `(px, py)` has its centre at NDC `x = 2(px+½)/w − 1`, `y = 1 − 2(py+½)/h` (row 0 at the top).

use glam::{DMat4, DVec2, DVec3, DVec4};
use serde::{Deserialize, Serialize};

/// An axis-aligned box in world millimetres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: DVec3,
    /// Largest corner.
    pub max: DVec3,
}

impl Aabb {
    /// The bounding box of a volume: voxel centre `i` at `i * s`, so `[-s/2, (n - 1/2) s]`.
    pub fn of_volume(dims: [u32; 3], spacing_mm: [f64; 3]) -> Self {
        let s = DVec3::from_array(spacing_mm);
        let n = DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64);
        Self {
            min: -0.5 * s,
            max: (n - 0.5) * s,
        }
    }

    /// Centre of the box.
    pub fn center(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// Edge lengths.
    pub fn size(&self) -> DVec3 {
        self.max - self.min
    }

    /// Radius of the bounding sphere.
    pub fn radius(&self) -> f64 {
        0.5 * self.size().length()
    }

    /// The eight corners.
    pub fn corners(&self) -> [DVec3; 8] {
        std::array::from_fn(|i| {
            DVec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }

    /// The affine map from normalised box coordinates `[0,1]³` (the volume's texture
    /// coordinates) to world millimetres.
    pub(crate) fn world_from_box(&self) -> DMat4 {
        DMat4::from_translation(self.min) * DMat4::from_scale(self.size())
    }

    /// Parametric interval `[t0, t1]` over which `origin + t·dir` lies in the box (slab test),
    /// or `None` when the line misses it. Axis-parallel rays (zero direction components) are
    /// handled exactly: such a ray is inside the slab iff its origin is.
    pub fn intersect(&self, origin: DVec3, dir: DVec3) -> Option<(f64, f64)> {
        let mut t0 = f64::NEG_INFINITY;
        let mut t1 = f64::INFINITY;
        for a in 0..3 {
            let (o, d, lo, hi) = (origin[a], dir[a], self.min[a], self.max[a]);
            if d == 0.0 {
                if o < lo || o > hi {
                    return None;
                }
                continue;
            }
            let (ta, tb) = ((lo - o) / d, (hi - o) / d);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
        (t0 <= t1).then_some((t0, t1))
    }
}

/// How the camera projects.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Projection {
    /// Pinhole camera with a vertical field of view in degrees.
    Perspective {
        /// Vertical field of view, degrees, in (0, 180).
        fov_y_deg: f64,
    },
    /// Parallel projection showing a view `height_mm` tall.
    Orthographic {
        /// Height of the visible region in millimetres.
        height_mm: f64,
    },
}

/// Which kind of projection, without its parameter (for the CLI and settings).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
pub enum ProjectionKind {
    /// Perspective (pinhole) projection.
    Perspective,
    /// Orthographic (parallel) projection.
    Orthographic,
}

/// The standard views: look along an axis of the volume, or a fixed oblique view.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ViewPreset {
    /// Look along +x (eye on the −x side).
    PlusX,
    /// Look along −x.
    MinusX,
    /// Look along +y.
    PlusY,
    /// Look along −y.
    MinusY,
    /// Look along +z.
    PlusZ,
    /// Look along −z.
    MinusZ,
    /// Azimuth 30°, elevation 20°: a three-quarter view.
    Oblique,
}

impl ViewPreset {
    /// Parses `+x`, `-x`, …, `oblique`.
    pub fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "+x" | "x" => Self::PlusX,
            "-x" => Self::MinusX,
            "+y" | "y" => Self::PlusY,
            "-y" => Self::MinusY,
            "+z" | "z" => Self::PlusZ,
            "-z" => Self::MinusZ,
            "oblique" => Self::Oblique,
            _ => return None,
        })
    }

    /// Unit viewing direction and up vector in world (= volume axis) frame.
    ///
    /// Volumes from DICOM and NIfTI have z pointing to the head (superior) and y to the back
    /// (posterior), so side views keep +z up and views along z keep −y (anterior) up, as in
    /// radiological displays.
    pub fn direction_and_up(self) -> (DVec3, DVec3) {
        match self {
            Self::PlusX => (DVec3::X, DVec3::Z),
            Self::MinusX => (DVec3::NEG_X, DVec3::Z),
            Self::PlusY => (DVec3::Y, DVec3::Z),
            Self::MinusY => (DVec3::NEG_Y, DVec3::Z),
            Self::PlusZ => (DVec3::Z, DVec3::NEG_Y),
            Self::MinusZ => (DVec3::NEG_Z, DVec3::NEG_Y),
            Self::Oblique => (orbit_direction(30.0, 20.0), DVec3::Z),
        }
    }
}

/// Viewing direction for an orbit position: azimuth 0° looks along +y (eye on the −y side,
/// facing the patient's front), positive azimuth turns the eye towards +x; elevation lifts the eye
/// towards +z.
pub fn orbit_direction(azimuth_deg: f64, elevation_deg: f64) -> DVec3 {
    let (az, el) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
    // Eye offset from the target, then the viewing direction is its opposite.
    let eye_dir = DVec3::new(az.sin() * el.cos(), -az.cos() * el.cos(), el.sin());
    -eye_dir
}

/// A look-at camera in world millimetres.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    /// Eye position.
    pub eye: DVec3,
    /// Point looked at (also the orbit centre).
    pub target: DVec3,
    /// Approximate up direction (made orthogonal to the view direction).
    pub up: DVec3,
    /// Projection.
    pub projection: Projection,
}

/// Default vertical field of view in degrees.
pub const DEFAULT_FOV_Y_DEG: f64 = 30.0;

impl Camera {
    /// A camera looking along `direction` at the centre of `bounds`, far enough that the whole
    /// bounding sphere fits the viewport (for either projection), with a 5 % margin.
    pub fn framing(bounds: &Aabb, direction: DVec3, up: DVec3, kind: ProjectionKind) -> Self {
        let dir = direction.normalize_or(DVec3::NEG_Z);
        let radius = bounds.radius().max(f64::MIN_POSITIVE);
        let fov = DEFAULT_FOV_Y_DEG.to_radians();
        let distance = 1.05 * radius / (0.5 * fov).sin();
        let target = bounds.center();
        let projection = match kind {
            ProjectionKind::Perspective => Projection::Perspective {
                fov_y_deg: DEFAULT_FOV_Y_DEG,
            },
            ProjectionKind::Orthographic => Projection::Orthographic {
                height_mm: 2.1 * radius,
            },
        };
        Self {
            eye: target - dir * distance,
            target,
            up: if up.cross(dir).length_squared() > 1e-12 {
                up
            } else {
                dir.any_orthonormal_vector()
            },
            projection,
        }
    }

    /// Unit viewing direction.
    pub fn forward(&self) -> DVec3 {
        (self.target - self.eye).normalize_or(DVec3::NEG_Z)
    }

    /// The view matrix (world → view, right-handed, looking down −z).
    pub(crate) fn view_from_world(&self) -> DMat4 {
        let forward = self.forward();
        let up = if self.up.cross(forward).length_squared() > 1e-12 {
            self.up
        } else {
            forward.any_orthonormal_vector()
        };
        DMat4::look_to_rh(self.eye, forward, up)
    }

    /// View-space depth range `(near, far)` that contains `bounds`: far just beyond the farthest
    /// corner; near just before the nearest corner, or a small fraction of `far` when the eye is
    /// inside or close to the box (then rays start on the near plane).
    pub(crate) fn near_far(&self, bounds: &Aabb) -> (f64, f64) {
        let view = self.view_from_world();
        let depths = bounds.corners().map(|c| -view.transform_point3(c).z);
        let d_min = depths.iter().copied().fold(f64::INFINITY, f64::min);
        let d_max = depths.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let far = (d_max * 1.01)
            .max(bounds.radius() * 1e-3)
            .max(f64::MIN_POSITIVE);
        let near = (d_min * 0.99).max(far * 1e-5);
        (near, far)
    }

    /// The projection matrix (view → clip, wgpu depth 0..1) for a viewport aspect `w / h`.
    fn clip_from_view(&self, aspect: f64, near: f64, far: f64) -> DMat4 {
        match self.projection {
            Projection::Perspective { fov_y_deg } => {
                DMat4::perspective_rh(fov_y_deg.to_radians(), aspect, near, far)
            }
            Projection::Orthographic { height_mm } => {
                let h = 0.5 * height_mm;
                let w = h * aspect;
                DMat4::orthographic_rh(-w, w, -h, h, near, far)
            }
        }
    }

    /// World → clip for a viewport of `size` pixels framing `bounds`.
    pub(crate) fn clip_from_world(&self, size: [u32; 2], bounds: &Aabb) -> DMat4 {
        let aspect = size[0].max(1) as f64 / size[1].max(1) as f64;
        let (near, far) = self.near_far(bounds);
        self.clip_from_view(aspect, near, far) * self.view_from_world()
    }

    /// The ray through the centre of pixel `(px, py)`: origin on the near plane, unit direction.
    pub fn pixel_ray(&self, px: f64, py: f64, size: [u32; 2], bounds: &Aabb) -> (DVec3, DVec3) {
        let world_from_clip = self.clip_from_world(size, bounds).inverse();
        let ndc = pixel_to_ndc(DVec2::new(px + 0.5, py + 0.5), size);
        let near = unproject(world_from_clip, ndc, 0.0);
        let far = unproject(world_from_clip, ndc, 1.0);
        (near, (far - near).normalize())
    }

    /// Rotates the eye about the target: `d_azimuth_deg` about the up axis, `d_elevation_deg`
    /// about the camera's right axis (clamped short of the poles so up stays defined).
    pub fn orbit(&mut self, d_azimuth_deg: f64, d_elevation_deg: f64) {
        let offset = self.eye - self.target;
        let up = self.up.normalize_or(DVec3::Z);
        let right = self.forward().cross(up).normalize_or(DVec3::X);
        let yaw = glam::DQuat::from_axis_angle(up, -d_azimuth_deg.to_radians());
        let mut offset = yaw * offset;
        let angle_to_up = offset.angle_between(up).to_degrees();
        let pitch_deg = d_elevation_deg.clamp(angle_to_up - 179.0, angle_to_up - 1.0);
        let right = yaw * right;
        offset = glam::DQuat::from_axis_angle(right, -pitch_deg.to_radians()) * offset;
        self.eye = self.target + offset;
    }

    /// Turns the view about its viewing direction by `deg` degrees, clockwise on screen for
    /// positive angles (the picture turns, the eye stays): a rolled patient is put upright.
    pub(crate) fn roll(&mut self, deg: f64) {
        let forward = self.forward();
        let up = self.up.normalize_or(DVec3::Z);
        // Up rotated anticlockwise about the line of sight (as seen from the eye) turns the
        // picture clockwise.
        let turned = glam::DQuat::from_axis_angle(forward, -deg.to_radians()) * up;
        // Keep it exactly across the line of sight, whatever rounding did.
        let right = forward.cross(turned);
        self.up = right.cross(forward).normalize_or(up);
    }

    /// Moves eye and target together by a fraction of the view's size: `dx` to the right, `dy` up.
    pub(crate) fn pan(&mut self, dx: f64, dy: f64, view_height_mm: f64) {
        let forward = self.forward();
        let right = forward.cross(self.up).normalize_or(DVec3::X);
        let up = right.cross(forward);
        let shift = (right * dx + up * dy) * view_height_mm;
        self.eye += shift;
        self.target += shift;
    }

    /// Height of the visible region at the target's distance, in millimetres.
    pub(crate) fn view_height_at_target_mm(&self) -> f64 {
        match self.projection {
            Projection::Perspective { fov_y_deg } => {
                2.0 * (self.eye - self.target).length() * (0.5 * fov_y_deg.to_radians()).tan()
            }
            Projection::Orthographic { height_mm } => height_mm,
        }
    }

    /// Zooms by `factor` (> 1 moves closer): dolly for perspective, shrink the view for
    /// orthographic. The distance never drops below a micrometre.
    pub(crate) fn zoom(&mut self, factor: f64) {
        let factor = if factor.is_finite() && factor > 0.0 {
            factor
        } else {
            1.0
        };
        match &mut self.projection {
            Projection::Perspective { .. } => {
                let offset = (self.eye - self.target) / factor;
                let len = offset.length().max(1e-3);
                self.eye = self.target + offset.normalize_or(DVec3::Z) * len;
            }
            Projection::Orthographic { height_mm } => *height_mm = (*height_mm / factor).max(1e-3),
        }
    }
}

/// NDC coordinates of a point given in pixels (y down) for a viewport of `size` pixels.
pub(crate) fn pixel_to_ndc(p: DVec2, size: [u32; 2]) -> DVec2 {
    DVec2::new(
        2.0 * p.x / size[0].max(1) as f64 - 1.0,
        1.0 - 2.0 * p.y / size[1].max(1) as f64,
    )
}

/// World point at NDC `(x, y)` and clip depth `z`.
pub(crate) fn unproject(world_from_clip: DMat4, ndc: DVec2, z: f64) -> DVec3 {
    let p = world_from_clip * DVec4::new(ndc.x, ndc.y, z, 1.0);
    p.truncate() / p.w
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box() -> Aabb {
        Aabb::of_volume([10, 20, 5], [1.0, 0.5, 2.0])
    }

    #[test]
    fn volume_box_puts_voxel_centres_at_multiples_of_spacing() {
        let b = unit_box();
        assert_eq!(b.min, DVec3::new(-0.5, -0.25, -1.0));
        assert_eq!(b.max, DVec3::new(9.5, 9.75, 9.0));
        let wb = b.world_from_box();
        // Texture coordinate (i + 0.5) / n must land on voxel centre i * s.
        let p = wb.transform_point3(DVec3::new(3.5 / 10.0, 0.5 / 20.0, 4.5 / 5.0));
        assert!((p - DVec3::new(3.0, 0.0, 8.0)).length() < 1e-12);
    }

    #[test]
    fn slab_test_handles_axis_parallel_rays() {
        let b = unit_box();
        let hit = b.intersect(DVec3::new(0.0, 0.0, -10.0), DVec3::Z);
        assert_eq!(hit, Some((9.0, 19.0)));
        assert_eq!(b.intersect(DVec3::new(20.0, 0.0, -10.0), DVec3::Z), None);
    }

    #[test]
    fn framing_sees_the_whole_box_and_centre_ray_hits_the_centre() {
        let b = unit_box();
        for preset in [ViewPreset::PlusX, ViewPreset::MinusZ, ViewPreset::Oblique] {
            let (dir, up) = preset.direction_and_up();
            for kind in [ProjectionKind::Perspective, ProjectionKind::Orthographic] {
                let cam = Camera::framing(&b, dir, up, kind);
                let clip = cam.clip_from_world([64, 64], &b);
                for c in b.corners() {
                    let p = clip * c.extend(1.0);
                    let ndc = p.truncate() / p.w;
                    assert!(
                        ndc.x.abs() < 1.0 && ndc.y.abs() < 1.0,
                        "{preset:?} {kind:?}"
                    );
                    assert!(
                        (0.0..=1.0).contains(&ndc.z),
                        "{preset:?} {kind:?} depth {}",
                        ndc.z
                    );
                }
                // The ray through the image centre (between pixels 31 and 32) passes the target.
                let (o, d) = cam.pixel_ray(31.5, 31.5, [64, 64], &b);
                let to_target = cam.target - o;
                let off_axis = to_target - d * to_target.dot(d);
                assert!(off_axis.length() < 1e-9, "{preset:?} {kind:?}");
            }
        }
    }

    #[test]
    fn orbit_keeps_distance_and_up_side() {
        let b = unit_box();
        let (dir, up) = ViewPreset::MinusY.direction_and_up();
        let mut cam = Camera::framing(&b, dir, up, ProjectionKind::Perspective);
        let d0 = (cam.eye - cam.target).length();
        cam.orbit(90.0, 0.0);
        assert!(((cam.eye - cam.target).length() - d0).abs() < 1e-9);
        cam.orbit(0.0, 500.0);
        // Clamped 1° short of the pole: the eye never reaches the up axis.
        assert!((cam.eye - cam.target).angle_between(cam.up).to_degrees() >= 0.99);
    }

    #[test]
    fn roll_turns_the_picture_about_the_line_of_sight() {
        let b = unit_box();
        let (dir, up) = ViewPreset::MinusY.direction_and_up();
        let mut cam = Camera::framing(&b, dir, up, ProjectionKind::Perspective);
        let (eye, target) = (cam.eye, cam.target);
        let screen_right = |c: &Camera| c.forward().cross(c.up).normalize();
        // Clockwise by 90°: what was at the top of the picture is now on the right.
        let top = cam.up;
        cam.roll(90.0);
        assert!((screen_right(&cam) - top).length() < 1e-12, "{:?}", cam.up);
        assert_eq!((cam.eye, cam.target), (eye, target), "the eye stays");
        assert!(cam.up.dot(cam.forward()).abs() < 1e-12);
        // Four quarter turns, or one turn and its reverse, bring the view back.
        for _ in 0..3 {
            cam.roll(90.0);
        }
        assert!((cam.up - top).length() < 1e-12);
        cam.roll(37.0);
        cam.roll(-37.0);
        assert!((cam.up - top).length() < 1e-12);
    }
}
