//! A smooth dielectric interface (glass, water, diamond): Fresnel reflection
//! (thesis eq. 2.4, unpolarised) and Snell refraction (eq. 2.3), with the
//! choice between them made stochastically with probability F, and total
//! internal reflection handled (F = 1). Refracted radiance is scaled by
//! `1 / η²` (η = η_t / η_i, pbrt-v4 §9.5.2), which cancels over a path that
//! enters and leaves. No absorption.
//!
//! The index of refraction may depend on wavelength ([`Ior`]): then the model
//! is dispersive, and the integrator asks for one wavelength's direction at a time.
//!
//! ```ron
//! "glass": Dielectric(ior: Named("N-BK7")),
//! "crown": Dielectric(ior: Constant(1.5)),
//! "flint": Dielectric(ior: Cauchy(a: 1.67, b: 0.0074)),
//! ```

use glam::Vec3;

use super::{BsdfSample, Ior, fresnel_dielectric, refract};
use crate::spectral::Sampled;

/// A smooth dielectric; the outside (the side the normal points to) is the
/// scene's medium, of index 1 (vacuum; see the crate docs).
#[derive(Clone, Debug)]
pub struct Dielectric {
    /// Index of refraction of the inside.
    pub ior: Ior,
}

impl Dielectric {
    /// Samples reflection or refraction for index `eta` (inside / outside).
    #[inline]
    pub fn sample<const N: usize>(&self, wo: Vec3, uc: f32, eta: f32) -> Option<BsdfSample<N>> {
        // Below the smallest normal f32, 1 / |cos θ| overflows to infinity.
        if wo.z.abs() < f32::MIN_POSITIVE {
            return None;
        }
        let r = fresnel_dielectric(wo.z, eta);
        let t = 1.0 - r;
        if uc < r || t <= 0.0 {
            // Specular reflection, chosen with probability R.
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return Some(BsdfSample { wi, f: Sampled::splat(r / wi.z.abs()), pdf: r, is_delta: true, eta: 1.0 });
        }
        // Refraction, chosen with probability T = 1 - R.
        let (wi, etap) = refract(wo, Vec3::Z, eta)?;
        if wi.z.abs() < f32::MIN_POSITIVE {
            return None;
        }
        let f = t / (wi.z.abs() * etap * etap);
        Some(BsdfSample { wi, f: Sampled::splat(f), pdf: t, is_delta: true, eta: etap })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// R + T = 1 exactly: the expected weight of the stochastic choice,
    /// R·(R/R) + T·(T/T), is 1, and each branch's probability is its Fresnel
    /// term; checked with the branch probabilities themselves at several angles,
    /// both sides, for normal and total internal reflection.
    #[test]
    fn reflection_plus_transmission_is_one() {
        let d = Dielectric { ior: Ior::Constant(1.5) };
        for cos in [1.0f32, 0.7, 0.3, 0.05, -0.05, -0.5, -0.9, -1.0] {
            let sin = (1.0 - cos * cos).sqrt();
            let wo = Vec3::new(sin, 0.0, cos);
            let refl: BsdfSample<1> = d.sample(wo, 0.0, 1.5).unwrap();
            let r = refl.pdf;
            let weight_r = refl.f[0] * refl.wi.z.abs() / refl.pdf;
            assert!((weight_r - 1.0).abs() < 1e-5);
            if r < 1.0 {
                let tr: BsdfSample<1> = d.sample(wo, 0.999_999, 1.5).unwrap();
                assert!((r + tr.pdf - 1.0).abs() < 1e-6, "R + T at cos {cos}");
                // Transmitted weight is 1/η² in radiance units, undone on the way out.
                let w = tr.f[0] * tr.wi.z.abs() / tr.pdf;
                assert!((w * tr.eta * tr.eta - 1.0).abs() < 1e-4);
                assert!(tr.wi.z * wo.z < 0.0, "refraction crosses the surface");
            }
        }
    }

    /// Snell's law per wavelength with a dispersive glass: η_i sin θ_i =
    /// η_t(λ) sin θ_t for the index the Sellmeier equation gives at λ, and
    /// violet bends more than red.
    #[test]
    fn snell_per_wavelength() {
        let ior = crate::bxdf::named_glass("N-BK7").unwrap();
        let d = Dielectric { ior: ior.clone() };
        let theta = 50f32.to_radians();
        let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
        let mut last_sin_t = 0.0;
        for lambda in [400.0, 550.0, 700.0] {
            let n = ior.at(lambda);
            let t: BsdfSample<1> = d.sample(wo, 0.999_999, n).unwrap();
            let sin_t = (t.wi.x * t.wi.x + t.wi.y * t.wi.y).sqrt();
            assert!((theta.sin() - n * sin_t).abs() < 1e-5, "{lambda} nm");
            assert!(sin_t > last_sin_t, "longer wavelengths bend less");
            last_sin_t = sin_t;
        }
    }
}
