//! Continuous wavelengths: where a path follows single wavelengths (after a
//! dispersive split or collapse), they are drawn over 360-830 nm, not only at
//! the 36 bin centres, so that a prism shows a smooth spectrum instead of 36
//! bands. The proof that the estimates stay unbiased is in the parent module's
//! doc ([`super`], "Continuous wavelengths").
//!
//! - [`continuous_wavelength`]: one wavelength for a collapse, drawn from the
//!   36-bin selection weights (throughput × visual importance) and placed
//!   within the chosen bin's interpolation tent; [`for_each_rotated_continuous`]
//!   draws `C` of them by stratified rotation;
//! - [`sample_packet_continuous`]: a packet of the `spectral` integrator at
//!   continuous wavelengths, uniform over 360-830 nm.

use crate::color::{self, INTEGRAL_RANGE_NM, LAMBDA_MIN_NM, LAMBDA_STEP_NM, N_BINS};

use super::{BinDistribution, Lambdas, Readout, WavelengthSampling};

/// The first and last wavelength a continuous draw can take, in nm (the
/// colour integral's range).
const RANGE: (f32, f32) = (INTEGRAL_RANGE_NM.0 as f32, INTEGRAL_RANGE_NM.1 as f32);

/// The width of the colour integral's range, in nm.
const SPAN_NM: f32 = RANGE.1 - RANGE.0;

/// The area `A_b = ∫ φ_b(λ) dλ` (nm) of bin `b`'s interpolation tent
/// ([`color::tent`]): 10 nm inside; the first bin's tent is flat from 360 to
/// 380 nm (20 + 5), the last one's from 730 to 830 nm (5 + 100).
#[inline]
pub fn tent_area(b: usize) -> f32 {
    let half = 0.5 * LAMBDA_STEP_NM;
    if b == 0 {
        LAMBDA_MIN_NM - RANGE.0 + half
    } else if b == N_BINS - 1 {
        RANGE.1 - bin_nm(N_BINS - 1) + half
    } else {
        LAMBDA_STEP_NM
    }
}

/// The centre of bin `b` in nm.
#[inline]
fn bin_nm(b: usize) -> f32 {
    LAMBDA_MIN_NM + LAMBDA_STEP_NM * b as f32
}

/// The wavelength (nm) that `v` in [0, 1) maps to under the inverse
/// cumulative distribution of bin `b`'s tent, `φ_b(λ) / A_b`.
#[inline]
pub fn sample_tent(b: usize, v: f32) -> f32 {
    let (c, h) = (bin_nm(b), LAMBDA_STEP_NM);
    let v = v.clamp(0.0, 1.0);
    // The rising half [c − h, c] has cumulative area x² / 2h at c − h + x; the
    // falling half [c, c + h] has x − x² / 2h at c + x (both of total h / 2).
    let rising = |area: f32| c - h + (2.0 * h * area).max(0.0).sqrt();
    let falling = |area: f32| c + h - (h * h - 2.0 * h * area).max(0.0).sqrt();
    if b == 0 {
        let flat = LAMBDA_MIN_NM - RANGE.0;
        let s = v * tent_area(0);
        if s < flat { RANGE.0 + s } else { falling(s - flat) }
    } else if b == N_BINS - 1 {
        let s = v * tent_area(b);
        if s < 0.5 * h { rising(s) } else { c + (s - 0.5 * h) }
    } else if v < 0.5 {
        rising(v * h)
    } else {
        falling(v * h - 0.5 * h)
    }
}

/// The density (per nm) of a continuous draw from `select` at `lambda_nm`:
/// `p(λ) = Σ_b P_b · φ_b(λ) / A_b` over the (at most two) tents that cover λ.
#[inline]
pub fn continuous_density(select: &BinDistribution, lambda_nm: f32) -> f32 {
    let pos = (lambda_nm - LAMBDA_MIN_NM) / LAMBDA_STEP_NM;
    let b0 = (pos.max(0.0) as usize).min(N_BINS - 1);
    let mut p = 0.0;
    for b in b0.saturating_sub(1)..(b0 + 2).min(N_BINS) {
        let t = color::tent(b, lambda_nm as f64) as f32;
        if t > 0.0 {
            p += select.prob(b) * t / tent_area(b);
        }
    }
    p
}

/// One continuous wavelength for a collapse, for any integrator: a bin chosen
/// from the 36-bin selection weights `select` (e.g. throughput × visual
/// importance) by inverting `u`, then placed within that bin's interpolation
/// tent by the rest of `u` (its position within the bin's share, uniform
/// again). Returns the packet of that one wavelength (readout
/// [`Readout::Continuous`], its weight `1 / p(λ)`) and that weight, where
/// `p(λ) = Σ_b P_b · φ_b(λ) / A_b` is the draw's full density per nm
/// ([`continuous_density`]); the estimate `L(λ) · cmf(λ) / p(λ)` is unbiased
/// for `∫ cmf · L` (parent module doc). Multiply the weight by the packet's own
/// weight (and by `1 / C` for `C` draws) before tracing.
///
/// `p(λ) > 0` wherever the interpolated selection weights are, so the weight is
/// finite; a draw that lands exactly on a tent's foot (density 0, probability
/// 0 in exact arithmetic, possible through f32 rounding) moves to the bin's
/// centre.
#[inline]
pub fn continuous_wavelength(select: &BinDistribution, u: f32) -> (Lambdas<1>, f32) {
    let (bin, v) = select.sample_with_remainder(u);
    let mut lambda = sample_tent(bin, v);
    let mut p = continuous_density(select, lambda);
    if p.is_nan() || p <= 0.0 {
        lambda = bin_nm(bin);
        p = continuous_density(select, lambda);
    }
    let weight = 1.0 / p;
    let pos = [(lambda - LAMBDA_MIN_NM) / LAMBDA_STEP_NM];
    (Lambdas { pos, weight, readout: Readout::Continuous }, weight)
}

/// [`continuous_wavelength`] for `c` draws by stratified rotation (as
/// [`super::for_each_rotated`]): draw `k` inverts `(u + k / c) mod 1`. Calls
/// `visit(lambdas, weight)` with each draw's packet, its weight already
/// `1 / (c · p(λ))`.
#[inline]
pub fn for_each_rotated_continuous(d: &BinDistribution, c: usize, u: f32, mut visit: impl FnMut(Lambdas<1>, f32)) {
    for k in 0..c {
        let (mut one, w) = continuous_wavelength(d, (u + k as f32 / c as f32).fract());
        one.weight = w / c as f32;
        visit(one, one.weight);
    }
}

/// A packet of `C` continuous wavelengths, each uniform over 360-830 nm: hero
/// (the first at `u[0]`, the others at equal rotation of the range) or
/// independent. Each wavelength has density `1 / 470` per nm, so the packet's
/// weight is `470 / C`. `u` supplies `C` uniform numbers in [0, 1).
pub fn sample_packet_continuous<const C: usize>(how: WavelengthSampling, u: [f32; C]) -> Lambdas<C> {
    let at = |x: f32| RANGE.0 + SPAN_NM * x.clamp(0.0, 1.0);
    let nm: [f32; C] = match how {
        WavelengthSampling::Hero => std::array::from_fn(|k| at((u[0] + k as f32 / C as f32).fract())),
        WavelengthSampling::Random => u.map(at),
    };
    Lambdas {
        pos: nm.map(|l| (l - LAMBDA_MIN_NM) / LAMBDA_STEP_NM),
        weight: SPAN_NM / C as f32,
        readout: Readout::Continuous,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::{Sampled, Spectrum};
    use crate::spectral::bin_importance;

    /// A selection with uneven weights and a run of zero bins (a throughput
    /// that is 0 in bins 9-11), like a collapse sees.
    fn selection() -> BinDistribution {
        let imp = bin_importance();
        BinDistribution::new(|b| if (9..=11).contains(&b) { 0.0 } else { imp[b] * (1.2 + (b as f32 * 0.7).sin()) })
            .unwrap()
    }

    /// Each tent sampler inverts its own cumulative distribution: a histogram
    /// of `sample_tent` over an even grid of `v` matches `φ_b / A_b` integrated
    /// over each 1 nm cell (midpoint values; the tent is linear per cell, so
    /// exact), within 2e-3 absolute probability per cell. The grid has 200 000
    /// points, so discretisation is below 1e-4; a sampler with a wrong branch
    /// (e.g. a symmetric triangle for bin 0) is off by over 0.02.
    #[test]
    fn tent_samplers_follow_the_tents() {
        for b in [0, 1, 17, 34, 35] {
            let n = 200_000;
            let mut hist = vec![0.0f64; 471];
            for i in 0..n {
                let l = sample_tent(b, (i as f32 + 0.5) / n as f32);
                assert!((RANGE.0..=RANGE.1).contains(&l), "bin {b}: {l}");
                hist[((l - RANGE.0) as usize).min(469)] += 1.0 / n as f64;
            }
            for (cell, &h) in hist.iter().enumerate().take(470) {
                let want = color::tent(b, RANGE.0 as f64 + cell as f64 + 0.5) / tent_area(b) as f64;
                assert!((h - want).abs() < 2e-3, "bin {b}, {} nm: {h} vs {want}", 360 + cell);
            }
        }
    }

    /// The continuous density integrates to 1 over 360-830 nm: a 0.01 nm
    /// midpoint sum of `continuous_density` (piecewise linear, so the sum is
    /// exact up to the kinks), within 1e-4. The tent areas are checked the
    /// same way against `color::tent`.
    #[test]
    fn continuous_density_integrates_to_one() {
        let d = selection();
        let h = 0.01f64;
        let steps = (SPAN_NM as f64 / h) as usize;
        let (mut total, mut areas) = (0.0f64, [0.0f64; N_BINS]);
        for i in 0..steps {
            let l = RANGE.0 as f64 + (i as f64 + 0.5) * h;
            total += continuous_density(&d, l as f32) as f64 * h;
            for (b, a) in areas.iter_mut().enumerate() {
                *a += color::tent(b, l) * h;
            }
        }
        assert!((total - 1.0).abs() < 1e-4, "∫ p = {total}");
        for (b, a) in areas.iter().enumerate() {
            assert!((a - tent_area(b) as f64).abs() < 1e-6 * a.max(1.0) + 1e-6, "bin {b}: {a}");
        }
    }

    /// The unbiasedness proof, checked numerically: for an analytic spectrum
    /// `L` (a narrow Gaussian at 587 nm, σ = 3 nm, between bins; and a linear
    /// ramp over the whole range) times the interpolated selection weights'
    /// support, the expectation of `L(λ) · cmf(λ) · weight` over `u` equals
    /// the colour integral `∫ cmf · L / ∫ ȳ` computed independently from the
    /// 1 nm CSV text (trapezoidal rule on the 1 nm rows, for both integrals).
    ///
    /// The expectation is taken as a midpoint sum over 400 000 values of `u`
    /// for 4 rotated draws (quasi-Monte Carlo in one dimension: error O(1/n)
    /// for the piecewise-smooth integrand, about 1e-5); the 1 nm trapezoid of
    /// `cmf · L` differs from the integral of the interpolated `cmf` times `L`
    /// by about h²/12 · |cmf''/cmf| ≈ 1e-4 relative (the CMFs vary over tens
    /// of nm). Tolerance: 3e-3 relative per channel. The discrete bin-centre estimator misses the
    /// Gaussian's shape (it sees the 580 and 590 nm values only) by over 5%.
    #[test]
    fn continuous_estimate_matches_the_1nm_integral() {
        let d = selection();
        let gauss = |l: f64| (-0.5 * ((l - 587.0) / 3.0).powi(2)).exp();
        let ramp = |l: f64| 0.2 + (l - 360.0) / 470.0;
        // The selection is 0 in bins 9-11, so the light there is 0 too (the
        // estimator is unbiased for L times the interpolated throughput's support).
        let support = |l: f64| 1.0 - (9..=11).map(|b| color::tent(b, l)).sum::<f64>();
        for (name, f) in [("gaussian", &gauss as &dyn Fn(f64) -> f64), ("ramp", &ramp)] {
            let l_of = |l: f64| f(l) * support(l);
            let mut want = [0.0f64; 3];
            // Independent truth: the 1 nm table, read here from the CSV text
            // through the renderer's weights' normalisation (Σ_b W_b,y = 1).
            let rows: Vec<Vec<f64>> = include_str!("../color/data/cmf_1931_2deg_360_830_1nm.csv")
                .lines()
                .skip(1)
                .map(|r| r.split(',').map(|c| c.trim().parse().unwrap()).collect())
                .collect();
            let ybar: f64 = rows.windows(2).map(|p| 0.5 * (p[0][2] + p[1][2])).sum();
            for (i, r) in rows.iter().enumerate() {
                let end = if i == 0 || i == rows.len() - 1 { 0.5 } else { 1.0 };
                for k in 0..3 {
                    want[k] += end * r[k + 1] * l_of(r[0]) / ybar;
                }
            }
            let n = 400_000;
            let mut got = [0.0f64; 3];
            for i in 0..n {
                let u = (i as f32 + 0.5) / n as f32;
                for_each_rotated_continuous(&d, 4, u, |one, w| {
                    let l = one.lambda_nm(0) as f64;
                    let v = l_of(l) as f32;
                    let xyz = one.xyz(&Sampled([v]));
                    assert!(w.is_finite() && w > 0.0);
                    got[0] += xyz.x as f64 / n as f64;
                    got[1] += xyz.y as f64 / n as f64;
                    got[2] += xyz.z as f64 / n as f64;
                });
            }
            for k in 0..3 {
                let rel = (got[k] - want[k]).abs() / want[k];
                assert!(rel < 3e-3, "{name} channel {k}: {} vs {} ({rel:e})", got[k], want[k]);
            }
        }
        // The bin-centre estimator (the discrete draw) of the Gaussian is far off.
        let s = Spectrum::from_fn(|b| gauss(crate::color::bin_lambda_nm(b) as f64) as f32);
        let exact: f64 = (360..830).map(|l| gauss(l as f64 + 0.5) * color::cmf_at(l as f32 + 0.5)[1] as f64).sum();
        assert!((s.to_xyz().y as f64 / exact - 1.0).abs() > 0.05);
    }

    /// Uniform continuous packets: hero rotation keeps every wavelength in
    /// range and spaced 470 / C nm apart (mod the range); the weight is 470 / C.
    #[test]
    fn continuous_packets_are_uniform_over_the_range() {
        let l = sample_packet_continuous::<4>(WavelengthSampling::Hero, [0.9, 0.0, 0.0, 0.0]);
        assert_eq!(l.weight, 470.0 / 4.0);
        let nm: Vec<f32> = (0..4).map(|i| l.lambda_nm(i)).collect();
        assert!((nm[0] - (360.0 + 0.9 * 470.0)).abs() < 1e-3, "{nm:?}");
        assert!((nm[1] - (360.0 + 0.15 * 470.0)).abs() < 1e-2, "{nm:?}");
        let r = sample_packet_continuous::<2>(WavelengthSampling::Random, [0.0, 0.999_999_9]);
        assert!((r.lambda_nm(0) - 360.0).abs() < 1e-4 && (r.lambda_nm(1) - 830.0).abs() < 1e-2);
    }

    /// No NaN or infinity at the ends of the range: draws at u = 0 and u → 1
    /// from selections that put everything in the first or last bin land at
    /// 360 and 830 nm with finite weights, and their readout is finite.
    #[test]
    fn ends_of_the_range_are_finite() {
        for only in [0usize, N_BINS - 1] {
            let d = BinDistribution::new(|b| (b == only) as u8 as f32).unwrap();
            for u in [0.0f32, 1e-9, 0.5, 0.999_999_9, 1.0] {
                let (one, w) = continuous_wavelength(&d, u);
                let l = one.lambda_nm(0);
                assert!((RANGE.0..=RANGE.1).contains(&l) && w.is_finite() && w > 0.0, "{only} {u}: {l} {w}");
                let xyz = one.xyz(&Sampled([1.0]));
                assert!(xyz.x.is_finite() && xyz.y.is_finite() && xyz.z.is_finite());
            }
        }
        // Interior bins' tent feet (density 0 when the neighbour has probability 0).
        let d = BinDistribution::new(|b| (b == 17) as u8 as f32).unwrap();
        for u in [0.0f32, 1.0] {
            let (_, w) = continuous_wavelength(&d, u);
            assert!(w.is_finite() && w > 0.0, "{u}: {w}");
        }
        for l in [360.0f32, 830.0, 359.0, 831.0, f32::NAN] {
            assert!(color::cmf_at(l).iter().all(|v| v.is_finite() && *v >= 0.0));
        }
    }
}
