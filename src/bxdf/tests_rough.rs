//! The rough models' sampling and energy tests (GGX conductors, rough
//! dielectrics, plastic), against independent truths: chi-square of `sample`
//! against `pdf`, albedos against numerical integrals of the textbook BSDFs
//! written out in f64 here, and continuity towards the smooth models. Split
//! from `tests.rs` (whose chi-square helpers they use) to keep files small.

use std::f64::consts::PI;

use glam::Vec3;

use super::microfacet::SMOOTH_ALPHA;
use super::test_util::check_sample_consistency;
use super::tests::{chi2_test, conductor, dir, expected_counts_sub, rough_glass, sampled_counts};
use super::*;
use crate::color::{N_BINS, Spectrum};
use crate::sampler::Sampler;

/// GGX rough conductors (visible-normal sampling) at several widths and
/// incident angles, from above and below: as `chi_square_sample_matches_pdf`,
/// with a 48 × 48 midpoint rule per cell, whose relative error on the
/// narrowest lobe (α = 0.15, ~0.1% in the pole cell) stays below a third of
/// the cell's standard error at 100k samples. Šidák-corrected 1% overall.
#[test]
fn chi_square_rough_conductor() {
    let (eta, k) = named_metal("Cu").unwrap();
    let alphas = [0.15f32, 0.4, 1.0];
    let thetas = [0.0f32, 45.0, 80.0, 135.0];
    let tests = alphas.len() * thetas.len();
    let sig = 1.0 - 0.99f64.powf(1.0 / tests as f64);
    let n = 100_000;
    let mut seed = 100;
    for alpha in alphas {
        let b = Bxdf::Conductor(Conductor { eta, k, alpha, coating: None });
        for theta in thetas {
            let t = theta.to_radians();
            let wo = Vec3::new(t.sin() * 0.6, t.sin() * 0.8, t.cos()).normalize();
            let expected = expected_counts_sub(|wi| b.pdf(wo, wi, &Lambdas::full()), n, 48);
            seed += 1;
            let l = Lambdas::<1> { pos: [20.0], weight: 36.0, readout: crate::spectral::Readout::Spectral };
            let observed = sampled_counts(&b, wo, &l, n, seed, |bs| {
                assert!(!bs.is_delta && bs.pdf > 0.0 && bs.wi.z * wo.z > 0.0);
                true
            });
            let p = chi2_test(&observed, &expected);
            assert!(p > sig, "GGX α {alpha}, θo = {theta}°: p = {p:e} < {sig:e}");
        }
    }
}

// ---------------------------------------------------------------------------
// Rough conductors: energy against an independent numerical integral, and
// continuity towards the smooth model.

/// GGX D and Smith Λ written out in f64 from their textbook forms (with the
/// tangent), independent of `microfacet.rs`.
fn ggx_d_f64(alpha: f64, cos_m: f64) -> f64 {
    if cos_m <= 0.0 {
        return 0.0;
    }
    let tan2 = (1.0 - cos_m * cos_m) / (cos_m * cos_m);
    let c4 = cos_m.powi(4);
    1.0 / (PI * alpha * alpha * c4 * (1.0 + tan2 / (alpha * alpha)).powi(2))
}

fn smith_lambda_f64(alpha: f64, cos: f64) -> f64 {
    let tan2 = (1.0 - cos * cos) / (cos * cos);
    0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0)
}

/// The directional albedo of a GGX perfect reflector (F = 1),
/// E(μo) = ∫ D(h) G2(o, i) / (4 μo) dωi over the upper hemisphere, by the
/// midpoint rule on a (θ, φ) grid dense near the mirror direction.
fn ggx_albedo_integral(alpha: f64, mu_o: f64) -> f64 {
    let (nt, np) = (1200, 600);
    let wo = [(1.0 - mu_o * mu_o).sqrt(), 0.0, mu_o];
    let mut sum = 0.0;
    for i in 0..nt {
        let theta = (i as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
        let dtheta = std::f64::consts::FRAC_PI_2 / nt as f64;
        for j in 0..np {
            let phi = (j as f64 + 0.5) / np as f64 * 2.0 * PI;
            let wi = [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()];
            let h = [wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]];
            let len = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
            let g2 = 1.0 / (1.0 + smith_lambda_f64(alpha, mu_o) + smith_lambda_f64(alpha, wi[2]));
            sum += ggx_d_f64(alpha, h[2] / len) * g2 / (4.0 * mu_o) * theta.sin() * dtheta * 2.0 * PI / np as f64;
        }
    }
    sum
}

/// White furnace of a rough perfect reflector (n = 0, k = 1 gives F = 1
/// exactly at every angle): the Monte Carlo albedo of `sample` (weights
/// G2/G1, 200k samples, standard error below 0.1%) matches the numerical
/// integral of D·G2/(4μo) within 0.5% at α = 0.1, 0.3, 0.6, 1.0 and
/// μo = 1, 0.5, 0.15; the loss grows with α and towards grazing (single
/// scattering loses what Kulla and Conty 2017 restore by multiple scattering:
/// at α = 1 and normal incidence about 40%).
#[test]
fn rough_perfect_reflector_albedo_matches_the_integral() {
    let white = |alpha| Bxdf::Conductor(Conductor { eta: Spectrum::ZERO, k: Spectrum::ONE, alpha, coating: None });
    assert_eq!(fresnel_conductor(0.3, 0.0, 1.0), 1.0);
    let mut last = 1.0f64;
    for alpha in [0.1f32, 0.3, 0.6, 1.0] {
        for mu in [1.0f32, 0.5, 0.15] {
            let wo = dir(mu, 0.4);
            let mc = check_sample_consistency(&white(alpha), wo, 200_000)[0] as f64;
            let want = ggx_albedo_integral(alpha as f64, mu as f64);
            assert!((mc - want).abs() < 5e-3 * want, "α {alpha} μ {mu}: MC {mc} vs integral {want}");
            assert!(want <= 1.0 + 1e-3);
            if mu == 1.0 {
                assert!(want < last + 1e-3, "loss grows with α");
                last = want;
            }
        }
    }
    // At α = 1, D = 1/π and G2 = 2μi/(1 + μi) seen from the normal, so E = ∫₀¹ μ/(1+μ) dμ = 1 − ln 2.
    assert!((last - (1.0 - 2f64.ln())).abs() < 1e-3, "α = 1, normal incidence: {last}");
}

/// Roughness near 0 approaches the smooth model continuously: at α just
/// above the smooth threshold the rough lobe's albedo is the smooth
/// conductor's F(θo) within 0.5% per bin (gold, from normal to 84°), and
/// at least 95% of its samples leave within 1° of the mirror direction
/// (GGX's tails put P(tan θm > t) = α² / (α² + t²), 1.3% beyond 0.5° for the
/// half vector).
#[test]
fn rough_conductor_tends_to_the_smooth_one() {
    let l = Lambdas::full();
    let smooth = conductor("Au", 0.0);
    let rough = conductor("Au", SMOOTH_ALPHA * 1.001);
    assert!(smooth.is_delta() && !rough.is_delta());
    for mu in [1.0f32, 0.5, 0.1] {
        let wo = dir(mu, 0.9);
        let a = check_sample_consistency(&rough, wo, 2000);
        let s = check_sample_consistency(&smooth, wo, 1);
        for i in 0..N_BINS {
            assert!((a[i] - s[i]).abs() < 5e-3 * s[i], "μ {mu} bin {i}: {} vs {}", a[i], s[i]);
        }
        let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
        let mut smp = Sampler::new(9, 9, 9);
        let mut near = 0;
        for _ in 0..1000 {
            let bs = rough.sample(wo, smp.next_2d(), smp.next_1d(), &l).unwrap();
            near += (bs.wi.dot(mirror) > 1f32.to_radians().cos()) as usize;
        }
        assert!(near >= 950, "μ {mu}: {near} of 1000 within 1°");
    }
}

// ---------------------------------------------------------------------------
// Rough dielectrics.

/// Rough glass (visible-normal sampling, then reflection with probability F
/// or refraction) at several widths and indices, from outside and inside
/// (total internal reflection at 135° and 170° for some microfacets): as
/// `chi_square_sample_matches_pdf` over the whole sphere, with a 48 × 48
/// midpoint rule per cell. Šidák-corrected 1% overall.
#[test]
fn chi_square_rough_dielectric() {
    let cases = [(0.2f32, 1.5f32), (0.5, 1.5), (0.3, 2.4)];
    let thetas = [0.0f32, 50.0, 85.0, 135.0, 170.0];
    let tests = cases.len() * thetas.len();
    let sig = 1.0 - 0.99f64.powf(1.0 / tests as f64);
    let n = 100_000;
    let mut seed = 200;
    let l = Lambdas::<1> { pos: [20.0], weight: 36.0, readout: crate::spectral::Readout::Spectral };
    for (alpha, eta) in cases {
        let b = rough_glass(Ior::Constant(eta), alpha);
        for theta in thetas {
            let t = theta.to_radians();
            let wo = Vec3::new(t.sin() * 0.6, t.sin() * 0.8, t.cos()).normalize();
            let expected = expected_counts_sub(|wi| b.pdf(wo, wi, &l), n, 48);
            seed += 1;
            let observed = sampled_counts(&b, wo, &l, n, seed, |bs| {
                assert!(!bs.is_delta && bs.pdf > 0.0);
                true
            });
            let p = chi2_test(&observed, &expected);
            assert!(p > sig, "rough glass α {alpha} η {eta}, θo = {theta}°: p = {p:e} < {sig:e}");
        }
    }
}

/// The unpolarised Fresnel reflectance in f64, written out for the test.
fn fresnel_f64(cos_i: f64, eta_i: f64, eta_t: f64) -> f64 {
    let sin_t2 = (eta_i / eta_t).powi(2) * (1.0 - cos_i * cos_i);
    if sin_t2 >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t2).sqrt();
    let rs = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    let rp = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Walter et al. 2007 (eqs. 20, 21 with the half vectors 13, 16) in f64:
/// `f(o, i) |cos θi|` for light arriving along `i` and leaving along `o`,
/// without the radiance scaling of refraction; `η` of the inside, vacuum outside.
fn walter_f_cos(alpha: f64, o: [f64; 3], i: [f64; 3], eta: f64) -> f64 {
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (eo, ei) = (if o[2] > 0.0 { 1.0 } else { eta }, if i[2] > 0.0 { 1.0 } else { eta });
    let reflect = o[2] * i[2] > 0.0;
    let mut h = if reflect {
        [o[0] + i[0], o[1] + i[1], o[2] + i[2]]
    } else {
        [-(eo * o[0] + ei * i[0]), -(eo * o[1] + ei * i[1]), -(eo * o[2] + ei * i[2])]
    };
    let len = dot(h, h).sqrt();
    if len == 0.0 {
        return 0.0;
    }
    h = [h[0] / len, h[1] / len, h[2] / len];
    if h[2] < 0.0 {
        h = [-h[0], -h[1], -h[2]];
    }
    if dot(o, h) * o[2] <= 0.0 || dot(i, h) * i[2] <= 0.0 {
        return 0.0;
    }
    let g2 = 1.0 / (1.0 + smith_lambda_f64(alpha, o[2].abs()) + smith_lambda_f64(alpha, i[2].abs()));
    let d = ggx_d_f64(alpha, h[2]);
    let f = fresnel_f64(dot(o, h).abs(), eo, if o[2] > 0.0 { eta } else { 1.0 });
    if reflect {
        f * d * g2 / (4.0 * o[2].abs())
    } else {
        let denom = eo * dot(o, h) + ei * dot(i, h);
        dot(o, h).abs() * dot(i, h).abs() / o[2].abs() * ei * ei * (1.0 - f) * g2 * d / (denom * denom)
    }
}

/// White furnace of rough glass: the albedo R + T (refraction's radiance
/// scaling undone, so it measures energy) of `sample`'s weights (100k
/// samples, standard error below 0.3%) matches Walter's BSDF integrated
/// numerically over the sphere in f64 (1200 × 600 midpoint grid per
/// hemisphere) within 1%, and never exceeds 1, for α = 0.1, 0.3, 0.7 and
/// directions outside and inside (where total internal reflection applies).
#[test]
fn rough_dielectric_albedo_matches_walters_integral() {
    let eta = 1.5f32;
    for alpha in [0.1f32, 0.3, 0.7] {
        let b = rough_glass(Ior::Constant(eta), alpha);
        for mu in [1.0f32, 0.5, 0.1, -0.3, -0.9] {
            let wo = dir(mu, 0.4);
            let l = Lambdas::full();
            let mut s = Sampler::new(5, 6, 7);
            let (mut sum, n) = (0.0f64, 100_000);
            for _ in 0..n {
                if let Some(bs) = b.sample(wo, s.next_2d(), s.next_1d(), &l) {
                    let w = bs.f[0] * bs.wi.z.abs() / bs.pdf * bs.eta * bs.eta;
                    assert!(w.is_finite() && w >= 0.0);
                    sum += w as f64;
                }
            }
            let mc = sum / n as f64;
            let o = [wo.x as f64, wo.y as f64, wo.z as f64];
            let (nt, np) = (1200, 600);
            let mut want = 0.0;
            for hemi in [1.0f64, -1.0] {
                for i in 0..nt {
                    let theta = (i as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
                    let dw = theta.sin() * std::f64::consts::FRAC_PI_2 / nt as f64 * 2.0 * PI / np as f64;
                    for j in 0..np {
                        let phi = (j as f64 + 0.5) / np as f64 * 2.0 * PI;
                        let wi = [theta.sin() * phi.cos(), theta.sin() * phi.sin(), hemi * theta.cos()];
                        want += walter_f_cos(alpha as f64, o, wi, eta as f64) * dw;
                    }
                }
            }
            assert!((mc - want).abs() < 0.01 * want, "α {alpha} μ {mu}: MC {mc} vs integral {want}");
            assert!(mc <= 1.0 + 3e-3, "α {alpha} μ {mu}: R + T = {mc}");
        }
    }
}

/// Plastic, smooth and rough coats: the non-delta part of `sample` (the
/// diffuse lobe, plus the GGX reflection of a rough coat) against `pdf`, as
/// `chi_square_sample_matches_pdf` (48 × 48 rule; the smooth coat's mirror
/// samples are left out, and its pdf integrates to the diffuse lobe's
/// probability 1 − F). Šidák-corrected 1% overall.
#[test]
fn chi_square_plastic() {
    let rho = Spectrum::splat(0.6);
    let models = [0.0f32, 0.1, 0.4].map(|alpha| Bxdf::Plastic(Plastic::new(rho, &Ior::Constant(1.5), alpha)));
    let thetas = [0.0f32, 60.0, 88.0, 150.0];
    let sig = 1.0 - 0.99f64.powf(1.0 / (models.len() * thetas.len()) as f64);
    let n = 100_000;
    let l = Lambdas::<1> { pos: [20.0], weight: 36.0, readout: crate::spectral::Readout::Spectral };
    let mut seed = 300;
    for b in &models {
        for theta in thetas {
            let t = theta.to_radians();
            let wo = Vec3::new(t.sin() * 0.6, t.sin() * 0.8, t.cos()).normalize();
            let expected = expected_counts_sub(|wi| b.pdf(wo, wi, &l), n, 48);
            seed += 1;
            let observed = sampled_counts(b, wo, &l, n, seed, |bs| !bs.is_delta);
            let p = chi2_test(&observed, &expected);
            assert!(p > sig, "plastic {b:?}, θo = {theta}°: p = {p:e} < {sig:e}");
        }
    }
}

/// Rough glass under a thin film (n 1.5, film 300 nm of n 1.38): `sample`
/// against `pdf` for one wavelength (the lobe chosen with that wavelength's
/// film reflectance), from outside and inside, as `chi_square_rough_dielectric`.
#[test]
fn chi_square_coated_rough_dielectric() {
    let thetas = [0.0f32, 50.0, 140.0];
    let sig = 1.0 - 0.99f64.powf(1.0 / (2 * thetas.len()) as f64);
    let film = ThinFilm::new(300.0, &Ior::Constant(1.38));
    let mut seed = 300;
    for alpha in [0.2f32, 0.5] {
        let b = Bxdf::Dielectric(Dielectric::new(Ior::Constant(1.5)).with_roughness(alpha).with_coating(film.clone()));
        let l = Lambdas::<1> { pos: [12.0], weight: 36.0, readout: crate::spectral::Readout::Spectral };
        for theta in thetas {
            let t = theta.to_radians();
            let wo = Vec3::new(t.sin() * 0.6, t.sin() * 0.8, t.cos()).normalize();
            let expected = expected_counts_sub(|wi| b.pdf(wo, wi, &l), 100_000, 48);
            seed += 1;
            let observed = sampled_counts(&b, wo, &l, 100_000, seed, |bs| {
                assert!(!bs.is_delta && bs.pdf > 0.0);
                true
            });
            let p = chi2_test(&observed, &expected);
            assert!(p > sig, "coated rough glass α {alpha}, θo = {theta}°: p = {p:e} < {sig:e}");
        }
    }
}

/// Coated rough glass against independent truths: a film of thickness 0 is
/// no film, so `eval` and `pdf` equal the bare rough glass's (within f32
/// rounding of the Airy sum); for the full spectrum `sample` agrees with
/// `eval` and `pdf`, and R + T ≤ 1 per bin; and near the smooth limit
/// (α = 0.002) the reflected share of each bin is the film's Airy
/// reflectance `thin_film::airy` at the incidence angle (within 0.01).
#[test]
fn coated_rough_glass_matches_bare_glass_and_the_airy_formula() {
    let glass = |d: f32, alpha: f32| {
        Bxdf::Dielectric(
            Dielectric::new(Ior::Constant(1.5))
                .with_roughness(alpha)
                .with_coating(ThinFilm::new(d, &Ior::Constant(1.38))),
        )
    };
    let (bare, none) = (rough_glass(Ior::Constant(1.5), 0.3), glass(0.0, 0.3));
    let l = Lambdas::full();
    for (mo, mi) in [(0.9f32, 0.7f32), (0.5, -0.6), (-0.8, -0.4), (-0.3, 0.9), (0.2, 0.3)] {
        let (wo, wi) = (dir(mo, 0.3), dir(mi, 2.0));
        let (a, b) = (bare.eval(wo, wi, &l), none.eval(wo, wi, &l));
        for k in 0..N_BINS {
            assert!((a[k] - b[k]).abs() <= 1e-4 * a[k].max(1e-3), "d = 0: f {} vs {}", b[k], a[k]);
        }
        let (pa, pb) = (bare.pdf(wo, wi, &l), none.pdf(wo, wi, &l));
        assert!((pa - pb).abs() <= 1e-4 * pa.max(1e-3), "d = 0: pdf {pb} vs {pa}");
    }
    for mu in [0.9f32, 0.4, -0.7] {
        let (b, wo) = (glass(300.0, 0.3), dir(mu, 0.2));
        check_sample_consistency(&b, wo, 20_000);
        // R + T in energy (radiance weights times η², as Walter's test above).
        let mut s = Sampler::new(4, 5, 6);
        let (mut total, n) = (Spectrum::ZERO, 20_000);
        for _ in 0..n {
            if let Some(bs) = b.sample(wo, s.next_2d(), s.next_1d(), &l) {
                total += bs.f * (bs.wi.z.abs() / bs.pdf * bs.eta * bs.eta);
            }
        }
        assert!(total.0.iter().all(|&v| v / n as f32 <= 1.0 + 0.02), "μ {mu}: R + T above 1: {total:?}");
    }
    let (b, cos) = (glass(300.0, 0.002), 0.8f32);
    let wo = dir(cos, 0.0);
    let mut s = Sampler::new(8, 9, 10);
    let (mut reflected, n) = (Spectrum::ZERO, 50_000);
    for _ in 0..n {
        if let Some(bs) = b.sample(wo, s.next_2d(), s.next_1d(), &l)
            && bs.wi.z > 0.0
        {
            reflected += bs.f * (bs.wi.z.abs() / bs.pdf);
        }
    }
    for k in (0..N_BINS).step_by(5) {
        let want = airy(cos, 1.0, 1.38, 300.0, 1.5, 0.0, crate::color::bin_lambda_nm(k)).0;
        let got = reflected[k] / n as f32;
        assert!((got - want).abs() < 0.01, "bin {k}: reflected {got} vs Airy {want}");
    }
}
