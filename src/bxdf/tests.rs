//! Sampling correctness of every BxDF, as pbrt-v4 and Mitsuba 3 test it: a
//! chi-square goodness-of-fit test of `sample` against `pdf`, and for every
//! model reciprocity, `sample` = `eval`, and energy (albedo ≤ 1) at all
//! incident angles (grazing included) and wavelengths.

use std::f64::consts::PI;

use glam::{Vec2, Vec3};

use super::microfacet::SMOOTH_ALPHA;
use super::test_util::check_sample_consistency;
use super::*;
use crate::color::{N_BINS, Spectrum};
use crate::sampler::Sampler;

// ---------------------------------------------------------------------------
// The regularized incomplete gamma function (Numerical Recipes §6.2 style:
// series for x < a + 1, Lentz's continued fraction otherwise).

/// ln Γ(x) for x > 0 (Lanczos, g = 7, n = 9; relative error below 1e-13).
fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Γ(x) Γ(1 − x) = π / sin(πx).
        return (PI / (PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (i, g) in G.iter().enumerate().skip(1) {
        a += g / (x + i as f64);
    }
    0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularized upper incomplete gamma function Q(a, x) = Γ(a, x) / Γ(a).
fn gamma_q(a: f64, x: f64) -> f64 {
    assert!(a > 0.0 && x >= 0.0);
    if x == 0.0 {
        return 1.0;
    }
    let prefactor = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        // P(a, x) = e^-x x^a / Γ(a) Σ x^n / (a (a+1) ... (a+n)).
        let (mut ap, mut term, mut sum) = (a, 1.0 / a, 1.0 / a);
        for _ in 0..10_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * prefactor
    } else {
        // Q(a, x) = e^-x x^a / Γ(a) · 1 / (x + 1 − a − 1·(1 − a) / (x + 3 − a − ...)), modified Lentz.
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-15 {
                break;
            }
        }
        prefactor * h
    }
}

/// The p-value of a chi-square statistic with `dof` degrees of freedom.
fn chi2_p_value(chi2: f64, dof: usize) -> f64 {
    gamma_q(dof as f64 / 2.0, chi2 / 2.0)
}

#[test]
fn incomplete_gamma_matches_closed_forms() {
    // Q(1, x) = e^-x; Q(1/2, x) = erfc(√x); Q(n, x) = e^-x Σ_{k<n} x^k / k!.
    for x in [0.01, 0.5, 1.0, 2.0, 7.5, 30.0] {
        assert!((gamma_q(1.0, x) - (-x).exp()).abs() < 1e-12, "Q(1, {x})");
        let poisson: f64 = (0..5).map(|k| x.powi(k) / (1..=k).product::<i32>().max(1) as f64).sum::<f64>() * (-x).exp();
        assert!((gamma_q(5.0, x) - poisson).abs() < 1e-12, "Q(5, {x})");
    }
    // erfc(1) = 0.157299207050285, erfc(0.5) = 0.479500122186953.
    assert!((gamma_q(0.5, 1.0) - 0.157_299_207_050_285).abs() < 1e-12);
    assert!((gamma_q(0.5, 0.25) - 0.479_500_122_186_953).abs() < 1e-12);
    // Chi-square tables: the 95th percentile for 10 d.o.f. is 18.307, the 99th for 100 d.o.f. 135.807.
    assert!((chi2_p_value(18.307, 10) - 0.05).abs() < 1e-4);
    assert!((chi2_p_value(135.807, 100) - 0.01).abs() < 1e-4);
    assert!((ln_gamma(0.5) - PI.sqrt().ln()).abs() < 1e-12 && (ln_gamma(10.0) - 362_880f64.ln()).abs() < 1e-10);
}

// ---------------------------------------------------------------------------
// The chi-square test of a sampler against its pdf.

/// Cells in cos θ (over the whole sphere, [−1, 1]) and φ: odd counts, so no
/// cell boundary sits on a symmetry of the distributions (cos θ = 0, φ = 0, π).
const THETA_RES: usize = 15;
const PHI_RES: usize = 31;

/// Expected count per cell: `n · ∫ pdf dω` over the cell (dω = sin θ dθ dφ),
/// by the midpoint rule on 16 × 16 sub-cells uniform in θ and φ. The pdf is
/// smooth except for its kink at cos θ = 0, which falls on a sub-cell
/// boundary (the middle cell is symmetric about it and split into an even
/// number), so the rule's error (~1e-4 relative) is far below the test's
/// sensitivity. Never uses the sampler.
fn expected_counts(pdf: impl Fn(Vec3) -> f32, n: usize) -> Vec<f64> {
    expected_counts_sub(pdf, n, 16)
}

/// As [`expected_counts`] with `sub × sub` midpoint sub-cells per cell (the
/// peaked microfacet lobes need a finer rule).
fn expected_counts_sub(pdf: impl Fn(Vec3) -> f32, n: usize, sub: usize) -> Vec<f64> {
    let mut out = vec![0.0; THETA_RES * PHI_RES];
    for i in 0..THETA_RES {
        // Sub-cells uniform in θ (weight sin θ dθ), so the pole cells, where
        // narrow lobes sit, are resolved as finely as the others.
        let z0 = -1.0 + 2.0 * i as f64 / THETA_RES as f64;
        let z1 = -1.0 + 2.0 * (i + 1) as f64 / THETA_RES as f64;
        let (t0, t1) = (z1.clamp(-1.0, 1.0).acos(), z0.clamp(-1.0, 1.0).acos());
        let dtheta = (t1 - t0) / sub as f64;
        for j in 0..PHI_RES {
            let mut sum = 0.0;
            for a in 0..sub {
                let theta = t0 + (a as f64 + 0.5) * dtheta;
                let (s, z) = (theta.sin(), theta.cos());
                for b in 0..sub {
                    let phi = 2.0 * PI * (j as f64 + (b as f64 + 0.5) / sub as f64) / PHI_RES as f64;
                    let v = pdf(Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32)) as f64;
                    sum += v * s * dtheta * (2.0 * PI / PHI_RES as f64) / sub as f64;
                }
            }
            out[i * PHI_RES + j] = n as f64 * sum;
        }
    }
    out
}

/// The cell of a direction.
fn cell(w: Vec3) -> usize {
    let z = w.z.clamp(-1.0, 1.0) as f64;
    let i = (((z + 1.0) / 2.0 * THETA_RES as f64) as usize).min(THETA_RES - 1);
    let mut phi = (w.y as f64).atan2(w.x as f64);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    let j = ((phi / (2.0 * PI) * PHI_RES as f64) as usize).min(PHI_RES - 1);
    i * PHI_RES + j
}

/// Pearson's chi-square test: cells with expected count below 5 are pooled
/// (sorted by expected count, merged until the pool reaches 5); a sample in
/// a cell of expected count 0 fails outright. Returns the p-value.
fn chi2_test(observed: &[f64], expected: &[f64]) -> f64 {
    let mut idx: Vec<usize> = (0..observed.len()).collect();
    idx.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut chi2, mut dof) = (0.0, 0usize);
    let (mut pool_e, mut pool_o) = (0.0, 0.0);
    for &k in &idx {
        if expected[k] == 0.0 {
            assert!(observed[k] == 0.0, "{} samples in a cell where the pdf is zero", observed[k]);
            continue;
        }
        if expected[k] < 5.0 || pool_e > 0.0 && pool_e < 5.0 {
            pool_e += expected[k];
            pool_o += observed[k];
            if pool_e >= 5.0 {
                chi2 += (pool_o - pool_e).powi(2) / pool_e;
                dof += 1;
                pool_e = 0.0;
                pool_o = 0.0;
            }
            continue;
        }
        chi2 += (observed[k] - expected[k]).powi(2) / expected[k];
        dof += 1;
    }
    if pool_e > 0.0 {
        chi2 += (pool_o - pool_e).powi(2) / pool_e;
        dof += 1;
    }
    chi2_p_value(chi2, dof - 1)
}

/// Every non-delta model at several incident directions (normal, oblique,
/// grazing, from below) and wavelengths: `sample` histogrammed against
/// ∫ `pdf` over the cells, 100k samples each. Significance 1% overall,
/// Šidák-corrected over all the tests run (α' = 1 − 0.99^(1/k)), so a
/// correct sampler fails with probability 1% in total; a wrong one (e.g. a
/// uniform hemisphere sampler with the cosine pdf) has p ≈ 0.
#[test]
fn chi_square_sample_matches_pdf() {
    let models = [
        ("Lambertian", Bxdf::Lambertian(Lambertian { reflectance: Spectrum::from_fn(|i| 0.2 + 0.02 * i as f32) })),
        ("Oren-Nayar σ=0", Bxdf::OrenNayar(OrenNayar::new(Spectrum::splat(0.7), 0.0))),
        ("Oren-Nayar σ=20", Bxdf::OrenNayar(OrenNayar::new(Spectrum::splat(0.7), 20.0))),
        ("Oren-Nayar σ=60", Bxdf::OrenNayar(OrenNayar::new(Spectrum::splat(0.9), 60.0))),
    ];
    let thetas = [0.0f32, 40.0, 89.0, 130.0, 179.9];
    let wavelength_bins = [0usize, 17, 35];
    let tests = models.len() * thetas.len() * wavelength_bins.len();
    let alpha = 1.0 - 0.99f64.powf(1.0 / tests as f64);
    let n = 100_000;
    let mut seed = 0;
    for (name, b) in &models {
        for theta in thetas {
            let t = theta.to_radians();
            let wo = Vec3::new(t.sin() * 0.6, t.sin() * 0.8, t.cos()).normalize();
            let expected = expected_counts(|wi| b.pdf(wo, wi, &Lambdas::full()), n);
            for bin in wavelength_bins {
                seed += 1;
                let l = Lambdas::<1> { pos: [bin as f32], weight: 36.0, readout: crate::spectral::Readout::Spectral };
                let mut s = Sampler::new(seed, 11, 13);
                let mut observed = vec![0.0; THETA_RES * PHI_RES];
                for _ in 0..n {
                    if let Some(bs) = b.sample(wo, s.next_2d(), s.next_1d(), &l) {
                        assert!(!bs.is_delta && bs.pdf > 0.0);
                        observed[cell(bs.wi)] += 1.0;
                    }
                }
                let p = chi2_test(&observed, &expected);
                assert!(p > alpha, "{name}, θo = {theta}°, bin {bin}: p = {p:e} < {alpha:e}");
            }
        }
    }
}

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
            let mut s = Sampler::new(seed, 11, 13);
            let mut observed = vec![0.0; THETA_RES * PHI_RES];
            for _ in 0..n {
                if let Some(bs) = b.sample(wo, s.next_2d(), s.next_1d(), &l) {
                    assert!(!bs.is_delta && bs.pdf > 0.0 && bs.wi.z * wo.z > 0.0);
                    observed[cell(bs.wi)] += 1.0;
                }
            }
            let p = chi2_test(&observed, &expected);
            assert!(p > sig, "GGX α {alpha}, θo = {theta}°: p = {p:e} < {sig:e}");
        }
    }
}

/// The test has power: a uniform-hemisphere sampler is rejected against the
/// cosine pdf (p below 1e-12), so the passing results above mean something.
#[test]
fn chi_square_rejects_a_wrong_sampler() {
    let n = 100_000;
    let wo = Vec3::Z;
    let b = Bxdf::Lambertian(Lambertian { reflectance: Spectrum::ONE });
    let expected = expected_counts(|wi| b.pdf(wo, wi, &Lambdas::full()), n);
    let mut s = Sampler::new(1, 2, 3);
    let mut observed = vec![0.0; THETA_RES * PHI_RES];
    for _ in 0..n {
        let mut w = crate::sampler::warp::uniform_sphere(s.next_2d());
        w.z = w.z.abs();
        observed[cell(w)] += 1.0;
    }
    assert!(chi2_test(&observed, &expected) < 1e-12);
}

// ---------------------------------------------------------------------------
// Reciprocity, sample = eval, energy: every model, all angles, all wavelengths.

fn all_models() -> Vec<(&'static str, Bxdf)> {
    let rho = Spectrum::from_fn(|i| 0.05 + 0.95 * i as f32 / 35.0);
    vec![
        ("Lambertian", Bxdf::Lambertian(Lambertian { reflectance: rho })),
        ("Oren-Nayar σ=0", Bxdf::OrenNayar(OrenNayar::new(rho, 0.0))),
        ("Oren-Nayar σ=20", Bxdf::OrenNayar(OrenNayar::new(rho, 20.0))),
        ("Oren-Nayar σ=60", Bxdf::OrenNayar(OrenNayar::new(rho, 60.0))),
        ("Oren-Nayar σ=90", Bxdf::OrenNayar(OrenNayar::new(rho, 90.0))),
        ("Mirror", Bxdf::Mirror(Mirror { reflectance: rho })),
        ("Dielectric 1.5", Bxdf::Dielectric(Dielectric::new(Ior::Constant(1.5)))),
        ("Dielectric N-SF11", Bxdf::Dielectric(Dielectric::new(named_glass("N-SF11").unwrap()))),
        ("Conductor Au", conductor("Au", 0.0)),
        ("Conductor Cu α=0.001", conductor("Cu", SMOOTH_ALPHA)),
        ("Conductor Al α=0.05", conductor("Al", 0.05)),
        ("Conductor CuZn α=0.3", conductor("CuZn", 0.3)),
        ("Conductor Ag α=1", conductor("Ag", 1.0)),
        ("Plastic 1.5", Bxdf::Plastic(Plastic::new(rho, &Ior::Constant(1.5), 0.0))),
        ("Plastic N-SF11 α=0.2", Bxdf::Plastic(Plastic::new(rho, &named_glass("N-SF11").unwrap(), 0.2))),
        ("Coated Cr", coated("Cr", 0.0, 300.0)),
        ("Coated Au α=0.3", coated("Au", 0.3, 2000.0)),
        ("ThinSheet 400 nm", Bxdf::ThinSheet(ThinSheet { film: ThinFilm::new(400.0, &Ior::Constant(1.33)) })),
        ("Rough glass 1.5 α=0.001", rough_glass(Ior::Constant(1.5), SMOOTH_ALPHA)),
        ("Rough glass 1.5 α=0.15", rough_glass(Ior::Constant(1.5), 0.15)),
        ("Rough N-SF11 α=0.5", rough_glass(named_glass("N-SF11").unwrap(), 0.5)),
    ]
}

fn coated(metal: &str, alpha: f32, thickness_nm: f32) -> Bxdf {
    let (eta, k) = named_metal(metal).unwrap();
    let coating = Some(ThinFilm::new(thickness_nm, &Ior::Constant(1.45)));
    Bxdf::Conductor(Conductor { eta, k, alpha, coating })
}

fn rough_glass(ior: Ior, alpha: f32) -> Bxdf {
    Bxdf::Dielectric(Dielectric::new(ior).with_roughness(alpha))
}

/// The index on the side of `w` for a glass of index `eta` (outside: 1).
fn side_eta(w: Vec3, eta: f32) -> f32 {
    if w.z > 0.0 { 1.0 } else { eta }
}

fn conductor(metal: &str, alpha: f32) -> Bxdf {
    let (eta, k) = named_metal(metal).unwrap();
    Bxdf::Conductor(Conductor { eta, k, alpha, coating: None })
}

/// Incident cosines from normal to grazing, on both sides: down to 1e-6
/// (0.00006° from the surface).
const COSINES: [f32; 10] = [1.0, 0.7, 0.2, 0.02, 1e-4, 1e-6, -1e-6, -0.03, -0.5, -1.0];

fn dir(cos: f32, phi: f32) -> Vec3 {
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)
}

/// f(wo, wi) = f(wi, wo) for the non-delta models, for every wavelength bin,
/// over pairs of directions including grazing ones (both on one side).
#[test]
fn every_model_is_reciprocal() {
    let l = Lambdas::full();
    for (name, b) in all_models() {
        for &c1 in &COSINES {
            for &c2 in &COSINES {
                let (a, c) = (dir(c1, 0.3), dir(c2, 2.1));
                let (f1, f2) = (b.eval(a, c, &l), b.eval(c, a, &l));
                // Glass transmits radiance scaled by 1/η'², so its reciprocity is
                // f(a, c) / η(c)² = f(c, a) / η(a)² (Veach 1997, eq. 5.14 with the scaling).
                let (sa, sc) = match &b {
                    Bxdf::Dielectric(d) if c1 * c2 < 0.0 => {
                        let eta = d.eta_for(&l);
                        (side_eta(a, eta).powi(2), side_eta(c, eta).powi(2))
                    }
                    _ => (1.0, 1.0),
                };
                for i in 0..N_BINS {
                    assert!(f1[i].is_finite() && f1[i] >= 0.0, "{name}: f = {}", f1[i]);
                    let (g1, g2) = (f1[i] * sc, f2[i] * sa);
                    assert!((g1 - g2).abs() <= 1e-4 * g1.max(1.0), "{name} cos {c1}, {c2}: {} vs {}", f1[i], f2[i]);
                }
                if c1 * c2 < 0.0 && !matches!(b, Bxdf::Dielectric(_)) {
                    assert!(f1.is_black(), "{name}: opaque models never transmit");
                }
            }
        }
    }
}

/// For every model, every incident angle (grazing ones included) and every
/// wavelength: samples are finite, `sample`'s value and pdf equal `eval` and
/// `pdf` (checked inside `check_sample_consistency`), and the albedo is at
/// most 1. Diffuse models use 4000 cosine-weighted samples: for Lambertian
/// f cos / pdf = ρ exactly; for Oren-Nayar the weight A + B(...) varies by at
/// most a factor ~2, giving a relative std. error below 1%, so the bound is
/// 1 + 3%. Mirrors return exactly ρ; the dielectric exactly 1 (R + T, with
/// T's 1/η² undone).
#[test]
fn every_model_conserves_energy_at_all_angles_and_wavelengths() {
    for (name, b) in all_models() {
        for &c in &COSINES {
            let wo = dir(c, 0.7);
            if let Bxdf::Dielectric(_) | Bxdf::ThinSheet(_) = b {
                continue; // exactly (smooth, sheet) and against an integral (rough): below, thin_film.rs
            }
            let a = check_sample_consistency(&b, wo, 4000);
            for i in 0..N_BINS {
                assert!(a[i] <= 1.03, "{name}: cos θo {c}, bin {i}: albedo {}", a[i]);
                assert!(a[i] >= 0.0);
            }
            // A white diffuse surface keeps at least half (Oren-Nayar at σ = 90° keeps A = 0.56 at normal incidence).
            if let Bxdf::Conductor(m) = &b {
                if m.is_smooth() {
                    let f = m.fresnel(wo.z, &Lambdas::full());
                    for i in 0..N_BINS {
                        assert!(
                            (a[i] - f[i]).abs() < 1e-4 * f[i],
                            "{name}: cos {c}: albedo {} is not F = {}",
                            a[i],
                            f[i]
                        );
                    }
                }
            } else if !matches!(b, Bxdf::Mirror(_)) {
                let (white, low) = match &b {
                    Bxdf::OrenNayar(_) | Bxdf::Lambertian(_) => (a[N_BINS - 1], 0.5),
                    // A rough coat's single-scattering GGX reflection loses much of
                    // the light at grazing, where F sends most of it, and all of it
                    // in the limit (G1 → 0): no lower bound (plastic.rs).
                    Bxdf::Plastic(_) => (a[N_BINS - 1], 0.0),
                    _ => unreachable!(),
                };
                assert!(white > low && white <= 1.03, "{name}: cos θo {c}: white albedo {white}");
            } else {
                assert!((a[5] - (0.05 + 0.95 * 5.0 / 35.0)).abs() < 1e-5, "mirror keeps ρ at cos {c}");
            }
        }
    }
}

/// The dielectric conserves energy exactly at every angle (down to grazing,
/// on both sides, through total internal reflection) and for every named
/// glass at every bin's wavelength: R + T = 1 where R and T are the branch
/// probabilities `sample` reports, each branch's weight is 1 (reflection) or
/// 1/η² (refraction, undone on the way out), and nothing is NaN or infinite.
#[test]
fn dielectric_r_plus_t_is_one_for_every_glass_wavelength_and_angle() {
    for (glass, _, _) in NAMED_GLASSES {
        let d = Dielectric::new(named_glass(glass).unwrap());
        for bin in 0..N_BINS {
            let lambda = crate::color::bin_lambda_nm(bin);
            let eta = d.ior().at(lambda);
            let l = Lambdas::<1> { pos: [bin as f32], weight: 36.0, readout: crate::spectral::Readout::Spectral };
            let mut cos = 1.0f32;
            while cos > 1e-7 {
                for side in [1.0f32, -1.0] {
                    let wo = dir(cos * side, 1.1);
                    let b = Bxdf::Dielectric(d.clone());
                    let refl = b.sample(wo, Vec2::ZERO, 0.0, &l).expect("reflection");
                    let r = refl.pdf;
                    let wr = refl.f[0] * refl.wi.z.abs() / refl.pdf;
                    assert!((wr - 1.0).abs() < 1e-5 && refl.wi.z * wo.z > 0.0, "{glass} {lambda} cos {cos}");
                    let tr = b.sample(wo, Vec2::ZERO, 1.0 - 1e-7, &l).expect("a branch");
                    if tr.wi.z * wo.z < 0.0 {
                        assert!((r + tr.pdf - 1.0).abs() < 1e-6, "{glass} {lambda} nm cos {}: R + T", wo.z);
                        let w = tr.f[0] * tr.wi.z.abs() / tr.pdf;
                        assert!(w.is_finite() && (w * tr.eta * tr.eta - 1.0).abs() < 1e-3, "{glass}: weight {w}");
                        let want_eta = if side > 0.0 { eta } else { 1.0 / eta };
                        assert!((tr.eta - want_eta).abs() < 1e-6);
                    } else {
                        // Total internal reflection (only from inside): R = 1.
                        assert!(side < 0.0 && r == 1.0, "{glass} {lambda} cos {}: no refraction but R = {r}", wo.z);
                    }
                }
                cos *= 0.5;
            }
        }
    }
}

/// At the most grazing directions f32 can express (|cos θ| down to the
/// smallest normal and subnormal numbers, and exactly 0), sampling either
/// declines or returns finite weights: never NaN or infinity.
#[test]
fn grazing_directions_never_give_nan_or_infinity() {
    let l = Lambdas::full();
    for (name, b) in all_models() {
        for cos in [1e-20f32, f32::MIN_POSITIVE, 1e-40, 1e-45, 0.0, -1e-40, -f32::MIN_POSITIVE] {
            let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
            let mut s = Sampler::new(4, 4, 4);
            for _ in 0..64 {
                if let Some(bs) = b.sample(wo, s.next_2d(), s.next_1d(), &l) {
                    let w = bs.f * (bs.wi.z.abs() / bs.pdf);
                    assert!(!w.has_nan_or_inf() && bs.pdf.is_finite(), "{name} at cos {cos:e}: {bs:?}");
                }
                let f = b.eval(wo, Vec3::new(0.0, 0.6, 0.8), &l);
                assert!(!f.has_nan_or_inf(), "{name} eval at cos {cos:e}");
            }
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
            let mut s = Sampler::new(seed, 11, 13);
            let mut observed = vec![0.0; THETA_RES * PHI_RES];
            for _ in 0..n {
                if let Some(bs) = b.sample(wo, s.next_2d(), s.next_1d(), &l) {
                    assert!(!bs.is_delta && bs.pdf > 0.0);
                    observed[cell(bs.wi)] += 1.0;
                }
            }
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
            let mut s = Sampler::new(seed, 11, 13);
            let mut observed = vec![0.0; THETA_RES * PHI_RES];
            for _ in 0..n {
                if let Some(bs) = b.sample(wo, s.next_2d(), s.next_1d(), &l)
                    && !bs.is_delta
                {
                    observed[cell(bs.wi)] += 1.0;
                }
            }
            let p = chi2_test(&observed, &expected);
            assert!(p > sig, "plastic {b:?}, θo = {theta}°: p = {p:e} < {sig:e}");
        }
    }
}
