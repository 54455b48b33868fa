//! A disk area light: radiance `L_e(λ)` to the side its normal points to
//! (both when two-sided), sampled uniformly by area (pdf converted to solid
//! angle: `d² / (|cos θ_l| A)`).
//!
//! ```ron
//! objects: [ (shape: Disk(center: (0, 1.98, 0), normal: (0, -1, 0), radius: 0.2), emission: Scaled(15, D65)) ],
//! ```

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

use super::EmissionSample;
use super::emit::{surface_pdf_dir, surface_ray};
use super::{EmissionTexture, LightSample, mean_radiance, sides};
use crate::color::Spectrum;
use crate::geometry::Frame;
use crate::geometry::Hit;
use crate::sampler::warp::concentric_disk;
use crate::shape::{Disk, Shape};

/// A disk light emitting `radiance` to the side its normal points to (both when two-sided).
#[derive(Clone, Debug)]
pub struct DiskLight {
    /// Its shape.
    pub disk: Disk,
    /// Emitted radiance per wavelength.
    pub radiance: Spectrum,
    /// Emits from both sides.
    pub two_sided: bool,
    /// The radiance over the surface's (u, v) when it varies (then
    /// `radiance` is its per-bin peak).
    pub texture: Option<Box<EmissionTexture>>,
}

impl DiskLight {
    /// Total power up to the spectrum's shape: `π A` times the mean radiance per side.
    pub fn power(&self) -> f32 {
        let r = self.disk.radius;
        sides(self.two_sided) * PI * PI * r * r * mean_radiance(&self.radiance, &self.texture)
    }

    /// Samples a point on the disk uniformly by area; the pdf is per solid angle from `p`.
    #[inline]
    pub fn sample_li(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        let disk = &self.disk;
        let frame = Frame::from_z(disk.normal);
        let q = concentric_disk(u) * disk.radius;
        let point = disk.center + frame.to_world(Vec3::new(q.x, q.y, 0.0));
        let d = point - p;
        let d2 = d.length_squared();
        if d2 == 0.0 {
            return None;
        }
        let wi = d / d2.sqrt();
        let cos_l = self.cos_emit(wi);
        if cos_l <= 0.0 {
            return None; // the back of a one-sided light
        }
        let area = PI * disk.radius * disk.radius;
        Some(LightSample { wi, point, n: disk.normal, pdf: d2 / (cos_l * area), scale: 1.0, is_delta: false })
    }

    /// The pdf per solid angle of [`DiskLight::sample_li`] from `p` for `wi` hitting `point`.
    #[inline]
    pub fn pdf_li(&self, p: Vec3, wi: Vec3, point: Vec3) -> f32 {
        let cos_l = self.cos_emit(wi);
        if cos_l <= 0.0 {
            return 0.0;
        }
        let d2 = (point - p).length_squared();
        d2 / (cos_l * PI * self.disk.radius * self.disk.radius)
    }

    /// The cosine at the light of a direction `wi` arriving at it; not
    /// positive from the back of a one-sided light.
    #[inline]
    fn cos_emit(&self, wi: Vec3) -> f32 {
        if self.two_sided { wi.dot(self.disk.normal).abs() } else { -wi.dot(self.disk.normal) }
    }
}

/// Emission sampling: rays leaving the light (BDPT's light subpaths, light tracing).
impl DiskLight {
    /// A cosine-distributed ray from a uniform point of the disk.
    #[inline]
    pub(super) fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Option<EmissionSample> {
        let q = concentric_disk(u_pos) * self.disk.radius;
        let point = self.disk.center + Frame::from_z(self.disk.normal).to_world(Vec3::new(q.x, q.y, 0.0));
        let area = PI * self.disk.radius * self.disk.radius;
        surface_ray(point, self.disk.normal, self.uv(point), area, self.two_sided, u_dir)
    }

    /// The (u, v) of `point` on the disk when the light has a texture (else zero).
    #[inline]
    pub(super) fn uv(&self, point: Vec3) -> Vec2 {
        match self.texture {
            Some(_) => Shape::Disk(self.disk).uv(&Hit::flat(0.0, point, self.disk.normal)),
            None => Vec2::ZERO,
        }
    }

    /// The densities `(pdf_pos, pdf_dir)` of [`Self::sample_le`].
    #[inline]
    pub(super) fn pdf_le(&self, n: Vec3, dir: Vec3) -> (f32, f32) {
        (1.0 / (PI * self.disk.radius * self.disk.radius), surface_pdf_dir(n, dir, self.two_sided))
    }
}
