//! A spot light: a point light limited to a cone, with a smooth falloff at
//! its edge (pbrt-v4's spotlight, §12.2.1). Inside `cone_deg - falloff_deg`
//! of the axis the intensity is `I(λ)`; between that and `cone_deg` it falls
//! to 0 by a smoothstep in the cosine; outside it is 0. A delta light.
//!
//! ```ron
//! lights: [ Spot(position: (0, 1.9, 0), look_at: (0, 0, 0), cone_deg: 30, falloff_deg: 5, intensity: Scaled(20, D65)) ],
//! ```

use crate::error::Result;
use crate::scene::check::Check;
use crate::scene::desc::{SpectrumDesc, V3};
use glam::Vec3;
use std::f32::consts::PI;

use super::EmissionSample;
use super::LightSample;
use super::point::toward;
use crate::color::Spectrum;
use crate::geometry::Frame;
use glam::Vec2;

/// A spot light at `position` pointing along `axis`.
#[derive(Clone, Debug)]
pub struct SpotLight {
    /// Position.
    pub position: Vec3,
    /// Unit direction of the cone's axis.
    pub axis: Vec3,
    /// Cosine of the cone's half-angle: no light beyond it.
    pub cos_total: f32,
    /// Cosine of the angle where the falloff starts: full intensity within it.
    pub cos_falloff_start: f32,
    /// Radiant intensity per wavelength on the axis.
    pub intensity: Spectrum,
}

impl SpotLight {
    /// A spot light of half-angle `cone_deg` whose edge falls off over `falloff_deg`.
    pub fn new(position: Vec3, axis: Vec3, cone_deg: f32, falloff_deg: f32, intensity: Spectrum) -> SpotLight {
        let cos_total = cone_deg.to_radians().cos();
        let cos_falloff_start = (cone_deg - falloff_deg).max(0.0).to_radians().cos();
        SpotLight { position, axis, cos_total, cos_falloff_start, intensity }
    }

    /// The intensity's factor towards a unit direction `w` leaving the light.
    #[inline]
    pub fn falloff(&self, w: Vec3) -> f32 {
        let cos = w.dot(self.axis);
        if cos >= self.cos_falloff_start {
            1.0
        } else if cos <= self.cos_total {
            0.0
        } else {
            let t = (cos - self.cos_total) / (self.cos_falloff_start - self.cos_total);
            t * t * (3.0 - 2.0 * t)
        }
    }

    /// Total power up to the spectrum's shape: the mean intensity times the
    /// falloff integrated over the sphere, `2π ((1 − cos_start) + (cos_start − cos_total) / 2)`
    /// (the smoothstep averages 1/2 over its interval of cosines).
    pub fn power(&self) -> f32 {
        let full = 1.0 - self.cos_falloff_start;
        let edge = (self.cos_falloff_start - self.cos_total) * 0.5;
        2.0 * PI * (full + edge) * self.intensity.average()
    }

    /// The direction to the light from `p`, with falloff and `1/d²` as `scale`.
    #[inline]
    pub fn sample_li(&self, p: Vec3) -> Option<LightSample> {
        let mut ls = toward(self.position, p)?;
        let f = self.falloff(-ls.wi);
        if f <= 0.0 {
            return None;
        }
        ls.scale *= f;
        Some(ls)
    }
}

/// Emission sampling: rays leaving the light (BDPT's light subpaths, light tracing).
impl SpotLight {
    /// A ray leaving the light in a direction drawn uniformly within its cone
    /// with `u_dir`, carrying the falloff as its scale.
    #[inline]
    pub(super) fn sample_le(&self, u_dir: Vec2) -> Option<EmissionSample> {
        let one_minus_cos = 1.0 - self.cos_total;
        if one_minus_cos <= 0.0 {
            return None;
        }
        let v = u_dir.x * one_minus_cos;
        let cos = 1.0 - v;
        let sin = (v * (2.0 - v)).max(0.0).sqrt();
        let phi = 2.0 * PI * u_dir.y;
        let dir = Frame::from_z(self.axis).to_world(Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)).normalize();
        let scale = self.falloff(dir);
        (scale > 0.0).then_some(EmissionSample {
            point: self.position,
            n: Vec3::ZERO,
            dir,
            pdf_pos: 1.0,
            pdf_dir: 1.0 / (2.0 * PI * one_minus_cos),
            scale,
            uv: Vec2::ZERO,
        })
    }

    /// The densities `(pdf_pos, pdf_dir)` of [`Self::sample_le`] for `dir`.
    #[inline]
    pub(super) fn pdf_le(&self, dir: Vec3) -> (f32, f32) {
        let inside = dir.dot(self.axis) >= self.cos_total && self.cos_total < 1.0;
        (1.0, if inside { 1.0 / (2.0 * PI * (1.0 - self.cos_total)) } else { 0.0 })
    }
}

impl SpotLight {
    /// A spot light from the scene description at `field` (`lights[i]`): the cone
    /// in (0, 90] degrees, the falloff within it.
    pub(crate) fn from_desc(
        check: &Check,
        field: &str,
        position: V3,
        look_at: V3,
        cone_deg: f32,
        falloff_deg: f32,
        intensity: &SpectrumDesc,
    ) -> Result<SpotLight> {
        let f = |name: &str| format!("{field}.{name}");
        let position = check.vec(&f("position"), position)?;
        let target = check.vec(&f("look_at"), look_at)?;
        let axis =
            (target - position).try_normalize().ok_or_else(|| check.err(f("look_at"), "must differ from position"))?;
        if !(cone_deg.is_finite() && cone_deg > 0.0 && cone_deg <= 90.0) {
            return Err(check.err(f("cone_deg"), format!("expected degrees in (0, 90], found {cone_deg}")));
        }
        if !(falloff_deg.is_finite() && (0.0..=cone_deg).contains(&falloff_deg)) {
            return Err(check.err(
                f("falloff_deg"),
                format!("expected degrees from 0 to cone_deg ({cone_deg}), found {falloff_deg}"),
            ));
        }
        let intensity = check.spectrum(&f("intensity"), intensity)?;
        Ok(SpotLight::new(position, axis, cone_deg, falloff_deg, intensity))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The falloff is 1 inside the inner cone, 0 outside the cone, a
    /// smoothstep between; `power` equals the falloff integrated over the
    /// sphere numerically (midpoint rule in cos θ, 20k steps).
    #[test]
    fn falloff_and_power() {
        let s = SpotLight::new(Vec3::ZERO, Vec3::NEG_Y, 30.0, 10.0, Spectrum::ONE);
        let at = |deg: f32| s.falloff(Vec3::new(deg.to_radians().sin(), -deg.to_radians().cos(), 0.0));
        assert_eq!(at(0.0), 1.0);
        assert_eq!(at(19.9), 1.0);
        assert_eq!(at(30.1), 0.0);
        assert_eq!(at(90.0), 0.0);
        let mid = at(25.0);
        assert!(mid > 0.0 && mid < 1.0);
        let n = 20_000;
        let mut integral = 0.0f64;
        for k in 0..n {
            let cos = -1.0 + 2.0 * (k as f64 + 0.5) / n as f64;
            let sin = (1.0 - cos * cos).sqrt();
            integral += s.falloff(Vec3::new(sin as f32, -cos as f32, 0.0)) as f64 * 2.0 / n as f64;
        }
        let want = 2.0 * std::f64::consts::PI * integral;
        assert!((s.power() as f64 - want).abs() < 1e-3 * want, "{} vs {want}", s.power());
        // Light reaches a point in the cone with I falloff / d², not outside it.
        let ls = s.sample_li(Vec3::new(0.0, -2.0, 0.0)).unwrap();
        assert!((ls.scale - 0.25).abs() < 1e-6 && ls.is_delta);
        assert!(s.sample_li(Vec3::new(2.0, -1.0, 0.0)).is_none());
    }
}
