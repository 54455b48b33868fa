//! A distant light (the sun): irradiance `E(λ)` on a surface facing it,
//! from one direction, everywhere in the scene. A delta light in direction:
//! a shading point sees it through a shadow ray towards `-direction`, long
//! enough to leave the scene's bounds.
//!
//! ```ron
//! lights: [ Distant(direction: (-1, -2, -1), irradiance: Scaled(3, D65)) ],
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

/// Parallel light travelling along `direction`.
#[derive(Clone, Debug)]
pub struct DistantLight {
    /// Unit direction the light travels in.
    pub direction: Vec3,
    /// Irradiance per wavelength on a surface perpendicular to it.
    pub irradiance: Spectrum,
    /// Radius of a sphere around the scene's bounded objects and camera
    /// (set by the scene): shadow rays are this long, twice over.
    pub scene_radius: f32,
    /// The centre of that sphere (where light tracing starts its rays).
    pub scene_center: Vec3,
}

impl DistantLight {
    /// Total power up to the spectrum's shape: the irradiance through the
    /// scene's disk, `π R² E`.
    pub fn power(&self) -> f32 {
        PI * self.scene_radius * self.scene_radius * self.irradiance.average()
    }

    /// The direction to the light from any point, and a point far outside the scene along it.
    #[inline]
    pub fn sample_li(&self, p: Vec3) -> Option<LightSample> {
        let wi = -self.direction;
        let point = p + wi * (2.0 * self.scene_radius);
        Some(LightSample { wi, point, n: self.direction, pdf: 1.0, scale: 1.0, is_delta: true })
    }
}

/// Emission sampling: rays leaving the light (BDPT's light subpaths, light tracing).
impl DistantLight {
    /// A ray of the light's parallel bundle through the disk that covers the
    /// scene's bounding sphere, facing the light's direction.
    #[inline]
    pub(super) fn sample_le(&self, u_pos: Vec2) -> Option<EmissionSample> {
        let r = self.scene_radius;
        parallel_ray(self.scene_center - self.direction * r, self.direction, r, u_pos)
    }

    /// The densities `(pdf_pos, pdf_dir)` of [`Self::sample_le`] (the
    /// direction is a delta: its part is 1).
    #[inline]
    pub(super) fn pdf_le(&self) -> (f32, f32) {
        (1.0 / (PI * self.scene_radius * self.scene_radius), 1.0)
    }
}

impl DistantLight {
    /// A distant light from the scene description at `field` (`lights[i]`); the scene
    /// sets its bounds later.
    pub(crate) fn from_desc(
        check: &Check,
        field: &str,
        direction: V3,
        irradiance: &SpectrumDesc,
    ) -> Result<DistantLight> {
        Ok(DistantLight {
            direction: check.direction(&format!("{field}.direction"), direction)?,
            irradiance: check.spectrum(&format!("{field}.irradiance"), irradiance)?,
            scene_radius: 1.0,
            scene_center: Vec3::ZERO,
        })
    }
}
