//! A conductor (metal): reflection only, with the full complex Fresnel
//! reflectance of index `n + i k` per wavelength ([`super::fresnel_conductor`]),
//! smooth (a delta mirror lobe) or rough (GGX microfacets, [`Ggx`]):
//! `f = D(wm) G2(wo, wi) F(wo·wm) / (4 |cos θo| |cos θi|)` with `wm` the half
//! vector, sampled through the visible normals, so a sample's weight is
//! `F G2 / G1(wo)` ≤ 1. Single scattering only: a rough metal loses the
//! energy of light that would bounce between microfacets (at α = 1 a
//! perfect reflector keeps about 60% at normal incidence; see the tests).
//!
//! Two-sided, like the diffuse models: a ray from below sees the same metal.
//! `roughness` is GGX α (Mitsuba's `alpha`); below 1e-3 (and at 0) the
//! surface is the smooth model exactly.
//!
//! ```ron
//! "gold": Conductor(metal: "Au"),
//! "rough_copper": Conductor(metal: "Cu", roughness: 0.2),
//! "custom": Conductor(eta: Constant(0.2), k: Constant(3.0), roughness: 0.05),
//! "tempered": Conductor(metal: "Cr", coating: ThinFilm(thickness_nm: 250, ior: Constant(2.2))),
//! ```
//!
//! A `coating` replaces the bare Fresnel reflectance by the Airy reflectance
//! of the film on the metal ([`super::thin_film`]), at the macro-surface
//! (smooth) or microfacet (rough) angle.

use glam::{Vec2, Vec3};

use super::microfacet::{Ggx, SMOOTH_ALPHA};
use super::thin_film::ThinFilm;
use super::{BsdfSample, fresnel_conductor};
use crate::color::{Sampled, Spectrum};
use crate::spectral::Lambdas;

/// A smooth or rough conductor.
#[derive(Clone, Debug)]
pub struct Conductor {
    /// Real part of the index, per bin.
    pub eta: Spectrum,
    /// Imaginary part of the index (extinction coefficient), per bin.
    pub k: Spectrum,
    /// GGX α; below [`SMOOTH_ALPHA`] the surface is smooth.
    pub alpha: f32,
    /// An optional thin film on top (interference colours: oxide, oil).
    pub coating: Option<ThinFilm>,
}

impl Conductor {
    /// True when the surface is the smooth (delta) model.
    #[inline]
    pub fn is_smooth(&self) -> bool {
        self.alpha.is_nan() || self.alpha < SMOOTH_ALPHA
    }

    /// The Fresnel reflectance at each of the packet's wavelengths for
    /// incidence cosine `cos` (through the coating's Airy sum when coated).
    #[inline]
    pub fn fresnel<const N: usize>(&self, cos: f32, lambdas: &Lambdas<N>) -> Sampled<N> {
        let (eta, k) = (lambdas.sample(&self.eta), lambdas.sample(&self.k));
        match &self.coating {
            Some(film) => film.airy(cos, &eta, &k, lambdas).0,
            None => Sampled(std::array::from_fn(|i| fresnel_conductor(cos, eta[i], k[i]))),
        }
    }

    /// `f(wo, wi)` (0 for the smooth model and across the surface).
    #[inline]
    pub fn eval<const N: usize>(&self, wo: Vec3, wi: Vec3, lambdas: &Lambdas<N>) -> Sampled<N> {
        let zero = Sampled::splat(0.0);
        if self.is_smooth() || wo.z * wi.z <= 0.0 {
            return zero;
        }
        let (wo, wi) = upper(wo, wi);
        let Some(wm) = (wo + wi).try_normalize() else {
            return zero;
        };
        let g = Ggx { alpha: self.alpha };
        let v = g.d(wm) * g.g2(wo, wi) / (4.0 * wo.z * wi.z);
        if !v.is_finite() || v <= 0.0 {
            return zero;
        }
        self.fresnel(wo.dot(wm), lambdas) * v
    }

    /// The pdf of `sample` choosing `wi` (0 for the smooth model):
    /// `D_wo(wm) / (4 |wo·wm|) = G1(wo) D(wm) / (4 cos θo)`.
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.is_smooth() || wo.z * wi.z <= 0.0 {
            return 0.0;
        }
        let (wo, wi) = upper(wo, wi);
        let Some(wm) = (wo + wi).try_normalize() else {
            return 0.0;
        };
        let g = Ggx { alpha: self.alpha };
        let p = g.g1(wo) * g.d(wm) / (4.0 * wo.z);
        if p.is_finite() { p } else { 0.0 }
    }

    /// Samples the mirror direction (smooth) or a visible microfacet normal
    /// and reflects `wo` about it (rough).
    #[inline]
    pub fn sample<const N: usize>(&self, wo: Vec3, u: Vec2, lambdas: &Lambdas<N>) -> Option<BsdfSample<N>> {
        // Below the smallest normal f32, 1 / |cos θ| overflows to infinity.
        if wo.z.abs() < f32::MIN_POSITIVE {
            return None;
        }
        if self.is_smooth() {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            let f = self.fresnel(wo.z, lambdas) * (1.0 / wi.z.abs());
            return Some(BsdfSample { wi, f, pdf: 1.0, is_delta: true, eta: 1.0 });
        }
        let flip = wo.z < 0.0;
        let wo_up = if flip { -wo } else { wo };
        let g = Ggx { alpha: self.alpha };
        let wm = g.sample_visible(wo_up, u);
        let wi_up = 2.0 * wo_up.dot(wm) * wm - wo_up;
        if wi_up.z <= 0.0 {
            return None; // reflected below the surface: masked
        }
        let wi = if flip { -wi_up } else { wi_up };
        let f = self.eval(wo, wi, lambdas);
        let pdf = self.pdf(wo, wi);
        if pdf.is_nan() || pdf <= 0.0 || f.has_nan_or_inf() {
            return None;
        }
        Some(BsdfSample { wi, f, pdf, is_delta: false, eta: 1.0 })
    }
}

/// Both directions mirrored into the upper hemisphere when `wo` is below
/// (the caller has checked that they are on one side).
#[inline]
fn upper(wo: Vec3, wi: Vec3) -> (Vec3, Vec3) {
    if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) }
}
