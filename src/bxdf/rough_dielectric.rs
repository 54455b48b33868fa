//! The rough side of [`super::Dielectric`]: a GGX microfacet interface
//! (Walter et al. 2007, "Microfacet models for refraction through rough
//! surfaces"; the generalised half vector and Jacobians as pbrt-v4 §9.7),
//! with Smith's height-correlated masking-shadowing and visible-normal
//! sampling ([`Ggx`]). One relative index `eta` (inside / outside) per call:
//! the caller picks it for the packet, exactly as for smooth glass.
//!
//! With `wm` the microfacet normal (upper hemisphere), `F = F(wo·wm)`:
//! - reflection: `f = D G2 F / (4 |cos θo cos θi|)`,
//! - transmission: `f = D G2 (1 − F) |wi·wm| |wo·wm| / (|cos θo cos θi| (wi·wm + wo·wm / η')²) / η'²`,
//!   where `η'` is the index ratio crossed and the last `1/η'²` is the
//!   radiance scaling of refraction (as the smooth model's).
//!
//! `sample` draws a visible normal, then reflection with probability `F` and
//! refraction otherwise; the pdf is the visible-normal density times the
//! Jacobian of reflection `1 / (4 |wo·wm|)` or refraction
//! `|wi·wm| / (wi·wm + wo·wm / η')²`.
//!
//! **Index-matched** (`|η − 1| ≤` [`INDEX_MATCHED`], e.g. glass inside the
//! same glass, or `ior: Constant(1.0)` in vacuum): every microfacet transmits
//! straight on, so the refracted lobe collapses to the delta `wi = −wo` with
//! weight 1 (as the smooth interface of index 1) and Fresnel reflects
//! nothing. The microfacet formulas above divide by a generalised half
//! vector that vanishes there and lose light, so [`eval`] and [`pdf`] give 0
//! and the caller samples the delta pass-through instead
//! ([`super::Dielectric`]'s `sample_any`).
//!
//! **Coated** (a thin film on every microfacet, [`super::thin_film`]): the
//! film's reflectance `R(λ, wo·wm)` replaces `F` per wavelength in `f`
//! ([`eval_coated`]), and the lobe is chosen with the packet's mean `P(wo·wm)`
//! ([`pdf_with`], [`sample_direction`]); the film is thin, so directions are
//! the bare interface's.

use glam::{Vec2, Vec3};

use super::fresnel_dielectric;
use super::microfacet::Ggx;
use crate::color::Sampled;

/// How far from 1 a relative index may be and still count as index-matched
/// (a few f32 ulps: equal indices divide to exactly 1).
pub(super) const INDEX_MATCHED: f32 = 1e-6;

/// True when the relative index `eta` is 1 within [`INDEX_MATCHED`]: the
/// interface passes light straight through.
#[inline]
pub(super) fn index_matched(eta: f32) -> bool {
    (eta - 1.0).abs() <= INDEX_MATCHED
}

/// A sampled direction of the rough interface: `wi`, `f`, pdf and `η'`.
pub(super) struct RoughSample {
    pub wi: Vec3,
    pub f: f32,
    pub pdf: f32,
    pub etap: f32,
}

/// The generalised half vector of `wo`, `wi` for relative index `eta`, in the
/// upper hemisphere, and `η'` (1 for reflection); `None` when degenerate or
/// when either direction sees the back of the microfacet.
#[inline]
pub(super) fn half_vector(wo: Vec3, wi: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let (co, ci) = (wo.z, wi.z);
    if co == 0.0 || ci == 0.0 {
        return None;
    }
    let reflect = co * ci > 0.0;
    let etap = if reflect {
        1.0
    } else if co > 0.0 {
        eta
    } else {
        1.0 / eta
    };
    let mut wm = (wi * etap + wo).try_normalize()?;
    if wm.z < 0.0 {
        wm = -wm;
    }
    if wm.z == 0.0 || wm.dot(wi) * ci < 0.0 || wm.dot(wo) * co < 0.0 {
        return None;
    }
    Some((wm, etap))
}

/// `f(wo, wi)` of the coated rough interface for each wavelength of a
/// packet, whose film reflects `film(wo·wm)` (one value per wavelength).
#[inline]
pub(super) fn eval_coated<const N: usize>(
    g: Ggx,
    wo: Vec3,
    wi: Vec3,
    eta: f32,
    film: impl Fn(f32) -> Sampled<N>,
) -> Sampled<N> {
    let Some((wm, etap)) = half_vector(wo, wi, eta) else {
        return Sampled::splat(0.0);
    };
    let r = film(wo.dot(wm));
    let (co, ci) = (wo.z, wi.z);
    let f = if etap == 1.0 && co * ci > 0.0 {
        r * (g.d(wm) * g.g2(wo, wi) / (4.0 * co * ci).abs())
    } else {
        let denom = wi.dot(wm) + wo.dot(wm) / etap;
        let denom = denom * denom * co * ci;
        Sampled(r.0.map(|r| 1.0 - r))
            * (g.d(wm) * g.g2(wo, wi) * (wi.dot(wm) * wo.dot(wm) / denom).abs() / (etap * etap))
    };
    Sampled(f.0.map(|v| if v.is_finite() && v > 0.0 { v } else { 0.0 }))
}

/// `f(wo, wi)` of the rough interface for relative index `eta` (0 when
/// index-matched: the pass-through is a delta).
#[inline]
pub(super) fn eval(g: Ggx, wo: Vec3, wi: Vec3, eta: f32) -> f32 {
    if index_matched(eta) {
        return 0.0;
    }
    let Some((wm, etap)) = half_vector(wo, wi, eta) else {
        return 0.0;
    };
    let f = fresnel_dielectric(wo.dot(wm), eta);
    let (co, ci) = (wo.z, wi.z);
    let v = if etap == 1.0 && co * ci > 0.0 {
        g.d(wm) * g.g2(wo, wi) * f / (4.0 * co * ci).abs()
    } else {
        let denom = wi.dot(wm) + wo.dot(wm) / etap;
        let denom = denom * denom * co * ci;
        g.d(wm) * (1.0 - f) * g.g2(wo, wi) * (wi.dot(wm) * wo.dot(wm) / denom).abs() / (etap * etap)
    };
    if v.is_finite() && v > 0.0 { v } else { 0.0 }
}

/// The pdf of [`sample`] choosing `wi` (0 when index-matched).
#[inline]
pub(super) fn pdf(g: Ggx, wo: Vec3, wi: Vec3, eta: f32) -> f32 {
    if index_matched(eta) {
        return 0.0;
    }
    pdf_with(g, wo, wi, eta, |c| fresnel_dielectric(c, eta))
}

/// The pdf of choosing `wi` when reflection is chosen with probability
/// `select(wo·wm)` (Fresnel for bare glass, the film's mean for coated).
#[inline]
pub(super) fn pdf_with(g: Ggx, wo: Vec3, wi: Vec3, eta: f32, select: impl Fn(f32) -> f32) -> f32 {
    let Some((wm, etap)) = half_vector(wo, wi, eta) else {
        return 0.0;
    };
    let r = select(wo.dot(wm));
    let dv = visible_density(g, wo, wm);
    let p = if etap == 1.0 && wo.z * wi.z > 0.0 {
        dv / (4.0 * wo.dot(wm).abs()) * r
    } else {
        let denom = wi.dot(wm) + wo.dot(wm) / etap;
        dv * wi.dot(wm).abs() / (denom * denom) * (1.0 - r)
    };
    if p.is_finite() && p > 0.0 { p } else { 0.0 }
}

/// The visible-normal density from `wo` on either side: `G1(wo) |wo·wm| D(wm) / |cos θo|`.
#[inline]
fn visible_density(g: Ggx, wo: Vec3, wm: Vec3) -> f32 {
    g.g1(wo) * wo.dot(wm).abs() * g.d(wm) / wo.z.abs()
}

/// Samples reflection or refraction off a visible microfacet (`u`: the
/// normal, `uc`: the lobe).
#[inline]
pub(super) fn sample(g: Ggx, wo: Vec3, u: Vec2, uc: f32, eta: f32) -> Option<RoughSample> {
    let wi = sample_direction(g, wo, u, uc, eta, |c| fresnel_dielectric(c, eta))?;
    let f = eval(g, wo, wi, eta);
    let pdf = pdf(g, wo, wi, eta);
    if !(f > 0.0 && pdf > 0.0) {
        return None;
    }
    let (_, etap) = half_vector(wo, wi, eta)?;
    Some(RoughSample { wi, f, pdf, etap })
}

/// A direction off a visible microfacet, reflecting with probability
/// `select(wo·wm)` and refracting (at `eta`) otherwise.
#[inline]
pub(super) fn sample_direction(
    g: Ggx,
    wo: Vec3,
    u: Vec2,
    uc: f32,
    eta: f32,
    select: impl Fn(f32) -> f32,
) -> Option<Vec3> {
    if wo.z.abs() < f32::MIN_POSITIVE {
        return None;
    }
    let wo_up = if wo.z < 0.0 { -wo } else { wo };
    let wm_up = g.sample_visible(wo_up, u);
    // The normal in the upper hemisphere, as `half_vector` returns it.
    let wm = if wo.z < 0.0 { -wm_up } else { wm_up };
    let wm = if wm.z < 0.0 { -wm } else { wm };
    let r = select(wo.dot(wm));
    if uc < r {
        let wi = 2.0 * wo.dot(wm) * wm - wo;
        if wi.z * wo.z <= 0.0 {
            return None;
        }
        Some(wi)
    } else {
        let (wi, _) = super::refract(wo, wm, eta)?;
        if wi.z * wo.z >= 0.0 {
            return None;
        }
        Some(wi)
    }
}
