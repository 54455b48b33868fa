//! The thin lens: an aperture disk at the eye, perpendicular to the view
//! direction, and the distance of the plane in focus (pbrt-v4 §5.2.3).
//!
//! A point at depth `d` along the view direction is imaged, through the lens
//! of radius `R` focused at depth `F`, as a disk whose diameter on the plane
//! in focus is the circle of confusion `c = 2R · |d − F| / d` (similar
//! triangles through the lens's rim); a point on the plane in focus images to
//! a point. On the film, that plane's `2 F tan(fov/2)` spans the image's
//! height.
//!
//! ```ron
//! camera: (eye: (0, 1, 3.5), look_at: (0, 1, 0), fov_deg: 45, aperture_radius: 0.05, focus_distance: 3.5),
//! ```

use glam::Vec2;

use crate::sampler::warp::concentric_disk;

/// A thin lens: its radius (> 0) and focus distance (> 0), both in scene units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    /// The aperture's radius.
    pub radius: f32,
    /// The distance from the lens to the plane in focus, along the view direction.
    pub focus: f32,
}

impl ThinLens {
    /// The point of the lens disk for sample `u` in [0, 1)², in the lens
    /// plane's own coordinates (right, up): uniform by area.
    #[inline]
    pub fn disk(&self, u: Vec2) -> Vec2 {
        concentric_disk(u) * self.radius
    }

    /// The lens's area, `π R²`.
    #[inline]
    pub fn area(&self) -> f32 {
        std::f32::consts::PI * self.radius * self.radius
    }
}
