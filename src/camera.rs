//! The camera: a pinhole, or a thin lens with depth of field.
//!
//! A look-at camera with a vertical field of view. Film position
//! `(px, py)` in `[0, W) × [0, H)` (row 0 at the top) maps to the direction
//! `normalize((2 px / W - 1) tan(fov/2) (W/H) r + (1 - 2 py / H) tan(fov/2) u + f)`,
//! exactly the primary ray of the Mitsuba peer's canonical scene
//! (`shared/peers/mitsuba/SCENE-SPEC.md` §1). Each camera sample is
//! uniformly jittered inside its pixel and contributes to that pixel only
//! (a one-pixel box filter).
//!
//! With `aperture_radius: R > 0` the eye becomes a thin lens of radius `R`
//! centred on it ([`ThinLens`], pbrt-v4's `PerspectiveCamera` with
//! `lensradius` and `focaldistance`): a camera ray starts at a point of the
//! lens and passes through the point where the pinhole ray of its film
//! position meets the plane in focus. With `R = 0` (the default) there is no
//! lens, no lens sample is drawn, and every ray is the pinhole's.
//!
//! ```ron
//! camera: (eye: (0, 1, 3.5), look_at: (0, 1, 0), up: (0, 1, 0), fov_deg: 45),
//! ```

mod lens_camera;
pub mod lens_system;
mod thin_lens;

pub use lens_camera::{LensCamera, LensSample};
pub use thin_lens::ThinLens;

use std::sync::Arc;

use glam::{Vec2, Vec3};

use crate::geometry::Ray;

/// A pinhole or thin-lens camera with its image size.
#[derive(Clone, Debug)]
pub struct Camera {
    eye: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    tan_half_y: f32,
    tan_half_x: f32,
    width: u32,
    height: u32,
    /// The thin lens (`None`: a pinhole at `eye`, or a lens system).
    lens: Option<ThinLens>,
    /// A lens system in front of a film (then `lens` is `None`; the field of
    /// view above is the system's, for the pinhole methods only).
    system: Option<Arc<LensCamera>>,
}

impl Camera {
    /// The eye's position.
    pub fn eye(&self) -> Vec3 {
        self.eye
    }

    /// A camera at `eye` looking at `look_at`; `up` need not be orthogonal to
    /// the view direction, only not parallel to it (checked by the scene loader).
    pub fn new(eye: Vec3, look_at: Vec3, up: Vec3, fov_deg: f32, width: u32, height: u32) -> Self {
        let forward = (look_at - eye).normalize();
        let right = forward.cross(up).normalize();
        let up = right.cross(forward);
        let tan_half_y = (fov_deg.to_radians() * 0.5).tan();
        let tan_half_x = tan_half_y * width as f32 / height as f32;
        Camera { eye, forward, right, up, tan_half_y, tan_half_x, width, height, lens: None, system: None }
    }

    /// This camera with a thin lens of radius `radius` focused on the plane at
    /// distance `focus` along the view direction; a radius of 0 keeps the pinhole.
    pub fn with_thin_lens(mut self, radius: f32, focus: f32) -> Self {
        self.lens = (radius > 0.0).then_some(ThinLens { radius, focus });
        self
    }

    /// This camera looking through the lens system `system` (its front
    /// vertex at the eye), instead of a pinhole or thin lens.
    pub fn with_lens_system(mut self, system: LensCamera) -> Self {
        self.lens = None;
        self.system = Some(Arc::new(system));
        self
    }

    /// The lens system, if the camera looks through one.
    #[inline]
    pub fn lens_system(&self) -> Option<&LensCamera> {
        self.system.as_deref()
    }

    /// The camera ray through the lens system for film position `film`,
    /// exit-pupil sample `u` and wavelength `lambda_nm`, in world space, with
    /// its weight; `None` without a lens system or when the lens blocks it.
    #[inline]
    pub fn lens_system_ray(&self, film: Vec2, u: Vec2, lambda_nm: f32) -> Option<(Ray, f32)> {
        let s = self.system.as_ref()?.ray(film, u, lambda_nm)?;
        let origin = self.eye + self.right * s.origin.x + self.up * s.origin.y + self.forward * s.origin.z;
        let dir = (self.right * s.dir.x + self.up * s.dir.y + self.forward * s.dir.z).normalize();
        Some((Ray::new(origin, dir), s.weight))
    }

    /// The thin lens, if the camera has one.
    #[inline]
    pub fn lens(&self) -> Option<ThinLens> {
        self.lens
    }

    /// True when camera rays need a lens sample (a thin lens of radius > 0).
    #[inline]
    pub fn has_lens(&self) -> bool {
        self.lens.is_some()
    }

    /// The point of the lens for lens sample `u` in [0, 1)² (uniform on the
    /// lens disk, Shirley-Chiu's concentric map); the eye without a lens.
    #[inline]
    pub fn lens_point(&self, u: Vec2) -> Vec3 {
        match self.lens {
            None => self.eye,
            Some(lens) => {
                let d = lens.disk(u);
                self.eye + self.right * d.x + self.up * d.y
            }
        }
    }

    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The primary ray through film position `film` (pixel units, y down)
    /// from the eye: the pinhole's ray, and with a thin lens the ray through
    /// the lens centre (the chief ray, which no lens bends).
    #[inline]
    pub fn ray(&self, film: Vec2) -> Ray {
        let sx = (2.0 * film.x / self.width as f32 - 1.0) * self.tan_half_x;
        let sy = (1.0 - 2.0 * film.y / self.height as f32) * self.tan_half_y;
        let dir = (self.right * sx + self.up * sy + self.forward).normalize();
        Ray::new(self.eye, dir)
    }

    /// The camera ray through film position `film` and lens sample `u_lens`:
    /// from [`Camera::lens_point`] towards the point where the pinhole ray of
    /// `film` meets the plane in focus (pbrt-v4 §5.2.3). Without a lens,
    /// exactly [`Camera::ray`] (`u_lens` unread).
    #[inline]
    pub fn ray_through(&self, film: Vec2, u_lens: Vec2) -> Ray {
        let Some(lens) = self.lens else {
            return self.ray(film);
        };
        let sx = (2.0 * film.x / self.width as f32 - 1.0) * self.tan_half_x;
        let sy = (1.0 - 2.0 * film.y / self.height as f32) * self.tan_half_y;
        // The pinhole direction with unit depth, scaled to the plane in focus.
        let focus = self.eye + (self.right * sx + self.up * sy + self.forward) * lens.focus;
        let origin = self.lens_point(u_lens);
        Ray::new(origin, (focus - origin).normalize())
    }

    /// The viewing direction (unit).
    #[inline]
    pub fn forward(&self) -> Vec3 {
        self.forward
    }

    /// The film position (pixel units) that the unit direction `dir` from
    /// the eye passes through, if it lies on the film: the inverse of
    /// [`Camera::ray`].
    #[inline]
    pub fn project(&self, dir: Vec3) -> Option<Vec2> {
        let z = dir.dot(self.forward);
        if z.is_nan() || z <= 0.0 {
            return None;
        }
        let sx = dir.dot(self.right) / z;
        let sy = dir.dot(self.up) / z;
        let fx = (sx / self.tan_half_x + 1.0) * 0.5 * self.width as f32;
        let fy = (1.0 - sy / self.tan_half_y) * 0.5 * self.height as f32;
        (fx >= 0.0 && fx < self.width as f32 && fy >= 0.0 && fy < self.height as f32).then_some(Vec2::new(fx, fy))
    }

    /// The film position (pixel units) that the camera ray from lens point
    /// `origin` along unit direction `dir` comes from, if it lies on the film:
    /// the inverse of [`Camera::ray_through`]. The ray meets the plane in focus
    /// at `origin + dir · F / cos θ`, and that point's pinhole projection is
    /// the film position. Without a lens, [`Camera::project`] of `dir`
    /// (`origin` is the eye).
    #[inline]
    pub fn project_from(&self, origin: Vec3, dir: Vec3) -> Option<Vec2> {
        let Some(lens) = self.lens else {
            return self.project(dir);
        };
        let z = dir.dot(self.forward);
        if z.is_nan() || z <= 0.0 {
            return None;
        }
        // The focus point relative to the eye, over the focus distance (the
        // lens lies in the plane through the eye perpendicular to `forward`).
        let offset = (origin - self.eye) / lens.focus;
        let sx = offset.dot(self.right) + dir.dot(self.right) / z;
        let sy = offset.dot(self.up) + dir.dot(self.up) / z;
        let fx = (sx / self.tan_half_x + 1.0) * 0.5 * self.width as f32;
        let fy = (1.0 - sy / self.tan_half_y) * 0.5 * self.height as f32;
        (fx >= 0.0 && fx < self.width as f32 && fy >= 0.0 && fy < self.height as f32).then_some(Vec2::new(fx, fy))
    }

    /// The area of the whole film on the image plane at distance 1 from the eye.
    #[inline]
    pub fn plane_area(&self) -> f32 {
        4.0 * self.tan_half_x * self.tan_half_y
    }

    /// The density per unit solid angle of the camera ray directions over
    /// the whole film (one ray per pixel, uniform on the film): `1 / (A cos³θ)`
    /// with `A` the [`Camera::plane_area`], for directions that reach the film
    /// (0 otherwise). Importance `W_e = 1 / (A cos⁴θ)` is this over `cos θ`.
    #[inline]
    pub fn pdf_dir(&self, dir: Vec3) -> f32 {
        if self.project(dir).is_none() {
            return 0.0;
        }
        let cos = dir.dot(self.forward);
        1.0 / (self.plane_area() * cos * cos * cos)
    }

    /// [`Camera::pdf_dir`] for a camera ray from lens point `origin`: the
    /// same `1 / (A cos³θ)` (from any one lens point the directions through
    /// the plane in focus are spread as the pinhole's through its image
    /// plane), for rays whose film position ([`Camera::project_from`]) is on
    /// the film. The lens point's own density is `1 / (π R²)` for every
    /// strategy of a path, so it cancels in MIS and is left out, as pbrt-v4
    /// leaves the camera vertex out of its MIS ratios.
    #[inline]
    pub fn pdf_dir_from(&self, origin: Vec3, dir: Vec3) -> f32 {
        if self.lens.is_none() {
            return self.pdf_dir(dir);
        }
        if self.project_from(origin, dir).is_none() {
            return 0.0;
        }
        let cos = dir.dot(self.forward);
        1.0 / (self.plane_area() * cos * cos * cos)
    }

    /// A connection of a scene point to the camera (light tracing, BDPT's
    /// `t = 1`): `dir` is the unit direction from lens point `from` (the eye
    /// without a lens) towards the point, `d2` their squared distance.
    /// Returns the film position the point is seen at and the camera's
    /// importance over the density of the connection, `W_e / p` (the point's
    /// cosine left to the caller): `1 / (d² A cos³θ)`, `A` the
    /// [`Camera::plane_area`]. For a pinhole `W_e = 1 / (A cos⁴θ)` and the
    /// eye is fixed (`cos θ / d²` turns the eye's solid angle into the
    /// point's area). For a thin lens (pbrt-v4 `PerspectiveCamera::SampleWi`)
    /// `W_e = 1 / (A π R² cos⁴θ)` and the lens point is uniform on the lens,
    /// a density per solid angle at the point of `d² / (cos θ π R²)`: the
    /// lens area cancels and the ratio is the same expression.
    #[inline]
    pub fn importance(&self, from: Vec3, dir: Vec3, d2: f32) -> Option<(Vec2, f32)> {
        let film = self.project_from(from, dir)?;
        let cos = dir.dot(self.forward);
        Some((film, 1.0 / (d2 * self.plane_area() * cos * cos * cos)))
    }
}

#[cfg(test)]
mod tests;
