//! Image metrics: the error measures of the thesis (chapter 4) and a few standard ones.
//!
//! `rust-v compare` and `rust-v converge` measure an image against a reference with
//! these functions, so that a number printed by one and charted by the other mean the
//! same thing. Two families of values are kept for every image ([`Image`]):
//!
//! - **16-bit sRGB codes** (0..=65535 per channel), on which the thesis defines its
//!   metrics (§4.1-4.2): a pixel is the vector `(r, g, b)` of codes and two pixels differ
//!   by the Euclidean distance Δ (eq. 4.1). [`mse16`] (eq. 4.6), [`psnr16`] (eq. 4.7,
//!   with `L = |(65535, 65535, 65535)|` = [`THESIS_L`]), [`ssim_global`] (eq. 4.8) and
//!   [`error_variance`] (Figure 5.2d) work on them. For an EXR the codes are made as
//!   our PNG output makes them ([`crate::io::image::encode_u16`]: clamp to [0, 1], sRGB
//!   curve, round); for a PNG they are the file's values (8-bit values scaled by 257).
//! - **Linear sRGB** values, on which [`mse_linear`], [`relmse`] and the mean relative
//!   errors work, defined as in the Mitsuba 3 peer harness (`common.py`) so the numbers
//!   can be compared with its CSVs. For an EXR they are the file's floats; for a PNG they
//!   are decoded from the sRGB curve (so they are clamped to [0, 1] and quantised).
//!
//! [`ssim_windowed`] is the standard SSIM of Wang et al. (2004): 11x11 Gaussian window
//! with σ = 1.5, computed per channel on the 16-bit codes with `L = 65535`, averaged
//! over all window positions inside the image and over the three channels.

use std::path::Path;

use crate::color::srgb_eotf;
use crate::error::{Error, Result};
use crate::film::Film;
use crate::io::image::{Pixels, encode_u16, read_image};

/// The thesis' maximum signal, `L = |(65535, 65535, 65535)| = 65535 √3` (eq. 4.5).
pub const THESIS_L: f64 = 113_509.949_674_026_37;
/// SSIM constant `k1` (`c1 = (k1 L)²`).
pub const K1: f64 = 0.01;
/// SSIM constant `k2` (`c2 = (k2 L)²`).
pub const K2: f64 = 0.03;
/// Side of the Gaussian window of [`ssim_windowed`].
pub const SSIM_WINDOW: usize = 11;
/// Standard deviation (pixels) of the Gaussian window of [`ssim_windowed`].
pub const SSIM_SIGMA: f64 = 1.5;
/// Per-channel dynamic range of [`ssim_windowed`] (16-bit codes).
pub const CHANNEL_L: f64 = 65535.0;
/// The bias in the denominator of [`relmse`] (as in the Mitsuba harness).
pub const RELMSE_EPSILON: f64 = 0.01;

/// Where an image's values came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// Linear floats (an EXR file or a film); 16-bit codes are encoded from them.
    Linear,
    /// sRGB-encoded integers (a PNG file); linear values are decoded from them.
    Encoded,
}

/// An image held both as 16-bit sRGB codes and as linear sRGB values, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// 16-bit sRGB codes (0..=65535) per pixel, as f64.
    pub code16: Vec<[f64; 3]>,
    /// Linear sRGB per pixel.
    pub linear: Vec<[f64; 3]>,
    /// Which of the two was primary.
    pub source: Source,
}

impl Image {
    /// An image from linear sRGB values; the codes are encoded as in our PNG output.
    pub fn from_linear(width: u32, height: u32, linear: Vec<[f64; 3]>) -> Image {
        let code16 = linear.iter().map(|p| p.map(|v| encode_u16(v) as f64)).collect();
        Image { width, height, code16, linear, source: Source::Linear }
    }

    /// An image from 16-bit sRGB codes; the linear values are decoded with the sRGB curve.
    pub fn from_code16(width: u32, height: u32, codes: &[[u16; 3]]) -> Image {
        let code16 = codes.iter().map(|p| p.map(f64::from)).collect();
        let linear = codes.iter().map(|p| p.map(|c| srgb_eotf(c as f32 / 65535.0) as f64)).collect();
        Image { width, height, code16, linear, source: Source::Encoded }
    }

    /// The current mean of a film.
    pub fn from_film(film: &Film) -> Image {
        Image::from_linear(film.width(), film.height(), film.linear_srgb())
    }

    /// Reads a PNG (8 or 16 bits per channel) or an EXR (linear sRGB floats).
    pub fn read(path: &Path) -> Result<Image> {
        Ok(match read_image(path)? {
            (w, h, Pixels::Linear(linear)) => Image::from_linear(w, h, linear),
            (w, h, Pixels::Code16(codes)) => Image::from_code16(w, h, &codes),
        })
    }

    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.code16.len()
    }

    /// True for an image without pixels.
    pub fn is_empty(&self) -> bool {
        self.code16.is_empty()
    }
}

/// Every metric of an image against a reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    /// Thesis MSE (eq. 4.6): mean squared Euclidean distance of 16-bit RGB codes.
    pub mse: f64,
    /// Thesis PSNR in dB (eq. 4.7), `L` = [`THESIS_L`].
    pub psnr: f64,
    /// Thesis global SSIM (eq. 4.8) on pixel magnitudes of 16-bit codes.
    pub ssim: f64,
    /// Standard windowed SSIM (Wang et al. 2004) on 16-bit codes.
    pub ssim_windowed: f64,
    /// Variance of the per-pixel error distance Δ (thesis Figure 5.2d, our definition: [`error_variance`]).
    pub variance: f64,
    /// Linear MSE: mean over pixels and channels of the squared difference of linear values.
    pub mse_lin: f64,
    /// Linear PSNR in dB with peak 1 (display white): `10 log10(1 / mse_lin)`.
    pub psnr_lin: f64,
    /// Relative MSE: mean over pixels and channels of `d² / (ref² + 0.01)` (linear).
    pub relmse: f64,
    /// `|mean_A - mean_B| / mean_B` of linear luminance Y over the image.
    pub rel_err_luminance: f64,
    /// `|mean_A - mean_B| / mean_B` of each linear channel (R, G, B).
    pub rel_err_rgb: [f64; 3],
    /// Firefly share of the image (not the reference): [`firefly_share`] of its linear values.
    pub firefly: f64,
}

/// All metrics of `img` against `reference`. Errors when the sizes differ.
pub fn measure(img: &Image, reference: &Image) -> Result<Metrics> {
    if (img.width, img.height) != (reference.width, reference.height) {
        return Err(Error::Settings(format!(
            "images differ in size: {}x{} and {}x{}",
            img.width, img.height, reference.width, reference.height
        )));
    }
    let (a, b) = (&img.code16, &reference.code16);
    let mse = mse16(a, b);
    let (mean_a, mean_b) = (channel_means(&img.linear), channel_means(&reference.linear));
    let lum = |m: [f64; 3]| LUMINANCE[0] * m[0] + LUMINANCE[1] * m[1] + LUMINANCE[2] * m[2];
    let mse_lin = mse_linear(&img.linear, &reference.linear);
    Ok(Metrics {
        mse,
        psnr: psnr16(mse),
        ssim: ssim_global(a, b),
        ssim_windowed: ssim_windowed(a, b, img.width as usize, img.height as usize),
        variance: error_variance(a, b),
        mse_lin,
        psnr_lin: if mse_lin > 0.0 { -10.0 * mse_lin.log10() } else { f64::INFINITY },
        relmse: relmse(&img.linear, &reference.linear),
        rel_err_luminance: relative_error(lum(mean_a), lum(mean_b)),
        rel_err_rgb: [0, 1, 2].map(|c| relative_error(mean_a[c], mean_b[c])),
        firefly: firefly_share(&img.linear),
    })
}

/// The fraction of pixels counted as fireflies by [`firefly_share`] (0.1%).
pub const FIREFLY_FRACTION: f64 = 0.001;

/// The firefly measure: the share of the image's total linear luminance
/// (`Y = 0.2126 R + 0.7152 G + 0.0722 B`, [`LUMINANCE`]) held by its brightest 0.1%
/// of pixels ([`FIREFLY_FRACTION`]), at least one pixel: `k = max(1, ceil(0.001 n))`
/// pixels of `n`. Negative luminances count as 0. It is between `k / n` (a uniform
/// image) and 1 (all energy in `k` pixels); a converged, smooth image sits near
/// `k / n`, and a few fireflies push it up. NaN for an image without energy.
pub fn firefly_share(linear: &[[f64; 3]]) -> f64 {
    let mut y: Vec<f64> =
        linear.iter().map(|p| (LUMINANCE[0] * p[0] + LUMINANCE[1] * p[1] + LUMINANCE[2] * p[2]).max(0.0)).collect();
    let total: f64 = y.iter().sum();
    if y.is_empty() || total.is_nan() || total <= 0.0 {
        return f64::NAN;
    }
    let k = ((FIREFLY_FRACTION * y.len() as f64).ceil() as usize).clamp(1, y.len());
    y.sort_unstable_by(|a, b| b.total_cmp(a));
    y[..k].iter().sum::<f64>() / total
}

/// Rec. 709 / sRGB luminance weights (the Y row of the linear sRGB to XYZ matrix).
pub const LUMINANCE: [f64; 3] = [0.2126, 0.7152, 0.0722];

fn relative_error(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn channel_means(p: &[[f64; 3]]) -> [f64; 3] {
    let n = p.len().max(1) as f64;
    let mut s = [0.0; 3];
    for v in p {
        for c in 0..3 {
            s[c] += v[c];
        }
    }
    s.map(|x| x / n)
}

fn dist2(p: &[f64; 3], q: &[f64; 3]) -> f64 {
    (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)
}

fn mean(v: impl ExactSizeIterator<Item = f64>) -> f64 {
    let n = v.len().max(1) as f64;
    v.sum::<f64>() / n
}

/// Thesis MSE (eq. 4.6 with the distance of eq. 4.1): the mean over pixels of the
/// squared Euclidean distance between RGB vectors.
pub fn mse16(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    mean(a.iter().zip(b).map(|(p, q)| dist2(p, q)))
}

/// Thesis PSNR (eq. 4.7): `20 log10(L) - 10 log10(MSE)` with `L` = [`THESIS_L`];
/// infinite for identical images.
pub fn psnr16(mse: f64) -> f64 {
    if mse > 0.0 { 20.0 * THESIS_L.log10() - 10.0 * mse.log10() } else { f64::INFINITY }
}

/// Thesis global SSIM (eq. 4.8, statistics of eqs. 4.2-4.4 over the whole image).
///
/// A pixel is a 3-vector and eq. 4.8 needs scalars, so each pixel is taken as its
/// magnitude `|x_ij|` (the quantity whose maximum is `L`, eq. 4.5), as the thesis'
/// own implementation did; `c1 = (k1 L)²`, `c2 = (k2 L)²` with `L` = [`THESIS_L`].
pub fn ssim_global(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    let mag = |p: &[f64; 3]| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    let x: Vec<f64> = a.iter().map(mag).collect();
    let y: Vec<f64> = b.iter().map(mag).collect();
    let (mx, my) = (mean(x.iter().copied()), mean(y.iter().copied()));
    let vx = mean(x.iter().map(|v| (v - mx).powi(2)));
    let vy = mean(y.iter().map(|v| (v - my).powi(2)));
    let cov = mean(x.iter().zip(&y).map(|(u, v)| (u - mx) * (v - my)));
    let c1 = (K1 * THESIS_L).powi(2);
    let c2 = (K2 * THESIS_L).powi(2);
    ssim_formula(mx, my, vx, vy, cov, c1, c2)
}

/// `((2 μx μy + c1)(2 σxy + c2)) / ((μx² + μy² + c1)(σx² + σy² + c2))`.
pub fn ssim_formula(mx: f64, my: f64, vx: f64, vy: f64, cov: f64, c1: f64, c2: f64) -> f64 {
    ((2.0 * mx * my + c1) * (2.0 * cov + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2))
}

/// The normalised 1-D Gaussian of `n` taps with standard deviation [`SSIM_SIGMA`].
fn gaussian(n: usize) -> Vec<f64> {
    let c = (n as f64 - 1.0) / 2.0;
    let w: Vec<f64> = (0..n).map(|i| (-((i as f64 - c).powi(2)) / (2.0 * SSIM_SIGMA * SSIM_SIGMA)).exp()).collect();
    let s: f64 = w.iter().sum();
    w.into_iter().map(|v| v / s).collect()
}

/// 'Valid' separable filtering of a `w × h` plane with kernel `k`: `(w-n+1) × (h-n+1)`.
fn filter_valid(plane: &[f64], w: usize, h: usize, k: &[f64]) -> Vec<f64> {
    let n = k.len();
    let (ow, oh) = (w + 1 - n, h + 1 - n);
    let mut rows = vec![0.0; ow * h];
    for y in 0..h {
        for x in 0..ow {
            rows[y * ow + x] = k.iter().enumerate().map(|(i, kv)| kv * plane[y * w + x + i]).sum();
        }
    }
    let mut out = vec![0.0; ow * oh];
    for y in 0..oh {
        for x in 0..ow {
            out[y * ow + x] = k.iter().enumerate().map(|(i, kv)| kv * rows[(y + i) * ow + x]).sum();
        }
    }
    out
}

/// Standard windowed SSIM (Wang, Bovik, Sheikh, Simoncelli 2004).
///
/// Per channel of the 16-bit codes: Gaussian-weighted means, variances and covariance
/// over an 11x11 window (σ = 1.5) at every position where the window lies inside the
/// image, the SSIM formula with `c1 = (0.01 · 65535)²`, `c2 = (0.03 · 65535)²`, then
/// the mean over positions and channels. Images smaller than 11 pixels on a side use
/// a window as large as their smaller side (the Gaussian is cut and renormalised).
pub fn ssim_windowed(a: &[[f64; 3]], b: &[[f64; 3]], width: usize, height: usize) -> f64 {
    if a.is_empty() || a.len() != width * height || b.len() != a.len() {
        return f64::NAN;
    }
    let k = gaussian(SSIM_WINDOW.min(width).min(height));
    let c1 = (K1 * CHANNEL_L).powi(2);
    let c2 = (K2 * CHANNEL_L).powi(2);
    let mut total = 0.0;
    let mut count = 0usize;
    for c in 0..3 {
        let x: Vec<f64> = a.iter().map(|p| p[c]).collect();
        let y: Vec<f64> = b.iter().map(|p| p[c]).collect();
        let f = |v: &[f64]| filter_valid(v, width, height, &k);
        let prod = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(p, q)| p * q).collect::<Vec<f64>>();
        let (mx, my) = (f(&x), f(&y));
        let (xx, yy, xy) = (f(&prod(&x, &x)), f(&prod(&y, &y)), f(&prod(&x, &y)));
        for i in 0..mx.len() {
            let vx = xx[i] - mx[i] * mx[i];
            let vy = yy[i] - my[i] * my[i];
            let cov = xy[i] - mx[i] * my[i];
            total += ssim_formula(mx[i], my[i], vx, vy, cov, c1, c2);
            count += 1;
        }
    }
    total / count as f64
}

/// The variance of the thesis' Figure 5.2d, defined here (the thesis plots it but
/// gives no formula) as the variance (eq. 4.3) of the per-pixel error distance
/// `Δ_ij = |x_ij - y_ij|` (eq. 4.1) on 16-bit codes: how unevenly the error is spread
/// over the image, in squared 16-bit code units. It is `MSE - (mean Δ)²`.
pub fn error_variance(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    let d: Vec<f64> = a.iter().zip(b).map(|(p, q)| dist2(p, q).sqrt()).collect();
    let m = mean(d.iter().copied());
    mean(d.iter().map(|v| (v - m).powi(2)))
}

/// Linear MSE as in the Mitsuba harness: the mean over pixels and channels of the
/// squared difference of linear values.
pub fn mse_linear(a: &[[f64; 3]], reference: &[[f64; 3]]) -> f64 {
    mean(a.iter().zip(reference).map(|(p, q)| dist2(p, q))) / 3.0
}

/// Relative MSE as in the Mitsuba harness: the mean over pixels and channels of
/// `(a - ref)² / (ref² + 0.01)` on linear values.
pub fn relmse(a: &[[f64; 3]], reference: &[[f64; 3]]) -> f64 {
    let per_pixel = a
        .iter()
        .zip(reference)
        .map(|(p, q)| (0..3).map(|c| (p[c] - q[c]).powi(2) / (q[c] * q[c] + RELMSE_EPSILON)).sum::<f64>() / 3.0);
    mean(per_pixel)
}

/// The thesis' ratios of hero to random sampling (eqs. 4.9-4.12), each below 1 when
/// hero sampling is better.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ratios {
    /// `hero MSE / random MSE` (eq. 4.9).
    pub mse: f64,
    /// `random PSNR / hero PSNR` (eq. 4.10).
    pub psnr: f64,
    /// `random SSIM / hero SSIM` (eq. 4.11).
    pub ssim: f64,
    /// `hero variance / random variance` (lower is better, like the MSE).
    pub variance: f64,
}

impl Ratios {
    /// The ratios of `hero` to `random` metrics.
    pub fn new(hero: &Metrics, random: &Metrics) -> Ratios {
        Ratios {
            mse: hero.mse / random.mse,
            psnr: random.psnr / hero.psnr,
            ssim: random.ssim / hero.ssim,
            variance: hero.variance / random.variance,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn constant(n: usize, v: [f64; 3]) -> Vec<[f64; 3]> {
        vec![v; n]
    }

    #[test]
    fn l_constant_matches_the_thesis() {
        assert!((THESIS_L - 113_509.949_7).abs() < 1e-4);
        assert!((THESIS_L - 65535.0 * 3f64.sqrt()).abs() < 1e-9);
        assert!((20.0 * THESIS_L.log10() - 101.1007).abs() < 1e-4);
    }

    #[test]
    fn gaussian_window_is_normalised_and_symmetric() {
        let g = gaussian(SSIM_WINDOW);
        assert!((g.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!((g[0] - g[10]).abs() < 1e-15 && g[5] > g[4]);
    }

    #[test]
    fn linear_metrics_follow_the_mitsuba_definitions() {
        let a = constant(4, [0.5, 0.25, 0.0]);
        let b = constant(4, [0.4, 0.25, 0.1]);
        // mean over channels of d²: (0.01 + 0 + 0.01) / 3.
        assert!((mse_linear(&a, &b) - 0.02 / 3.0).abs() < 1e-15);
        let r = (0.01 / (0.16 + 0.01) + 0.0 + 0.01 / (0.01 + 0.01)) / 3.0;
        assert!((relmse(&a, &b) - r).abs() < 1e-15);
    }

    #[test]
    fn firefly_share_by_hand() {
        // 10 pixels: one is k = max(1, ceil(0.01)) = 1 pixel. Grey pixels have Y = value.
        let mut p = constant(10, [1.0, 1.0, 1.0]);
        assert!((firefly_share(&p) - 0.1).abs() < 1e-12);
        p[3] = [11.0, 11.0, 11.0]; // total 9 + 11 = 20, brightest 11
        assert!((firefly_share(&p) - 0.55).abs() < 1e-12);
        // Pure red: Y = 0.2126 R; the ratio is unchanged by the weight.
        p[3] = [11.0, 0.0, 0.0];
        let y = 0.2126 * 11.0;
        assert!((firefly_share(&p) - y / (9.0 + y)).abs() < 1e-12);
        // 2001 pixels: k = ceil(2.001) = 3 brightest (5, 4, 3) of a total 1998 + 12.
        let mut q = constant(2001, [1.0; 3]);
        q[0] = [5.0; 3];
        q[1] = [4.0; 3];
        q[2] = [3.0; 3];
        assert!((firefly_share(&q) - 12.0 / 2010.0).abs() < 1e-12);
        assert!(firefly_share(&constant(4, [0.0; 3])).is_nan());
    }

    #[test]
    fn error_variance_is_zero_for_a_uniform_error() {
        let a = constant(9, [100.0, 200.0, 300.0]);
        let b = constant(9, [110.0, 200.0, 300.0]);
        assert_eq!(error_variance(&a, &b), 0.0);
        // Half the pixels off by 10, half exact: Δ ∈ {0, 10}, variance 25.
        let mut c = a.clone();
        c.truncate(8);
        let mut d = c.clone();
        for p in d.iter_mut().take(4) {
            p[0] += 10.0;
        }
        assert!((error_variance(&c, &d) - 25.0).abs() < 1e-12);
    }
}
