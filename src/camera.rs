//! The pinhole camera.
//!
//! A look-at pinhole with a vertical field of view. Film position
//! `(px, py)` in `[0, W) × [0, H)` (row 0 at the top) maps to the direction
//! `normalize((2 px / W - 1) tan(fov/2) (W/H) r + (1 - 2 py / H) tan(fov/2) u + f)`,
//! exactly the primary ray of the Mitsuba peer's canonical scene
//! (`shared/peers/mitsuba/SCENE-SPEC.md` §1). Each camera sample is
//! uniformly jittered inside its pixel and contributes to that pixel only
//! (a one-pixel box filter).
//!
//! ```ron
//! camera: (eye: (0, 1, 3.5), look_at: (0, 1, 0), up: (0, 1, 0), fov_deg: 45),
//! ```

use glam::{Vec2, Vec3};

use crate::geometry::Ray;

/// A pinhole camera with its image size.
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
        Camera { eye, forward, right, up, tan_half_y, tan_half_x, width, height }
    }

    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The primary ray through film position `film` (pixel units, y down).
    #[inline]
    pub fn ray(&self, film: Vec2) -> Ray {
        let sx = (2.0 * film.x / self.width as f32 - 1.0) * self.tan_half_x;
        let sy = (1.0 - 2.0 * film.y / self.height as f32) * self.tan_half_y;
        let dir = (self.right * sx + self.up * sy + self.forward).normalize();
        Ray::new(self.eye, dir)
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
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The canonical scene's camera: the box front edges x = ±1 at z = 1
    /// (2.5 from the eye) fall at film coordinate 128 ± 123.6 (SCENE-SPEC §1).
    #[test]
    fn canonical_camera_matches_the_spec() {
        let cam = Camera::new(Vec3::new(0.0, 1.0, 3.5), Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 45.0, 256, 256);
        let centre = cam.ray(Vec2::new(128.0, 128.0));
        assert!((centre.dir - Vec3::NEG_Z).length() < 1e-6);
        let px = 128.0 + 123.6;
        let r = cam.ray(Vec2::new(px, 128.0));
        let t = 2.5 / -r.dir.z;
        assert!((r.at(t).x - 1.0).abs() < 1e-3, "edge at {}", r.at(t).x);
        // Row 0 is the top of the image.
        assert!(cam.ray(Vec2::new(128.0, 0.0)).dir.y > 0.0);
        assert!(cam.ray(Vec2::new(0.0, 128.0)).dir.x < 0.0);
    }

    /// `project` inverts `ray` over the film, and refuses directions off it
    /// or behind the eye; the direction density integrates to 1 over the
    /// film (a midpoint sum over a fine grid of film positions, with the
    /// Jacobian dω = cos³θ dA of the image plane at distance 1).
    #[test]
    fn project_inverts_ray_and_the_density_integrates_to_one() {
        let cam = Camera::new(Vec3::new(0.3, 1.0, 3.0), Vec3::new(0.0, 0.8, 0.0), Vec3::Y, 40.0, 64, 48);
        for (x, y) in [(0.5f32, 0.5f32), (63.9, 0.1), (10.25, 47.75), (32.0, 24.0)] {
            let p = cam.project(cam.ray(Vec2::new(x, y)).dir).unwrap();
            assert!((p - Vec2::new(x, y)).length() < 2e-3, "{x},{y} -> {p}");
        }
        assert!(cam.project(-cam.forward()).is_none());
        assert!(cam.project(cam.ray(Vec2::new(-0.5, 3.0)).dir).is_none());
        let n = 400;
        let mut integral = 0.0f64;
        let da = cam.plane_area() as f64 / (n * n) as f64;
        for i in 0..n {
            for j in 0..n {
                let f = Vec2::new((i as f32 + 0.5) * 64.0 / n as f32, (j as f32 + 0.5) * 48.0 / n as f32);
                let d = cam.ray(f).dir;
                let cos = d.dot(cam.forward()) as f64;
                integral += cam.pdf_dir(d) as f64 * cos * cos * cos * da;
            }
        }
        assert!((integral - 1.0).abs() < 1e-4, "{integral}");
    }

    #[test]
    fn non_square_images_keep_the_vertical_fov() {
        let cam = Camera::new(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 90.0, 200, 100);
        let top = cam.ray(Vec2::new(100.0, 0.0)).dir;
        assert!((top.y / -top.z - 1.0).abs() < 1e-5);
        let right = cam.ray(Vec2::new(200.0, 50.0)).dir;
        assert!((right.x / -right.z - 2.0).abs() < 1e-5);
    }
}
