//! A collimated beam (a sunbeam through a slit, a laser pointer): parallel
//! light of irradiance `E(λ)` travelling along `direction` from a disk of
//! `radius` around `origin`, perpendicular to it. A delta light in direction
//! and limited in space: a point is lit when it lies in the beam's cylinder,
//! in front of the disk, and nothing blocks the segment back to the disk.
//!
//! ```ron
//! lights: [ Beam(origin: (-2, 1, 0), direction: (1, 0, 0), radius: 0.05, irradiance: Scaled(50, EqualEnergy)) ],
//! ```

use crate::error::Result;
use crate::scene::check::Check;
use crate::scene::desc::{SpectrumDesc, V3};
use glam::Vec3;
use std::f32::consts::PI;

use super::EmissionSample;
use super::LightSample;
use super::emit::parallel_ray;
use crate::color::Spectrum;
use glam::Vec2;

/// A beam of parallel light from a disk.
#[derive(Clone, Debug)]
pub struct BeamLight {
    /// Centre of the emitting disk.
    pub origin: Vec3,
    /// Unit direction the light travels in (the disk's normal).
    pub direction: Vec3,
    /// Radius of the beam.
    pub radius: f32,
    /// Irradiance per wavelength across the beam.
    pub irradiance: Spectrum,
}

impl BeamLight {
    /// Total power up to the spectrum's shape: `π r² E`.
    pub fn power(&self) -> f32 {
        PI * self.radius * self.radius * self.irradiance.average()
    }

    /// The direction back along the beam from `p`, and the point on the disk
    /// it came from; `None` outside the beam.
    #[inline]
    pub fn sample_li(&self, p: Vec3) -> Option<LightSample> {
        let q = p - self.origin;
        let t = q.dot(self.direction);
        if t <= 0.0 {
            return None;
        }
        let off_axis = q - self.direction * t;
        if off_axis.length_squared() > self.radius * self.radius {
            return None;
        }
        let point = self.origin + off_axis;
        Some(LightSample { wi: -self.direction, point, n: self.direction, pdf: 1.0, scale: 1.0, is_delta: true })
    }
}

/// Emission sampling: rays leaving the light (BDPT's light subpaths, light tracing).
impl BeamLight {
    /// A ray of the beam, from a uniform point of its disk.
    #[inline]
    pub(super) fn sample_le(&self, u_pos: Vec2) -> Option<EmissionSample> {
        parallel_ray(self.origin, self.direction, self.radius, u_pos)
    }

    /// The densities `(pdf_pos, pdf_dir)` of [`Self::sample_le`] (the
    /// direction is a delta: its part is 1).
    #[inline]
    pub(super) fn pdf_le(&self) -> (f32, f32) {
        (1.0 / (PI * self.radius * self.radius), 1.0)
    }
}

impl BeamLight {
    /// A beam from the scene description at `field` (`lights[i]`).
    pub(crate) fn from_desc(
        check: &Check,
        field: &str,
        origin: V3,
        direction: V3,
        radius: f32,
        irradiance: &SpectrumDesc,
    ) -> Result<BeamLight> {
        Ok(BeamLight {
            origin: check.vec(&format!("{field}.origin"), origin)?,
            direction: check.direction(&format!("{field}.direction"), direction)?,
            radius: check.positive(&format!("{field}.radius"), radius)?,
            irradiance: check.spectrum(&format!("{field}.irradiance"), irradiance)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lit_inside_the_cylinder_in_front_of_the_disk_only() {
        let b = BeamLight { origin: Vec3::ZERO, direction: Vec3::X, radius: 0.5, irradiance: Spectrum::ONE };
        let ls = b.sample_li(Vec3::new(3.0, 0.4, 0.0)).unwrap();
        assert_eq!(ls.wi, Vec3::NEG_X);
        assert!((ls.point - Vec3::new(0.0, 0.4, 0.0)).length() < 1e-6);
        assert!(b.sample_li(Vec3::new(3.0, 0.6, 0.0)).is_none(), "outside the radius");
        assert!(b.sample_li(Vec3::new(-1.0, 0.0, 0.0)).is_none(), "behind the disk");
        assert!((b.power() - std::f32::consts::PI * 0.25).abs() < 1e-6);
    }
}
