//! Perfect specular reflection (a mirror): `wi` is `wo` reflected about the
//! normal (law of reflection, thesis eq. 2.2), scaled by a spectral reflectance.
//!
//! ```ron
//! "mirror": Mirror(reflectance: Constant(0.95)),
//! ```

use glam::Vec3;

use super::BsdfSample;
use crate::color::Spectrum;
use crate::spectral::Lambdas;

/// A perfect mirror.
#[derive(Clone, Debug)]
pub struct Mirror {
    /// Reflectance per wavelength.
    pub reflectance: Spectrum,
}

impl Mirror {
    /// The reflected direction, always (pdf 1).
    #[inline]
    pub fn sample<const N: usize>(&self, wo: Vec3, lambdas: &Lambdas<N>) -> Option<BsdfSample<N>> {
        let wi = Vec3::new(-wo.x, -wo.y, wo.z);
        // Below the smallest normal f32, 1 / |cos θi| overflows to infinity.
        if wi.z.abs() < f32::MIN_POSITIVE {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: lambdas.sample(&self.reflectance) * (1.0 / wi.z.abs()),
            pdf: 1.0,
            is_delta: true,
            eta: 1.0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Bxdf, test_util::check_sample_consistency};
    use super::*;

    #[test]
    fn reflects_and_keeps_its_reflectance() {
        let b = Bxdf::Mirror(Mirror { reflectance: Spectrum::splat(0.8) });
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let a = check_sample_consistency(&b, wo, 10);
        assert!((a[10] - 0.8).abs() < 1e-6);
        let s = b.sample(wo, glam::Vec2::ZERO, 0.0, &Lambdas::full()).unwrap();
        assert!((s.wi - Vec3::new(-0.6, 0.0, 0.8)).length() < 1e-6);
    }
}
