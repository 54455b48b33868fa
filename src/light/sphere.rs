//! A spherical area light: radiance `L_e(λ)` from the outer surface (and
//! the inner one when two-sided). Seen from outside it is sampled uniformly
//! over the cone it subtends (pdf per solid angle `1 / (2π (1 − cos θmax))`,
//! pbrt-v4 §6.2.4); from inside (two-sided only), uniformly by area (pdf
//! converted to solid angle: `d² / (|cos θ_l| A)`).
//!
//! ```ron
//! objects: [ (shape: Sphere(center: (-0.6, 1.7, -0.4), radius: 0.2), emission: Scaled(10, EqualEnergy)) ],
//! ```

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

use super::EmissionSample;
use super::emit::{surface_pdf_dir, surface_ray};
use super::{EmissionTexture, LightSample, mean_radiance, sides};
use crate::color::Spectrum;
use crate::geometry::Frame;
use crate::geometry::Hit;
use crate::sampler::warp::{cone_one_minus_cos, cos_sin_2pi, uniform_sphere};
use crate::shape::{Shape, Sphere};

/// A spherical area light emitting `radiance` outward (and inward too when two-sided).
#[derive(Clone, Debug)]
pub struct SphereLight {
    /// Its shape.
    pub sphere: Sphere,
    /// Emitted radiance per wavelength.
    pub radiance: Spectrum,
    /// Emits from both sides.
    pub two_sided: bool,
    /// The radiance over the surface's (u, v) when it varies (then
    /// `radiance` is its per-bin peak).
    pub texture: Option<Box<EmissionTexture>>,
}

impl SphereLight {
    /// Total power up to the spectrum's shape: `π A` times the mean radiance per side.
    pub fn power(&self) -> f32 {
        let r = self.sphere.radius;
        sides(self.two_sided) * PI * 4.0 * PI * r * r * mean_radiance(&self.radiance, &self.texture)
    }

    /// Samples a direction from `p` towards the sphere.
    #[inline(always)]
    pub fn sample_li(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        let sphere = &self.sphere;
        let to_c = sphere.center - p;
        let d2 = to_c.length_squared();
        let r2 = sphere.radius * sphere.radius;
        if by_area(d2, r2) {
            // Inside, or on the sphere within rounding: uniform by area,
            // converted to solid angle.
            let n = uniform_sphere(u);
            let point = sphere.center + n * sphere.radius;
            let d = point - p;
            // A one-sided sphere emits outward only: nothing from a point whose
            // outside does not face `p` (every point, seen from inside).
            if !self.two_sided && d.dot(n) >= 0.0 {
                return None;
            }
            let dist2 = d.length_squared();
            if dist2.is_nan() || dist2 <= 0.0 {
                return None;
            }
            let wi = d / dist2.sqrt();
            let cos_l = wi.dot(n).abs();
            if cos_l == 0.0 {
                return None;
            }
            let pdf = dist2 / (cos_l * 4.0 * PI * r2);
            return Some(LightSample { wi, point, n, pdf, scale: 1.0, is_delta: false });
        }
        let d = d2.sqrt();
        let one_minus_cos_max = cone_one_minus_cos(r2 / d2);
        let frame = Frame::from_z(to_c / d);
        // Uniform in solid angle: 1 − cos θ = u (1 − cos θmax). Computed from
        // v = 1 − cos θ (and sin² θ = v (2 − v)), never from cos θ, which
        // f32 cannot resolve near 1 for a small or distant light.
        let v = u.x * one_minus_cos_max;
        let cos_t = 1.0 - v;
        let sin2_t = (v * (2.0 - v)).max(0.0);
        let sin_t = sin2_t.sqrt();
        let (cos_phi, sin_phi) = cos_sin_2pi(u.y);
        let local = Vec3::new(sin_t * cos_phi, sin_t * sin_phi, cos_t);
        let wi = frame.to_world(local).normalize();
        // Distance to the near intersection along wi (pbrt-v4 eq. 6.x, stable form).
        let dist = d * cos_t - (r2 - d2 * sin2_t).max(0.0).sqrt();
        let point = p + wi * dist;
        let pdf = 1.0 / (2.0 * PI * one_minus_cos_max);
        let n = (point - sphere.center) / sphere.radius;
        Some(LightSample { wi, point, n, pdf, scale: 1.0, is_delta: false })
    }

    /// The pdf per solid angle of [`SphereLight::sample_li`] from `p` for `wi` hitting `point`.
    #[inline]
    pub fn pdf_li(&self, p: Vec3, wi: Vec3, point: Vec3) -> f32 {
        let sphere = &self.sphere;
        let d2 = (sphere.center - p).length_squared();
        let r2 = sphere.radius * sphere.radius;
        if by_area(d2, r2) {
            let n = (point - sphere.center) / sphere.radius;
            if !self.two_sided && (point - p).dot(n) >= 0.0 {
                return 0.0;
            }
            let cos_l = wi.dot(n).abs();
            return (point - p).length_squared() / (cos_l * 4.0 * PI * r2);
        }
        1.0 / (2.0 * PI * cone_one_minus_cos(r2 / d2))
    }
}

/// Whether a shading point at squared distance `d2` from the centre of a
/// sphere of squared radius `r2` samples the sphere by area (inside it, or on
/// it within rounding: [`ON_SPHERE`]) rather than by the cone it subtends
/// (outside). A point on the sphere itself (a path scattering on the emitting
/// sphere, or a furnace made of it) is inside or outside only by rounding; the
/// cone there is a hemisphere whose sampled point is `p` itself, at distance 0,
/// which made BDPT 11.5% dark in a two-sided sphere furnace and let a
/// one-sided sphere light its own inside. Area sampling is right from
/// anywhere (the sphere's far side is occluded by the sphere), so the band
/// only trades a little variance for points just outside.
#[inline]
fn by_area(d2: f32, r2: f32) -> bool {
    d2 <= r2 * (1.0 + ON_SPHERE)
}

/// The relative band of squared distance around the sphere treated as on it
/// (1e-4: points within 5e-5 radii; hit points lie within about 1e-6).
const ON_SPHERE: f32 = 1e-4;

/// Emission sampling: rays leaving the light (BDPT's light subpaths, light tracing).
impl SphereLight {
    /// A cosine-distributed ray from a uniform point of the sphere.
    #[inline]
    pub(super) fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Option<EmissionSample> {
        let n = uniform_sphere(u_pos);
        let point = self.sphere.center + n * self.sphere.radius;
        let area = 4.0 * PI * self.sphere.radius * self.sphere.radius;
        surface_ray(point, n, self.uv(point), area, self.two_sided, u_dir)
    }

    /// The (u, v) of `point` on the sphere when the light has a texture (else zero).
    #[inline]
    pub(super) fn uv(&self, point: Vec3) -> Vec2 {
        match self.texture {
            Some(_) => Shape::Sphere(self.sphere).uv(&Hit::flat(0.0, point, Vec3::ZERO)),
            None => Vec2::ZERO,
        }
    }

    /// The densities `(pdf_pos, pdf_dir)` of [`Self::sample_le`].
    #[inline]
    pub(super) fn pdf_le(&self, n: Vec3, dir: Vec3) -> (f32, f32) {
        (1.0 / (4.0 * PI * self.sphere.radius * self.sphere.radius), surface_pdf_dir(n, dir, self.two_sided))
    }
}
