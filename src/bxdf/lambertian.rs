//! Ideal diffuse (Lambertian) reflection: `f = ρ / π`, sampled with a
//! cosine-weighted hemisphere. Two-sided.
//!
//! ```ron
//! "white": Lambertian(reflectance: ColorChecker("white 9.5 (.05 D)")),
//! ```

use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

use super::BsdfSample;
use crate::color::Sampled;
use crate::color::Spectrum;
use crate::sampler::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
use crate::spectral::Lambdas;

/// Lambertian reflection with a spectral reflectance.
#[derive(Clone, Debug)]
pub struct Lambertian {
    /// Reflectance ρ(λ) in [0, 1].
    pub reflectance: Spectrum,
}

/// The cosine-hemisphere pdf on `wo`'s side (0 across the surface). Shared by
/// both diffuse models, which sample the same way.
#[inline]
pub(super) fn pdf(wo: Vec3, wi: Vec3) -> f32 {
    if wo.z * wi.z <= 0.0 { 0.0 } else { cosine_hemisphere_pdf(wi.z.abs()) }
}

/// Cosine-weighted sampling on `wo`'s side, shared by both diffuse models:
/// `f` evaluates the model for the chosen direction.
#[inline]
pub(super) fn sample_diffuse<const N: usize>(
    wo: Vec3,
    u: Vec2,
    f: impl FnOnce(Vec3) -> Sampled<N>,
) -> Option<BsdfSample<N>> {
    let mut wi = cosine_hemisphere(u);
    if wo.z < 0.0 {
        wi.z = -wi.z;
    }
    if wi.z == 0.0 || wo.z == 0.0 {
        return None;
    }
    Some(BsdfSample { wi, f: f(wi), pdf: cosine_hemisphere_pdf(wi.z.abs()), is_delta: false, eta: 1.0 })
}

impl Lambertian {
    /// `f(wo, wi)`.
    #[inline]
    pub fn eval<const N: usize>(&self, wo: Vec3, wi: Vec3, lambdas: &Lambdas<N>) -> Sampled<N> {
        if wo.z * wi.z <= 0.0 {
            return Sampled::splat(0.0);
        }
        lambdas.sample(&self.reflectance) * FRAC_1_PI
    }

    /// Cosine-weighted sampling.
    #[inline]
    pub fn sample<const N: usize>(&self, wo: Vec3, u: Vec2, lambdas: &Lambdas<N>) -> Option<BsdfSample<N>> {
        sample_diffuse(wo, u, |_| lambdas.sample(&self.reflectance) * FRAC_1_PI)
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Bxdf, test_util::check_sample_consistency};
    use super::*;

    /// With cosine sampling, f cos / pdf = ρ exactly for every sample, so the
    /// albedo estimate equals ρ to rounding, from either side.
    #[test]
    fn albedo_equals_reflectance() {
        let rho = Spectrum::from_fn(|i| i as f32 / 40.0);
        let b = Bxdf::Lambertian(Lambertian { reflectance: rho });
        for wo in [Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, 0.6, -0.8)] {
            let a = check_sample_consistency(&b, wo, 2000);
            for i in 0..36 {
                assert!((a[i] - rho[i]).abs() < 1e-4, "bin {i}: {} vs {}", a[i], rho[i]);
            }
        }
    }

    #[test]
    fn reciprocal_and_zero_across_the_surface() {
        let b = Bxdf::Lambertian(Lambertian { reflectance: Spectrum::splat(0.5) });
        let l = Lambdas::full();
        let (a, c) = (Vec3::new(0.3, 0.1, 0.9).normalize(), Vec3::new(-0.5, 0.2, 0.4).normalize());
        assert_eq!(b.eval(a, c, &l), b.eval(c, a, &l));
        assert!(b.eval(a, -c, &l).is_black());
    }
}
