//! The Trowbridge-Reitz (GGX) microfacet distribution shared by the rough
//! models: its normal distribution `D`, Smith's height-correlated
//! masking-shadowing `G2` (Heitz 2014, "Understanding the masking-shadowing
//! function", eq. 99), and sampling of the visible normals (Heitz 2018,
//! "Sampling the GGX distribution of visible normals"), isotropic.
//!
//! `alpha` is the GGX width, as Mitsuba's `alpha` and pbrt-v4's `alpha`
//! (no remapping from a perceptual "roughness"). Below [`SMOOTH_ALPHA`] a
//! surface is treated as perfectly smooth (pbrt-v4's `EffectivelySmooth`
//! uses the same bound): there the lobe is narrower than f32 directions
//! resolve well and its albedo equals the smooth model's to 0.1%
//! (`bxdf::tests`).
//!
//! Every function takes local-frame directions (normal `+z`) and is written
//! so that grazing directions (`z` → 0) give 0 or finite values, never NaN:
//! `D` uses `α² / (π (α² z² + x² + y²)²)`, which has no tangent in it, and
//! `Λ` overflows to +∞ (so `G` → 0) rather than dividing 0 by 0.

use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// Below this GGX alpha a surface is the smooth (delta) model.
pub const SMOOTH_ALPHA: f32 = 1e-3;

/// An isotropic GGX distribution of width `alpha`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    /// The GGX width α (≥ [`SMOOTH_ALPHA`] for a rough surface).
    pub alpha: f32,
}

impl Ggx {
    /// The normal distribution `D(wm)` per unit solid angle of microfacet
    /// normals (∫ D(wm) cos θm dωm = 1); 0 below the surface.
    #[inline]
    pub fn d(&self, wm: Vec3) -> f32 {
        if wm.z <= 0.0 {
            return 0.0;
        }
        let a2 = self.alpha * self.alpha;
        let t = a2 * wm.z * wm.z + wm.x * wm.x + wm.y * wm.y;
        if t <= 0.0 {
            return 0.0;
        }
        a2 * FRAC_1_PI / (t * t)
    }

    /// Smith's auxiliary function `Λ(w) = (−1 + √(1 + α² tan²θ)) / 2`.
    #[inline]
    pub fn lambda(&self, w: Vec3) -> f32 {
        let sin2 = w.x * w.x + w.y * w.y;
        let z2 = w.z * w.z;
        if sin2 == 0.0 {
            return 0.0;
        }
        let a2_tan2 = self.alpha * self.alpha * sin2 / z2; // +∞ when z² is 0
        0.5 * ((1.0 + a2_tan2).sqrt() - 1.0)
    }

    /// The masking function `G1(w) = 1 / (1 + Λ(w))`.
    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking-shadowing `G2 = 1 / (1 + Λ(wo) + Λ(wi))`.
    #[inline]
    pub fn g2(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// The density of visible normals seen from `wo` (upper hemisphere):
    /// `D_wo(wm) = G1(wo) max(0, wo·wm) D(wm) / cos θo`.
    #[inline]
    pub fn d_visible(&self, wo: Vec3, wm: Vec3) -> f32 {
        let cos_o = wo.z;
        let dot = wo.dot(wm);
        if cos_o <= 0.0 || dot <= 0.0 {
            return 0.0;
        }
        self.g1(wo) * dot * self.d(wm) / cos_o
    }

    /// Samples a visible normal seen from `wo` (which must have `wo.z > 0`),
    /// with density [`Ggx::d_visible`] (Heitz 2018, listing 1).
    #[inline]
    pub fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let a = self.alpha;
        // Stretch the view direction to the configuration of a unit hemisphere.
        let vh = Vec3::new(a * wo.x, a * wo.y, wo.z).normalize();
        // An orthonormal basis around it (any when it is the pole).
        let len2 = vh.x * vh.x + vh.y * vh.y;
        let t1 = if len2 > 0.0 { Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt() } else { Vec3::X };
        let t2 = vh.cross(t1);
        // A point on the projected disk, warped to the visible half.
        let r = u.x.sqrt();
        let (cos_phi, sin_phi) = crate::sampler::warp::cos_sin_2pi(u.y);
        let p1 = r * cos_phi;
        let s = 0.5 * (1.0 + vh.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * sin_phi;
        // Lift to the hemisphere and unstretch.
        let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
        Vec3::new(a * nh.x, a * nh.y, nh.z.max(1e-6)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ D(wm) cos θm dωm = 1 (the projected microfacet area is the
    /// macro-surface's), by the midpoint rule in θ on a grid fine enough for
    /// the narrowest lobe tested; and the visible normal density integrates
    /// to 1 for several views (Heitz 2014, eq. 16), both in f64 outside `Ggx`
    /// except for the function under test.
    #[test]
    fn normalisation_of_d_and_of_the_visible_normals() {
        for alpha in [0.01f32, 0.1, 0.3, 0.7, 1.0] {
            let g = Ggx { alpha };
            let n = 20_000;
            let mut sum = 0.0f64;
            for i in 0..n {
                // Substitute θ = (π/2) t², dense near the pole where narrow lobes live.
                let t = (i as f64 + 0.5) / n as f64;
                let theta = std::f64::consts::FRAC_PI_2 * t * t;
                let dtheta = std::f64::consts::PI * t / n as f64;
                let wm = Vec3::new(theta.sin() as f32, 0.0, theta.cos() as f32);
                sum += g.d(wm) as f64 * theta.cos() * theta.sin() * dtheta * 2.0 * std::f64::consts::PI;
            }
            assert!((sum - 1.0).abs() < 2e-3, "alpha {alpha}: ∫ D cos = {sum}");
        }
        for alpha in [0.2f32, 0.6] {
            let g = Ggx { alpha };
            for cos_o in [1.0f32, 0.5, 0.1] {
                let wo = Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
                let (nt, np) = (400, 200);
                let mut sum = 0.0f64;
                for i in 0..nt {
                    let t = (i as f64 + 0.5) / nt as f64;
                    let theta = std::f64::consts::FRAC_PI_2 * t * t;
                    let dtheta = std::f64::consts::PI * t / nt as f64;
                    for j in 0..np {
                        let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / np as f64;
                        let wm = Vec3::new(
                            (theta.sin() * phi.cos()) as f32,
                            (theta.sin() * phi.sin()) as f32,
                            theta.cos() as f32,
                        );
                        sum +=
                            g.d_visible(wo, wm) as f64 * theta.sin() * dtheta * 2.0 * std::f64::consts::PI / np as f64;
                    }
                }
                assert!((sum - 1.0).abs() < 5e-3, "alpha {alpha}, cos {cos_o}: ∫ D_wo = {sum}");
            }
        }
    }

    /// Λ against its closed form through the tangent, and G → 0 (not NaN) at grazing.
    #[test]
    fn lambda_closed_form_and_grazing() {
        let g = Ggx { alpha: 0.4 };
        for theta in [0.1f64, 0.7, 1.2, 1.5] {
            let w = Vec3::new(theta.sin() as f32, 0.0, theta.cos() as f32);
            let want = 0.5 * ((1.0 + 0.16 * theta.tan().powi(2)).sqrt() - 1.0);
            assert!((g.lambda(w) as f64 - want).abs() < 1e-4 * want.max(1.0), "θ {theta}");
        }
        for z in [0.0f32, 1e-30, 1e-45] {
            let w = Vec3::new(1.0, 0.0, z);
            assert!(g.g1(w).is_finite() && g.g1(w) >= 0.0 && g.g1(w) < 1e-6);
            assert!(g.d(Vec3::new(1.0, 0.0, z)).is_finite());
        }
        assert_eq!(g.g1(Vec3::Z), 1.0);
    }
}
