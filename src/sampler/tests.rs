//! Tests of the samplers: determinism, uniformity, the stratification of the `sobol`
//! sampler's draws, and its convergence rate on a smooth integrand.

use super::*;

fn draw_1d(kind: SamplerKind, seed: u64, pixel: u64, pass: u64, dim: Dim) -> f32 {
    Sampler::of_kind(kind, seed, pixel, pass, 1).get_1d(dim)
}

fn draw_2d(kind: SamplerKind, seed: u64, pixel: u64, pass: u64, dim: Dim) -> Vec2 {
    Sampler::of_kind(kind, seed, pixel, pass, 1).get_2d(dim)
}

#[test]
fn same_key_same_numbers_different_key_different_numbers() {
    let draw = |s: u64, p: u64, q: u64| {
        let mut r = Sampler::new(s, p, q);
        (0..8).map(|_| r.next_1d()).collect::<Vec<_>>()
    };
    assert_eq!(draw(1, 2, 3), draw(1, 2, 3));
    assert_ne!(draw(1, 2, 3), draw(1, 2, 4));
    assert_ne!(draw(1, 2, 3), draw(1, 3, 3));
    assert_ne!(draw(1, 2, 3), draw(2, 2, 3));
    let sobol = |s: u64, p: u64, q: u64, d: Dim| draw_2d(SamplerKind::Sobol, s, p, q, d);
    let d = Dim::bsdf(2);
    assert_eq!(sobol(1, 2, 3, d), sobol(1, 2, 3, d));
    for other in [sobol(1, 2, 4, d), sobol(1, 3, 3, d), sobol(2, 2, 3, d), sobol(1, 2, 3, Dim::bsdf(3))] {
        assert_ne!(sobol(1, 2, 3, d), other);
    }
}

/// The independent sampler ignores dimensions: it is the PCG32 stream of
/// `(seed, pixel, pass)` in request order, whatever dimension is named, exactly as
/// rust-v drew numbers before the dimension layout (reimplemented here from the old
/// `Sampler::new`: the same hashes, `Pcg32::new(state, stream)`, the top 24 bits).
#[test]
fn independent_is_the_old_stream_and_ignores_the_layout() {
    let old_stream = |seed: u64, pixel: u64, pass: u64| {
        let a = mix64(seed ^ 0x9e37_79b9_7f4a_7c15);
        let b = mix64(a ^ pixel.wrapping_mul(0xd1b5_4a32_d192_ed03));
        let state = mix64(b ^ pass.wrapping_mul(0x8cb9_2ba7_2f3d_8dd7));
        Pcg32::new(state, mix64(state ^ 0x5851_f42d_4c95_7f2d))
    };
    let mut rng = old_stream(5, 6, 7);
    let mut a = Sampler::of_kind(SamplerKind::Independent, 5, 6, 7, 1);
    for k in 0..16u32 {
        let x = if k % 3 == 0 { a.get_1d(Dim::roulette(k)) } else { a.get_2d(Dim::bsdf(40 - k)).y };
        if k % 3 != 0 {
            rng.next_u32();
        }
        assert_eq!(x, (rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32);
    }
}

/// Mean and variance of U[0,1) over 200k draws spread over many streams:
/// mean 1/2 with standard error sqrt(1/12/2e5) = 6.5e-4, so 4e-3 is > 6 sigma.
#[test]
fn numbers_are_uniform() {
    let (mut sum, mut sum2, mut n) = (0.0f64, 0.0f64, 0usize);
    for p in 0..2000 {
        let mut r = Sampler::new(7, p, 0);
        for _ in 0..100 {
            let x = r.next_1d() as f64;
            assert!((0.0..1.0).contains(&x));
            sum += x;
            sum2 += x * x;
            n += 1;
        }
    }
    let mean = sum / n as f64;
    let var = sum2 / n as f64 - mean * mean;
    assert!((mean - 0.5).abs() < 4e-3, "mean {mean}");
    assert!((var - 1.0 / 12.0).abs() < 4e-3, "variance {var}");
}

/// How many of `points` fall in each cell of the `2^a × 2^b` grid.
fn cell_counts(points: &[Vec2], a: u32, b: u32) -> Vec<u32> {
    let mut counts = vec![0u32; 1 << (a + b)];
    for p in points {
        let (i, j) = ((p.x * (1u32 << a) as f32) as usize, (p.y * (1u32 << b) as f32) as usize);
        counts[i * (1 << b) + j] += 1;
    }
    counts
}

/// The (0,m,2)-net property, against its definition: the first `2^m` samples of a pixel
/// put exactly one point in every elementary interval of area `2^-m` (every shape
/// `2^-a × 2^-(m-a)`), for the film draw (Sobol dimensions 0 and 1 themselves) and padded
/// pairs of the camera path, several m, seeds and pixels; 1D draws put one point in every
/// interval of length `2^-m`. A sample count that is a power of two times an aligned block
/// (samples `2^m .. 2^(m+1)`) is a net too (what `--passes` renders).
#[test]
fn sobol_draws_are_nets_in_every_elementary_interval() {
    for dim in [Dim::FILM, Dim::bsdf(0), Dim::light_sample(5)] {
        for (seed, pixel) in [(0u64, 0u64), (1, 77), (12345, 9_999_999)] {
            for m in [1u32, 4, 7, 10] {
                for start in [0u64, 1 << m] {
                    let pts: Vec<Vec2> =
                        (start..start + (1 << m)).map(|k| draw_2d(SamplerKind::Sobol, seed, pixel, k, dim)).collect();
                    for a in 0..=m {
                        let counts = cell_counts(&pts, a, m - a);
                        assert!(counts.iter().all(|&c| c == 1), "{dim:?} seed {seed} pixel {pixel} m {m} a {a}");
                    }
                }
            }
        }
    }
    for dim in [Dim::wavelength(0), Dim::lobe(2)] {
        let m = 8;
        let mut counts = vec![0u32; 1 << m];
        for k in 0..1u64 << m {
            counts[(draw_1d(SamplerKind::Sobol, 3, 4, k, dim) * (1 << m) as f32) as usize] += 1;
        }
        assert!(counts.iter().all(|&c| c == 1), "{dim:?}");
    }
}

/// BDPT's light subpaths draw from one point set over the film: on a film of `2^m`
/// pixels, the light subpaths of one pass (every pixel, pass fixed) are a (0,m,2)-net in
/// every 2D light draw and put one point in every interval of length `2^-m` in every 1D
/// one, for several m, seeds and passes; a pixel's own light draws over its passes are
/// not (they are `pixels` apart in the film's sequence).
#[test]
fn light_subpaths_are_stratified_over_the_film() {
    for m in [4u32, 7, 10] {
        let pixels = 1u64 << m;
        for (seed, pass) in [(0u64, 0u64), (1, 1), (12345, 37)] {
            let sample = |p: u64| Sampler::of_kind(SamplerKind::Sobol, seed, p, pass, pixels);
            for dim in [Dim::EMIT_POSITION, Dim::EMIT_DIRECTION, Dim::bsdf(3).on_light_path()] {
                let pts: Vec<Vec2> = (0..pixels).map(|p| sample(p).get_2d(dim)).collect();
                for a in 0..=m {
                    let counts = cell_counts(&pts, a, m - a);
                    assert!(counts.iter().all(|&c| c == 1), "{dim:?} seed {seed} pass {pass} m {m} a {a}");
                }
            }
            for dim in [Dim::EMIT_CHOICE, Dim::roulette(7).on_light_path()] {
                let mut counts = vec![0u32; 1 << m];
                for p in 0..pixels {
                    counts[(sample(p).get_1d(dim) * (1u64 << m) as f32) as usize] += 1;
                }
                assert!(counts.iter().all(|&c| c == 1), "{dim:?} seed {seed} pass {pass} m {m}");
            }
        }
    }
    // Past 2^32 light subpaths (pass 2^14 of a 2^18-pixel film) the numbers do not repeat.
    let (big, wrap) = (1u64 << 18, 1u64 << 14);
    let at = |pass: u64| Sampler::of_kind(SamplerKind::Sobol, 9, 5, pass, big).get_2d(Dim::EMIT_POSITION);
    assert_ne!(at(0), at(wrap));
    assert!(Dim::EMIT_CHOICE.is_light_path() && Dim::bsdf(0).on_light_path().is_light_path());
    assert!(!Dim::bsdf(0).is_light_path() && !Dim::FILM.is_light_path() && !Dim::wavelength(0).is_light_path());
}

/// Off the table (deep bounces) the `sobol` sampler gives hashed numbers: uniform
/// (chi-square over 64 cells of [0,1)², 63 degrees of freedom: 120 is p < 1e-5),
/// not stratified (a net would have chi-square 0), and uncorrelated between
/// consecutive samples and between neighbouring pixels (|r| < 0.02 over 20k
/// pairs is 2.8 standard errors of 1/sqrt(20000) = 0.007).
#[test]
fn the_fallback_is_uniform_and_independent() {
    let deep = Dim::bsdf(TABLE_BOUNCES);
    assert!(!deep.on_table() && Dim::bsdf(TABLE_BOUNCES - 1).on_table());
    let n = 20_000u64;
    let pts: Vec<Vec2> = (0..n).map(|k| draw_2d(SamplerKind::Sobol, 1, 2, k, deep)).collect();
    let counts = cell_counts(&pts, 3, 3);
    let expected = n as f64 / 64.0;
    let chi2: f64 = counts.iter().map(|&c| (c as f64 - expected).powi(2) / expected).sum();
    assert!(chi2 < 120.0 && chi2 > 20.0, "chi-square {chi2}");
    let corr = |a: &[f64], b: &[f64]| {
        let (ma, mb) = (a.iter().sum::<f64>() / a.len() as f64, b.iter().sum::<f64>() / b.len() as f64);
        let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
        let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
        let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
        cov / (va * vb).sqrt()
    };
    let xs: Vec<f64> = pts.iter().map(|p| p.x as f64).collect();
    let ys: Vec<f64> = pts.iter().map(|p| p.y as f64).collect();
    assert!(corr(&xs[..n as usize - 1], &xs[1..]).abs() < 0.02);
    assert!(corr(&xs, &ys).abs() < 0.02);
    let next_pixel: Vec<f64> = (0..n).map(|k| draw_2d(SamplerKind::Sobol, 1, 3, k, deep).x as f64).collect();
    assert!(corr(&xs, &next_pixel).abs() < 0.02);
    let mut deep1 = Sampler::of_kind(SamplerKind::Sobol, 1, 2, 0, 1);
    assert!((0.0..1.0).contains(&deep1.get_1d(Dim::roulette(100))));
}

/// Different pixels (and seeds) get different, uncorrelated scrambles of the same net:
/// over 4096 pixels the sample-0 film points are uniform (chi-square on 64 cells as above)
/// and a pixel's point says nothing about its neighbour's (|r| < 0.05, 3.2 standard errors).
#[test]
fn pixels_get_independent_scrambles() {
    let first: Vec<Vec2> = (0..4096u64).map(|p| draw_2d(SamplerKind::Sobol, 0, p, 0, Dim::FILM)).collect();
    let counts = cell_counts(&first, 3, 3);
    let chi2: f64 = counts.iter().map(|&c| (c as f64 - 64.0).powi(2) / 64.0).sum();
    assert!(chi2 < 120.0, "chi-square {chi2}");
    let (a, b): (Vec<f64>, Vec<f64>) = first.windows(2).map(|w| (w[0].x as f64 - 0.5, w[1].x as f64 - 0.5)).unzip();
    let r = a.iter().zip(&b).map(|(x, y)| x * y).sum::<f64>() / (a.len() as f64 / 12.0);
    assert!(r.abs() < 0.05, "neighbour correlation {r}");
    let mut distinct: Vec<(u32, u32)> = first.iter().map(|p| (p.x.to_bits(), p.y.to_bits())).collect();
    distinct.sort_unstable();
    distinct.dedup();
    assert!(distinct.len() > 4090, "{} distinct first points", distinct.len());
}

/// A smooth integrand, `cos x cos y` over [0,1)², integral sin²(1): with N = 1024 samples
/// the `sobol` estimate's RMS error over 32 pixels (independent scrambles) is at least 5x
/// below the independent sampler's RMS error, which is sqrt(Var f / N) in closed form
/// (Var f = ((1 + sin 2 / 2) / 2)² − sin⁴ 1). Owen-scrambled nets converge as N^-1.5 on
/// smooth integrands, so the expected factor is about sqrt(N) = 32; 5 leaves a wide margin.
/// Checked for the film draw and for a padded pair.
#[test]
fn sobol_beats_independent_by_5x_on_a_smooth_integral_at_1024_samples() {
    let exact = 1f64.sin().powi(2);
    let e_f2 = ((1.0 + 2f64.sin() / 2.0) / 2.0).powi(2);
    let n = 1024u64;
    let rms_independent = ((e_f2 - exact * exact) / n as f64).sqrt();
    for dim in [Dim::FILM, Dim::bsdf(4)] {
        let mut sq = 0.0;
        for pixel in 0..32u64 {
            let mean = (0..n)
                .map(|k| {
                    let u = draw_2d(SamplerKind::Sobol, 42, pixel, k, dim);
                    (u.x as f64).cos() * (u.y as f64).cos()
                })
                .sum::<f64>()
                / n as f64;
            sq += (mean - exact).powi(2);
        }
        let rms = (sq / 32.0).sqrt();
        assert!(rms * 5.0 < rms_independent, "{dim:?}: sobol {rms:e} vs independent {rms_independent:e}");
    }
}
