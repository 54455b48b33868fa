//! Oren-Nayar rough diffuse reflection (Oren and Nayar 1994, in the
//! qualitative form of pbrt-v3 §8.4.2): a Lambertian surface made of
//! V-cavities with slope standard deviation σ. σ = 0 is exactly Lambertian.
//! Sampled with the cosine-weighted hemisphere (the same pdf as Lambertian).
//! Two-sided.
//!
//! ```ron
//! "white": OrenNayar(reflectance: ColorChecker("white 9.5 (.05 D)"), sigma_deg: 20),
//! ```

use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

use super::{BsdfSample, lambertian};
use crate::color::Sampled;
use crate::color::Spectrum;
use crate::spectral::Lambdas;

/// Oren-Nayar reflection.
#[derive(Clone, Copy, Debug)]
pub struct OrenNayar {
    /// Reflectance ρ(λ) in [0, 1].
    pub reflectance: Spectrum,
    a: f32,
    b: f32,
}

impl OrenNayar {
    /// A surface with reflectance `reflectance` and roughness σ in degrees.
    pub fn new(reflectance: Spectrum, sigma_deg: f32) -> Self {
        let s2 = sigma_deg.to_radians().powi(2);
        OrenNayar { reflectance, a: 1.0 - s2 / (2.0 * (s2 + 0.33)), b: 0.45 * s2 / (s2 + 0.09) }
    }

    /// The wavelength-independent factor `A + B max(0, cos(φi - φo)) sin α tan β`.
    #[inline]
    fn factor(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (ci, co) = (wi.z.abs(), wo.z.abs());
        let si = (1.0 - ci * ci).max(0.0).sqrt();
        let so = (1.0 - co * co).max(0.0).sqrt();
        let max_cos = if si > 1e-4 && so > 1e-4 {
            // cos(φi - φo) from the projected directions.
            ((wi.x * wo.x + wi.y * wo.y) / (si * so)).max(0.0)
        } else {
            0.0
        };
        let (sin_alpha, tan_beta) = if ci > co { (so, si / ci) } else { (si, so / co.max(1e-8)) };
        self.a + self.b * max_cos * sin_alpha * tan_beta
    }

    /// `f(wo, wi)`.
    #[inline]
    pub fn eval<const N: usize>(&self, wo: Vec3, wi: Vec3, lambdas: &Lambdas<N>) -> Sampled<N> {
        if wo.z * wi.z <= 0.0 {
            return Sampled::splat(0.0);
        }
        lambdas.sample(&self.reflectance) * (FRAC_1_PI * self.factor(wo, wi))
    }

    /// Cosine-weighted sampling.
    #[inline]
    pub fn sample<const N: usize>(&self, wo: Vec3, u: Vec2, lambdas: &Lambdas<N>) -> Option<BsdfSample<N>> {
        lambertian::sample_diffuse(wo, u, |wi| self.eval(wo, wi, lambdas))
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Bxdf, Lambertian, test_util::check_sample_consistency};
    use super::*;

    #[test]
    fn sigma_zero_is_lambertian() {
        let rho = Spectrum::splat(0.7);
        let on = Bxdf::OrenNayar(OrenNayar::new(rho, 0.0));
        let lam = Bxdf::Lambertian(Lambertian { reflectance: rho });
        let l = Lambdas::full();
        for (wo, wi) in [(Vec3::Z, Vec3::new(0.6, 0.0, 0.8)), (Vec3::new(0.0, 0.8, 0.6), Vec3::new(0.8, 0.0, 0.6))] {
            assert_eq!(on.eval(wo, wi, &l), lam.eval(wo, wi, &l));
        }
    }

    /// Reciprocity f(wo, wi) = f(wi, wo), and albedo ≤ 1 for a white surface
    /// at σ = 20° and 60° over incident angles (2000 samples each: the
    /// estimator's relative std. error is below 2%, so 1.02 is the bound).
    #[test]
    fn reciprocal_and_energy_bounded() {
        let l = Lambdas::full();
        for sigma in [20.0, 60.0] {
            let b = Bxdf::OrenNayar(OrenNayar::new(Spectrum::ONE, sigma));
            let (a, c) = (Vec3::new(0.3, 0.1, 0.9).normalize(), Vec3::new(-0.5, 0.2, 0.4).normalize());
            let (f1, f2) = (b.eval(a, c, &l), b.eval(c, a, &l));
            assert!((f1[0] - f2[0]).abs() < 1e-6);
            for theta in [0.0f32, 30.0, 60.0, 85.0] {
                let t = theta.to_radians();
                let wo = Vec3::new(t.sin(), 0.0, t.cos());
                let albedo = check_sample_consistency(&b, wo, 2000)[0];
                assert!(albedo <= 1.02, "σ {sigma} θ {theta}: albedo {albedo}");
                assert!(albedo > 0.5);
            }
        }
    }
}
