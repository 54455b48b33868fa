//! An isotropic point light: intensity `I(λ)` from one point, a delta
//! light (found only by light sampling; irradiance `I cos θ / d²`).
//!
//! ```ron
//! lights: [ Point(position: (0, 1.9, 0), intensity: Scaled(2, D65)) ],
//! ```

use crate::error::Result;
use crate::scene::check::Check;
use crate::scene::desc::{SpectrumDesc, V3};
use glam::Vec3;
use std::f32::consts::PI;

use super::EmissionSample;
use super::LightSample;
use crate::color::Spectrum;
use crate::sampler::warp::uniform_sphere;
use glam::Vec2;

/// An isotropic point light of intensity `intensity` (W/sr/nm, arbitrary units).
#[derive(Clone, Debug)]
pub struct PointLight {
    /// Position.
    pub position: Vec3,
    /// Radiant intensity per wavelength.
    pub intensity: Spectrum,
}

impl PointLight {
    /// Total power up to the spectrum's shape: `4π` times the mean intensity.
    pub fn power(&self) -> f32 {
        4.0 * PI * self.intensity.average()
    }

    /// The direction to the light from `p`, with the `1/d²` falloff as `scale`.
    #[inline]
    pub fn sample_li(&self, p: Vec3) -> Option<LightSample> {
        toward(self.position, p)
    }
}

/// The delta sample of a light at `position` seen from `p`: the unit
/// direction and `1/d²` as `scale` (spot lights multiply in their falloff).
#[inline]
pub(super) fn toward(position: Vec3, p: Vec3) -> Option<LightSample> {
    let d = position - p;
    let d2 = d.length_squared();
    if d2 == 0.0 {
        return None;
    }
    Some(LightSample { wi: d / d2.sqrt(), point: position, n: Vec3::ZERO, pdf: 1.0, scale: 1.0 / d2, is_delta: true })
}

/// Emission sampling: rays leaving the light (BDPT's light subpaths, light tracing).
impl PointLight {
    /// A ray leaving the light in a uniform direction drawn with `u_dir`.
    #[inline]
    pub(super) fn sample_le(&self, u_dir: Vec2) -> Option<EmissionSample> {
        Some(EmissionSample {
            point: self.position,
            n: Vec3::ZERO,
            dir: uniform_sphere(u_dir),
            pdf_pos: 1.0,
            pdf_dir: 1.0 / (4.0 * PI),
            scale: 1.0,
            uv: Vec2::ZERO,
        })
    }

    /// The densities `(pdf_pos, pdf_dir)` of [`Self::sample_le`].
    #[inline]
    pub(super) fn pdf_le(&self) -> (f32, f32) {
        (1.0, 1.0 / (4.0 * PI))
    }
}

impl PointLight {
    /// A point light from the scene description at `field` (`lights[i]`).
    pub(crate) fn from_desc(check: &Check, field: &str, position: V3, intensity: &SpectrumDesc) -> Result<PointLight> {
        Ok(PointLight {
            position: check.vec(&format!("{field}.position"), position)?,
            intensity: check.spectrum(&format!("{field}.intensity"), intensity)?,
        })
    }
}
